//! Scenes mutated the way a bad file, a bad script or a bad merge mutates
//! them (absurd numbers, huge keyframe frames, emptied and duplicated lists,
//! dropped keys, wrong types), rendered through the bundle's C ABI by every
//! method on a small plate: each ends in a picture or a failure status with
//! a message, never a crash, an abort or a hang (each case has a deadline),
//! and the scene parser takes arbitrary bytes without panicking.

mod common;

use std::sync::mpsc;
use std::sync::Arc;
use std::time::Duration;

use morphfx::geom::RectI;
use morphfx::image::Image;
use morphfx_harness::host::{Frame, OutputSpec};
use proptest::prelude::*;
use serde_json::{json, Value};

use common::{bundle, Still};

const METHODS: [&str; 7] = [
    "field",
    "mesh",
    "triangles",
    "thin-plate",
    "mffd",
    "hybrid",
    "auto",
];

/// Numbers that have broken morph tools: huge, tiny, signed zero, powers
/// of two past integer ranges.
const ABSURD: [f64; 12] = [
    1e18,
    -1e18,
    9.2e18,
    1e308,
    -1e308,
    0.0,
    -0.0,
    1e-300,
    4294967296.0,
    -1.0,
    1e9,
    65536.5,
];

/// A valid scene using every feature type, keyframes, progress and each
/// method's settings.
fn valid(method: &str) -> Value {
    let features = |d: f64| {
        json!([
            {"type": "line", "a": [[8, 8], [40, 10]], "b": [[10.0 + d, 8], [42, 12]]},
            {"type": "point", "a": [[24, 20]], "b": [[25, 22]]},
            {"type": "polyline", "a": [[6, 26], [20, 30], [40, 26]], "b": [[7, 27], [21, 31], [41, 26]]},
            {"type": "curve", "a": [[10, 14], [24, 18], [38, 14]], "b": [[11, 15], [25, 20], [39, 15]]}
        ])
    };
    json!({
        "format": "morphfx-scene", "version": 1, "method": method,
        "field": {"a": 0.001, "b": 2, "p": 0.5},
        "mesh": {"rows": 3, "cols": 3,
            "a": [[0,0],[24,0],[48,0],[0,16],[24,16],[48,16],[0,32],[24,32],[48,32]],
            "b": [[0,0],[24,0],[48,0],[0,16],[27,18],[48,16],[0,32],[24,32],[48,32]]},
        "thin-plate": {"alpha": 100, "cell": 4},
        "mffd": {"coarsest": 2, "alpha": 0.5},
        "auto": {"levels": 3},
        "keyframes": [{"frame": 0, "features": features(0.0)}, {"frame": 10, "features": features(3.0)}],
        "progress": [[0, 0.0], [10, 1.0]]
    })
}

/// Every place in `v` a mutation can hit, as JSON pointers.
fn places(v: &Value, at: String, out: &mut Vec<String>) {
    out.push(at.clone());
    match v {
        Value::Object(m) => m
            .iter()
            .for_each(|(k, x)| places(x, format!("{at}/{k}"), out)),
        Value::Array(a) => a
            .iter()
            .enumerate()
            .for_each(|(i, x)| places(x, format!("{at}/{i}"), out)),
        _ => {}
    }
}

/// Mutation `kind` with `pick` applied at place `place` (indices modulo).
fn mutate(doc: &mut Value, place: usize, kind: u8, pick: usize) {
    let mut all = Vec::new();
    places(doc, String::new(), &mut all);
    let at = all[place % all.len()].clone();
    let Some(target) = doc.pointer_mut(&at) else {
        return;
    };
    match (kind % 6, &mut *target) {
        (0 | 1, Value::Number(_)) => *target = json!(ABSURD[pick % ABSURD.len()]),
        (2, Value::Array(a)) => a.clear(),
        (3, Value::Array(a)) if !a.is_empty() => {
            let x = a[pick % a.len()].clone();
            a.push(x);
        }
        (4, Value::Object(m)) if !m.is_empty() => {
            let k = m.keys().nth(pick % m.len()).cloned().unwrap_or_default();
            m.remove(&k);
        }
        (5, _) => {
            *target = [
                json!("line"),
                json!(null),
                json!([]),
                json!({}),
                json!(1e18),
            ][pick % 5]
                .clone()
        }
        // Numbers anywhere else: the most common corruption.
        (_, Value::Number(_)) => *target = json!(ABSURD[pick % ABSURD.len()]),
        _ => {}
    }
}

/// `scene` rendered at `time` through a Morph node, its settings applied.
fn render(scene: &str, time: f64) -> Result<Arc<Frame>, morphfx_harness::host::HostError> {
    let inst = bundle()
        .instance("net.morphfx.Morph", "OfxImageEffectContextGeneral")
        .unwrap();
    let p = plate();
    inst.connect("SourceA", p.clone()).unwrap();
    inst.connect("SourceB", p).unwrap();
    inst.set_project(48.0, 32.0);
    inst.set_int("settings_from_scene", 1).unwrap();
    inst.set_string("scene_text", scene).unwrap();
    inst.render(time, OutputSpec::default())
}

fn plate() -> Arc<Still> {
    let img = Image::from_fn(RectI::from_size(48, 32), 4, |i, j, c| {
        if c == 3 {
            1.0
        } else {
            0.5 + 0.4 * ((i as f32 * 0.37 + j as f32 * 0.23 + c as f32).sin())
        }
    });
    Arc::new(Still(Arc::new(Frame::from_image(
        &img,
        "OfxBitDepthFloat",
        false,
    ))))
}

/// Renders `scene` at `time` through the Morph node on another thread;
/// Err when it did not finish within the deadline (a hang).
fn render_within(scene: String, time: f64) -> Result<(), String> {
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        // A picture, or a failure status with a message: both fine.
        let result = render(&scene, time);
        let _ = tx.send(result.map(|_| ()).map_err(|e| e.message));
    });
    match rx.recv_timeout(Duration::from_secs(30)) {
        Ok(_) => Ok(()),
        Err(mpsc::RecvTimeoutError::Timeout) => Err("no result within 30 s".into()),
        Err(mpsc::RecvTimeoutError::Disconnected) => {
            Err("the render thread died (a panic in our host)".into())
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 300, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn mutated_scenes_render_or_fail_cleanly_with_every_method(
        method in 0usize..METHODS.len(),
        mutations in proptest::collection::vec((any::<usize>(), any::<u8>(), any::<usize>()), 1..4),
        time in prop_oneof![Just(0.0), Just(5.0), Just(10.0), Just(1e9)],
    ) {
        let mut doc = valid(METHODS[method]);
        for (place, kind, pick) in mutations {
            mutate(&mut doc, place, kind, pick);
        }
        let scene = doc.to_string();
        prop_assert_eq!(render_within(scene.clone(), time), Ok(()), "{}", scene);
    }

    #[test]
    fn the_parser_takes_arbitrary_bytes(bytes in proptest::collection::vec(any::<u8>(), 0..400)) {
        let text = String::from_utf8_lossy(&bytes);
        let _ = morphfx::scene::Scene::parse(&text);
    }
}

#[test]
fn every_unmutated_method_renders() {
    for method in METHODS {
        render(&valid(method).to_string(), 5.0)
            .unwrap_or_else(|e| panic!("{method}: {}", e.message));
    }
}
