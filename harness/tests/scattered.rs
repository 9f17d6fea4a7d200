//! The scattered-feature methods (thin-plate, mffd, hybrid) and transition
//! control end to end: scenes rendered by `morphfx` through the bundle.

use std::path::Path;

mod common;

use morphfx::features::Side;
use morphfx::geom::{PixelScale, RectD, RectI, Vec2};
use morphfx::image::Image;
use morphfx::make_warp::{self, WarpSettings};
use morphfx::scene::Scene;
use morphfx::testing::texture;
use morphfx_harness::io;

const W: usize = 128;
const H: usize = 96;

fn plate(path: &Path, colour: impl Fn(Vec2) -> [f32; 3]) -> Image {
    common::colour_plate(path, W, H, colour)
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn morph(d: &Path, scene: &str, t: &str, view: &str, extra: &[&str]) -> Image {
    std::fs::write(d.join("s.json"), scene).unwrap();
    let out_path = d.join(format!("out-{view}-{t}.exr"));
    let (sp, ap, bp) = (d.join("s.json"), d.join("a.exr"), d.join("b.exr"));
    let mut args = vec![
        "morph",
        "--scene",
        s(&sp),
        "--a",
        s(&ap),
        "--b",
        s(&bp),
        "--t",
        t,
        "--view",
        view,
        "-o",
        s(&out_path),
    ];
    args.extend_from_slice(extra);
    let out = common::run_morphfx(&args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    io::read(&out_path).unwrap().image
}

/// Point features whose in-between positions at t = 0.5 are pixel centres,
/// and a polyline (sampled into point pairs).
const FEATURES: &str = r#""features": [
    {"type": "point", "a": [[30.5, 40.5]], "b": [[34.5, 44.5]]},
    {"type": "point", "a": [[90.5, 30.5]], "b": [[86.5, 36.5]]},
    {"type": "point", "a": [[64.5, 70.5]], "b": [[60.5, 66.5]]},
    {"type": "polyline", "a": [[20, 80], [50, 84], [80, 80]], "b": [[22, 76], [52, 82], [82, 78]]}]"#;

#[test]
fn scattered_methods_render_through_the_plugin_as_the_core_does() {
    let d = common::scratch("scattered-core");
    plate(&d.join("a.exr"), texture);
    plate(&d.join("b.exr"), texture);
    for method in ["thin-plate", "mffd", "hybrid"] {
        let scene = format!(r#"{{"method": "{method}", {FEATURES}}}"#);
        let st_path = d.join(format!("st-{method}.exr"));
        morph(&d, &scene, "0.5", "warped-a", &["--stmap-a", s(&st_path)]);
        let st = io::read(&st_path).unwrap().image;

        let parsed = Scene::parse(&scene).unwrap();
        let features = parsed.features_at(0.0);
        let settings = WarpSettings {
            region: Some(RectD::new(0.0, 0.0, W as f64, H as f64)),
            ..parsed.warp_settings_at(0.0)
        };
        let core = make_warp::toward(&features, Side::A, 0.5, &settings).unwrap();
        let map = core.map_window(RectI::from_size(W, H), PixelScale::new(1.0, 1.0, 1.0));
        let at = |i: i32, j: i32| {
            let q = st.pixel(i, j);
            Vec2::new(q[0] as f64 * W as f64, q[1] as f64 * H as f64)
        };
        for j in 0..H as i32 {
            for i in 0..W as i32 {
                let (got, want) = (at(i, j), map.get(i, j));
                assert!(
                    got.distance(want) < 1e-3,
                    "{method} ({i}, {j}): plugin {got:?}, core {want:?}"
                );
            }
        }
        // Each point's in-between pixel samples A at the point.
        for f in &features[..3] {
            let mid = f.a[0].lerp(f.b[0], 0.5);
            let got = at(mid.x as i32, mid.y as i32);
            assert!(
                got.distance(f.a[0]) < 0.05,
                "{method}: {got:?} vs {:?}",
                f.a[0]
            );
        }
    }
}

#[test]
fn a_colour_ramp_dissolves_left_to_right_through_the_plugin() {
    // Identity warp (features equal on both sides): the output is the
    // closed-form dissolve (1 − r) A + r B with r = 1 − x / W at t = 0.5.
    let d = common::scratch("scattered-ramp");
    plate(&d.join("a.exr"), |_| [0.2, 0.3, 0.4]);
    plate(&d.join("b.exr"), |_| [0.8, 0.7, 0.6]);
    let scene = r#"{"method": "mffd",
        "features": [{"type": "point", "a": [[60, 50]], "b": [[60, 50]]}],
        "transition": {"colour": {"type": "procedural", "pattern": "ramp", "spread": 0.5}}}"#;
    let out = morph(&d, scene, "0.5", "morph", &[]);
    let grey = morph(
        &d,
        &scene.replace("colour", "geometry"),
        "0.5",
        "transition",
        &[],
    );
    for j in [0, 40, 95] {
        for i in 0..W as i32 {
            let r = 1.0 - (i as f64 + 0.5) / W as f64;
            let px = out.pixel(i, j);
            for (c, (a, b)) in [(0.2, 0.8), (0.3, 0.7), (0.4, 0.6)].into_iter().enumerate() {
                let want = (1.0 - r) * a + r * b;
                assert!(
                    (px[c] as f64 - want).abs() < 1e-4,
                    "({i}, {j}) c{c}: {} vs {want}",
                    px[c]
                );
            }
            assert!((grey.pixel(i, j)[0] as f64 - r).abs() < 1e-4);
        }
    }
}

#[test]
fn transitions_keep_the_end_frames_exact() {
    let d = common::scratch("scattered-ends");
    let a = plate(&d.join("a.exr"), texture);
    let b = plate(&d.join("b.exr"), |p| texture(p + Vec2::new(3.0, -2.0)));
    let scene = format!(
        r#"{{"method": "thin-plate", {FEATURES},
        "transition": {{"geometry": {{"type": "curves", "curves": [{{"feature": 0, "keys": [[0.5, 0.9]]}}]}},
                        "colour": {{"type": "procedural", "pattern": "radial", "cycles": 2}}}}}}"#
    );
    for (t, want) in [("0", &a), ("1", &b)] {
        let out = morph(&d, &scene, t, "morph", &[]);
        for j in 0..H as i32 {
            for i in 0..W as i32 {
                assert_eq!(out.pixel(i, j), want.pixel(i, j), "t {t} ({i}, {j})");
            }
        }
    }
    // In between, the curve's feature is further along than the others:
    // the grey of the transition view at its in-between position is 0.9.
    let grey = morph(&d, &scene, "0.5", "transition", &[]);
    let mid = Vec2::new(30.5, 40.5).lerp(Vec2::new(34.5, 44.5), 0.9);
    let g = grey.pixel(mid.x as i32, mid.y as i32)[0] as f64;
    assert!((g - 0.9).abs() < 0.02, "{g}");
}

/// `thin-plate: frame F side S: warm start, X + Y cycles` lines of `--verbose`.
fn plate_solves(err: &str) -> Vec<(i32, String, bool, usize)> {
    err.lines()
        .filter_map(|l| {
            let rest = l.strip_prefix("thin-plate: frame ")?;
            let (frame, rest) = rest.split_once(" side ")?;
            let (side, rest) = rest.split_once(": ")?;
            let (start, rest) = rest.split_once(" start, ")?;
            let (x, rest) = rest.split_once(" + ")?;
            let y = rest.strip_suffix(" cycles")?;
            Some((
                frame.parse().ok()?,
                side.to_string(),
                start == "warm",
                x.parse::<usize>().ok()? + y.parse::<usize>().ok()?,
            ))
        })
        .collect()
}

#[test]
fn thin_plates_solve_every_frame_cold_in_a_sequence_render() {
    // A final render's frame depends on that frame alone: a sequence
    // solves each frame's plates cold (warm starts are for the viewer), so
    // a frame alone is the same bits as in the sequence.
    let d = common::scratch("scattered-cold");
    for f in 1..=3 {
        plate(&d.join(format!("a.{f:04}.exr")), texture);
        plate(&d.join(format!("b.{f:04}.exr")), texture);
    }
    // Every point moves about a pixel a frame.
    let keyed = |dx: f64| FEATURES.replace("[[30.5, 40.5]]", &format!("[[{}, 40.5]]", 30.5 + dx));
    let scene = format!(
        r#"{{"method": "thin-plate", "thin-plate": {{"tolerance": 0.001}}, {},
        "keyframes": [{{"frame": 1, {}}}, {{"frame": 3, {}}}]}}"#,
        FEATURES,
        keyed(0.0).trim_start_matches(|c| c != '"'),
        keyed(2.0).trim_start_matches(|c| c != '"'),
    );
    std::fs::write(d.join("s.json"), &scene).unwrap();
    let render = |frames: &str, tag: &str| {
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
            frames,
            "--t",
            "0.5",
            "-o",
            s(&d.join(format!("{tag}.####.exr"))),
            "--stmap-a",
            s(&d.join(format!("{tag}-st.####.exr"))),
        ]);
        let err = String::from_utf8_lossy(&out.stderr).to_string();
        assert!(out.status.success(), "{err}");
        err
    };
    let err = render("1-3", "seq");
    let solves: Vec<_> = plate_solves(&err)
        .into_iter()
        .filter(|s| s.1 == "A")
        .collect();
    assert_eq!(solves.len(), 3, "{err}");
    assert!(solves.iter().all(|s| !s.2), "a warm start: {err}");
    let err = render("2", "alone");
    assert!(plate_solves(&err).iter().all(|s| !s.2), "{err}");
    for tag in ["", "-st"] {
        let read = |run: &str| std::fs::read(d.join(format!("{run}{tag}.0002.exr"))).unwrap();
        assert!(read("seq") == read("alone"), "frame 2{tag} differs alone");
    }
}
