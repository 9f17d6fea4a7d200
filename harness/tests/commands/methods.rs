//! The mesh and triangle methods end to end: a scene file, the `morphfx`
//! binary, the bundle through its C ABI, EXR out — checked against closed
//! forms on a ramp plate whose red and green hold each pixel's own centre, so
//! the warped plate shows where every output pixel was read from.

use std::path::Path;

use crate::common;

use morphfx::geom::{RectI, Vec2};
use morphfx::image::Image;
use morphfx_harness::io::{self, ExrPrecision, Plate};

const W: usize = 160;
const H: usize = 120;

fn write_ramp(path: &Path) {
    let img = Image::from_fn(RectI::from_size(W, H), 4, |i, j, c| match c {
        0 => i as f32 + 0.5,
        1 => j as f32 + 0.5,
        2 => 0.25,
        _ => 1.0,
    });
    let plate = Plate::new(img, (W, H));
    io::write(path, &plate, ExrPrecision::Float).unwrap();
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn morphfx_ok(args: &[&str]) {
    let out = common::run_morphfx(args);
    assert!(
        out.status.success(),
        "morphfx {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// Rows of the plate at `path`, canonical order (bottom row first).
fn read(path: &Path) -> Image {
    io::read(path).unwrap().image
}

const CENTRE: Vec2 = Vec2 { x: 80.0, y: 60.0 };
fn affine(p: Vec2) -> Vec2 {
    let d = p - CENTRE;
    CENTRE
        + Vec2::new(
            1.06 * d.x + 0.08 * d.y + 1.5,
            -0.05 * d.x + 1.04 * d.y - 2.0,
        )
}
fn affine_inverse(q: Vec2) -> Vec2 {
    let e = q - CENTRE - Vec2::new(1.5, -2.0);
    let det = 1.06 * 1.04 + 0.08 * 0.05;
    CENTRE
        + Vec2::new(
            (1.04 * e.x - 0.08 * e.y) / det,
            (0.05 * e.x + 1.06 * e.y) / det,
        )
}

/// A 9 × 9 mesh on the frame, listed top row first as a user reading an
/// image would; B moves the interior nodes by `affine`, the border is frozen.
fn mesh_scene(pass: &str) -> String {
    let mut a = Vec::new();
    let mut b = Vec::new();
    for r in (0..9).rev() {
        for c in 0..9 {
            let p = Vec2::new(c as f64 * 20.0, r as f64 * 15.0);
            let q = if r == 0 || c == 0 || r == 8 || c == 8 {
                p
            } else {
                affine(p)
            };
            a.push(format!("[{}, {}]", p.x, p.y));
            b.push(format!("[{}, {}]", q.x, q.y));
        }
    }
    format!(
        r#"{{"format": "morphfx-scene", "version": 1, "method": "mesh",
            "mesh": {{"rows": 9, "cols": 9, "pass": "{pass}", "a": [{}], "b": [{}]}}}}"#,
        a.join(","),
        b.join(",")
    )
}

/// Output pixels whose spline support is wholly inside the moved interior.
fn interior() -> Vec<(i32, i32)> {
    let mut px = Vec::new();
    for j in 0..H as i32 {
        for i in 0..W as i32 {
            let p = affine_inverse(Vec2::new(i as f64 + 0.5, j as f64 + 0.5));
            let (s, r) = (p.x / 20.0, p.y / 15.0);
            if (2.1..5.9).contains(&s) && (2.1..5.9).contains(&r) {
                px.push((i, j));
            }
        }
    }
    px
}

#[test]
fn mesh_warps_reproduce_an_affine_interior_through_the_plugin() {
    let d = common::scratch("mesh-affine");
    write_ramp(&d.join("a.exr"));
    for pass in ["two-pass", "one-pass"] {
        std::fs::write(d.join("m.json"), mesh_scene(pass)).unwrap();
        let out = d.join(format!("{pass}.exr"));
        let st = d.join(format!("{pass}-st.exr"));
        morphfx_ok(&[
            "warp",
            "--scene",
            s(&d.join("m.json")),
            "--input",
            s(&d.join("a.exr")),
            "--t",
            "1",
            "-o",
            s(&out),
            "--stmap",
            s(&st),
        ]);
        let (img, st) = (read(&out), read(&st));
        let pixels = interior();
        assert!(pixels.len() > 2000);
        for (i, j) in pixels {
            let want = affine_inverse(Vec2::new(i as f64 + 0.5, j as f64 + 0.5));
            let px = img.pixel(i, j);
            assert!(
                (px[0] as f64 - want.x).abs() < 2e-3 && (px[1] as f64 - want.y).abs() < 2e-3,
                "{pass} ({i}, {j}): {px:?} vs {want:?}"
            );
            // The ST map is the one-pass map in both modes.
            let q = st.pixel(i, j);
            let (x, y) = (q[0] as f64 * W as f64, q[1] as f64 * H as f64);
            assert!(
                (x - want.x).abs() < 1e-3 && (y - want.y).abs() < 1e-3,
                "{pass} ST ({i}, {j}): ({x}, {y}) vs {want:?}"
            );
        }
    }
}

#[test]
fn triangles_map_feature_points_exactly_and_leave_no_pixel_unwritten() {
    let d = common::scratch("triangles");
    write_ramp(&d.join("a.exr"));
    // B positions on pixel centres, so at t = 1 those output pixels must read
    // exactly the A positions.
    let pairs = [
        ([30.25, 40.5], [32.5, 44.5]),
        ([70.0, 80.0], [66.5, 77.5]),
        ([120.5, 30.5], [125.5, 35.5]),
        ([100.0, 95.0], [96.5, 100.5]),
        ([50.0, 20.0], [52.5, 18.5]),
    ];
    let features: Vec<String> = pairs
        .iter()
        .map(|(a, b)| {
            format!(
                r#"{{"type": "point", "a": [[{}, {}]], "b": [[{}, {}]]}}"#,
                a[0], a[1], b[0], b[1]
            )
        })
        .collect();
    let scene = format!(
        r#"{{"method": "triangles", "features": [{}]}}"#,
        features.join(",")
    );
    std::fs::write(d.join("t.json"), scene).unwrap();
    let out = d.join("w.exr");
    morphfx_ok(&[
        "warp",
        "--scene",
        s(&d.join("t.json")),
        "--input",
        s(&d.join("a.exr")),
        "--t",
        "1",
        "-o",
        s(&out),
    ]);
    let img = read(&out);
    for (a, b) in pairs {
        let px = img.pixel((b[0] - 0.5) as i32, (b[1] - 0.5) as i32);
        assert!(
            (px[0] as f64 - a[0]).abs() < 1e-3 && (px[1] as f64 - a[1]).abs() < 1e-3,
            "{b:?}: read {px:?}, want {a:?}"
        );
    }
    // No cracks or dots: every pixel reads from inside the plate (alpha 1 and
    // blue intact up to filter round-off, positions within the plate).
    for j in 0..H as i32 {
        for i in 0..W as i32 {
            let px = img.pixel(i, j);
            assert!(
                (px[3] - 1.0).abs() < 1e-5 && (px[2] - 0.25).abs() < 1e-5,
                "({i}, {j}): {px:?}"
            );
            let inside = |v: f32, n: usize| (0.499..=n as f32 - 0.499).contains(&v);
            assert!(inside(px[0], W) && inside(px[1], H), "({i}, {j}): {px:?}");
        }
    }
    // And the morph renders through the same triangulation for both sides.
    let b = d.join("b.exr");
    write_ramp(&b);
    morphfx_ok(&[
        "morph",
        "--scene",
        s(&d.join("t.json")),
        "--a",
        s(&d.join("a.exr")),
        "--b",
        s(&b),
        "--t",
        "0.5",
        "-o",
        s(&d.join("m.exr")),
    ]);
}

#[test]
fn a_folded_mesh_is_bad_input_naming_the_cell() {
    let d = common::scratch("mesh-bad");
    write_ramp(&d.join("a.exr"));
    let scene = r#"{"method": "mesh", "mesh": {"rows": 3, "cols": 3,
        "a": [[0,0],[80,0],[160,0],[0,60],[80,60],[160,60],[0,120],[80,120],[160,120]],
        "b": [[0,0],[80,0],[160,0],[0,60],[150,20],[160,60],[0,120],[80,120],[160,120]]}}"#;
    std::fs::write(d.join("m.json"), scene).unwrap();
    let out = d.join("w.exr");
    let r = common::run_morphfx(&[
        "warp",
        "--scene",
        s(&d.join("m.json")),
        "--input",
        s(&d.join("a.exr")),
        "--t",
        "1",
        "-o",
        s(&out),
    ]);
    let err = String::from_utf8_lossy(&r.stderr);
    assert_eq!(r.status.code(), Some(2), "{err}");
    assert!(
        err.contains("mesh b") && err.contains("cell (row 0, col 1)"),
        "{err}"
    );
    assert!(!out.exists());
}
