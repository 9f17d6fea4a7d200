//! The built bundle loaded through its C ABI (never linked): plugin list,
//! descriptors, params, and renders held against the core engine's output for
//! the same inputs at render scale 1 and 0.5, every depth and component kind,
//! shifted image bounds, negative row bytes, and concurrent tiles — for the
//! field, mesh and triangle methods.

use std::sync::Arc;

mod common;

use morphfx::choice::Choice;
use morphfx::features::{Feature, FeatureKind, Side};
use morphfx::geom::{PixelScale, RectD, RectI, Vec2};
use morphfx::image::{EdgeMode, Filter, Image, Sampler};
use morphfx::morph::{dissolve, Warped};
use morphfx::warp::auto::{self, AutoSettings, WorkImage};
use morphfx::warp::field::{Evaluation, FieldSettings, FieldWarp};
use morphfx::warp::mesh::{two_pass, Mesh, MeshPair};
use morphfx::warp::triangles::TriangleWarp;
use morphfx::warp::Warp;
use morphfx_harness::host::{Frame, OutputSpec};
use openfx::sys::generic::core::*;
use openfx::sys::image_effect_v1::param::*;

use common::{bundle, Still};

const DEPTHS: [&str; 3] = ["OfxBitDepthByte", "OfxBitDepthShort", "OfxBitDepthFloat"];

/// Line pair k (A start, A end, B start, B end) in canonical pixels.
fn lines() -> Vec<[(f64, f64); 4]> {
    vec![
        [(12.0, 10.0), (50.0, 14.0), (16.0, 6.0), (55.0, 12.0)],
        [(20.0, 40.0), (22.0, 22.0), (24.0, 42.0), (20.0, 20.0)],
        [(44.0, 20.0), (60.0, 38.0), (40.0, 24.0), (58.0, 40.0)],
    ]
}

fn features() -> Vec<Feature> {
    let v = |(x, y): (f64, f64)| Vec2::new(x, y);
    lines()
        .into_iter()
        .map(|[a0, a1, b0, b1]| Feature {
            name: None,
            kind: FeatureKind::Line,
            a: vec![v(a0), v(a1)],
            b: vec![v(b0), v(b1)],
            closed: false,
            confidence: None,
        })
        .collect()
}

/// A plate with smooth detail (values in [0, 1] so 8/16-bit hold them).
fn plate(bounds: RectI, channels: usize, seed: f32) -> Image {
    Image::from_fn(bounds, channels, |i, j, c| {
        0.5 + 0.45 * ((i as f32 * 0.21 + seed) * (c as f32 + 1.0) + j as f32 * 0.13).sin()
    })
}

/// The warp generator a case renders with.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Method {
    /// Line slots keyed on the node.
    Field,
    /// The scene text's mesh, two-pass.
    Mesh,
    /// The scene text's features, triangulated.
    Triangles,
    /// Found from the two sources (work minimisation).
    Auto,
    /// The scene text's features as point pairs: thin-plate, mffd or hybrid.
    Scattered(morphfx::make_warp::Method),
}

/// A 4 × 4 mesh on `bounds` (canonical at full resolution), its inner
/// nodes moved on B.
fn mesh_pair(bounds: RectI) -> MeshPair {
    let (x1, y1, x2, y2) = (
        bounds.x1 as f64,
        bounds.y1 as f64,
        bounds.x2 as f64,
        bounds.y2 as f64,
    );
    let a = Mesh::regular(4, 4, x1, y1, x2, y2).unwrap();
    let b = a.map_nodes(|r, c, p| {
        let inner = (1..3).contains(&r) && (1..3).contains(&c);
        if inner {
            p + Vec2::new(3.0 * (c as f64 - 1.5), 2.5 * (r as f64 - 1.2))
        } else {
            p
        }
    });
    MeshPair::new(a, b).unwrap()
}

fn points_json(points: &[Vec2]) -> String {
    let p: Vec<String> = points
        .iter()
        .map(|p| format!("[{}, {}]", p.x, p.y))
        .collect();
    format!("[{}]", p.join(", "))
}

/// The scene text a case puts on the node.
fn scene_text(case: &Case) -> String {
    match case.method {
        Method::Field => String::new(),
        Method::Auto => r#"{"method": "auto"}"#.into(),
        Method::Mesh => {
            let pair = mesh_pair(case.bounds);
            format!(
                r#"{{"method": "mesh", "mesh": {{"rows": 4, "cols": 4, "a": {}, "b": {}}}}}"#,
                points_json(pair.a.nodes()),
                points_json(pair.b.nodes())
            )
        }
        Method::Triangles | Method::Scattered(_) => {
            let name = match case.method {
                Method::Scattered(m) => m.name(),
                _ => "triangles",
            };
            let f: Vec<String> = features()
                .iter()
                .map(|f| {
                    format!(
                        r#"{{"type": "line", "a": {}, "b": {}}}"#,
                        points_json(&f.a),
                        points_json(&f.b)
                    )
                })
                .collect();
            format!(
                r#"{{"method": "{}", "features": [{}]}}"#,
                name,
                f.join(", ")
            )
        }
    }
}

struct Case {
    method: Method,
    depth: &'static str,
    channels: usize,
    scale: f64,
    bounds: RectI,
    top_down: bool,
    tiles: usize,
}

impl Default for Case {
    fn default() -> Self {
        Case {
            method: Method::Field,
            depth: "OfxBitDepthFloat",
            channels: 4,
            scale: 1.0,
            bounds: RectI::new(0, 0, 64, 48),
            top_down: false,
            tiles: 1,
        }
    }
}

const T: f64 = 0.4;

/// The Morph node set up for `case`, its sources and the output spec.
fn morph_node(
    case: &Case,
) -> (
    morphfx_harness::host::Instance<'static>,
    [Arc<Frame>; 2],
    OutputSpec,
) {
    let b = bundle();
    let inst = b
        .instance("net.morphfx.Morph", "OfxImageEffectContextGeneral")
        .unwrap();
    let fa = Arc::new(Frame::from_image(
        &plate(case.bounds, case.channels, 0.0),
        case.depth,
        case.top_down,
    ));
    let fb = Arc::new(Frame::from_image(
        &plate(case.bounds, case.channels, 1.3),
        case.depth,
        case.top_down,
    ));
    inst.connect("SourceA", Arc::new(Still(fa.clone())))
        .unwrap();
    inst.connect("SourceB", Arc::new(Still(fb.clone())))
        .unwrap();
    inst.set_project(case.bounds.width() as f64, case.bounds.height() as f64);
    inst.set_double("progress", &[T], None).unwrap();
    inst.set_choice("evaluation", "exact").unwrap();
    if case.method != Method::Field {
        inst.set_string("scene_text", &scene_text(case)).unwrap();
    }
    let ls = if case.method == Method::Field {
        lines()
    } else {
        Vec::new()
    };
    inst.set_int("line_count", ls.len() as i32).unwrap();
    for (k, [a0, a1, b0, b1]) in ls.into_iter().enumerate() {
        let k = k + 1;
        for (id, (x, y)) in [
            ("a_start", a0),
            ("a_end", a1),
            ("b_start", b0),
            ("b_end", b1),
        ] {
            inst.set_double(&format!("line{k}_{id}"), &[x, y], None)
                .unwrap();
        }
    }
    let spec = OutputSpec {
        depth: case.depth,
        channels: case.channels,
        top_down: case.top_down,
        render_scale: (case.scale, case.scale),
        tiles: case.tiles,
        // The plugin's own pixels, compared with the core's.
        identity: false,
        sequential: false,
        interactive: false,
        window: None,
    };
    (inst, [fa, fb], spec)
}

/// Renders the Morph node through the C ABI: (output, source frames as the plugin saw them).
fn render_morph(case: &Case) -> (Image, Image, Image) {
    let (inst, [fa, fb], spec) = morph_node(case);
    inst.begin_sequence(1.0, 1.0).unwrap();
    let out = inst.render(1.0, spec).unwrap();
    inst.end_sequence(1.0, 1.0).unwrap();
    let s = (case.scale, case.scale);
    (
        out.to_image(),
        fa.scaled(s).to_image(),
        fb.scaled(s).to_image(),
    )
}

/// The core engine on the same (already scaled, already quantised) sources.
fn expected(case: &Case, a: &Image, b: &Image) -> Image {
    let settings = FieldSettings {
        evaluation: Evaluation::Exact,
        ..FieldSettings::default()
    };
    let f = features();
    let scale = PixelScale::new(case.scale, case.scale, 1.0);
    let full = a.bounds;
    let sa = Sampler::new(a.view(), scale, Filter::Bilinear, EdgeMode::Clamp, true);
    let sb = Sampler::new(b.view(), scale, Filter::Bilinear, EdgeMode::Clamp, true);
    let mut out = Image::new(full, case.channels);
    let frame = RectD::new(
        case.bounds.x1 as f64,
        case.bounds.y1 as f64,
        case.bounds.x2 as f64,
        case.bounds.y2 as f64,
    );
    let correspondence = (case.method == Method::Auto).then(|| {
        let canonical = |im: &Image| {
            let r = im.bounds;
            RectD::new(
                r.x1 as f64 / case.scale,
                r.y1 as f64 / case.scale,
                r.x2 as f64 / case.scale,
                r.y2 as f64 / case.scale,
            )
        };
        auto::correspond(
            &WorkImage::from_view(&a.view()),
            canonical(a),
            &WorkImage::from_view(&b.view()),
            canonical(b),
            &[],
            20,
            &AutoSettings::default(),
            None,
        )
        .unwrap()
        .0
    });
    let map = |side: Side| match case.method {
        Method::Auto => correspondence
            .as_ref()
            .expect("solved")
            .toward(side, T)
            .map_window(full, scale),
        Method::Triangles => TriangleWarp::toward(&f, side, T, 20, frame)
            .unwrap()
            .map_window(full, scale),
        Method::Scattered(m) => {
            let settings = morphfx::make_warp::WarpSettings {
                region: Some(frame),
                ..morphfx::make_warp::WarpSettings::new(morphfx::make_warp::MethodSettings {
                    method: m,
                    ..Default::default()
                })
            };
            morphfx::make_warp::toward(&f, side, T, &settings)
                .unwrap()
                .map_window(full, scale)
        }
        _ => FieldWarp::toward(&f, side, T, &settings).map_window(full, scale),
    };
    if case.method == Method::Mesh {
        let pair = mesh_pair(case.bounds);
        let to = pair.at(T);
        let pa = two_pass(&sa, &pair.a, &to, full, scale);
        let pb = two_pass(&sb, &pair.b, &to, full, scale);
        dissolve::<f32, f32>(
            Warped::Pixels(&pa),
            Warped::Pixels(&pb),
            T,
            out.view_mut().rows(),
        );
        return out;
    }
    let (ma, mb) = (map(Side::A), map(Side::B));
    dissolve(
        Warped::Map(&sa, &ma),
        Warped::Map(&sb, &mb),
        T,
        out.view_mut().rows(),
    );
    out
}

fn worst_difference(got: &Image, want: &Image) -> f32 {
    assert_eq!(got.bounds, want.bounds, "output bounds");
    assert_eq!(got.channels, want.channels);
    got.data
        .iter()
        .zip(&want.data)
        .map(|(g, w)| (g - w).abs())
        .fold(0.0, f32::max)
}

/// One quantisation step of the depth, plus float noise.
fn tolerance(depth: &str) -> f32 {
    match depth {
        "OfxBitDepthByte" => 1.0 / 255.0 + 1e-5,
        "OfxBitDepthShort" => 1.0 / 65535.0 + 1e-5,
        _ => 1e-5,
    }
}

fn check(case: Case) {
    let (got, a, b) = render_morph(&case);
    let want = expected(&case, &a, &b);
    let worst = worst_difference(&got, &want);
    assert!(
        worst <= tolerance(case.depth),
        "{:?} {} ×{} channels, scale {}, bounds {:?}, top-down {}: off by {worst}",
        case.method,
        case.depth,
        case.channels,
        case.scale,
        case.bounds,
        case.top_down
    );
    // Not a blank or pass-through image: the warp moved things.
    let moved = worst_difference(&got, &a);
    assert!(moved > 0.01, "output equals source A");
}

#[test]
fn plugins_are_listed_with_ids_and_versions() {
    let ids: Vec<_> = bundle()
        .plugins
        .iter()
        .map(|p| (p.id.as_str(), p.version))
        .collect();
    assert_eq!(
        ids,
        vec![("net.morphfx.Morph", (1, 0)), ("net.morphfx.Warp", (1, 0))]
    );
}

#[test]
fn every_context_describes_and_instantiates() {
    for (id, contexts) in [
        (
            "net.morphfx.Morph",
            &[
                "OfxImageEffectContextGeneral",
                "OfxImageEffectContextTransition",
            ][..],
        ),
        (
            "net.morphfx.Warp",
            &[
                "OfxImageEffectContextGeneral",
                "OfxImageEffectContextFilter",
            ][..],
        ),
    ] {
        for context in contexts {
            let inst = bundle().instance(id, context);
            assert!(inst.is_ok(), "{id} in {context}: {:?}", inst.err());
        }
    }
}

#[test]
fn every_param_is_declared_with_label_hint_and_script_name() {
    let inst = bundle()
        .instance("net.morphfx.Morph", "OfxImageEffectContextGeneral")
        .unwrap();
    let names = inst.param_names();
    let mut expected: Vec<String> = [
        "method",
        "progress",
        "use_scene_progress",
        "settings_from_scene",
        "field_a",
        "field_b",
        "field_p",
        "line_interpolation",
        "evaluation",
        "tolerance",
        "line_count",
        "snap_lines",
        "snap_sigma",
        "mesh_pass",
        "scene_file",
        "scene_text",
        "frame_offset_a",
        "frame_offset_b",
        "filter",
        "edge",
        "view",
    ]
    .map(String::from)
    .to_vec();
    for k in 1..=16 {
        for s in ["enable", "a_start", "a_end", "b_start", "b_end"] {
            expected.push(format!("line{k}_{s}"));
        }
    }
    for id in &expected {
        let props = inst
            .param_props(id)
            .unwrap_or_else(|| panic!("param {id} is missing"));
        let label = props.str(kOfxPropLabel).unwrap_or_default();
        let hint = props.str(kOfxParamPropHint).unwrap_or_default();
        let script = props.str(kOfxParamPropScriptName).unwrap_or_default();
        assert!(!label.is_empty(), "{id} has no label");
        assert!(!hint.is_empty(), "{id} has no hint");
        assert_eq!(script, *id, "{id}'s script name");
    }
    // Line positions are XY-absolute Double2D, animatable.
    let p = inst.param_props("line1_a_start").unwrap();
    let kind = names
        .iter()
        .find(|(n, _)| n == "line1_a_start")
        .unwrap()
        .1
        .clone();
    assert_eq!(kind, "OfxParamTypeDouble2D");
    assert_eq!(
        p.str(kOfxParamPropDoubleType).as_deref(),
        Some("OfxParamDoubleTypeXYAbsolute")
    );
    assert_eq!(p.ints(kOfxParamPropAnimates), vec![1]);
    // The method choice lists all seven methods.
    let options = inst
        .param_props("method")
        .unwrap()
        .strs(kOfxParamPropChoiceOption);
    assert_eq!(options.len(), 7, "{options:?}");
}

#[test]
fn renders_match_the_core_at_every_depth_and_component_kind() {
    for depth in DEPTHS {
        for channels in [4, 3, 1] {
            check(Case {
                depth,
                channels,
                ..Case::default()
            });
        }
    }
}

#[test]
fn renders_match_the_core_at_half_render_scale() {
    for depth in DEPTHS {
        check(Case {
            depth,
            scale: 0.5,
            ..Case::default()
        });
    }
}

#[test]
fn shifted_bounds_and_negative_row_bytes_match_the_core() {
    let shifted = RectI::new(10, 7, 74, 55);
    for depth in DEPTHS {
        check(Case {
            depth,
            bounds: shifted,
            top_down: true,
            ..Case::default()
        });
        check(Case {
            depth,
            bounds: shifted,
            scale: 0.5,
            ..Case::default()
        });
    }
}

/// Where a frame's samples start in memory, as the plugin is told.
fn data_pointer(f: &Arc<Frame>) -> usize {
    let props = f.image_props((1.0, 1.0), 0.0);
    let data = openfx::sys::image_effect_v1::image_effect::kOfxImagePropData;
    match props.get(&data.to_string_lossy()) {
        Some(morphfx_harness::host::props::Value::P(p)) => p[0],
        other => panic!("no data pointer: {other:?}"),
    }
}

/// A frame handed back (`Instance::recycle`) is the next render's output
/// buffer, as a viewer reuses its buffers, and what it held before is
/// never read: in a debug build (the tests') every sample is NaN until the
/// plugin writes it, so a pixel outside a render window reads NaN, not the
/// last render's pixel. A frame still held elsewhere is not reused.
#[test]
fn a_recycled_frame_is_written_into_again_and_unwritten_pixels_read_nan() {
    let (inst, _sources, spec) = morph_node(&Case::default());
    let full = inst.render(1.0, spec).unwrap();
    let (want, at) = (full.to_image(), data_pointer(&full));
    inst.recycle(full);
    let again = inst.render(1.0, spec).unwrap();
    assert_eq!(data_pointer(&again), at, "the frame handed back is reused");
    let bits = |img: &Image| img.data.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&again.to_image()), bits(&want));
    inst.recycle(again);
    let window = RectI::new(8, 8, 40, 30);
    let part = OutputSpec {
        window: Some(window),
        ..spec
    };
    let part = inst.render(1.0, part).unwrap();
    assert_eq!(data_pointer(&part), at);
    let got = part.to_image();
    for j in want.bounds.y1..want.bounds.y2 {
        for i in want.bounds.x1..want.bounds.x2 {
            let (g, w) = (got.pixel(i, j), want.pixel(i, j));
            let inside = (window.x1..window.x2).contains(&i) && (window.y1..window.y2).contains(&j);
            if inside {
                assert_eq!(g, w, "({i}, {j}) in the window");
            } else {
                let poisoned = g.iter().all(|v| v.is_nan());
                assert_eq!(poisoned, cfg!(debug_assertions), "({i}, {j}): {g:?}");
            }
        }
    }
    let held = part.clone();
    inst.recycle(part);
    let fresh = inst.render(1.0, spec).unwrap();
    assert_ne!(data_pointer(&fresh), data_pointer(&held));
}

#[test]
fn eight_concurrent_tiles_equal_the_serial_render() {
    for depth in DEPTHS {
        let serial = render_morph(&Case {
            depth,
            ..Case::default()
        })
        .0;
        let tiled = render_morph(&Case {
            depth,
            tiles: 8,
            ..Case::default()
        })
        .0;
        assert_eq!(
            serial, tiled,
            "{depth}: tiles differ from the serial render"
        );
    }
}

#[test]
fn mesh_triangle_scattered_and_auto_renders_match_the_core_at_every_depth_scale_and_layout() {
    for method in [
        Method::Mesh,
        Method::Triangles,
        Method::Scattered(morphfx::make_warp::Method::ThinPlate),
        Method::Scattered(morphfx::make_warp::Method::Mffd),
        Method::Scattered(morphfx::make_warp::Method::Hybrid),
        Method::Auto,
    ] {
        for depth in DEPTHS {
            for scale in [1.0, 0.5] {
                check(Case {
                    method,
                    depth,
                    scale,
                    ..Case::default()
                });
            }
            check(Case {
                method,
                depth,
                channels: 3,
                bounds: RectI::new(10, 7, 74, 55),
                top_down: true,
                ..Case::default()
            });
        }
        // Tiles of one frame agree with the whole frame (the two-pass warp
        // is made per render window).
        let whole = render_morph(&Case {
            method,
            ..Case::default()
        })
        .0;
        let tiled = render_morph(&Case {
            method,
            tiles: 8,
            ..Case::default()
        })
        .0;
        assert_eq!(
            whole, tiled,
            "{method:?}: tiles differ from the whole frame"
        );
    }
}

#[test]
fn snap_lines_keys_each_side_onto_its_own_edge_at_the_current_frame() {
    let bounds = RectI::new(0, 0, 64, 48);
    for depth in ["OfxBitDepthByte", "OfxBitDepthFloat"] {
        let inst = bundle()
            .instance("net.morphfx.Morph", "OfxImageEffectContextGeneral")
            .unwrap();
        let fa = Arc::new(Frame::from_image(
            &morphfx::testing::step_plate(bounds, 24.0),
            depth,
            false,
        ));
        let fb = Arc::new(Frame::from_image(
            &morphfx::testing::step_plate(bounds, 36.0),
            depth,
            true,
        ));
        inst.connect("SourceA", Arc::new(Still(fa))).unwrap();
        inst.connect("SourceB", Arc::new(Still(fb))).unwrap();
        inst.set_int("line_count", 1).unwrap();
        // Roughly placed: A 4 px right of its edge, B 4 px left of its own.
        inst.set_double("line1_a_start", &[28.0, 8.0], None)
            .unwrap();
        inst.set_double("line1_a_end", &[27.0, 40.0], None).unwrap();
        inst.set_double("line1_b_start", &[32.0, 8.0], None)
            .unwrap();
        inst.set_double("line1_b_end", &[32.5, 40.0], None).unwrap();
        morphfx_harness::host::params::take_edit_log();
        inst.instance_changed("snap_lines", 7.0).unwrap();
        // One press is one undo step: every key inside one edit block.
        let log = morphfx_harness::host::params::take_edit_log();
        assert_eq!(
            log.first().map(String::as_str),
            Some("begin Snap Lines"),
            "{log:?}"
        );
        assert_eq!(log.last().map(String::as_str), Some("end"), "{log:?}");
        assert_eq!(log.len(), 6, "begin, four keys at frame 7, end: {log:?}");
        assert!(log[1..5].iter().all(|e| e.ends_with("@7")), "{log:?}");
        // Written from the instance-changed action, the one place allowed.
        let seen = morphfx_harness::host::take_violations();
        assert!(!seen.iter().any(|v| v.contains("param line1")), "{seen:?}");
        for (id, edge) in [
            ("line1_a_start", 24.0),
            ("line1_a_end", 24.0),
            ("line1_b_start", 36.0),
            ("line1_b_end", 36.0),
        ] {
            let v = inst.doubles_at(id, 7.0).unwrap();
            assert!((v[0] - edge).abs() < 0.5, "{depth} {id}: {v:?}");
        }
        // Keyed at frame 7: the slot is animated now, frame 7 holds the key.
        let a_end = inst.doubles_at("line1_a_end", 7.0).unwrap();
        assert!(
            (a_end[1] - 40.0).abs() < 2.0,
            "the line kept its length: {a_end:?}"
        );
    }
}

#[test]
fn snap_lines_without_a_source_is_bad_input() {
    let inst = bundle()
        .instance("net.morphfx.Morph", "OfxImageEffectContextGeneral")
        .unwrap();
    inst.set_int("line_count", 1).unwrap();
    let err = inst.instance_changed("snap_lines", 1.0).unwrap_err();
    assert!(err.message.contains("SourceA"), "{}", err.message);
}

#[test]
fn snap_lines_slides_scene_text_curves_onto_each_sides_edge() {
    let bounds = RectI::new(0, 0, 64, 48);
    let inst = bundle()
        .instance("net.morphfx.Morph", "OfxImageEffectContextGeneral")
        .unwrap();
    let plate = |edge| {
        let img = morphfx::testing::step_plate(bounds, edge);
        Arc::new(Still(Arc::new(Frame::from_image(
            &img,
            "OfxBitDepthFloat",
            false,
        ))))
    };
    inst.connect("SourceA", plate(24.0)).unwrap();
    inst.connect("SourceB", plate(36.0)).unwrap();
    // A curve 3 px off each side's edge, and a point that must not move.
    let text = r#"{"features": [
        {"name": "edge", "type": "curve", "a": [[27, 8], [26, 24], [27, 40]], "b": [[33, 8], [33.5, 24], [33, 40]]},
        {"type": "point", "a": [[10, 10]], "b": [[12, 10]]}
    ]}"#;
    inst.set_string("scene_text", text).unwrap();
    morphfx_harness::host::params::take_edit_log();
    inst.instance_changed("snap_lines", 3.0).unwrap();
    let log = morphfx_harness::host::params::take_edit_log();
    assert_eq!(log, ["begin Snap Lines", "set scene_text", "end"]);
    let scene = morphfx::scene::Scene::read(&inst.string("scene_text").unwrap()).unwrap();
    let edge = &scene.features[0];
    assert_eq!(
        (edge.kind.name(), edge.a.len()),
        ("curve", 3),
        "control points kept"
    );
    for (points, x) in [(&edge.a, 24.0), (&edge.b, 36.0)] {
        for p in points.iter() {
            assert!((p.x - x).abs() < 0.5, "{p:?} onto x = {x}");
        }
    }
    assert_eq!(
        scene.features[1],
        morphfx::scene::Scene::read(text).unwrap().features[1]
    );
}
