//! Renders under load, through the C ABI: four instances at once, each
//! rendering its frames in 8 concurrent tiles, at random frames and render
//! scales, while their lines change (set, then instance-changed), their
//! caches are purged and instances are made and dropped, must give every
//! picture bit for bit as a serial render of the same request does, and
//! never deadlock (the whole run has a deadline).

use std::collections::HashMap;
use std::sync::{mpsc, Arc};
use std::time::Duration;

mod common;

use morphfx::image::Image;
use morphfx::testing::Lcg;
use morphfx_harness::host::{Instance, OutputSpec};

use common::bundle;

const W: usize = 64;
const H: usize = 48;

/// Three line layouts a user might switch between.
const LAYOUTS: [[f64; 8]; 3] = [
    [10.0, 10.0, 40.0, 12.0, 14.0, 8.0, 44.0, 15.0],
    [20.0, 30.0, 50.0, 20.0, 18.0, 34.0, 52.0, 26.0],
    [8.0, 40.0, 8.0, 8.0, 12.0, 42.0, 10.0, 6.0],
];

/// A Morph instance on two textured plates, every frame the same plates.
fn instance() -> Instance<'static> {
    let inst = bundle()
        .instance("net.morphfx.Morph", "OfxImageEffectContextGeneral")
        .unwrap();
    common::connect_textured(&inst, &[("SourceA", 0.0), ("SourceB", 1.9)], (W, H));
    inst.set_project(W as f64, H as f64);
    inst.set_int("line_count", 1).unwrap();
    inst
}

/// Sets layout `k` as a user edits it: the value, then instance-changed.
fn use_layout(inst: &Instance<'_>, k: usize) {
    let v = LAYOUTS[k];
    for (n, id) in ["a_start", "a_end", "b_start", "b_end"].iter().enumerate() {
        let id = format!("line1_{id}");
        inst.set_double(&id, &v[2 * n..2 * n + 2], None).unwrap();
        inst.instance_changed(&id, 0.0).unwrap();
    }
}

/// Every method lines alone can drive (a mesh needs a scene's meshes).
/// `thin-plate` and `auto` start from the frame before only in a sequential
/// render, which this random-access host never asks for: here, too, the
/// result depends on the request alone.
const METHODS: [&str; 6] = ["field", "triangles", "mffd", "thin-plate", "hybrid", "auto"];

/// One request: method, layout, time (progress follows it), render scale.
type Request = (usize, usize, u32, u32);

fn render(inst: &Instance<'_>, (method, layout, time, scale): Request, tiles: usize) -> Image {
    let s = [1.0, 0.5, 0.25][scale as usize];
    inst.set_choice("method", METHODS[method]).unwrap();
    inst.set_double("progress", &[time as f64 / 10.0], None)
        .unwrap();
    use_layout(inst, layout);
    let spec = OutputSpec {
        identity: false,
        render_scale: (s, s),
        tiles,
        ..OutputSpec::default()
    };
    inst.render(time as f64, spec).unwrap().to_image()
}

#[test]
fn four_instances_rendering_tiles_concurrently_match_serial_renders() {
    // Every request, rendered serially on one instance, one tile at a time.
    let mut requests: Vec<Request> = Vec::new();
    for method in 0..METHODS.len() {
        for layout in 0..LAYOUTS.len() {
            for time in [0, 5, 10] {
                for scale in 0..3 {
                    requests.push((method, layout, time, scale));
                }
            }
        }
    }
    let serial = instance();
    let expected: HashMap<Request, Image> = requests
        .iter()
        .map(|&r| (r, render(&serial, r, 1)))
        .collect();
    drop(serial);
    let expected = Arc::new(expected);
    let requests = Arc::new(requests);

    let (done, finished) = mpsc::channel();
    let workers: Vec<_> = (0..4u64)
        .map(|w| {
            let (expected, requests, done) = (expected.clone(), requests.clone(), done.clone());
            std::thread::spawn(move || {
                let mut rng = Lcg::new(w + 1);
                let mut inst = instance();
                for n in 0..40 {
                    let r = requests[(rng.unit() * requests.len() as f64) as usize];
                    match n % 8 {
                        // Caches purged between renders, as a host under
                        // memory pressure does.
                        3 => inst.purge_caches().unwrap(),
                        // The instance dropped and a new one made.
                        7 => inst = instance(),
                        _ => {}
                    }
                    let got = render(&inst, r, 8);
                    assert!(got == expected[&r], "worker {w}, render {n}: {r:?} differs");
                }
                let _ = done.send(w);
            })
        })
        .collect();
    drop(done);
    for _ in 0..4 {
        finished
            .recv_timeout(Duration::from_secs(300))
            .expect("every worker finished (no deadlock, no panic)");
    }
    for w in workers {
        w.join().unwrap();
    }
}
