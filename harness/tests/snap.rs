//! `morphfx snap`: polylines and curves of a scene refined onto nearby edges
//! of both plates, everything else written back as it was.

use std::path::Path;

mod common;

use morphfx::geom::RectI;
use morphfx::scene::Scene;
use morphfx_harness::io::{self, ExrPrecision, Plate};

/// A 96×64 plate with a vertical step edge at canonical x = `edge`.
fn write_step(path: &Path, edge: f64) {
    let img = morphfx::testing::step_plate(RectI::from_size(96, 64), edge);
    io::write(path, &Plate::new(img, (96, 64)), ExrPrecision::Float).unwrap();
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// `morphfx snap --scene SCENE --a A --b B -o OUT EXTRA...`.
fn run_snap(scene: &Path, a: &Path, b: &Path, out: &Path, extra: &[&str]) -> std::process::Output {
    let args = [
        "snap",
        "--scene",
        s(scene),
        "--a",
        s(a),
        "--b",
        s(b),
        "-o",
        s(out),
    ];
    common::run_morphfx(&[&args[..], extra].concat())
}

/// `morphfx snap` of `d/s.json` on `d/a.exr` and `d/b.exr` into `out`,
/// which must succeed; the scene it wrote.
fn snap_in(d: &Path, out: &Path) -> Scene {
    let r = run_snap(
        &d.join("s.json"),
        &d.join("a.exr"),
        &d.join("b.exr"),
        out,
        &[],
    );
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    Scene::parse(&std::fs::read_to_string(out).unwrap()).unwrap()
}

const SCENE: &str = r#"{"format": "morphfx-scene", "version": 1, "method": "field",
  "field": {"b": 1.5},
  "features": [
    {"name": "edge", "type": "curve", "a": [[44, 10], [45, 32], [44, 54]], "b": [[48, 10], [47, 32], [48, 54]]},
    {"name": "dot", "type": "point", "a": [[20, 20]], "b": [[22, 21]]}
  ]}"#;

#[test]
fn snap_moves_curves_onto_the_edges_of_each_plate_and_keeps_the_rest() {
    let d = common::scratch("snap");
    write_step(&d.join("a.exr"), 40.0);
    write_step(&d.join("b.exr"), 52.0);
    std::fs::write(d.join("s.json"), SCENE).unwrap();
    let scene = snap_in(&d, &d.join("snapped.json"));
    let edge = &scene.features[0];
    assert_eq!(edge.name.as_deref(), Some("edge"));
    assert_eq!(edge.kind.name(), "polyline");
    assert_eq!(edge.a.len(), 41);
    assert_eq!(edge.b.len(), 41);
    for p in &edge.a {
        assert!((p.x - 40.0).abs() < 0.5, "A point {p:?}");
    }
    for p in &edge.b {
        assert!((p.x - 52.0).abs() < 0.5, "B point {p:?}");
    }
    // Untouched: the point feature and the field settings.
    let original = Scene::parse(SCENE).unwrap();
    assert_eq!(scene.features[1], original.features[1]);
    assert_eq!(scene.settings.field, original.settings.field);
}

#[test]
fn snap_refuses_bad_input_without_writing() {
    let d = common::scratch("snap-bad");
    write_step(&d.join("a.exr"), 40.0);
    std::fs::write(d.join("s.json"), SCENE).unwrap();
    let out = d.join("snapped.json");
    // A missing plate.
    let r = run_snap(
        &d.join("s.json"),
        &d.join("a.exr"),
        &d.join("missing.exr"),
        &out,
        &[],
    );
    assert_eq!(r.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&r.stderr).contains("missing.exr"));
    assert!(!out.exists());
    // A scene keyed at two frames without --frame: which is not said.
    let key = |f: u32| {
        format!(
            r#"{{"frame": {f}, "features": [{{"type": "polyline", "a": [[44, 10], [44, 54]], "b": [[48, 10], [48, 54]]}}]}}"#
        )
    };
    let two = format!(r#"{{"keyframes": [{}, {}]}}"#, key(5), key(9));
    std::fs::write(d.join("two.json"), two).unwrap();
    let r = run_snap(
        &d.join("two.json"),
        &d.join("a.exr"),
        &d.join("a.exr"),
        &out,
        &[],
    );
    assert_eq!(r.status.code(), Some(2));
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(err.contains("--frame") && err.contains("5, 9"), "{err}");
    assert!(!out.exists());
    // Keyed at one frame, it needs none: that key is refined.
    let keyed = format!(r#"{{"keyframes": [{}]}}"#, key(5));
    std::fs::write(d.join("k.json"), keyed).unwrap();
    let r = run_snap(
        &d.join("k.json"),
        &d.join("a.exr"),
        &d.join("a.exr"),
        &out,
        &[],
    );
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let alone = std::fs::read_to_string(&out).unwrap();
    std::fs::remove_file(&out).unwrap();
    // With --frame 5 it refines that keyframe.
    let r = run_snap(
        &d.join("k.json"),
        &d.join("a.exr"),
        &d.join("a.exr"),
        &out,
        &["--frame", "5"],
    );
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let scene = Scene::parse(&std::fs::read_to_string(&out).unwrap()).unwrap();
    assert!(scene.keyframes[0].features[0]
        .a
        .iter()
        .all(|p| (p.x - 40.0).abs() < 0.5));
    assert_eq!(
        std::fs::read_to_string(&out).unwrap(),
        alone,
        "--frame 5 or none"
    );
}

#[test]
fn snap_keeps_a_closed_curve_closed_with_its_closing_span_refined() {
    let d = common::scratch("snap-closed");
    write_step(&d.join("a.exr"), 40.0);
    write_step(&d.join("b.exr"), 40.0);
    // A thin closed loop hugging the edge at x = 40: up at x = 43, back
    // down at x = 44 (the closing span runs from the top back to the start).
    let scene = r#"{"features": [{"name": "loop", "type": "curve", "closed": true,
        "a": [[43, 10], [43, 32], [43, 54], [44, 32]], "b": [[43, 10], [43, 32], [43, 54], [44, 32]]}]}"#;
    std::fs::write(d.join("s.json"), scene).unwrap();
    let snapped = snap_in(&d, &d.join("snapped.json"));
    let f = &snapped.features[0];
    assert!(f.closed, "still closed");
    // Four spans of 20 samples, the first point once.
    assert_eq!(f.a.len(), 80);
    assert_ne!(f.a[0], f.a[79]);
    for p in &f.a {
        assert!((p.x - 40.0).abs() < 0.5, "{p:?}");
    }
}
