//! End to end through the bundle's C ABI: the `morphfx` binary on generated
//! EXR plates, checked against closed-form expectations.

use std::path::{Path, PathBuf};

use crate::common;
use crate::common::morphfx_said as morphfx;
use std::process::Command;

use morphfx::geom::RectI;
use morphfx::image::Image;
use morphfx_harness::io::{self, ExrPrecision, Plate};

fn tmp(name: &str) -> common::Scratch {
    common::scratch(name)
}

/// `morphfx morph --scene DIR/s.morph.json --a A --b B [MORE] -o OUT`:
/// exit status and stderr.
fn morph_in(d: &Path, a: &str, b: &str, more: &[&str], out: &Path) -> (i32, String) {
    let scene = d.join("s.morph.json");
    let mut args = vec![
        "morph",
        "--scene",
        scene.to_str().unwrap(),
        "--a",
        a,
        "--b",
        b,
    ];
    args.extend(more);
    args.extend(["-o", out.to_str().unwrap()]);
    morphfx(&args)
}

/// Writes `image` as a float EXR in a `size` display window; returns its path.
fn write_plate(dir: &Path, name: &str, image: Image, size: (usize, usize)) -> String {
    write_exr(dir, name, &Plate::new(image, size))
}

/// Writes `plate` as a float EXR; returns its path.
fn write_exr(dir: &Path, name: &str, plate: &Plate) -> String {
    let p = dir.join(name);
    io::write(&p, plate, ExrPrecision::Float).unwrap();
    p.to_string_lossy().into_owned()
}

fn plate(dir: &Path, name: &str, w: usize, h: usize, seed: f32) -> String {
    let img = Image::from_fn(RectI::from_size(w, h), 4, |i, j, c| {
        (i as f32 * 0.37 + j as f32 * 0.11 + seed + c as f32).sin() * 2.0
    });
    write_plate(dir, name, img, (w, h))
}

const TRANSLATE: &str = r#"{"format": "morphfx-scene", "version": 1, "method": "field",
  "field": {"a": 0.001, "b": 2, "p": 0.5, "evaluation": "exact"},
  "features": [{"name": "bar", "type": "line", "a": [[10, 10], [40, 10]], "b": [[17, 5], [47, 5]]}]}"#;

#[test]
fn warp_stmap_of_one_translated_line_is_the_closed_form_translation() {
    let d = tmp("stmap");
    let a = plate(&d, "a.exr", 64, 48, 0.0);
    std::fs::write(d.join("s.morph.json"), TRANSLATE).unwrap();
    let out = d.join("st.exr");
    let (code, err) = morphfx(&[
        "warp",
        "--scene",
        d.join("s.morph.json").to_str().unwrap(),
        "--input",
        &a,
        "--t",
        "1",
        "-o",
        out.to_str().unwrap(),
        "--view",
        "stmap",
    ]);
    assert_eq!(code, 0, "{err}");
    let st = io::read(&out).unwrap().image;
    // One line pair of equal length and direction is a pure translation: the
    // output at X samples A at X - (7, -5).
    for j in 0..48 {
        for i in 0..64 {
            let px = st.pixel(i, j);
            let (sx, sy) = ((i as f32 + 0.5 - 7.0) / 64.0, (j as f32 + 0.5 + 5.0) / 48.0);
            assert!(
                (px[0] - sx).abs() < 1e-4 && (px[1] - sy).abs() < 1e-4,
                "({i},{j}): {px:?}"
            );
            assert_eq!((px[2], px[3]), (0.0, 1.0));
        }
    }
}

#[test]
fn morph_at_t0_is_a_and_at_t1_is_b_bit_for_bit() {
    let d = tmp("ends");
    let (a, b) = (
        plate(&d, "a.exr", 40, 30, 0.0),
        plate(&d, "b.exr", 40, 30, 1.7),
    );
    std::fs::write(d.join("s.morph.json"), TRANSLATE).unwrap();
    for (t, src) in [("0", &a), ("1", &b)] {
        let out = d.join(format!("m{t}.exr"));
        let (code, err) = morph_in(&d, &a, &b, &["--t", t], &out);
        assert_eq!(code, 0, "{err}");
        assert_eq!(
            io::read(&out).unwrap().image,
            io::read(Path::new(src)).unwrap().image,
            "t = {t}"
        );
    }
}

#[test]
fn bad_scene_exits_2_naming_the_feature_and_writes_nothing() {
    let d = tmp("bad");
    let (a, b) = (
        plate(&d, "a.exr", 16, 16, 0.0),
        plate(&d, "b.exr", 16, 16, 1.0),
    );
    std::fs::write(
        d.join("s.morph.json"),
        r#"{"features": [{"name": "nose", "type": "line", "a": [[1,1],[2,2]], "b": [[1,1]]}]}"#,
    )
    .unwrap();
    let out = d.join("m.exr");
    let (code, err) = morph_in(&d, &a, &b, &[], &out);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("\"nose\"") && err.contains("a has 2 points but b has 1"),
        "{err}"
    );
    assert!(!out.exists());
}

#[test]
fn size_mismatch_and_missing_frames_exit_2() {
    let d = tmp("mismatch");
    let (a, b) = (
        plate(&d, "a.exr", 16, 16, 0.0),
        plate(&d, "b.exr", 20, 16, 1.0),
    );
    std::fs::write(d.join("s.morph.json"), TRANSLATE).unwrap();
    let out = d.join("m.exr");
    let (code, err) = morph_in(&d, &a, &b, &[], &out);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("size mismatch") && err.contains("b.exr"),
        "{err}"
    );
    let seq = d.join("p.####.exr");
    let (code, err) = morphfx(&[
        "warp",
        "--scene",
        d.join("s.morph.json").to_str().unwrap(),
        "--input",
        seq.to_str().unwrap(),
        "--frames",
        "1-2",
        "-o",
        d.join("o.####.exr").to_str().unwrap(),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("p.0001.exr"), "{err}");
    assert!(!out.exists());
}

#[test]
fn unreadable_and_truncated_plates_exit_2_naming_the_file() {
    let d = tmp("unreadable");
    std::fs::write(d.join("s.morph.json"), TRANSLATE).unwrap();
    std::fs::write(d.join("junk.exr"), b"not an image at all").unwrap();
    // A valid header whose pixel data is cut short: only decoding finds out.
    let whole = plate(&d, "whole.exr", 64, 48, 0.0);
    let bytes = std::fs::read(&whole).unwrap();
    std::fs::write(d.join("cut.exr"), &bytes[..bytes.len() * 2 / 3]).unwrap();
    for name in ["junk.exr", "cut.exr"] {
        let out = d.join(format!("o-{name}"));
        let (code, err) = morphfx(&[
            "warp",
            "--scene",
            d.join("s.morph.json").to_str().unwrap(),
            "--input",
            d.join(name).to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ]);
        assert_eq!(code, 2, "{name}: {err}");
        assert!(err.contains(name), "{name}: {err}");
        assert!(!out.exists(), "{name}: output written");
        let leftovers: Vec<_> = std::fs::read_dir(&d)
            .unwrap()
            .filter_map(|e| e.ok())
            .filter(|e| e.file_name().to_string_lossy().contains("partial"))
            .collect();
        assert!(leftovers.is_empty(), "{name}: partial files left");
    }
}

#[test]
fn a_panic_inside_the_plugin_becomes_a_failure_status_not_a_crash() {
    let d = tmp("panic");
    let a = plate(&d, "a.exr", 16, 16, 0.0);
    std::fs::write(d.join("s.morph.json"), TRANSLATE).unwrap();
    let out = d.join("w.exr");
    let status = Command::new(env!("CARGO_BIN_EXE_morphfx"))
        .env("MORPHFX_FORCE_PANIC", "OfxImageEffectActionRender")
        .args([
            "--bundle",
            common::bundle_path().to_str().unwrap(),
            "warp",
            "--scene",
            d.join("s.morph.json").to_str().unwrap(),
            "--input",
            &a,
            "-o",
            out.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&status.stderr);
    assert_eq!(status.status.code(), Some(1), "{err}");
    assert!(
        err.contains("internal error") && err.contains("forced panic"),
        "{err}"
    );
    assert!(!out.exists());
}

/// The demo renders the same morph by field, mesh, triangles and auto; whatever
/// the method, the first frame (t = 0) is plate A and the last (t = 1) plate
/// B, pixel for pixel.
#[test]
fn demo_renders_every_built_method_with_exact_end_frames() {
    let d = tmp("demo");
    let (code, err) = morphfx(&["demo", "-o", d.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    let read = |p: PathBuf| {
        io::read(&p)
            .unwrap_or_else(|e| panic!("{}: {}", p.display(), e.message))
            .image
    };
    let (a, b) = (read(d.join("plates/a.exr")), read(d.join("plates/b.exr")));
    for method in ["preview", "mesh", "triangles", "auto"] {
        let first = read(d.join(format!("{method}/morph.0001.png")));
        let last = read(d.join(format!("{method}/morph.0012.png")));
        for (got, want, which) in [(&first, &a, "A"), (&last, &b, "B")] {
            // PNG holds 8 sRGB-encoded bits: equal to the plate within one
            // code step.
            let code = |v: f32| io::linear_to_srgb(v.clamp(0.0, 1.0));
            let worst = got
                .data
                .iter()
                .zip(&want.data)
                .map(|(g, w)| (code(*g) - code(*w)).abs())
                .fold(0f32, f32::max);
            assert!(
                worst <= 1.0 / 255.0 + 1e-6,
                "{method}: end frame differs from plate {which} by {worst}"
            );
        }
        let mid = read(d.join(format!("{method}/morph.0006.png")));
        let moved = mid
            .data
            .iter()
            .zip(&a.data)
            .map(|(g, w)| (g - w).abs())
            .fold(0f32, f32::max);
        assert!(moved > 0.1, "{method}: the middle frame is plate A");
    }
    // Every method lines the faces up: the middle frame's ghost is dark,
    // and darkest where the eyes and mouth are (doubled eyes or a torn
    // mouth light these boxes up, in-between positions, 160 x 120 centre).
    for (method, ghost) in [
        ("field", d.join("ghost.0006.exr")),
        ("mesh", d.join("mesh/ghost.0006.exr")),
        ("triangles", d.join("triangles/ghost.0006.exr")),
        ("auto", d.join("auto/ghost.0006.exr")),
    ] {
        let ghost = read(ghost);
        let alpha: Vec<f32> = ghost.data.chunks(4).map(|p| p[3]).collect();
        let mean = alpha.iter().sum::<f32>() / alpha.len() as f32;
        let bright = alpha.iter().filter(|a| **a > 0.1).count() as f32 / alpha.len() as f32;
        assert!(
            mean < 0.04 && bright < 0.08,
            "{method}: ghost mean {mean}, {bright} above 0.1"
        );
        let boxed = |(x, y): (i32, i32), (hw, hh): (i32, i32)| {
            let mut sum = 0.0;
            for j in y - hh..y + hh {
                for i in x - hw..x + hw {
                    sum += ghost.pixel(160 + i, 120 + j)[3];
                }
            }
            sum / (4 * hw * hh) as f32
        };
        for (part, centre, half) in [
            ("left eye", (-32, 30), (13, 13)),
            ("right eye", (32, 30), (13, 13)),
            ("mouth", (0, -37), (44, 8)),
        ] {
            // The skins' own difference gives about 0.06; doubled eyes gave
            // 0.2, a mouth held by one line along it 0.13.
            let g = boxed(centre, half);
            assert!(g < 0.09, "{method}: the {part} doubles (ghost {g} there)");
        }
    }
    // The last line names the contact sheet: every frame, half size, 4 across.
    let out = common::run_morphfx(&["demo", "-o", d.to_str().unwrap()]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    let last = stdout.lines().last().unwrap_or_default();
    let sheet = last
        .strip_prefix("contact sheet: ")
        .expect("the sheet, last");
    let sheet = io::read(Path::new(sheet)).unwrap();
    assert_eq!(sheet.size, (4 * 160, 3 * 120));
}

/// A plate whose data window is `bounds` (canonical, may reach outside the
/// display window or cover part of it) in a `w × h` display window whose
/// top-left corner lies at `origin` in the file.
fn windowed_plate(
    dir: &Path,
    name: &str,
    bounds: RectI,
    (size, origin): ((usize, usize), (i32, i32)),
    seed: f32,
) -> (String, Image) {
    let img = Image::from_fn(bounds, 4, |i, j, c| {
        if c == 3 {
            1.0
        } else {
            0.5 + 0.4 * (i as f32 * 0.37 + j as f32 * 0.11 + seed + c as f32).sin()
        }
    });
    let plate = Plate {
        image: img.clone(),
        size,
        origin,
    };
    (write_exr(dir, name, &plate), img)
}

#[test]
fn plates_with_other_data_windows_morph_over_the_union_in_the_display_window() {
    let d = tmp("windows");
    // A: overscan 8 px on every side (negative origin); B: bbox-cropped;
    // both display windows away from the file's origin.
    let window = ((64, 48), (100, 20));
    let (a, a_img) = windowed_plate(&d, "a.exr", RectI::new(-8, -8, 72, 56), window, 0.0);
    let (b, b_img) = windowed_plate(&d, "b.exr", RectI::new(16, 8, 48, 40), window, 2.0);
    // A line that stays put: both warps are the identity.
    let still = r#"{"format": "morphfx-scene", "version": 1, "method": "field",
      "features": [{"type": "line", "a": [[10, 10], [40, 12]], "b": [[10, 10], [40, 12]]}]}"#;
    std::fs::write(d.join("s.morph.json"), still).unwrap();
    let out = d.join("m.exr");
    let (code, err) = morph_in(&d, &a, &b, &["--t", "0.5"], &out);
    assert_eq!(code, 0, "{err}");
    let m = io::read(&out).unwrap();
    assert_eq!(m.size, (64, 48), "the display window is kept");
    assert_eq!(m.origin, (100, 20), "where it lies, too");
    assert_eq!(
        m.image.bounds,
        RectI::new(-8, -8, 72, 56),
        "the union of the data windows"
    );
    for (i, j) in [(16, 8), (30, 20), (47, 39)] {
        let (pa, pb, pm) = (a_img.pixel(i, j), b_img.pixel(i, j), m.image.pixel(i, j));
        for c in 0..4 {
            assert!(
                (pm[c] - 0.5 * (pa[c] + pb[c])).abs() < 1e-5,
                "({i}, {j}) channel {c}"
            );
        }
    }
    // OpenImageIO reads the same windows back.
    if let Ok(info) = Command::new("oiiotool")
        .arg("--info")
        .arg("-v")
        .arg(&out)
        .output()
    {
        let text = String::from_utf8_lossy(&info.stdout);
        let text = text.split_whitespace().collect::<Vec<_>>().join(" ");
        assert!(
            text.contains("80 x 64, 4 channel"),
            "data window size: {text}"
        );
        // EXR y grows downwards: the data window's top is 8 px above the
        // display window's, which lies at (100, 20).
        assert!(text.contains("pixel data origin: x=92, y=12"), "{text}");
        assert!(text.contains("full/display size: 64 x 48"), "{text}");
        assert!(text.contains("full/display origin: 100, 20"), "{text}");
    }
}

/// An identity warp: one line, the same on A and B, at t = 0.
const IDENTITY: &str = "1=10,10,20,10,10,10,20,10";

#[test]
fn outputs_follow_the_first_inputs_precision_and_compression_unless_told() {
    use exr::prelude::Compression;
    let d = tmp("formats");
    let img = Image::from_fn(RectI::from_size(32, 24), 4, |i, j, c| {
        (i as f32 * 0.3 + j as f32 * 0.2 + c as f32).sin() + 1.5
    });
    let input = d.join("in.exr");
    let piz = io::OutputFormat {
        compression: Compression::PIZ,
        ..io::OutputFormat::new(ExrPrecision::Half)
    };
    io::write_as(&input, &Plate::new(img, (32, 24)), piz).unwrap();
    let run = |out: &str, extra: &[&str]| {
        let out = d.join(out);
        let mut args = vec![
            "warp",
            "--line",
            IDENTITY,
            "--input",
            input.to_str().unwrap(),
        ];
        args.extend_from_slice(&["--t", "0", "-o", out.to_str().unwrap()]);
        args.extend_from_slice(extra);
        let (code, err) = morphfx(&args);
        (code, err, out)
    };
    let header = |p: &Path| io::probe(p).unwrap();
    let (code, err, same) = run("same.exr", &[]);
    assert_eq!(code, 0, "{err}");
    assert!(header(&same).half);
    assert_eq!(header(&same).compression, Some(Compression::PIZ));
    // Half in, half out, bit for bit at the identity.
    assert_eq!(
        io::read(&same).unwrap().image,
        io::read(&input).unwrap().image
    );
    let (code, err, dwaa) = run("dwaa.exr", &["--compression", "dwaa", "--float"]);
    assert_eq!(code, 0, "{err}");
    assert!(!header(&dwaa).half);
    assert!(matches!(
        header(&dwaa).compression,
        Some(Compression::DWAA(_))
    ));
    let (code, err, bad) = run("bad.exr", &["--compression", "lzw"]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("--compression lzw") && err.contains("pxr24"),
        "{err}"
    );
    assert!(!bad.exists());
}

/// `morphfx warp` of `input` by the identity line at t = 0 into `out`,
/// with `extra` options: the plate as the IO reads and writes it.
fn identity_warp(input: &Path, out: &Path, extra: &[&str]) -> PathBuf {
    let mut args = vec![
        "warp",
        "--line",
        IDENTITY,
        "--input",
        input.to_str().unwrap(),
    ];
    args.extend_from_slice(&["--t", "0", "-o", out.to_str().unwrap()]);
    args.extend_from_slice(extra);
    let (code, err) = morphfx(&args);
    assert_eq!(code, 0, "{err}");
    out.to_path_buf()
}

#[test]
fn png_plates_are_decoded_from_srgb_and_png_outputs_encoded_unless_raw() {
    let d = tmp("srgb");
    let png = d.join("grey.png");
    ::image::RgbaImage::from_pixel(24, 16, ::image::Rgba([128, 64, 255, 255]))
        .save(&png)
        .unwrap();
    let warp = |out: &str, extra: &[&str]| identity_warp(&png, &d.join(out), extra);
    // IEC 61966-2-1: code 128 is 0.21586 of linear light, 64 is 0.05127.
    let linear = io::read_as(&warp("linear.exr", &[]), io::Colour::Raw)
        .unwrap()
        .image;
    let px = linear.pixel(5, 5);
    assert!(
        (px[0] - 0.21586).abs() < 1e-4 && (px[1] - 0.05127).abs() < 1e-4,
        "{px:?}"
    );
    assert_eq!((px[2], px[3]), (1.0, 1.0));
    let raw = io::read_as(&warp("raw.exr", &["--raw"]), io::Colour::Raw)
        .unwrap()
        .image;
    assert!((raw.pixel(5, 5)[0] - 128.0 / 255.0).abs() < 1e-6);
    // PNG out: encoded back to the same code values, with and without --raw.
    for (name, extra) in [("back.png", &[][..]), ("back_raw.png", &["--raw"][..])] {
        let back = ::image::open(warp(name, extra)).unwrap().to_rgba8();
        assert_eq!(back.get_pixel(5, 5).0, [128, 64, 255, 255], "{name}");
    }
}

/// PNG holds straight colour, the render premultiplied colour: a half
/// transparent PNG is premultiplied on read (EXR out holds colour × alpha)
/// and written back straight, the same code values (as a host's PNG
/// writer writes them), with or without --raw.
#[test]
fn png_alpha_is_straight_in_the_file_and_premultiplied_in_the_render() {
    let d = tmp("png-alpha");
    let png = d.join("half.png");
    ::image::RgbaImage::from_pixel(24, 16, ::image::Rgba([128, 64, 255, 128]))
        .save(&png)
        .unwrap();
    let warp = |out: &str, extra: &[&str]| identity_warp(&png, &d.join(out), extra);
    let exr = io::read_as(&warp("linear.exr", &[]), io::Colour::Raw)
        .unwrap()
        .image;
    let (px, a) = (exr.pixel(5, 5), 128.0 / 255.0);
    assert!((px[3] - a).abs() < 1e-6, "{px:?}");
    // Code 128 is 0.21586 of linear light, straight; premultiplied by alpha.
    assert!((px[0] - 0.21586 * a).abs() < 1e-4, "{px:?}");
    assert!((px[2] - a).abs() < 1e-4, "{px:?}");
    for (name, extra) in [("back.png", &[][..]), ("back_raw.png", &["--raw"][..])] {
        let back = ::image::open(warp(name, extra)).unwrap().to_rgba8();
        assert_eq!(back.get_pixel(5, 5).0, [128, 64, 255, 128], "{name}");
    }
}

/// A header that claims 32768 × 32768 pixels in a file of a few hundred
/// bytes: refused from its header with the limit named, before any pixel
/// is read or any memory asked for, and nothing written.
#[test]
fn a_plate_over_the_size_limit_is_refused_from_its_header() {
    let d = tmp("huge");
    let small = d.join("small.exr");
    let img = Image::from_fn(RectI::from_size(4, 4), 4, |_, _, _| 0.5);
    io::write(&small, &Plate::new(img, (4, 4)), ExrPrecision::Half).unwrap();
    let mut bytes = std::fs::read(&small).unwrap();
    for name in [&b"dataWindow\0box2i\0"[..], &b"displayWindow\0box2i\0"[..]] {
        let at = bytes
            .windows(name.len())
            .position(|w| w == name)
            .expect("the attribute")
            + name.len()
            + 4;
        // xMax and yMax of the box.
        bytes[at + 8..at + 12].copy_from_slice(&32767i32.to_le_bytes());
        bytes[at + 12..at + 16].copy_from_slice(&32767i32.to_le_bytes());
    }
    let huge = d.join("huge.exr");
    std::fs::write(&huge, &bytes).unwrap();
    let out = d.join("out.exr");
    let (code, err) = morphfx(&[
        "warp",
        "--line",
        "1=10,10,20,10,10,10,20,10",
        "--input",
        huge.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("huge.exr") && err.contains("32768x32768") && err.contains("limit"),
        "{err}"
    );
    assert!(!out.exists());
}

/// `morphfx bench --drag` runs as a user runs it, says what it timed, and
/// refuses a frame it cannot bench.
#[test]
fn bench_drag_times_renders_after_a_move_at_both_scales() {
    let run = common::run_morphfx(&[
        "bench", "--drag", "--width", "64", "--height", "48", "--moves", "2",
    ]);
    let err = String::from_utf8_lossy(&run.stderr);
    assert!(run.status.success(), "{err}");
    for scale in ["render scale 1:", "render scale 0.5:"] {
        let line = err
            .lines()
            .find(|l| l.contains(scale))
            .unwrap_or_else(|| panic!("{scale} in {err}"));
        assert!(
            line.contains("ms after a move (slowest ") && line.contains("with nothing moved"),
            "{line}"
        );
    }
    let bad = common::run_morphfx(&["bench", "--drag", "--moves", "0"]);
    assert_eq!(bad.status.code(), Some(2));
}

/// `morphfx bench --drag` says which build of the plugin ran: the v3 one
/// where the bundle has it and the CPU runs it, else the baseline one (as
/// with `MORPHFX_CPU=baseline`, which makes a CPU with AVX2 look like one
/// without).
#[test]
fn bench_drag_says_which_build_of_the_plugin_ran() {
    let said = |baseline: bool| {
        let mut c = std::process::Command::new(env!("CARGO_BIN_EXE_morphfx"));
        c.arg("--bundle").arg(common::bundle_path());
        c.args([
            "bench", "--drag", "--width", "32", "--height", "32", "--moves", "1",
        ]);
        if baseline {
            c.env("MORPHFX_CPU", "baseline");
        }
        let run = c.output().unwrap();
        assert!(run.status.success());
        String::from_utf8_lossy(&run.stderr).into_owned()
    };
    assert!(
        said(true).contains("the bundle's baseline x86-64 build ran"),
        "{}",
        said(true)
    );
    let v3 = common::bundle_path()
        .join("Contents/Linux-x86-64/MorphFX-x86-64-v3.so")
        .is_file();
    #[cfg(target_arch = "x86_64")]
    let cpu =
        std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma");
    #[cfg(not(target_arch = "x86_64"))]
    let cpu = false;
    let want = if v3 && cpu {
        "the bundle's x86-64-v3 build with AVX2 and FMA ran"
    } else {
        "the bundle's baseline x86-64 build ran"
    };
    let text = said(false);
    assert!(text.contains(want), "{text}");
}

/// Several frames into one file name would overwrite it frame after frame:
/// refused before anything is rendered, as is a frame named twice.
#[test]
fn several_frames_need_a_numbered_output_and_each_frame_once() {
    let d = tmp("one-name");
    let a = plate(&d, "a.exr", 32, 24, 0.0);
    std::fs::write(d.join("s.morph.json"), TRANSLATE).unwrap();
    let scene = d.join("s.morph.json");
    let scene = scene.to_str().unwrap();
    let one = d.join("one.exr");
    let st = d.join("st.####.exr");
    let seq = d.join("w.####.exr");
    for (frames, out, stmap, why) in [
        (
            "1-3",
            one.to_str().unwrap(),
            st.to_str().unwrap(),
            "3 frames would overwrite one file",
        ),
        (
            "1-3",
            seq.to_str().unwrap(),
            one.to_str().unwrap(),
            "3 frames would overwrite one file",
        ),
        (
            "1,2,1",
            seq.to_str().unwrap(),
            st.to_str().unwrap(),
            "frame 1 is named twice",
        ),
    ] {
        let (code, err) = morphfx(&[
            "warp", "--scene", scene, "--input", &a, "--frames", frames, "-o", out, "--stmap",
            stmap,
        ]);
        assert_eq!(code, 2, "{frames} {out}: {err}");
        assert!(err.contains(why), "{err}");
        assert_eq!(
            std::fs::read_dir(&d).unwrap().count(),
            2,
            "something was written"
        );
    }
}

/// ST maps are 32-bit float whatever the plates' precision: a half float
/// holds x/W to about 0.001 near 1, almost a pixel at 1920 wide.
#[test]
fn stmaps_are_float_from_half_plates() {
    let d = tmp("stmap-half");
    let (w, h) = (1920, 4);
    let img = Image::from_fn(RectI::from_size(w, h), 4, |_, _, _| 0.5);
    let a = d.join("a.exr");
    io::write(&a, &Plate::new(img, (w, h)), ExrPrecision::Half).unwrap();
    std::fs::write(d.join("s.morph.json"), TRANSLATE).unwrap();
    let (st, warped) = (d.join("st.exr"), d.join("w.exr"));
    let (code, err) = morphfx(&[
        "warp",
        "--scene",
        d.join("s.morph.json").to_str().unwrap(),
        "--input",
        a.to_str().unwrap(),
        "--t",
        "0",
        "-o",
        warped.to_str().unwrap(),
        "--stmap",
        st.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(
        io::probe(&warped).unwrap().half,
        "the picture follows its plate"
    );
    assert!(!io::probe(&st).unwrap().half, "the ST map is float");
    // At t = 0 the map is the identity: every pixel centre to 1/40 px.
    let map = io::read(&st).unwrap().image;
    for j in 0..h {
        for i in (0..w).step_by(7) {
            let s = map.data[(j * w + i) * 4] as f64 * w as f64;
            assert!((s - (i as f64 + 0.5)).abs() < 0.025, "({i}, {j}): {s}");
        }
    }
}

/// `morphfx bench` leaves nothing where it runs unless told where to keep
/// its plates (a 1080p run writes about 330 MB).
#[test]
fn bench_keeps_its_plates_only_under_the_folder_it_is_given() {
    let d = tmp("bench-clean");
    let run = |extra: &[&str]| {
        let out = Command::new(env!("CARGO_BIN_EXE_morphfx"))
            .arg("--bundle")
            .arg(common::bundle_path())
            .args(["bench", "--frames", "2", "--width", "32", "--height", "24"])
            .args(extra)
            .current_dir(&d)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
    };
    run(&[]);
    assert_eq!(
        std::fs::read_dir(&d).unwrap().count(),
        0,
        "bench left files"
    );
    run(&["-o", "kept"]);
    assert!(d.join("kept/plates/a.0002.exr").is_file());
    assert!(d.join("kept/morph.0002.exr").is_file());
}

/// The folds view's PNG holds the morph in R, G and B (straight colour, as
/// a host's PNG writer stores it), its alpha the folds: the picture is in
/// the file even where an image viewer that composites alpha shows none.
#[test]
fn a_folds_png_holds_the_morph_in_its_colour_channels() {
    let d = tmp("folds-png");
    // Opaque plates in [0, 1]: the morph's PNG is its colour as it is.
    let texture = |seed: f64| {
        move |p: morphfx::geom::Vec2| {
            let v = |c: f64| (0.5 + 0.4 * (p.x * 0.3 + p.y * 0.17 + seed + c).sin()) as f32;
            [v(0.0), v(1.0), v(2.0)]
        }
    };
    let (a, b) = (d.join("a.exr"), d.join("b.exr"));
    common::colour_plate(&a, 64, 48, texture(0.0));
    common::colour_plate(&b, 64, 48, texture(1.3));
    let (a, b) = (a.to_str().unwrap(), b.to_str().unwrap());
    std::fs::write(d.join("s.morph.json"), TRANSLATE).unwrap();
    let scene = d.join("s.morph.json");
    let render = |view: &str, out: &str| {
        let out = d.join(out);
        let (code, err) = morphfx(&[
            "morph",
            "--scene",
            scene.to_str().unwrap(),
            "--a",
            a,
            "--b",
            b,
            "--t",
            "0.5",
            "--view",
            view,
            "-o",
            out.to_str().unwrap(),
        ]);
        assert_eq!(code, 0, "{err}");
        ::image::open(out).unwrap().to_rgba8()
    };
    let (folds, morph) = (render("folds", "folds.png"), render("morph", "morph.png"));
    let mut unfolded = 0;
    for (f, m) in folds.pixels().zip(morph.pixels()) {
        if f.0[3] == 0 {
            unfolded += 1;
            assert_eq!(f.0[..3], m.0[..3], "the morph's colour, alpha 0");
        }
    }
    assert!(unfolded > 64 * 48 / 2, "{unfolded} pixels without folds");
}
