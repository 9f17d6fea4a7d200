//! `morphfx morph|warp --mask --timing --param` and `morphfx params` end to
//! end: the mask's closed form through EXR and PNG, the timing matte, and
//! bad input refused with exit 2 before anything is written.

use std::path::{Path, PathBuf};

use crate::common;
use crate::common::{morphfx_ok as ok, morphfx_said as morphfx};

use morphfx::geom::RectI;
use morphfx::image::Image;
use morphfx_harness::io::{self, Colour, ExrPrecision, OutputFormat, Plate};

const W: usize = 80;
const H: usize = 60;
const LINE: &str = "1=10,10,60,14,18,6,66,22";
/// A line that stays put: the warps are the identity.
const STILL_LINE: &str = "1=10,10,60,10,10,10,60,10";

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// An opaque textured plate in `[0.1, 0.9]`, written as a float EXR.
fn plate(dir: &Path, name: &str, seed: f32) -> PathBuf {
    let img = Image::from_fn(RectI::from_size(W, H), 4, |i, j, c| {
        if c == 3 {
            1.0
        } else {
            0.5 + 0.4 * (i as f32 * 0.29 + j as f32 * 0.13 + seed + c as f32).sin()
        }
    });
    let p = dir.join(name);
    io::write(&p, &Plate::new(img, (W, H)), ExrPrecision::Float).unwrap();
    p
}

/// A mask of another size than the plates, 8-bit PNG (raw code values):
/// alpha a ramp across x.
fn mask_png(dir: &Path) -> (PathBuf, Image) {
    let (w, h) = (50, 40);
    let img = Image::from_fn(RectI::from_size(w, h), 4, |i, _, c| {
        if c == 3 {
            (i * 5) as f32 / 255.0
        } else {
            1.0
        }
    });
    let p = dir.join("mask.png");
    let format = OutputFormat {
        colour: Colour::Raw,
        ..OutputFormat::new(ExrPrecision::Float)
    };
    io::write_as(&p, &Plate::new(img.clone(), (w, h)), format).unwrap();
    (p, img)
}

fn read(p: &Path, colour: Colour) -> Image {
    io::read_as(p, colour).unwrap().image
}

/// The full warp of plate `a` at t = 1, no mask, and the plate itself.
fn unmasked(d: &Path, a: &Path) -> (Image, Image) {
    let full = d.join("full.exr");
    ok(&[
        "warp",
        "--line",
        LINE,
        "--input",
        s(a),
        "--t",
        "1",
        "-o",
        s(&full),
    ]);
    (read(&full, Colour::Raw), read(a, Colour::Raw))
}

#[test]
fn a_mask_and_mix_through_exr_and_png_match_the_closed_form() {
    let d = common::scratch("mask-cli");
    let a = plate(&d, "a.exr", 0.0);
    let (mask, m) = mask_png(&d);
    let (effect, src) = unmasked(&d, &a);
    // The mask's pixel rows are numbered from its own top: its display
    // window is 40 high, bottom-aligned with the plates' origin.
    let alpha = |i: i32, j: i32| {
        if (i as usize) < m.width() && (j as usize) < m.height() {
            m.pixel(i, j)[3]
        } else {
            0.0
        }
    };
    for (out, colour, tolerance) in [
        ("masked.exr", Colour::Raw, 1e-5),
        ("masked.png", Colour::Raw, 1.0 / 255.0 + 1e-4),
    ] {
        let out = d.join(out);
        ok(&[
            "warp",
            "--line",
            LINE,
            "--input",
            s(&a),
            "--t",
            "1",
            "--mask",
            s(&mask),
            "--param",
            "mix=0.5",
            "--raw",
            "-o",
            s(&out),
        ]);
        let got = read(&out, colour);
        for j in 0..H as i32 {
            for i in 0..W as i32 {
                for c in 0..3 {
                    let (e, sv) = (effect.pixel(i, j)[c], src.pixel(i, j)[c]);
                    let want = sv + (e - sv) * 0.5 * alpha(i, j);
                    let g = got.pixel(i, j)[c];
                    assert!(
                        (g - want).abs() <= tolerance,
                        "{} ({i}, {j}) {c}: {g} vs {want}",
                        out.display()
                    );
                }
            }
        }
    }
}

#[test]
fn a_timing_matte_on_the_command_line_paces_the_dissolve() {
    let d = common::scratch("timing-cli");
    let flat = |name: &str, v: f32| {
        let img = Image::from_fn(
            RectI::from_size(W, H),
            4,
            |_, _, c| {
                if c == 3 {
                    1.0
                } else {
                    v
                }
            },
        );
        let p = d.join(name);
        io::write(&p, &Plate::new(img, (W, H)), ExrPrecision::Float).unwrap();
        p
    };
    let (a, b) = (flat("a.exr", 0.2), flat("b.exr", 0.8));
    let matte = Image::from_fn(RectI::from_size(W, H), 4, |i, _, _| {
        i as f32 / (W - 1) as f32
    });
    let mp = d.join("timing.exr");
    io::write(&mp, &Plate::new(matte.clone(), (W, H)), ExrPrecision::Float).unwrap();
    let out = d.join("out.exr");
    ok(&[
        "morph",
        "--line",
        STILL_LINE,
        "--a",
        s(&a),
        "--b",
        s(&b),
        "--t",
        "0.5",
        "--timing",
        s(&mp),
        "--param",
        "transition_spread=0.5",
        "-o",
        s(&out),
    ]);
    let got = read(&out, Colour::Raw);
    for i in 0..W as i32 {
        let g = matte.pixel(i, 3)[3] as f64;
        let rate = ((0.5 - 0.5 * g) / 0.5).clamp(0.0, 1.0);
        let want = (0.2 + (0.8 - 0.2) * rate) as f32;
        assert!((got.pixel(i, 3)[0] - want).abs() < 1e-5, "column {i}");
    }
}

#[test]
fn unreadable_or_missing_mattes_and_bad_params_exit_2_writing_nothing() {
    let d = common::scratch("mattes-bad");
    let a = plate(&d, "a.exr", 0.0);
    let seq_a = d.join("a.####.exr");
    for f in 1..=3 {
        std::fs::copy(&a, d.join(format!("a.{f:04}.exr"))).unwrap();
    }
    // Frames 1 and 2 of the mask exist, 3 does not.
    let (mask, _) = mask_png(&d);
    std::fs::copy(&mask, d.join("m.0001.png")).unwrap();
    std::fs::copy(&mask, d.join("m.0002.png")).unwrap();
    let garbage = d.join("garbage.exr");
    std::fs::write(&garbage, b"not an exr").unwrap();
    let out = d.join("out.####.exr");
    let warp = |extra: &[&str]| {
        let mut args = vec![
            "warp",
            "--line",
            LINE,
            "--input",
            s(&seq_a),
            "--frames",
            "1-3",
            "-o",
            s(&out),
        ];
        args.extend_from_slice(extra);
        morphfx(&args)
    };
    let m_seq = d.join("m.####.png");
    for (extra, says) in [
        (vec!["--mask", s(&m_seq)], "m.0003.png"),
        (vec!["--mask", s(&garbage)], "garbage.exr"),
        (vec!["--param", "mix=2"], "out of range"),
        (vec!["--param", "no_such=1"], "no param no_such"),
        (vec!["--param", "mask_invert=maybe"], "true or false"),
        (vec!["--param", "filter=sharp"], "unknown option"),
        (vec!["--param", "tolerance@2=0.1"], "cannot be animated"),
        (vec!["--param", "view=ghost"], "--view"),
    ] {
        let (code, err) = warp(&extra);
        assert_eq!(code, 2, "{extra:?}: {err}");
        assert!(err.contains(says), "{extra:?}: {err}");
        let written: Vec<_> = std::fs::read_dir(&d)
            .unwrap()
            .filter_map(|e| e.ok())
            .filter(|e| e.file_name().to_string_lossy().starts_with("out"))
            .collect();
        assert!(written.is_empty(), "{extra:?} wrote {written:?}");
    }
    let (code, err) = morphfx(&[
        "morph",
        "--line",
        LINE,
        "--a",
        s(&a),
        "--b",
        s(&a),
        "--timing",
        s(&garbage),
        "-o",
        s(&d.join("x.exr")),
    ]);
    assert_eq!(code, 2, "{err}");
}

#[test]
fn keyed_params_interpolate_and_params_lists_every_id() {
    let d = common::scratch("param-keys");
    let a = plate(&d, "a.exr", 0.0);
    let seq = d.join("a.####.exr");
    for f in 1..=3 {
        std::fs::copy(&a, d.join(format!("a.{f:04}.exr"))).unwrap();
    }
    let out = d.join("o.####.exr");
    ok(&[
        "warp",
        "--line",
        LINE,
        "--input",
        s(&seq),
        "--frames",
        "1-3",
        "--t",
        "1",
        "--param",
        "mix@1=0",
        "--param",
        "mix@3=1",
        "-o",
        s(&out),
    ]);
    let (effect, src) = unmasked(&d, &a);
    for (f, mix) in [(1, 0.0f32), (2, 0.5), (3, 1.0)] {
        let got = read(&d.join(format!("o.{f:04}.exr")), Colour::Raw);
        for (k, g) in got.data.iter().enumerate() {
            let want = src.data[k] + (effect.data[k] - src.data[k]) * mix;
            assert!(
                (g - want).abs() < 1e-5,
                "frame {f} sample {k}: {g} vs {want}"
            );
        }
    }
    let listed = common::run_morphfx(&["params", "--node", "morph"]);
    let text = String::from_utf8_lossy(&listed.stdout);
    for id in [
        "mix ",
        "mask_invert ",
        "view ",
        "transition_spread ",
        "line1_b_end ",
        "line2_... to line64_...",
        "auto_levels ",
    ] {
        assert!(text.contains(id), "{id} missing from:\n{text}");
    }
    assert!(text.contains("ghost") && text.contains("folds"));
    // One screenful or so, with each param's label as a host shows it.
    assert!(text.lines().count() < 100, "{} lines", text.lines().count());
    assert!(text
        .lines()
        .any(|l| l.starts_with("field_b ") && l.ends_with(" b")));
    assert!(text
        .lines()
        .any(|l| l.starts_with("mix ") && l.ends_with(" Mix")));
    assert!(!text.contains("line2_a_start"));
    // The Warp node has no auto method, so none of its params.
    let warp = common::run_morphfx(&["params", "--node", "warp"]);
    let warp = String::from_utf8_lossy(&warp.stdout);
    assert!(
        warp.contains("field_b ") && !warp.contains("auto_"),
        "{warp}"
    );
    let (code, _) = morphfx(&["params", "--node", "blur"]);
    assert_eq!(code, 2);
}

/// A matte with no alpha (an RGB PNG, a one-channel grey PNG) acts by the
/// mean of its R, G and B, as the nodes read an RGB matte: not as alpha 1
/// everywhere. Each is compared with the same values given as alpha.
#[test]
fn mattes_without_alpha_act_by_their_mean() {
    let d = common::scratch("mask-rgb");
    let a = plate(&d, "a.exr", 0.0);
    let b = plate(&d, "b.exr", 1.7);
    let (w, h) = (W as u32, H as u32);
    // Left to right 0 → 1 in code values; R, G, B differ, their mean ramps.
    let level = |x: u32| (x * 255 / (w - 1)) as u8;
    let rgb = ::image::RgbImage::from_fn(w, h, |x, _| {
        let v = level(x);
        ::image::Rgb([v, v / 2, v.saturating_add(v / 2)])
    });
    rgb.save(d.join("rgb.png")).unwrap();
    let grey = ::image::GrayImage::from_fn(w, h, |x, _| ::image::Luma([level(x)]));
    grey.save(d.join("grey.png")).unwrap();
    // The same mattes as alpha, for the expected pictures.
    let as_alpha = |name: &str, m: &dyn Fn(u32) -> f32| {
        let img = ::image::RgbaImage::from_fn(w, h, |x, _| {
            ::image::Rgba([255, 255, 255, (m(x) * 255.0).round() as u8])
        });
        img.save(d.join(name)).unwrap();
    };
    let mean = |x: u32| {
        let v = level(x) as f32;
        (v + (level(x) / 2) as f32 + level(x).saturating_add(level(x) / 2) as f32) / (3.0 * 255.0)
    };
    as_alpha("rgb-alpha.png", &mean);
    as_alpha("grey-alpha.png", &|x| level(x) as f32 / 255.0);
    for (matte, like) in [("rgb.png", "rgb-alpha.png"), ("grey.png", "grey-alpha.png")] {
        for role in ["--mask", "--timing"] {
            let render = |m: &str, out: &str| {
                let matte = d.join(m);
                morph_line(&d, (&a, &b), "0.5", &[role, s(&matte), "--raw"], out)
            };
            let got = render(matte, "got.exr");
            let want = render(like, "want.exr");
            let plain = render_without(&d, &a, &b);
            let worst = got
                .data
                .iter()
                .zip(&want.data)
                .map(|(g, w)| (g - w).abs())
                .fold(0f32, f32::max);
            // 8-bit alpha rounds the mean to 1/510.
            assert!(worst < 0.01, "{matte} {role}: {worst} from the alpha matte");
            assert_ne!(
                got.data, plain.data,
                "{matte} {role}: the matte was ignored"
            );
        }
    }
}

/// `morphfx morph` of plates `a` and `b` by `LINE` at `t` with `extra`
/// options into `out` in `d`, read back as written.
fn morph_line(d: &Path, (a, b): (&Path, &Path), t: &str, extra: &[&str], out: &str) -> Image {
    let out = d.join(out);
    let mut args = vec!["morph", "--line", LINE, "--a", s(a), "--b", s(b), "--t", t];
    args.extend_from_slice(extra);
    args.extend(["-o", s(&out)]);
    ok(&args);
    read(&out, Colour::Raw)
}

/// The morph at t = 0.5 with no matte.
fn render_without(d: &Path, a: &Path, b: &Path) -> Image {
    morph_line(d, (a, b), "0.5", &[], "plain.exr")
}

/// A timing matte keeps opaque plates opaque (its weights on A and B sum
/// to 1 however the warps disagree), and where it holds A, the picture is
/// warped A up to the frame's edges: no sliver of B, no seam.
#[test]
fn a_timing_matte_keeps_plates_opaque_and_holds_a_to_the_edge() {
    let d = common::scratch("timing-edges");
    let a = plate(&d, "a.exr", 0.0);
    let b = plate(&d, "b.exr", 1.7);
    // Alpha 1 (A's turn last) left of x = 40, a ramp down to 0 at the right.
    let matte = Image::from_fn(RectI::from_size(W, H), 4, |i, _, c| match c {
        3 if i < 40 => 1.0,
        3 => 1.0 - (i - 40) as f32 / 40.0,
        _ => 1.0,
    });
    let m = d.join("timing.exr");
    io::write(&m, &Plate::new(matte, (W, H)), ExrPrecision::Float).unwrap();
    for t in ["0.3", "0.5"] {
        let render = |view: &str| {
            let out = format!("{view}.exr");
            morph_line(&d, (&a, &b), t, &["--timing", s(&m), "--view", view], &out)
        };
        let (got, warped_a) = (render("morph"), render("warped-a"));
        for j in 0..H as i32 {
            for i in 0..W as i32 {
                let px = got.pixel(i, j);
                assert!(
                    (px[3] - 1.0).abs() < 1e-5,
                    "t {t} ({i}, {j}): alpha {}",
                    px[3]
                );
                // Spread 0.5: where g = 1 the colour's rate is 0 until
                // t = 0.5, so the dissolve shows warped A alone (B differs
                // from A by up to 0.8 there).
                if i < 30 {
                    for (c, (g, want)) in px.iter().zip(warped_a.pixel(i, j)).take(3).enumerate() {
                        assert!(
                            (g - want).abs() < 1e-4,
                            "t {t} ({i}, {j}) {c}: {g} where the matte holds A ({want})"
                        );
                    }
                }
            }
        }
    }
}

/// `--param` has the last word: a setting the scene's own would silently
/// replace (Settings From Scene on) is refused, naming the way out; with
/// `settings_from_scene=false` it is honoured; a param the scene does not
/// set is honoured as it is.
#[test]
fn params_the_scene_overrides_are_refused_or_honoured_never_ignored() {
    let d = common::scratch("param-scene");
    let a = plate(&d, "a.exr", 0.0);
    let scene = d.join("s.morph.json");
    std::fs::write(
        &scene,
        r#"{"format": "morphfx-scene", "version": 1, "method": "field",
            "field": {"a": 0.001, "b": 2, "p": 0.5, "evaluation": "exact"},
            "features": [{"type": "line", "a": [[10, 10], [60, 14]], "b": [[18, 6], [66, 22]]}]}"#,
    )
    .unwrap();
    let warp = |params: &[&str], out: &str| {
        let mut args = vec!["warp", "--scene", s(&scene), "--input", s(&a), "--t", "1"];
        args.extend(params);
        let out = d.join(out);
        args.extend(["-o", s(&out)]);
        let r = morphfx(&args);
        (r, out)
    };
    for refused in [
        "method=mesh",
        "field_b=0.5",
        "line_interpolation=center-angle",
        "evaluation=adaptive",
        "mesh_pass=one-pass",
        "mffd_alpha=0.3",
        "plate_alpha=10",
    ] {
        let ((code, err), out) = warp(&["--param", refused], "refused.exr");
        assert_eq!(code, 2, "{refused}: {err}");
        assert!(
            err.contains("settings_from_scene") && err.contains(refused),
            "{err}"
        );
        assert!(!out.exists());
    }
    let ((code, err), scene_own) = warp(&[], "scene.exr");
    assert_eq!(code, 0, "{err}");
    let ((code, err), node_own) = warp(
        &[
            "--param",
            "settings_from_scene=false",
            "--param",
            "field_b=0.5",
        ],
        "node.exr",
    );
    assert_eq!(code, 0, "{err}");
    let ((code, err), mixed) = warp(&["--param", "mix=0.5"], "mix.exr");
    assert_eq!(code, 0, "{err}");
    let [scene_own, node_own, mixed] = [scene_own, node_own, mixed].map(|p| read(&p, Colour::Raw));
    assert_ne!(
        scene_own.data, node_own.data,
        "field_b=0.5 was not honoured"
    );
    assert_ne!(scene_own.data, mixed.data, "mix=0.5 was not honoured");
}
