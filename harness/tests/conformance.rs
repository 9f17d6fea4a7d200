//! Host conformance through the C ABI, as hosts other than ours behave: the
//! transition context's mandated param, the identity action, missing images
//! as transparent black, render errors as the node's persistent message,
//! suites fetched only from the load action, render-order independence, the
//! project rectangle, descriptor properties, and the CPU the bundle picks.

use std::sync::Arc;

mod common;

use morphfx::geom::{RectI, Vec2};
use morphfx::image::Image;
use morphfx_harness::host::{self, Frame, FrameSource, OutputSpec};
use openfx::sys::image_effect_v1::image_effect::*;

use common::{bundle, Still};

/// A connected clip whose every image fetch fails (Resolve hands back no
/// image for clips it reports connected).
struct NoImage;

impl FrameSource for NoImage {
    fn frame(&self, time: f64) -> Result<Arc<Frame>, String> {
        Err(format!("no image at {time}"))
    }
}

fn plate(w: usize, h: usize, seed: f32) -> Image {
    Image::from_fn(RectI::from_size(w, h), 4, |i, j, c| {
        if c == 3 {
            1.0
        } else {
            0.5 + 0.4 * (i as f32 * 0.31 + j as f32 * 0.17 + seed + c as f32).sin()
        }
    })
}

fn still(img: &Image) -> Arc<Still> {
    Arc::new(Still(Arc::new(Frame::from_image(
        img,
        "OfxBitDepthFloat",
        false,
    ))))
}

/// One line pair moving, so every in-between differs from both sources.
fn key_one_line(inst: &host::Instance<'_>) {
    key_line(
        inst,
        [[10.0, 10.0], [50.0, 14.0]],
        [[16.0, 6.0], [55.0, 20.0]],
    );
}

/// The only line pair: from `a` (start, end) on A to `b` on B.
fn key_line(inst: &host::Instance<'_>, a: [[f64; 2]; 2], b: [[f64; 2]; 2]) {
    inst.set_int("line_count", 1).unwrap();
    for (id, xy) in [
        ("line1_a_start", a[0]),
        ("line1_a_end", a[1]),
        ("line1_b_start", b[0]),
        ("line1_b_end", b[1]),
    ] {
        inst.set_double(id, &xy, None).unwrap();
    }
}

const OWN_PIXELS: OutputSpec = OutputSpec {
    depth: "OfxBitDepthFloat",
    channels: 4,
    top_down: false,
    render_scale: (1.0, 1.0),
    tiles: 1,
    identity: false,
    sequential: false,
    interactive: false,
    window: None,
};

#[test]
fn transition_context_renders_from_the_mandated_transition_param() {
    let (a, b) = (plate(64, 48, 0.0), plate(64, 48, 2.0));
    let inst = bundle()
        .instance("net.morphfx.Morph", "OfxImageEffectContextTransition")
        .unwrap();
    assert!(
        inst.param_names().iter().any(|(n, _)| n == "Transition"),
        "the plugin defines the mandated Transition param itself"
    );
    key_one_line(&inst);
    inst.set_project(64.0, 48.0);
    inst.connect("SourceFrom", still(&a)).unwrap();
    inst.connect("SourceTo", still(&b)).unwrap();
    let general = bundle()
        .instance("net.morphfx.Morph", "OfxImageEffectContextGeneral")
        .unwrap();
    key_one_line(&general);
    general.set_project(64.0, 48.0);
    general.connect("SourceA", still(&a)).unwrap();
    general.connect("SourceB", still(&b)).unwrap();
    general.set_double("progress", &[0.37], None).unwrap();

    inst.begin_sequence(1.0, 1.0).unwrap();
    for (t, want) in [(0.0, Some(&a)), (1.0, Some(&b)), (0.37, None)] {
        inst.set_double("Transition", &[t], None).unwrap();
        let got = inst.render(1.0, OutputSpec::default()).unwrap().to_image();
        match want {
            Some(source) => assert_eq!(got.data, source.data, "Transition = {t}"),
            None => {
                let g = general
                    .render(1.0, OutputSpec::default())
                    .unwrap()
                    .to_image();
                assert_eq!(got.data, g.data, "Transition 0.37 is the morph at 0.37");
                assert_ne!(got.data, a.data);
                assert_ne!(got.data, b.data);
            }
        }
    }
    inst.end_sequence(1.0, 1.0).unwrap();
}

#[test]
fn identity_names_the_source_the_output_equals() {
    let a = plate(64, 48, 0.0);
    let morph = bundle()
        .instance("net.morphfx.Morph", "OfxImageEffectContextGeneral")
        .unwrap();
    key_one_line(&morph);
    morph.connect("SourceA", still(&a)).unwrap();
    morph.connect("SourceB", still(&a)).unwrap();
    morph.set_int("frame_offset_b", 3).unwrap();
    let window = RectI::from_size(64, 48);
    let ask = |t: f64| {
        morph.set_double("progress", &[t], None).unwrap();
        morph.identity(7.0, window, (1.0, 1.0)).unwrap()
    };
    assert_eq!(ask(0.0), Some(("SourceA".to_owned(), 7.0)));
    assert_eq!(ask(1.0), Some(("SourceB".to_owned(), 10.0)), "B's offset");
    assert_eq!(ask(0.5), None);
    // A transition pattern delays pixels: never an identity in between...
    morph.set_int("transition", 1).unwrap();
    assert_eq!(ask(0.5), None);
    // ...and the ST map view is never a source.
    morph.set_int("transition", 0).unwrap();
    morph.set_choice("view", "stmap-a").unwrap();
    assert_eq!(ask(0.0), None);

    let warp = bundle()
        .instance("net.morphfx.Warp", "OfxImageEffectContextFilter")
        .unwrap();
    key_one_line(&warp);
    warp.connect("Source", still(&a)).unwrap();
    warp.set_double("progress", &[0.0], None).unwrap();
    assert_eq!(
        warp.identity(2.0, window, (0.5, 0.5)).unwrap(),
        Some(("Source".to_owned(), 2.0))
    );
    warp.set_double("progress", &[1.0], None).unwrap();
    assert_eq!(warp.identity(2.0, window, (1.0, 1.0)).unwrap(), None);
}

#[test]
fn a_source_without_an_image_is_transparent_black() {
    let a = plate(64, 48, 0.0);
    let inst = bundle()
        .instance("net.morphfx.Morph", "OfxImageEffectContextGeneral")
        .unwrap();
    key_one_line(&inst);
    inst.set_project(64.0, 48.0);
    inst.connect("SourceA", still(&a)).unwrap();
    inst.connect("SourceB", Arc::new(NoImage)).unwrap();
    inst.set_double("progress", &[0.25], None).unwrap();
    let morph = inst.render(1.0, OWN_PIXELS).unwrap().to_image();
    // The same morph's warped A alone, scaled by 1 - t: B adds nothing.
    inst.set_choice("view", "warped-a").unwrap();
    let warped_a = inst.render(1.0, OWN_PIXELS).unwrap().to_image();
    for (m, w) in morph.data.iter().zip(&warped_a.data) {
        assert!((m - 0.75 * w).abs() < 1e-5, "{m} vs 0.75 x {w}");
    }
    assert!(inst.effect.persistent.lock().unwrap().is_none());
}

#[test]
fn render_errors_stay_on_the_node_until_a_good_render() {
    let a = plate(32, 24, 0.0);
    let inst = bundle()
        .instance("net.morphfx.Warp", "OfxImageEffectContextFilter")
        .unwrap();
    inst.connect("Source", still(&a)).unwrap();
    inst.set_project(32.0, 24.0);
    inst.set_string("scene_text", "{ not a scene").unwrap();
    let err = inst.render(1.0, OWN_PIXELS).unwrap_err();
    assert!(err.message.contains("scene text"), "{}", err.message);
    let shown = inst.effect.persistent.lock().unwrap().clone();
    let shown = shown.expect("the error is the node's persistent message");
    assert_eq!(shown.kind, "OfxMessageError");
    assert!(shown.text.contains("scene text"));
    assert!(
        inst.effect.take_messages().is_empty(),
        "no transient message (a modal dialog per thread in some hosts)"
    );
    inst.set_string("scene_text", "").unwrap();
    inst.render(1.0, OWN_PIXELS).unwrap();
    assert!(inst.effect.persistent.lock().unwrap().is_none(), "cleared");
}

#[test]
fn suites_are_fetched_from_the_load_action_on() {
    let inst = bundle()
        .instance("net.morphfx.Warp", "OfxImageEffectContextFilter")
        .unwrap();
    inst.connect("Source", still(&plate(16, 16, 0.0))).unwrap();
    inst.render(1.0, OWN_PIXELS).unwrap();
    let seen = host::take_violations();
    assert!(seen.is_empty(), "spec violations: {seen:?}");
}

#[test]
fn descriptors_say_how_to_render_them() {
    for (id, context) in [
        ("net.morphfx.Morph", "OfxImageEffectContextGeneral"),
        ("net.morphfx.Warp", "OfxImageEffectContextFilter"),
    ] {
        let inst = bundle().instance(id, context).unwrap();
        let props = inst.descriptor_props();
        assert_eq!(
            props.ints(kOfxImageEffectInstancePropSequentialRender),
            vec![2],
            "{id}: any order is correct, frame order is faster"
        );
        // A geometric warp must render interlaced fields one at a time: the
        // default (1) stands unless the plugin renders fields itself.
        assert_ne!(
            props.ints(kOfxImageEffectPluginPropFieldRenderTwiceAlways),
            vec![0],
            "{id}"
        );
    }
}

#[test]
fn frames_render_the_same_in_any_order() {
    // Thin plates warm-start from a neighbouring frame only in a viewer's
    // interactive render; a host rendering frames in any order (farm
    // chunks, threads), in sequence or not, gets exactly the frame a fresh
    // instance makes.
    let a = plate(96, 64, 0.0);
    let render = |frames: &[f64], sequential: bool| {
        let inst = bundle()
            .instance("net.morphfx.Warp", "OfxImageEffectContextFilter")
            .unwrap();
        key_one_line(&inst);
        inst.set_int("method", 3).unwrap(); // thin-plate
        inst.set_double("line1_b_end", &[55.0, 20.0], Some(1.0))
            .unwrap();
        inst.set_double("line1_b_end", &[58.0, 26.0], Some(2.0))
            .unwrap();
        inst.set_project(96.0, 64.0);
        inst.connect("Source", still(&a)).unwrap();
        inst.set_double("progress", &[1.0], None).unwrap();
        let mut last = None;
        for &f in frames {
            let spec = OutputSpec {
                sequential,
                ..OWN_PIXELS
            };
            last = Some(inst.render(f, spec).unwrap().to_image());
        }
        last.unwrap()
    };
    for sequential in [false, true] {
        assert_eq!(
            render(&[1.0, 2.0], sequential).data,
            render(&[2.0], sequential).data,
            "sequential: {sequential}"
        );
    }
}

#[test]
fn st_maps_are_normalised_by_the_project_size_at_its_offset() {
    // A letterboxed project: extent 64 x 64 from 0,0; images 64 x 40 at y = 12.
    let img = Image::from_fn(RectI::new(0, 12, 64, 52), 4, |_, _, _| 1.0);
    let inst = bundle()
        .instance("net.morphfx.Warp", "OfxImageEffectContextFilter")
        .unwrap();
    inst.set_letterboxed_project((64.0, 64.0), (0.0, 12.0), (64.0, 40.0));
    inst.connect("Source", still(&img)).unwrap();
    inst.set_choice("view", "stmap").unwrap();
    let st = inst.render(1.0, OWN_PIXELS).unwrap().to_image();
    for (i, j) in [(0, 12), (63, 51), (20, 30)] {
        let p = st.pixel(i, j);
        let c = Vec2::new(i as f64 + 0.5, j as f64 + 0.5);
        assert!(
            (p[0] as f64 - c.x / 64.0).abs() < 1e-6,
            "s at {i},{j}: {}",
            p[0]
        );
        assert!(
            (p[1] as f64 - (c.y - 12.0) / 40.0).abs() < 1e-6,
            "t at {i},{j}: {}",
            p[1]
        );
    }
}

#[test]
fn the_bundle_runs_baseline_code_on_a_cpu_without_avx2() {
    let listing = |baseline: bool| {
        let mut c = std::process::Command::new(env!("CARGO_BIN_EXE_morphfx"));
        c.arg("--bundle").arg(common::bundle_path()).arg("plugins");
        if baseline {
            c.env("MORPHFX_CPU", "baseline");
        }
        let out = c.output().unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        String::from_utf8_lossy(&out.stdout).into_owned()
    };
    let old_cpu = listing(true);
    assert!(
        old_cpu.contains("net.morphfx.Morph\t1.0\tMorphFX.ofx"),
        "{old_cpu}"
    );
    if std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma") {
        let here = listing(false);
        assert!(
            here.contains("net.morphfx.Morph\t1.0\tMorphFX-x86-64-v3.so"),
            "{here}"
        );
    }
    // Under an emulated CPU without AVX2, when qemu-user is installed.
    let qemu = std::process::Command::new("qemu-x86_64")
        .args(["-cpu", "Nehalem"])
        .arg(env!("CARGO_BIN_EXE_morphfx"))
        .arg("--bundle")
        .arg(common::bundle_path())
        .arg("plugins")
        .output();
    match qemu {
        Ok(out) => {
            assert!(
                out.status.success(),
                "on Nehalem: {:?} {}",
                out.status,
                String::from_utf8_lossy(&out.stderr)
            );
            assert!(String::from_utf8_lossy(&out.stdout).contains("MorphFX.ofx"));
        }
        Err(e) => {
            assert!(
                common::may_skip_without("qemu-x86_64"),
                "qemu-x86_64 was installed for this run but does not start: {e}"
            );
            eprintln!("qemu-x86_64 not installed: the emulated-CPU check is skipped");
        }
    }
}

#[test]
fn line_points_have_a_range_and_a_display_range() {
    use openfx::sys::image_effect_v1::param::*;
    let inst = bundle()
        .instance("net.morphfx.Morph", "OfxImageEffectContextGeneral")
        .unwrap();
    let props = inst.param_props("line1_a_start").unwrap();
    let (min, max) = (
        props.doubles(kOfxParamPropMin),
        props.doubles(kOfxParamPropMax),
    );
    let (dmin, dmax) = (
        props.doubles(kOfxParamPropDisplayMin),
        props.doubles(kOfxParamPropDisplayMax),
    );
    assert_eq!((min.len(), max.len(), dmin.len(), dmax.len()), (2, 2, 2, 2));
    // Wide enough for overscan on a 4K frame, and a display range inside it.
    assert!(min.iter().all(|v| *v <= -4096.0) && max.iter().all(|v| *v >= 8192.0));
    assert!(dmin
        .iter()
        .zip(&dmax)
        .all(|(lo, hi)| *lo >= min[0] && lo < hi && *hi <= max[0]));
}

#[test]
fn the_output_is_declared_frame_varying_and_premultiplied() {
    let inst = bundle()
        .instance("net.morphfx.Morph", "OfxImageEffectContextGeneral")
        .unwrap();
    let a = plate(16, 16, 0.0);
    inst.connect("SourceA", still(&a)).unwrap();
    inst.connect("SourceB", still(&a)).unwrap();
    let prefs = inst.clip_preferences().unwrap();
    // Natron caches one frame for every time of an output not frame-varying.
    assert_eq!(prefs.ints(kOfxImageEffectFrameVarying), vec![1]);
    assert_eq!(
        prefs.strs(kOfxImageEffectPropPreMultiplication),
        vec!["OfxImageAlphaPremultiplied".to_owned()]
    );
}

#[test]
fn a_warm_started_thin_plate_matches_a_cold_one_at_another_scale() {
    // A viewer renders full size, then a proxy of the same frame: the warm
    // start from the full-size plates must land on the same warp.
    let a = plate(96, 64, 0.0);
    let render = |scales: &[f64]| {
        let inst = bundle()
            .instance("net.morphfx.Warp", "OfxImageEffectContextFilter")
            .unwrap();
        // One horizontal line, its ends moving apart vertically: the plates
        // were free to tilt about it.
        key_line(
            &inst,
            [[60.0, 50.0], [80.0, 50.0]],
            [[62.0, 48.0], [82.0, 53.0]],
        );
        inst.set_int("method", 3).unwrap(); // thin-plate
        inst.set_project(96.0, 64.0);
        inst.connect("Source", still(&a)).unwrap();
        let mut last = None;
        for &s in scales {
            // A viewer's renders: the only ones thin plates warm-start in.
            let spec = OutputSpec {
                render_scale: (s, s),
                interactive: true,
                ..OWN_PIXELS
            };
            last = Some(inst.render(0.0, spec).unwrap().to_image());
        }
        last.unwrap()
    };
    let (warm, cold) = (render(&[1.0, 0.5]), render(&[0.5]));
    let worst = warm
        .data
        .iter()
        .zip(&cold.data)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0f32, f32::max);
    assert!(worst < 1e-3, "warm and cold proxies differ by {worst}");
}

#[test]
fn a_straight_source_is_premultiplied_before_it_meets_a_premultiplied_one() {
    // Semi-transparent plates, A premultiplied and B straight, and a line
    // that stays put (both warps the identity): the output is declared
    // premultiplied, so it must be 0.5 A + 0.5 (B's colour times B's alpha).
    let semi = |seed: f32| {
        Image::from_fn(RectI::from_size(48, 32), 4, move |i, j, c| {
            let alpha = 0.5 + 0.5 * (i as f32 * 0.21 + j as f32 * 0.13 + seed).sin();
            if c == 3 {
                alpha
            } else {
                alpha * (0.5 + 0.4 * (i as f32 * 0.3 + seed + c as f32).cos())
            }
        })
    };
    let (a, b) = (semi(0.0), semi(1.7));
    let mut straight_b = Frame::from_image(&b, "OfxBitDepthFloat", false);
    straight_b.premultiplied = false;
    let inst = bundle()
        .instance("net.morphfx.Morph", "OfxImageEffectContextGeneral")
        .unwrap();
    key_line(
        &inst,
        [[10.0, 10.0], [30.0, 12.0]],
        [[10.0, 10.0], [30.0, 12.0]],
    );
    inst.set_project(48.0, 32.0);
    inst.connect("SourceA", still(&a)).unwrap();
    inst.connect("SourceB", Arc::new(Still(Arc::new(straight_b))))
        .unwrap();
    inst.set_double("progress", &[0.5], None).unwrap();
    let morph = inst.render(1.0, OWN_PIXELS).unwrap().to_image();
    inst.set_choice("view", "warped-b").unwrap();
    let warped_b = inst.render(1.0, OWN_PIXELS).unwrap().to_image();
    for j in 0..32 {
        for i in 0..48 {
            let (pa, pb) = (a.pixel(i, j), b.pixel(i, j));
            let premult_b = [pb[0] * pb[3], pb[1] * pb[3], pb[2] * pb[3], pb[3]];
            for c in 0..4 {
                let want = 0.5 * (pa[c] + premult_b[c]);
                let (m, w) = (morph.pixel(i, j)[c], warped_b.pixel(i, j)[c]);
                assert!((m - want).abs() < 1e-5, "({i}, {j}) ch {c}: {m} vs {want}");
                assert!(
                    (w - premult_b[c]).abs() < 1e-5,
                    "warped B ({i}, {j}) ch {c}: {w}"
                );
            }
        }
    }
}

/// A still whose clip reports an infinite region of definition (a constant
/// or a Roto upstream) while its images hold the plate's pixels.
struct Unbounded(Arc<Frame>);

impl FrameSource for Unbounded {
    fn frame(&self, _: f64) -> Result<Arc<Frame>, String> {
        Ok(self.0.clone())
    }
    fn infinite(&self) -> bool {
        true
    }
}

#[test]
fn an_infinite_source_region_renders_the_same_pixels_in_the_project() {
    let a = plate(64, 48, 0.0);
    let render = |source: Arc<dyn FrameSource>| {
        let inst = bundle()
            .instance("net.morphfx.Warp", "OfxImageEffectContextFilter")
            .unwrap();
        key_one_line(&inst);
        inst.set_project(64.0, 48.0);
        inst.connect("Source", source).unwrap();
        inst.render(1.0, OWN_PIXELS).unwrap().to_image()
    };
    let frame = Arc::new(Frame::from_image(&a, "OfxBitDepthFloat", false));
    let finite = render(Arc::new(Still(frame.clone())));
    let infinite = render(Arc::new(Unbounded(frame)));
    assert_eq!(infinite.bounds, RectI::from_size(64, 48), "the project");
    assert_eq!(infinite.data, finite.data);
}

#[test]
fn anamorphic_pixels_move_by_canonical_distance_over_the_pixel_aspect() {
    // Pixels twice as wide as tall: one line pair moved 10 canonical units
    // right (a pure translation for a single line) moves the picture 5 px.
    let a = plate(64, 48, 0.0);
    let mut frame = Frame::from_image(&a, "OfxBitDepthFloat", false);
    frame.par = 2.0;
    let inst = bundle()
        .instance("net.morphfx.Warp", "OfxImageEffectContextFilter")
        .unwrap();
    inst.set_pixel_aspect(2.0);
    inst.set_project(128.0, 48.0);
    key_line(
        &inst,
        [[40.0, 10.0], [80.0, 30.0]],
        [[50.0, 10.0], [90.0, 30.0]],
    );
    inst.set_double("progress", &[1.0], None).unwrap();
    inst.connect("Source", Arc::new(Still(Arc::new(frame))))
        .unwrap();
    let out = inst.render(1.0, OWN_PIXELS).unwrap().to_image();
    assert_eq!(out.bounds, RectI::from_size(64, 48), "64 pixels, 128 units");
    for j in 0..48 {
        for i in 5..64 {
            for c in 0..4 {
                let (o, s) = (out.pixel(i, j)[c], a.pixel(i - 5, j)[c]);
                assert!((o - s).abs() < 1e-4, "({i}, {j}) ch {c}: {o} vs {s}");
            }
        }
    }
}

#[test]
fn interlaced_footage_is_warped_one_field_at_a_time() {
    // Lower field first. A line pair moved 3 lines up (a pure translation)
    // must move each field within itself: output line y of either field is
    // that field's line nearest below y - 3, never a line of the other
    // field (what warping both fields at once would give).
    let a = plate(64, 48, 0.0);
    let inst = bundle()
        .instance("net.morphfx.Warp", "OfxImageEffectContextFilter")
        .unwrap();
    inst.set_project(64.0, 48.0);
    key_line(
        &inst,
        [[10.0, 10.0], [50.0, 30.0]],
        [[10.0, 13.0], [50.0, 33.0]],
    );
    inst.set_double("progress", &[1.0], None).unwrap();
    inst.connect("Source", still(&a)).unwrap();
    inst.set_field_order("OfxImageFieldLower");
    let out = inst.render(1.0, OWN_PIXELS).unwrap().to_image();
    for j in 4..48i32 {
        let field = j % 2;
        let from = (j - 3) - (j - 3).rem_euclid(2) + field;
        for i in 0..64 {
            for c in 0..4 {
                let (o, s) = (out.pixel(i, j)[c], a.pixel(i, from)[c]);
                assert!(
                    (o - s).abs() < 1e-4,
                    "({i}, {j}) ch {c}: {o} vs line {from}: {s}"
                );
            }
        }
    }
}

#[test]
fn the_ghost_and_folds_views_ask_for_rgba_output() {
    // Their measure is in alpha: a host that follows RGB sources with an
    // RGB output (Natron) would drop it unless the node asks for RGBA.
    let name = c"OfxImageClipPropComponents_Output";
    for (id, context, views) in [
        (
            "net.morphfx.Morph",
            "OfxImageEffectContextGeneral",
            &["ghost", "folds", "morph"][..],
        ),
        (
            "net.morphfx.Warp",
            "OfxImageEffectContextFilter",
            &["folds", "warped"][..],
        ),
    ] {
        let inst = bundle().instance(id, context).unwrap();
        for view in views {
            inst.set_choice("view", view).unwrap();
            let out = inst.clip_preferences_from("OfxImageComponentRGB").unwrap();
            let want = if matches!(*view, "ghost" | "folds") {
                "OfxImageComponentRGBA"
            } else {
                "OfxImageComponentRGB"
            };
            assert_eq!(out.str(name).as_deref(), Some(want), "{id} {view}");
        }
    }
}
