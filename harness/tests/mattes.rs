//! The nodes' mattes and diagnostic views through the C ABI: Mask and Mix
//! against `src + (effect − src) · mix · m` at every depth, a timing matte
//! against the procedural pacing closed form, the ghost view against the
//! warped sources it compares, and the folds view against a numeric
//! Jacobian of the ST maps.

use std::sync::Arc;

mod common;

use morphfx::geom::RectI;
use morphfx::image::Image;
use morphfx_harness::host::{self, Frame, FrameSource, OutputSpec};

use common::{bundle, Still};

const W: usize = 64;
const H: usize = 48;

fn plate(seed: f32) -> Image {
    Image::from_fn(RectI::from_size(W, H), 4, |i, j, c| {
        if c == 3 {
            1.0
        } else {
            0.5 + 0.4 * (i as f32 * 0.31 + j as f32 * 0.17 + seed + c as f32).sin()
        }
    })
}

fn still(img: &Image, depth: &'static str) -> Arc<Still> {
    Arc::new(Still(Arc::new(Frame::from_image(img, depth, false))))
}

/// A line that moves, so the effect differs from its source everywhere near it.
fn key_line(inst: &host::Instance<'_>) {
    inst.set_int("line_count", 1).unwrap();
    for (id, xy) in [
        ("line1_a_start", [10.0, 10.0]),
        ("line1_a_end", [50.0, 14.0]),
        ("line1_b_start", [16.0, 6.0]),
        ("line1_b_end", [55.0, 20.0]),
    ] {
        inst.set_double(id, &xy, None).unwrap();
    }
}

fn spec(depth: &'static str) -> OutputSpec {
    OutputSpec {
        depth,
        identity: false,
        ..OutputSpec::default()
    }
}

/// One code value of `depth`, the rounding a masked render may differ by
/// from the closed form on an effect already rounded to that depth.
fn code(depth: &str) -> f32 {
    match depth {
        "OfxBitDepthByte" => 1.0 / 255.0 + 1e-6,
        "OfxBitDepthShort" => 1.0 / 65535.0 + 1e-7,
        _ => 1e-5,
    }
}

/// `node` in `context` with source A (and B) connected at `depth` and one
/// line keyed; B only for Morph.
fn node<'b>(
    id: &str,
    context: &str,
    depth: &'static str,
    a: &Image,
    b: &Image,
) -> host::Instance<'b> {
    let inst = bundle().instance(id, context).unwrap();
    key_line(&inst);
    inst.set_project(W as f64, H as f64);
    if id.ends_with("Morph") {
        inst.connect("SourceA", still(a, depth)).unwrap();
        inst.connect("SourceB", still(b, depth)).unwrap();
        inst.set_double("progress", &[0.6], None).unwrap();
    } else {
        inst.connect("Source", still(a, depth)).unwrap();
        inst.set_double("progress", &[0.8], None).unwrap();
    }
    inst
}

/// The mask: alpha over a region that is not the sources' (and partly
/// outside them), at another depth than theirs.
fn mask_image() -> Image {
    Image::from_fn(RectI::new(10, 5, 80, 40), 1, |i, j, _| {
        ((i * 7 + j * 3) % 11) as f32 / 10.0
    })
}

#[test]
fn mask_and_mix_dial_the_effect_back_at_every_depth() {
    let (a, b) = (plate(0.0), plate(2.0));
    let mask = mask_image();
    let alpha = |i: i32, j: i32| {
        if mask.bounds.contains(&RectI::new(i, j, i + 1, j + 1)) {
            mask.pixel(i, j)[0]
        } else {
            0.0
        }
    };
    for (id, context) in [
        ("net.morphfx.Morph", "OfxImageEffectContextGeneral"),
        ("net.morphfx.Warp", "OfxImageEffectContextFilter"),
    ] {
        for depth in ["OfxBitDepthByte", "OfxBitDepthShort", "OfxBitDepthFloat"] {
            let plain = node(id, context, depth, &a, &b);
            let effect = plain.render(1.0, spec(depth)).unwrap().to_image();
            // Source A as the host holds it: rounded to the depth.
            let src = Frame::from_image(&a, depth, false).to_image();
            let masked = node(id, context, depth, &a, &b);
            masked
                .connect("Mask", still(&mask, "OfxBitDepthFloat"))
                .unwrap();
            masked.set_double("mix", &[0.7], None).unwrap();
            for invert in [false, true] {
                masked.set_int("mask_invert", invert as i32).unwrap();
                let got = masked.render(1.0, spec(depth)).unwrap().to_image();
                let mut moved = 0;
                for j in 0..H as i32 {
                    for i in 0..W as i32 {
                        let m = if invert {
                            1.0 - alpha(i, j)
                        } else {
                            alpha(i, j)
                        };
                        for c in 0..4 {
                            let (e, s) = (effect.pixel(i, j)[c], src.pixel(i, j)[c]);
                            let want = s + (e - s) * 0.7 * m;
                            let g = got.pixel(i, j)[c];
                            assert!(
                                (g - want).abs() <= code(depth),
                                "{id} {depth} invert {invert} ({i}, {j}) channel {c}: {g} vs {want}"
                            );
                            moved += ((e - s).abs() > 0.05 && m > 0.5) as usize;
                        }
                    }
                }
                assert!(moved > 100, "{id}: the effect reaches the output ({moved})");
            }
            // Alpha-only and RGB outputs mix like to like.
            for channels in [1, 3] {
                let out = OutputSpec {
                    channels,
                    ..spec(depth)
                };
                masked.set_int("mask_invert", 0).unwrap();
                let effect = plain.render(1.0, out).unwrap().to_image();
                let got = masked.render(1.0, out).unwrap().to_image();
                for j in 0..H as i32 {
                    for i in 0..W as i32 {
                        for c in 0..channels {
                            let s = src.pixel(i, j)[if channels == 1 { 3 } else { c }];
                            let e = effect.pixel(i, j)[c];
                            let want = s + (e - s) * 0.7 * alpha(i, j);
                            let g = got.pixel(i, j)[c];
                            assert!(
                                (g - want).abs() <= code(depth),
                                "{id} {depth} {channels} channels ({i}, {j}) {c}: {g} vs {want}"
                            );
                        }
                    }
                }
            }
            // Mix 0: the source, unchanged, as the identity action says.
            masked.set_double("mix", &[0.0], None).unwrap();
            let id_spec = OutputSpec {
                identity: true,
                ..spec(depth)
            };
            let got = masked.render(1.0, id_spec).unwrap().to_image();
            assert_eq!(got.data, src.data, "{id} {depth}: mix 0 passes A through");
        }
    }
}

/// Frame 1 one matte, frame 2 another: animated mattes are read at the
/// render time.
struct TwoMattes([Arc<Frame>; 2]);

impl FrameSource for TwoMattes {
    fn frame(&self, time: f64) -> Result<Arc<Frame>, String> {
        Ok(self.0[(time as usize).clamp(1, 2) - 1].clone())
    }
}

#[test]
fn a_timing_matte_paces_each_pixel_by_its_alpha() {
    let colour = |rgb: [f32; 3]| {
        Image::from_fn(
            RectI::from_size(W, H),
            4,
            move |_, _, c| {
                if c == 3 {
                    1.0
                } else {
                    rgb[c]
                }
            },
        )
    };
    let (a, b) = (colour([0.2, 0.4, 0.6]), colour([0.8, 0.1, 0.3]));
    let mattes = [
        Image::from_fn(RectI::from_size(W, H), 1, |i, _, _| {
            i as f32 / (W - 1) as f32
        }),
        Image::from_fn(RectI::from_size(W, H), 4, |_, j, c| {
            if c == 3 {
                j as f32 / (H - 1) as f32
            } else {
                0.3
            }
        }),
    ];
    let inst = bundle()
        .instance("net.morphfx.Morph", "OfxImageEffectContextGeneral")
        .unwrap();
    inst.set_project(W as f64, H as f64);
    inst.connect("SourceA", still(&a, "OfxBitDepthFloat"))
        .unwrap();
    inst.connect("SourceB", still(&b, "OfxBitDepthFloat"))
        .unwrap();
    let frames = mattes
        .clone()
        .map(|m| Arc::new(Frame::from_image(&m, "OfxBitDepthFloat", false)));
    inst.connect("Timing", Arc::new(TwoMattes(frames))).unwrap();
    let (t, s) = (0.45, 0.6);
    inst.set_double("progress", &[t], None).unwrap();
    inst.set_double("transition_spread", &[s], None).unwrap();
    for frame in [1usize, 2] {
        let got = inst.render(frame as f64, spec("OfxBitDepthFloat")).unwrap();
        let got = got.to_image();
        let matte = &mattes[frame - 1];
        for j in 0..H as i32 {
            for i in 0..W as i32 {
                let px = matte.pixel(i, j);
                let g = px[px.len() - 1] as f64;
                let rate = ((t - s * g) / (1.0 - s)).clamp(0.0, 1.0) as f32;
                for c in 0..3 {
                    let want = (1.0 - rate) * a.pixel(i, j)[c] + rate * b.pixel(i, j)[c];
                    let v = got.pixel(i, j)[c];
                    assert!(
                        (v - want).abs() < 1e-5,
                        "frame {frame} ({i}, {j}) channel {c}: {v} vs {want} (g {g})"
                    );
                }
            }
        }
    }
    // The ends stay exact whatever the matte says.
    for t in [0.0, 1.0] {
        inst.set_double("progress", &[t], None).unwrap();
        let got = inst
            .render(1.0, spec("OfxBitDepthFloat"))
            .unwrap()
            .to_image();
        let want = if t == 0.0 { &a } else { &b };
        assert_eq!(got.data, want.data, "t = {t}");
    }
}

#[test]
fn the_ghost_view_is_the_mean_difference_of_the_warped_sources() {
    let (a, b) = (plate(0.0), plate(2.0));
    let inst = node(
        "net.morphfx.Morph",
        "OfxImageEffectContextGeneral",
        "OfxBitDepthFloat",
        &a,
        &b,
    );
    let view = |v: &str| {
        inst.set_choice("view", v).unwrap();
        inst.render(1.0, spec("OfxBitDepthFloat"))
            .unwrap()
            .to_image()
    };
    let (wa, wb, ghost) = (view("warped-a"), view("warped-b"), view("ghost"));
    let mut lit = 0;
    for j in 0..H as i32 {
        for i in 0..W as i32 {
            let (pa, pb, g) = (wa.pixel(i, j), wb.pixel(i, j), ghost.pixel(i, j));
            let want = (0..3).map(|c| (pa[c] - pb[c]).abs()).sum::<f32>() / 3.0;
            assert!((g[3] - want).abs() < 1e-5, "({i}, {j}): {} vs {want}", g[3]);
            assert_eq!(&g[..3], &morphfx::views::heat(g[3])[..], "({i}, {j})");
            lit += (g[0] > 0.0) as usize;
        }
    }
    assert!(lit > W * H / 2, "different plates ghost almost everywhere");
    // Alike plates, no warp: no ghost at all.
    let same = node(
        "net.morphfx.Morph",
        "OfxImageEffectContextGeneral",
        "OfxBitDepthFloat",
        &a,
        &a,
    );
    same.set_int("line_count", 0).unwrap();
    same.set_choice("view", "ghost").unwrap();
    let g = same
        .render(1.0, spec("OfxBitDepthFloat"))
        .unwrap()
        .to_image();
    assert!(g.data.iter().all(|v| *v == 0.0), "no residual, all black");
}

/// Two parallel lines that swap places between A and B: at t = 0.3 the
/// field between them turns over.
fn swap_lines(inst: &host::Instance<'_>) {
    let (low, high) = ([[16.0, 18.0], [48.0, 18.0]], [[16.0, 30.0], [48.0, 30.0]]);
    common::set_line_slots(inst, &[(low, high), (high, low)]);
}

/// The Jacobian determinant of an ST map at an inner pixel, by central
/// differences (its sign is the map's: ST maps only scale positions).
fn stmap_det(st: &Image, i: i32, j: i32) -> f64 {
    let d = |c: usize, (i0, j0): (i32, i32), (i1, j1): (i32, i32)| {
        (st.pixel(i1, j1)[c] as f64 - st.pixel(i0, j0)[c] as f64) / 2.0
    };
    let (xi, yi) = (d(0, (i - 1, j), (i + 1, j)), d(1, (i - 1, j), (i + 1, j)));
    let (xj, yj) = (d(0, (i, j - 1), (i, j + 1)), d(1, (i, j - 1), (i, j + 1)));
    (xi * yj - yi * xj) * (W * H) as f64
}

/// Renders `inst`'s ST maps and folds view at `time` and checks that
/// folds mark exactly the pixels where a map's numeric Jacobian is not
/// positive; returns how many were folded and how many not.
fn check_folds(
    inst: &host::Instance<'_>,
    time: f64,
    stmaps: &[&str],
    picture: &str,
) -> (usize, usize) {
    let view = |v: &str| {
        inst.set_choice("view", v).unwrap();
        inst.render(time, spec("OfxBitDepthFloat"))
            .unwrap()
            .to_image()
    };
    let maps: Vec<Image> = stmaps.iter().map(|v| view(v)).collect();
    let (folds, picture) = (view("folds"), view(picture));
    let (mut folded, mut flat) = (0, 0);
    for j in 1..H as i32 - 1 {
        for i in 1..W as i32 - 1 {
            let dets: Vec<f64> = maps.iter().map(|m| stmap_det(m, i, j)).collect();
            // Too close to 0 for single-precision ST maps to say.
            if dets.iter().any(|d| d.abs() < 1e-3) {
                continue;
            }
            let want = dets.iter().any(|d| *d <= 0.0);
            let alpha = folds.pixel(i, j)[3];
            assert_eq!(alpha, if want { 1.0 } else { 0.0 }, "({i}, {j}): {dets:?}");
            if want {
                folded += 1;
            } else {
                flat += 1;
                assert_eq!(&folds.pixel(i, j)[..3], &picture.pixel(i, j)[..3]);
            }
        }
    }
    (folded, flat)
}

/// A float Morph node on two textured plates.
fn float_morph() -> host::Instance<'static> {
    let (a, b) = (plate(0.0), plate(2.0));
    node(
        "net.morphfx.Morph",
        "OfxImageEffectContextGeneral",
        "OfxBitDepthFloat",
        &a,
        &b,
    )
}

#[test]
fn the_folds_view_marks_where_a_numeric_jacobian_turns_over() {
    let (a, b) = (plate(0.0), plate(2.0));
    let morph = float_morph();
    let warp = node(
        "net.morphfx.Warp",
        "OfxImageEffectContextFilter",
        "OfxBitDepthFloat",
        &a,
        &b,
    );
    // At 0.3 B's map folds (its lines travel 0.7 of the way past each
    // other); the Warp node, with A's map alone, folds nearer B.
    for (inst, t, stmaps, picture) in [
        (&morph, 0.3, &["stmap-a", "stmap-b"][..], "morph"),
        (&warp, 0.7, &["stmap"][..], "warped"),
    ] {
        swap_lines(inst);
        inst.set_choice("evaluation", "exact").unwrap();
        inst.set_double("progress", &[t], None).unwrap();
        let (folded, flat) = check_folds(inst, 1.0, stmaps, picture);
        assert!(
            folded > 20 && flat > 20,
            "{picture} at {t}: {folded} folded, {flat} not"
        );
    }
}

/// A keyed grid (as Track Forward writes one: a key a frame) whose cells
/// are all convex, but whose B node is dragged up against its neighbour
/// at frame 10: the Catmull-Rom surface overshoots between them and the
/// map folds. The folds view marks exactly where, at the key and between
/// keys (frame 9), with both evaluations of the mesh; at frame 0 (A = B)
/// nothing folds.
#[test]
fn the_folds_view_marks_the_folds_a_keyed_grid_still_has() {
    let morph = float_morph();
    morph.set_int("line_count", 0).unwrap();
    morph.set_double("progress", &[0.7], None).unwrap();
    let (w, h) = (W as f64, H as f64);
    let grid = |middle: [f64; 2]| -> String {
        let mut nodes = Vec::new();
        for y in [0.0, h / 2.0, h] {
            for (c, x) in [0.0, 21.0, 42.0, w].into_iter().enumerate() {
                let p = if y == h / 2.0 && c == 1 {
                    middle
                } else {
                    [x, y]
                };
                nodes.push(format!("[{}, {}]", p[0], p[1]));
            }
        }
        format!("[{}]", nodes.join(", "))
    };
    let even = grid([21.0, h / 2.0]);
    let dragged = grid([40.0, h / 2.0]);
    for pass in ["one-pass", "two-pass"] {
        let scene = format!(
            r#"{{"method": "mesh", "mesh": {{"rows": 3, "cols": 4, "pass": "{pass}",
                "keyframes": [{{"frame": 0, "a": {even}, "b": {even}}},
                              {{"frame": 10, "a": {even}, "b": {dragged}}}]}}}}"#
        );
        morph.set_string("scene_text", &scene).unwrap();
        for frame in [10.0, 9.0] {
            let (folded, flat) = check_folds(&morph, frame, &["stmap-a", "stmap-b"], "morph");
            assert!(
                folded > 10 && flat > 1000,
                "{pass} at frame {frame}: {folded} folded, {flat} not"
            );
        }
        let (folded, _) = check_folds(&morph, 0.0, &["stmap-a", "stmap-b"], "morph");
        assert_eq!(folded, 0, "{pass}: the even grid at frame 0 folds nowhere");
    }
}

/// At render scale 0.5 (a proxy) the mask lines up by canonical position:
/// each output pixel takes the half-resolution mask's alpha there, and the
/// closed form holds against the proxy effect and source as the host
/// scaled them.
#[test]
fn the_mask_lines_up_at_half_render_scale() {
    let (a, b) = (plate(0.0), plate(2.0));
    let mask = mask_image();
    let half = OutputSpec {
        render_scale: (0.5, 0.5),
        ..spec("OfxBitDepthFloat")
    };
    let plain = node(
        "net.morphfx.Warp",
        "OfxImageEffectContextFilter",
        "OfxBitDepthFloat",
        &a,
        &b,
    );
    let effect = plain.render(1.0, half).unwrap().to_image();
    let masked = node(
        "net.morphfx.Warp",
        "OfxImageEffectContextFilter",
        "OfxBitDepthFloat",
        &a,
        &b,
    );
    masked
        .connect("Mask", still(&mask, "OfxBitDepthFloat"))
        .unwrap();
    masked.set_double("mix", &[0.7], None).unwrap();
    let got = masked.render(1.0, half).unwrap().to_image();
    // What the plugin is handed at this scale.
    let scaled = |img: &Image| {
        Frame::from_image(img, "OfxBitDepthFloat", false)
            .scaled((0.5, 0.5))
            .to_image()
    };
    let (src, m) = (scaled(&a), scaled(&mask));
    let mut masked_pixels = 0;
    for j in got.bounds.y1..got.bounds.y2 {
        for i in got.bounds.x1..got.bounds.x2 {
            let inside = m.bounds.contains(&RectI::new(i, j, i + 1, j + 1));
            let alpha = if inside { m.pixel(i, j)[0] } else { 0.0 };
            masked_pixels += (alpha > 0.0) as usize;
            for c in 0..4 {
                let (e, s) = (effect.pixel(i, j)[c], src.pixel(i, j)[c]);
                let want = s + (e - s) * 0.7 * alpha;
                let g = got.pixel(i, j)[c];
                assert!((g - want).abs() < 1e-5, "({i}, {j}) {c}: {g} vs {want}");
            }
        }
    }
    assert!(masked_pixels > 100);
}
