//! Sequences through the `morphfx` binary and the bundle: keyframed features
//! at in-between frames, sequence renders against single-frame renders,
//! EXR precision round trips, and OpenImageIO reading our outputs.

use std::path::Path;

use crate::common;
use std::process::Command;

use morphfx::geom::RectI;
use morphfx::image::Image;
use morphfx_harness::io::{self, ExrPrecision, Plate};

fn morphfx(args: &[&str]) {
    let out = common::run_morphfx(args);
    assert!(
        out.status.success(),
        "morphfx {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

fn tmp(name: &str) -> common::Scratch {
    common::scratch(name)
}

fn write_plate(path: &Path, w: usize, h: usize, seed: f32, precision: ExrPrecision) {
    let img = Image::from_fn(RectI::from_size(w, h), 4, |i, j, c| {
        // Multiples of 1/256 in [0, 4): exact in half as well as float.
        let v = ((i as f32 * 0.37 + j as f32 * 0.11 + seed + c as f32).sin() + 1.0) * 2.0;
        (v * 256.0).floor() / 256.0
    });
    let plate = Plate::new(img, (w, h));
    io::write(path, &plate, precision).unwrap();
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// One line, same on A at both keys; on B it sits (7, −5) away at frame 1001
/// and (−3, 5) away at 1011. A single line pair of equal length and direction
/// is a pure translation, so at t = 1 the map at frame 1006 must translate by
/// the halfway offset (2, 0).
const KEYED: &str = r#"{"format": "morphfx-scene", "version": 1, "method": "field",
  "field": {"evaluation": "exact"},
  "keyframes": [
    {"frame": 1001, "features": [{"type": "line", "a": [[10, 10], [40, 10]], "b": [[17, 5], [47, 5]]}]},
    {"frame": 1011, "features": [{"type": "line", "a": [[10, 10], [40, 10]], "b": [[7, 15], [37, 15]]}]}
  ]}"#;

#[test]
fn keyframed_features_interpolate_at_an_in_between_frame() {
    let d = tmp("keys");
    write_plate(&d.join("a.1006.exr"), 64, 48, 0.0, ExrPrecision::Float);
    std::fs::write(d.join("s.morph.json"), KEYED).unwrap();
    morphfx(&[
        "warp",
        "--scene",
        s(&d.join("s.morph.json")),
        "--input",
        s(&d.join("a.####.exr")),
        "--frames",
        "1006",
        "--t",
        "1",
        "--view",
        "stmap",
        "-o",
        s(&d.join("st.####.exr")),
    ]);
    assert_translation(&d.join("st.1006.exr"), (2.0, 0.0), 1e-4);
}

/// The 64×48 ST map at `path` is the translation of every pixel centre by
/// `-shift` (normalised), within `tol` of a unit square.
fn assert_translation(path: &Path, shift: (f32, f32), tol: f32) {
    let st = io::read(path).unwrap().image;
    for j in 0..48 {
        for i in 0..64 {
            let px = st.pixel(i, j);
            let want = (
                (i as f32 + 0.5 - shift.0) / 64.0,
                (j as f32 + 0.5 - shift.1) / 48.0,
            );
            assert!(
                (px[0] - want.0).abs() < tol && (px[1] - want.1).abs() < tol,
                "({i},{j}): {px:?}, want {want:?}"
            );
        }
    }
}

/// A keyed 3 × 3 mesh on the 48 × 32 plates: B's centre node moves.
const KEYED_MESH: &str = r#"{"format": "morphfx-scene", "version": 1, "method": "mesh",
  "mesh": {"rows": 3, "cols": 3, "keyframes": [
    {"frame": 1001, "a": [[0,0],[24,0],[48,0],[0,16],[24,16],[48,16],[0,32],[24,32],[48,32]],
                    "b": [[0,0],[24,0],[48,0],[0,16],[27,14],[48,16],[0,32],[24,32],[48,32]]},
    {"frame": 1004, "a": [[0,0],[24,0],[48,0],[0,16],[24,16],[48,16],[0,32],[24,32],[48,32]],
                    "b": [[0,0],[24,0],[48,0],[0,16],[21,19],[48,16],[0,32],[24,32],[48,32]]}]}}"#;

/// Every method's keyed scene over frames 1001–1004, progress keyed too.
fn every_method_scene() -> Vec<(&'static str, String)> {
    let progress = r#""progress": [[1001, 0.0], [1004, 1.0]], "keyframes""#;
    let mut scenes: Vec<(&str, String)> =
        ["field", "triangles", "thin-plate", "mffd", "hybrid", "auto"]
            .into_iter()
            .map(|m| {
                let scene = KEYED
                    .replace(r#""keyframes""#, progress)
                    .replace(r#""method": "field""#, &format!(r#""method": "{m}""#));
                (m, scene)
            })
            .collect();
    scenes.push((
        "mesh",
        KEYED_MESH.replace(
            r#""mesh": {"#,
            r#""progress": [[1001, 0.0], [1004, 1.0]], "mesh": {"#,
        ),
    ));
    scenes
}

#[test]
fn a_sequence_render_equals_single_frame_renders_whatever_the_chunking() {
    let d = tmp("chunks");
    for f in 1001..=1004 {
        write_plate(
            &d.join(format!("a.{f}.exr")),
            48,
            32,
            f as f32 * 0.3,
            ExrPrecision::Float,
        );
        write_plate(
            &d.join(format!("b.{f}.exr")),
            48,
            32,
            f as f32 * 0.7,
            ExrPrecision::Float,
        );
    }
    // Every method: warm starts and caches must not carry one frame's
    // solve into the next in a way a chunk starting there could not.
    for (method, scene) in every_method_scene() {
        let scene_path = d.join(format!("{method}.morph.json"));
        std::fs::write(&scene_path, scene).unwrap();
        let render = |frames: &str, out: &str| {
            morphfx(&[
                "morph",
                "--scene",
                s(&scene_path),
                "--a",
                s(&d.join("a.####.exr")),
                "--b",
                s(&d.join("b.####.exr")),
                "--frames",
                frames,
                "-o",
                s(&d.join(format!("{method}-{out}"))),
            ])
        };
        render("1001-1004", "whole.####.exr");
        render("1001-1002", "chunk.####.exr");
        render("1003-1004", "chunk.####.exr");
        for f in 1001..=1004 {
            render(&f.to_string(), "single.####.exr");
        }
        let read = |name: String| std::fs::read(d.join(name)).unwrap();
        for f in 1001..=1004 {
            let whole = read(format!("{method}-whole.{f}.exr"));
            for other in ["chunk", "single"] {
                assert!(
                    whole == read(format!("{method}-{other}.{f}.exr")),
                    "{method}, frame {f}: {other} differs from the sequence render"
                );
            }
        }
        // The in-between frames really are in between (not a copy of A).
        let mid = io::read(&d.join(format!("{method}-whole.1002.exr")))
            .unwrap()
            .image;
        let a = io::read(&d.join("a.1002.exr")).unwrap().image;
        assert_ne!(mid, a, "{method}");
        if method != "field" {
            continue;
        }
        // Farms' stepped ranges and lists render exactly the frames they
        // name, each as the sequence render made it.
        render("1001-1004x3", "stepped.####.exr");
        render("1001-1004:2,1004", "colon.####.exr");
        for (out, frames) in [("stepped", [1001, 1004]), ("colon", [1001, 1003])] {
            for f in 1001..=1004 {
                let path = d.join(format!("field-{out}.{f}.exr"));
                let named = frames.contains(&f) || (out == "colon" && f == 1004);
                assert_eq!(path.exists(), named, "{out}: frame {f}");
                if named {
                    assert!(
                        read(format!("field-whole.{f}.exr")) == std::fs::read(&path).unwrap(),
                        "{out}: frame {f}"
                    );
                }
            }
        }
    }
}

/// `morphfx morph` of `src` with itself at `t` through `scene` into `out`,
/// with an optional flag.
fn morph_itself(scene: &Path, src: &Path, t: &str, out: &Path, flag: Option<&str>) {
    let mut args = vec![
        "morph",
        "--scene",
        s(scene),
        "--a",
        s(src),
        "--b",
        s(src),
        "--t",
        t,
        "-o",
        s(out),
    ];
    args.extend(flag);
    morphfx(&args);
}

#[test]
fn float_and_half_exr_round_trip_bit_exactly() {
    let d = tmp("exr");
    for (precision, flag) in [
        (ExrPrecision::Float, None),
        (ExrPrecision::Half, Some("--half")),
    ] {
        let src = d.join("src.exr");
        write_plate(&src, 40, 24, 0.5, precision);
        let read = io::read(&src).unwrap();
        // Writing what we read gives the same pixels again.
        let again = d.join("again.exr");
        io::write(&again, &read, precision).unwrap();
        assert_eq!(io::read(&again).unwrap().image, read.image, "{precision:?}");
        // Through the plugin at t = 0 with an identity warp: pixels unchanged.
        std::fs::write(
            d.join("s.morph.json"),
            r#"{"format": "morphfx-scene", "version": 1,
                "features": [{"type": "line", "a": [[5, 5], [30, 5]], "b": [[5, 5], [30, 5]]}]}"#,
        )
        .unwrap();
        let (out, scene) = (d.join("out.exr"), d.join("s.morph.json"));
        morph_itself(&scene, &src, "0", &out, flag);
        assert_eq!(
            io::read(&out).unwrap().image,
            read.image,
            "{precision:?} through the plugin"
        );
    }
}

/// The contract's default: an output keeps its input's precision (half in,
/// half out); `--half` and `--float` override. Read back from the written
/// header by the exr crate, not by our own probe.
#[test]
fn outputs_keep_the_inputs_precision_unless_told() {
    let d = tmp("precision");
    let scene = d.join("s.morph.json");
    std::fs::write(
        &scene,
        r#"{"format": "morphfx-scene", "version": 1,
            "features": [{"type": "line", "a": [[5, 5], [30, 5]], "b": [[6, 5], [30, 7]]}]}"#,
    )
    .unwrap();
    let written_half = |path: &Path| {
        let meta = exr::meta::MetaData::read_from_file(path, false).unwrap();
        let types: Vec<_> = meta.headers[0]
            .channels
            .list
            .iter()
            .map(|c| c.sample_type)
            .collect();
        assert!(types.windows(2).all(|w| w[0] == w[1]), "{types:?}");
        types[0] == exr::meta::attribute::SampleType::F16
    };
    for (input, flag, want_half) in [
        (ExrPrecision::Half, None, true),
        (ExrPrecision::Float, None, false),
        (ExrPrecision::Half, Some("--float"), false),
        (ExrPrecision::Float, Some("--half"), true),
    ] {
        let src = d.join("src.exr");
        write_plate(&src, 40, 24, 0.5, input);
        let out = d.join("out.exr");
        morph_itself(&scene, &src, "0.5", &out, flag);
        assert_eq!(written_half(&out), want_half, "{input:?} with {flag:?}");
    }
}

/// OpenImageIO, an independent EXR reader, sees the pixels we think we wrote.
#[test]
fn openimageio_reads_our_outputs_as_we_do() {
    if Command::new("oiiotool").arg("--version").output().is_err() {
        assert!(
            common::may_skip_without("oiiotool"),
            "oiiotool was installed for this run but does not start"
        );
        eprintln!("skipped: oiiotool is not installed (apt-get install openimageio-tools)");
        return;
    }
    let d = tmp("oiio");
    for (precision, name) in [
        (ExrPrecision::Float, "f.exr"),
        (ExrPrecision::Half, "h.exr"),
    ] {
        let p = d.join(name);
        write_plate(&p, 16, 8, 0.2, precision);
        let ours = io::read(&p).unwrap().image;
        let dump = Command::new("oiiotool")
            .arg("--dumpdata")
            .arg(&p)
            .output()
            .expect("oiiotool runs");
        assert!(
            dump.status.success(),
            "{}",
            String::from_utf8_lossy(&dump.stderr)
        );
        let text = String::from_utf8_lossy(&dump.stdout);
        let mut seen = 0;
        for line in text.lines() {
            // "    Pixel (x, y): r g b a"
            let Some(rest) = line.trim().strip_prefix("Pixel (") else {
                continue;
            };
            let (xy, values) = rest.split_once("):").unwrap();
            let (x, y) = xy.split_once(',').unwrap();
            let (x, y): (i32, i32) = (x.trim().parse().unwrap(), y.trim().parse().unwrap());
            let values: Vec<f32> = values
                .split_whitespace()
                .map(|v| v.parse().unwrap())
                .collect();
            // OIIO counts rows from the top; ours from the bottom.
            let j = 8 - 1 - y;
            assert_eq!(values, ours.pixel(x, j), "{name} pixel ({x}, {y})");
            seen += 1;
        }
        assert_eq!(seen, 16 * 8, "{name}: oiiotool listed every pixel");
        // "file :   16 x    8, 4 channel, half openexr"
        let header = text.lines().next().unwrap_or_default();
        let words: Vec<&str> = header.split_whitespace().collect();
        let kind = if precision == ExrPrecision::Half {
            "half"
        } else {
            "float"
        };
        assert!(
            header.contains("16 x    8, 4 channel") && words.contains(&kind),
            "{name}: {header}"
        );
    }
}

/// The same in-between as the keyframed scene, but keyed in the node's line
/// slot through the host's param keyframes (`--line N@FRAME=...`).
#[test]
fn host_keyed_line_slots_interpolate_at_an_in_between_frame() {
    let d = tmp("slots");
    write_plate(&d.join("a.1006.exr"), 64, 48, 0.0, ExrPrecision::Float);
    morphfx(&[
        "warp",
        "--line",
        "1@1001=10,10,40,10,17,5,47,5",
        "--line",
        "1@1011=10,10,40,10,7,15,37,15",
        "--input",
        s(&d.join("a.####.exr")),
        "--frames",
        "1006",
        "--t",
        "1",
        "--view",
        "stmap",
        "-o",
        s(&d.join("st.####.exr")),
    ]);
    // Adaptive evaluation (the node's default): within its 0.05 px tolerance.
    assert_translation(&d.join("st.1006.exr"), (2.0, 0.0), 0.05 / 48.0);
    // A malformed slot is bad input, named.
    let out = common::run_morphfx(&[
        "warp",
        "--line",
        "65=1,2,3,4,5,6,7,8",
        "--input",
        s(&d.join("a.1006.exr")),
        "-o",
        s(&d.join("never.exr")),
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--line 65="));
    assert!(!d.join("never.exr").exists());
}
