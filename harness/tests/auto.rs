//! Method `auto` end to end: plates where B is A under a known smooth warp,
//! rendered by `morphfx` through the bundle; the ST map it writes must find
//! the known warp, and must be the core's own answer for the same plates.

use std::path::Path;

mod common;

use morphfx::features::Side;
use morphfx::geom::{RectD, Vec2};
use morphfx::image::Image;
use morphfx::testing::texture;
use morphfx::warp::auto::{self, AutoSettings, WorkImage};
use morphfx::warp::Warp;
use morphfx_harness::io;

const W: usize = 160;
const H: usize = 120;

/// The known reverse warp: B(y) = A(H(y)); up to 5 px, still at the border.
fn h(p: Vec2) -> Vec2 {
    let (u, v) = (p.x / W as f64, p.y / H as f64);
    let bump = (std::f64::consts::PI * u).sin() * (std::f64::consts::PI * v).sin();
    p + Vec2::new(5.0 * bump * (2.0 * v).cos(), -4.0 * bump * (3.0 * u).sin())
}

fn plate(path: &Path, warp: impl Fn(Vec2) -> Vec2) -> Image {
    common::colour_plate(path, W, H, |p| texture(warp(p)))
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

const SCENE: &str =
    r#"{ "format": "morphfx-scene", "version": 1, "method": "auto", "features": [] }"#;

#[test]
fn auto_finds_a_known_warp_through_the_plugin_as_the_core_does() {
    let d = common::scratch("auto-known");
    let a = plate(&d.join("a.exr"), |p| p);
    let b = plate(&d.join("b.exr"), h);
    std::fs::write(d.join("s.json"), SCENE).unwrap();
    let st_path = d.join("st.exr");
    let out = common::run_morphfx(&[
        "morph",
        "--scene",
        s(&d.join("s.json")),
        "--a",
        s(&d.join("a.exr")),
        "--b",
        s(&d.join("b.exr")),
        "--t",
        "1",
        "--view",
        "warped-a",
        "-o",
        s(&d.join("wa.exr")),
        "--stmap-a",
        s(&st_path),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let st = io::read(&st_path).unwrap().image;

    // The core on the same plates.
    let frame = RectD::new(0.0, 0.0, W as f64, H as f64);
    let (corr, _) = auto::correspond(
        &WorkImage::from_view(&a.view()),
        frame,
        &WorkImage::from_view(&b.view()),
        frame,
        &[],
        20,
        &AutoSettings::default(),
        None,
    )
    .unwrap();
    let core = corr.toward(Side::A, 1.0);

    let mut errors = Vec::new();
    for j in 8..H as i32 - 8 {
        for i in 8..W as i32 - 8 {
            let y = Vec2::new(i as f64 + 0.5, j as f64 + 0.5);
            let q = st.pixel(i, j);
            let got = Vec2::new(q[0] as f64 * W as f64, q[1] as f64 * H as f64);
            let want = core.map(y);
            assert!(
                got.distance(want) < 1e-3,
                "({i}, {j}): plugin {got:?}, core {want:?}"
            );
            errors.push(got.distance(h(y)));
        }
    }
    errors.sort_by(f64::total_cmp);
    let (median, p90) = (errors[errors.len() / 2], errors[errors.len() * 9 / 10]);
    assert!(
        median < 0.5 && p90 < 1.0,
        "known warp missed: median {median:.2} px, 90% {p90:.2} px"
    );
}

#[test]
fn auto_needs_two_images() {
    let d = common::scratch("auto-warp");
    plate(&d.join("a.exr"), |p| p);
    std::fs::write(d.join("s.json"), SCENE).unwrap();
    let out = common::run_morphfx(&[
        "warp",
        "--scene",
        s(&d.join("s.json")),
        "--input",
        s(&d.join("a.exr")),
        "-o",
        s(&d.join("w.exr")),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("Morph node"), "{err}");
    assert!(!d.join("w.exr").exists());
}

#[test]
fn verbose_sequences_print_the_work_table_and_start_warm_when_asked() {
    let d = common::scratch("auto-seq");
    for f in [1, 2] {
        plate(&d.join(format!("a.{f:04}.exr")), |p| p);
        plate(&d.join(format!("b.{f:04}.exr")), |p| {
            h(p) + Vec2::new(0.3 * f as f64, 0.0)
        });
    }
    // Warm starts are off by default (chunks would differ): asked for here.
    let warm = SCENE.replace(
        r#""features""#,
        r#""auto": {"warm_start": true}, "features""#,
    );
    std::fs::write(d.join("s.json"), warm).unwrap();
    let out = common::run_morphfx(&[
        "--verbose",
        "morph",
        "--scene",
        s(&d.join("s.json")),
        "--a",
        s(&d.join("a.####.exr")),
        "--b",
        s(&d.join("b.####.exr")),
        "--frames",
        "1-2",
        "--t",
        "0.5",
        "-o",
        s(&d.join("m.####.exr")),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("frame 1: 160x120 to 160x120, cold start"),
        "{err}"
    );
    assert!(
        err.contains("frame 2: 160x120 to 160x120, warm start"),
        "{err}"
    );
    assert!(err.contains("level") && err.contains("colour"), "{err}");
    assert!(d.join("m.0002.exr").exists());
}
