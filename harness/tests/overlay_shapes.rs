//! Shapes in the viewer through the C ABI: Scene Text's points, polylines
//! and curves drawn by the overlay, drawn and edited with the pen, keyed,
//! and refused when the text is not a scene.

mod common;

use morphfx::features::{catmull_rom, FeatureKind};
use morphfx::geom::Vec2;
use morphfx::scene::Scene;
use morphfx::testing::changed_numbers;
use morphfx_harness::host::overlay::{Answer, DrawCall, Overlay};
use morphfx_harness::host::params::take_edit_log;
use morphfx_harness::host::{take_violations, Instance};
use openfx::sys::image_effect_v1::draw_suite::*;
use openfx::sys::image_effect_v1::interact::*;

fn morph() -> Instance<'static> {
    common::overlay_bundle()
        .instance("net.morphfx.Morph", "OfxImageEffectContextGeneral")
        .unwrap()
}

fn overlay<'i>(inst: &'i Instance<'i>) -> Overlay<'i> {
    common::overlay(inst)
}

const PX: (f64, f64) = (1.0, 1.0);

/// A point, a curve "lip" and a closed polyline "eye", static.
const SHAPES: &str = r#"{
  "format": "morphfx-scene", "version": 1,
  "features": [
    { "type": "point", "a": [[50, 50]], "b": [[55, 52]] },
    { "name": "lip", "type": "curve", "a": [[100, 100], [150, 130], [200, 100]], "b": [[100, 110], [150, 150], [200, 110]] },
    { "name": "eye", "type": "polyline", "closed": true, "a": [[300, 300], [340, 300], [320, 330]], "b": [[300, 310], [340, 310], [320, 345]] }
  ]
}"#;

/// The lip keyed at frames 0 and 10 (A's middle point rises by 20).
const KEYED: &str = r#"{"keyframes": [
  {"frame": 0,  "features": [{"name": "lip", "type": "curve", "a": [[100, 100], [150, 130], [200, 100]], "b": [[100, 110], [150, 150], [200, 110]]}]},
  {"frame": 10, "features": [{"name": "lip", "type": "curve", "a": [[100, 100], [150, 150], [200, 100]], "b": [[100, 110], [150, 150], [200, 110]]}]}
]}"#;

fn scene_text(inst: &Instance<'_>) -> String {
    inst.string("scene_text").unwrap()
}

fn scene(inst: &Instance<'_>) -> Scene {
    Scene::read(&scene_text(inst)).expect("Scene Text stays a valid scene")
}

/// The numbers of `after` that differ from `before`'s: paths and new values.
fn changed(before: &str, after: &str) -> Vec<(String, f64)> {
    changed_numbers(before, after)
        .into_iter()
        .map(|(path, _, now)| (path, now))
        .collect()
}

/// Every point of every line strip drawn in colour `rgb` (any alpha).
fn strips_in(calls: &[DrawCall], rgb: [f32; 3]) -> Vec<Vec<[f64; 2]>> {
    let mut colour = [0.0f32; 4];
    let mut out = Vec::new();
    for c in calls {
        match c {
            DrawCall::Colour(c) => colour = *c,
            DrawCall::Draw { primitive, points }
                if *primitive == kOfxDrawPrimitiveLineStrip && colour[..3] == rgb =>
            {
                out.push(points.clone())
            }
            _ => {}
        }
    }
    out
}

use common::texts;

const A_COLOUR: [f32; 3] = [1.0, 0.55, 0.1];
const B_COLOUR: [f32; 3] = [0.25, 0.8, 1.0];

fn close(p: [f64; 2], q: Vec2) -> bool {
    (p[0] - q.x).abs() < 1e-9 && (p[1] - q.y).abs() < 1e-9
}

#[test]
fn scene_text_shapes_are_drawn_as_catmull_rom_and_closed_with_names() {
    let inst = morph();
    inst.set_string("scene_text", SHAPES).unwrap();
    let ov = overlay(&inst);
    let calls = ov.draw(0.0, PX).unwrap();
    // The lip on A: a strip through the Catmull-Rom samples of its points.
    let lip_a = [(100.0, 100.0), (150.0, 130.0), (200.0, 100.0)].map(|(x, y)| Vec2::new(x, y));
    let a = strips_in(&calls, A_COLOUR);
    let lip = a
        .iter()
        .find(|s| s.len() == 17)
        .expect("a 2-span curve drawn with 8 samples a span");
    for (k, p) in lip.iter().enumerate() {
        let want = if k == 16 {
            lip_a[2]
        } else {
            catmull_rom(&lip_a, k / 8, (k % 8) as f64 / 8.0)
        };
        assert!(close(*p, want), "sample {k}: {p:?} vs {want:?}");
    }
    // The closed eye on B: four points, back to its first.
    let b = strips_in(&calls, B_COLOUR);
    assert!(
        b.contains(&vec![
            [300.0, 310.0],
            [340.0, 310.0],
            [320.0, 345.0],
            [300.0, 310.0]
        ]),
        "{b:?}"
    );
    // Names, else the place in the scene, beside A and B (and shadows).
    let labels = texts(&calls);
    for name in ["lip", "eye", "#1"] {
        assert_eq!(
            labels.iter().filter(|t| *t == name).count(),
            4,
            "{name}: {labels:?}"
        );
    }
    assert!(take_violations().is_empty());
}

#[test]
fn dragging_a_control_point_changes_exactly_that_number_pair_in_one_undo_step() {
    let inst = morph();
    inst.set_string("scene_text", SHAPES).unwrap();
    let before = scene_text(&inst);
    let ov = overlay(&inst);
    take_edit_log();
    // The lip's middle point on B, (150, 150), to (160, 171.5).
    let answer = ov.drag(0.0, (151.0, 151.0), (160.0, 171.5), PX).unwrap();
    assert_eq!(answer, Answer::Trapped);
    let after = scene_text(&inst);
    assert_eq!(
        changed(&before, &after),
        [
            (".features[1].b[1][0]".to_owned(), 160.0),
            (".features[1].b[1][1]".to_owned(), 171.5)
        ]
    );
    let log = take_edit_log();
    assert_eq!(
        log.first().map(String::as_str),
        Some("begin Move Shape Point")
    );
    assert_eq!(log.last().map(String::as_str), Some("end"));
    assert_eq!(log.iter().filter(|l| l.starts_with("begin")).count(), 1);
    // One write per pen event: down, two motions, up.
    assert_eq!(
        log.iter().filter(|l| *l == "set scene_text").count(),
        4,
        "{log:?}"
    );
    // Written from pen actions, where the spec lets an interact set params.
    assert!(take_violations().is_empty());
}

#[test]
fn in_a_keyed_scene_a_drag_keys_its_frame_and_leaves_the_other_keys() {
    let inst = morph();
    inst.set_string("scene_text", KEYED).unwrap();
    let ov = overlay(&inst);
    // At frame 10 the key exists: only its number moves, in one edit block.
    let before = scene_text(&inst);
    take_edit_log();
    ov.drag(10.0, (150.0, 150.5), (150.0, 160.0), PX).unwrap();
    assert_eq!(
        changed(&before, &scene_text(&inst)),
        [(".keyframes[1].features[0].a[1][1]".to_owned(), 160.0)]
    );
    let log = take_edit_log();
    assert_eq!(log.iter().filter(|l| l.starts_with("begin")).count(), 1);
    assert_eq!(log.last().map(String::as_str), Some("end"));
    // At frame 5 there is none: one is made from the interpolated lip
    // (A's middle at (150, 145)), then edited; the keys at 0 and 10 stay.
    ov.drag(5.0, (150.0, 145.0), (170.0, 145.0), PX).unwrap();
    let s = scene(&inst);
    let frames: Vec<f64> = s.keyframes.iter().map(|k| k.frame).collect();
    assert_eq!(frames, [0.0, 5.0, 10.0]);
    assert_eq!(s.keyframes[1].features[0].a[1], Vec2::new(170.0, 145.0));
    assert_eq!(s.keyframes[1].features[0].a[0], Vec2::new(100.0, 100.0));
    assert_eq!(s.keyframes[0].features[0].a[1], Vec2::new(150.0, 130.0));
    assert_eq!(s.keyframes[2].features[0].a[1], Vec2::new(150.0, 160.0));
    // The overlay says where the shapes are keyed, the current frame marked.
    let labels = texts(&ov.draw(5.0, PX).unwrap());
    assert!(labels.iter().any(|t| t == "keys 0 [5] 10"), "{labels:?}");
}

#[test]
fn dragging_a_body_moves_the_whole_shape_on_that_side_only() {
    let inst = morph();
    inst.set_string("scene_text", SHAPES).unwrap();
    let ov = overlay(&inst);
    // The eye's A edge from (300, 300) to (340, 300), grabbed at its middle.
    ov.drag(0.0, (320.0, 301.0), (330.0, 296.0), PX).unwrap();
    let eye = &scene(&inst).features[2];
    let moved = [(310.0, 295.0), (350.0, 295.0), (330.0, 325.0)].map(|(x, y)| Vec2::new(x, y));
    assert_eq!(eye.a, moved);
    assert_eq!(eye.b[0], Vec2::new(300.0, 310.0), "B stays");
    assert!(eye.closed);
}

#[test]
fn the_point_tool_adds_a_point_with_b_on_a() {
    let inst = morph();
    inst.set_string("scene_text", SHAPES).unwrap();
    inst.set_choice("draw_tool", "point").unwrap();
    let ov = overlay(&inst);
    take_edit_log();
    assert_eq!(ov.click(0.0, (600.0, 400.0), PX).unwrap(), Answer::Trapped);
    let s = scene(&inst);
    assert_eq!(s.features.len(), 4);
    let p = &s.features[3];
    assert_eq!(p.kind, FeatureKind::Point);
    assert_eq!(
        (p.a[0], p.b[0]),
        (Vec2::new(600.0, 400.0), Vec2::new(600.0, 400.0))
    );
    let log = take_edit_log();
    assert_eq!(log.first().map(String::as_str), Some("begin New Point"));
    assert_eq!(log.iter().filter(|l| l.starts_with("begin")).count(), 1);
}

#[test]
fn polylines_close_on_their_first_point_and_curves_end_open() {
    let inst = morph();
    inst.set_choice("draw_tool", "polyline").unwrap();
    let ov = overlay(&inst);
    // An empty Scene Text: the first shape makes the document.
    for at in [(10.0, 10.0), (90.0, 10.0), (50.0, 70.0)] {
        ov.click(0.0, at, PX).unwrap();
    }
    // Drawn so far, before it is closed: the points joined, and a dashed
    // rubber band from the last one to the pen.
    ov.pen(kOfxInteractActionPenMotion, 0.0, (30.0, 40.0), PX)
        .unwrap();
    let calls = ov.draw(0.0, PX).unwrap();
    assert!(strips_in(&calls, A_COLOUR)
        .iter()
        .any(|s| s[..] == [[10.0, 10.0], [90.0, 10.0], [50.0, 70.0]]));
    let band = calls.windows(2).any(|w| {
        matches!(&w[1], DrawCall::Draw { primitive, points }
            if *primitive == kOfxDrawPrimitiveLines && points[..] == [[50.0, 70.0], [30.0, 40.0]])
    });
    assert!(band, "the rubber band");
    ov.click(0.0, (12.0, 11.0), PX).unwrap();
    let s = scene(&inst);
    assert_eq!(s.features.len(), 1);
    let tri = &s.features[0];
    assert_eq!(
        (tri.kind, tri.closed, tri.a.len()),
        (FeatureKind::Polyline, true, 3)
    );
    assert_eq!(tri.a, tri.b, "new shapes start with B on A");
    // A curve closes the same way.
    inst.set_choice("draw_tool", "curve").unwrap();
    for at in [
        (500.0, 100.0),
        (600.0, 100.0),
        (550.0, 180.0),
        (502.0, 99.0),
    ] {
        ov.click(0.0, at, PX).unwrap();
    }
    let s = scene(&inst);
    let loop_ = &s.features[1];
    assert_eq!(
        (loop_.kind, loop_.closed, loop_.a.len()),
        (FeatureKind::Curve, true, 3)
    );
    inst.instance_changed("delete_shape", 0.0).unwrap();
    assert_eq!(
        scene(&inst).features.len(),
        1,
        "Delete Shape: the curve just drawn"
    );
    // A curve: three clicks, then a second click on the last point ends it
    // open; then another by Return, and a third by the Finish Shape button.
    inst.set_choice("draw_tool", "curve").unwrap();
    let finishers: [&dyn Fn(); 3] = [
        &|| {
            ov.click(0.0, (300.0, 250.0), PX).unwrap();
        },
        &|| {
            let ret = 0xff0d;
            assert_eq!(
                ov.key(kOfxInteractActionKeyDown, 0.0, ret).unwrap(),
                Answer::Trapped
            );
        },
        &|| inst.instance_changed("finish_shape", 0.0).unwrap(),
    ];
    for (k, finish) in finishers.iter().enumerate() {
        let y = 200.0 + 100.0 * k as f64;
        for x in [100.0, 200.0, 300.0] {
            ov.click(0.0, (x, y + 50.0 * (k == 0 && x == 300.0) as u8 as f64), PX)
                .unwrap();
        }
        finish();
        let s = scene(&inst);
        let c = &s.features[1 + k];
        assert_eq!(
            (c.kind, c.closed, c.a.len()),
            (FeatureKind::Curve, false, 3),
            "{k}"
        );
    }
    // After finishing, a click in empty space starts a new curve (nothing
    // is written until its second point).
    ov.click(0.0, (700.0, 700.0), PX).unwrap();
    assert_eq!(scene(&inst).features.len(), 4);
}

#[test]
fn the_curve_tool_inserts_a_point_on_a_segment_and_delete_removes_points_and_shapes() {
    let inst = morph();
    inst.set_string("scene_text", SHAPES).unwrap();
    inst.set_choice("draw_tool", "curve").unwrap();
    let ov = overlay(&inst);
    // The eye's closing A segment, (320, 330) back to (300, 300): a click
    // halfway inserts a point there on A, and on B halfway along B's.
    take_edit_log();
    ov.click(0.0, (310.0, 315.0), PX).unwrap();
    let eye = &scene(&inst).features[2];
    assert_eq!(eye.a.len(), 4);
    assert_eq!(eye.a[3], Vec2::new(310.0, 315.0));
    assert_eq!(eye.b[3], Vec2::new(310.0, 327.5));
    assert_eq!(
        take_edit_log().first().map(String::as_str),
        Some("begin Insert Shape Point")
    );
    // Hover that point and press Delete: back to three points.
    let delete = 0xffff;
    ov.pen(kOfxInteractActionPenMotion, 0.0, (310.0, 315.0), PX)
        .unwrap();
    assert_eq!(
        ov.key(kOfxInteractActionKeyDown, 0.0, delete).unwrap(),
        Answer::Trapped
    );
    assert_eq!(scene(&inst).features[2].a.len(), 3);
    // Delete over a body deletes the shape; so does Delete Shape on the
    // last grabbed one.
    ov.pen(kOfxInteractActionPenMotion, 0.0, (320.0, 300.0), PX)
        .unwrap();
    ov.key(kOfxInteractActionKeyDown, 0.0, delete).unwrap();
    assert_eq!(scene(&inst).features.len(), 2);
    inst.set_choice("draw_tool", "line").unwrap();
    ov.drag(0.0, (50.0, 50.0), (51.0, 51.0), PX).unwrap();
    inst.instance_changed("delete_shape", 0.0).unwrap();
    let s = scene(&inst);
    assert_eq!(s.features.len(), 1);
    assert_eq!(s.features[0].name.as_deref(), Some("lip"));
}

#[test]
fn key_shapes_here_and_copy_scene_into_node() {
    // Keyed at the time the host's instance-changed action names, frame 0
    // included (a key at 1 there would be the host's time, not ours).
    for at in [0.0, 12.0] {
        let inst = morph();
        inst.set_string("scene_text", SHAPES).unwrap();
        inst.instance_changed("key_shapes", at).unwrap();
        let s = scene(&inst);
        assert_eq!(s.keyframes.len(), 1);
        assert_eq!(s.keyframes[0].frame, at);
        assert_eq!(s.features_at(0.0), Scene::read(SHAPES).unwrap().features);
    }
    // A scene file's features are drawn, dimmer, and the pen cannot move them.
    let dir = common::scratch("overlay-shapes-copy");
    let path = dir.join("face.morph.json");
    std::fs::write(&path, SHAPES).unwrap();
    let inst = morph();
    inst.set_string("scene_file", &path.to_string_lossy())
        .unwrap();
    let ov = overlay(&inst);
    let dim = ov
        .draw(0.0, PX)
        .unwrap()
        .iter()
        .any(|c| matches!(c, DrawCall::Colour(c) if c[..3] == A_COLOUR && c[3] < 0.5));
    assert!(dim, "file features drawn at reduced alpha");
    // The pen passes through them: a new point is refused (it would go
    // into Scene Text, which does not render while the file is in use).
    inst.set_choice("draw_tool", "point").unwrap();
    ov.drag(0.0, (150.0, 130.0), (170.0, 130.0), PX).unwrap();
    let message = inst.persistent_message().expect("a message on the node");
    assert!(message.contains("Copy Scene Into Node"), "{message}");
    // A warning: the node renders fine, and an error would mark it failed.
    let kind = inst.effect.persistent.lock().unwrap().clone().unwrap().kind;
    assert_eq!(kind, "OfxMessageWarning");
    assert_eq!(scene_text(&inst), "");
    inst.instance_changed("copy_scene", 0.0).unwrap();
    assert_eq!(inst.string("scene_file").unwrap(), "");
    assert_eq!(scene_text(&inst), SHAPES);
    ov.drag(0.0, (150.0, 130.0), (170.0, 130.0), PX).unwrap();
    assert_eq!(scene(&inst).features[1].a[1], Vec2::new(170.0, 130.0));
}

#[test]
fn a_scene_text_that_is_not_a_scene_is_drawn_as_nothing_and_never_overwritten() {
    let inst = morph();
    // Valid JSON, bad scene: a polyline with one point.
    let bad = r#"{"features": [{"type": "polyline", "a": [[1, 1]], "b": [[1, 1]]}]}"#;
    inst.set_string("scene_text", bad).unwrap();
    inst.set_int("line_count", 1).unwrap();
    inst.set_double("line1_a_start", &[10.0, 10.0], None)
        .unwrap();
    inst.set_double("line1_a_end", &[60.0, 10.0], None).unwrap();
    let ov = overlay(&inst);
    let calls = ov.draw(0.0, PX).unwrap();
    assert!(strips_in(&calls, A_COLOUR).is_empty(), "no shape drawn");
    assert!(texts(&calls).iter().any(|t| t == "1"), "the slot still is");
    for tool in ["point", "polyline"] {
        inst.set_choice("draw_tool", tool).unwrap();
        ov.click(0.0, (400.0, 400.0), PX).unwrap();
        assert_eq!(scene_text(&inst), bad);
        let message = inst.persistent_message().expect("a message on the node");
        assert!(
            message.contains("Scene Text is not a valid scene") && message.contains("features[0]"),
            "{message}"
        );
    }
    // Fixed text: the next edit works and clears the message.
    inst.set_string("scene_text", "").unwrap();
    inst.set_choice("draw_tool", "point").unwrap();
    ov.click(0.0, (400.0, 400.0), PX).unwrap();
    assert_eq!(scene(&inst).features.len(), 1);
    assert_eq!(inst.persistent_message(), None);
}

/// `morphfx overlay` draws a scene's shapes over the plate as the node
/// draws them: a closed curve all the way round.
#[test]
fn morphfx_overlay_draws_closed_curves_of_a_scene() {
    let dir = common::scratch("overlay-shapes-cli");
    let (a, b, out, scene_path) = (
        dir.join("a.exr"),
        dir.join("b.exr"),
        dir.join("out.exr"),
        dir.join("ring.morph.json"),
    );
    let grey = |_| [0.2f32, 0.2, 0.2];
    let plate = common::colour_plate(&a, 120, 80, grey);
    common::colour_plate(&b, 120, 80, grey);
    let ring =
        [(85.0, 40.0), (60.0, 65.0), (35.0, 40.0), (60.0, 15.0)].map(|(x, y)| Vec2::new(x, y));
    let pts: Vec<String> = ring.iter().map(|p| format!("[{}, {}]", p.x, p.y)).collect();
    let pts = pts.join(", ");
    std::fs::write(
        &scene_path,
        format!(
            r#"{{"format": "morphfx-scene", "version": 1, "features": [
                {{"name": "ring", "type": "curve", "closed": true, "a": [{pts}], "b": [{pts}]}}]}}"#
        ),
    )
    .unwrap();
    let s = |p: &std::path::Path| p.to_string_lossy().into_owned();
    let run = common::run_morphfx(&[
        "overlay",
        "--scene",
        &s(&scene_path),
        "--a",
        &s(&a),
        "--b",
        &s(&b),
        "--show",
        "a",
        "-o",
        &s(&out),
        "--float",
    ]);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let drawn = morphfx_harness::io::read(&out).unwrap().image;
    // Orange (red well above blue) within a pixel of `p` (canonical, y up).
    let orange_near = |p: Vec2| {
        let (i, j) = (p.x.floor() as i32, p.y.floor() as i32);
        (-1..=1).any(|dj| {
            (-1..=1).any(|di| {
                let px = drawn.pixel(i + di, j + dj);
                px[0] - px[2] > 0.4
            })
        })
    };
    // Halfway along every span, the closing one (from the last point back
    // to the first) included.
    for span in 0..4 {
        let mid = morphfx::features::catmull_rom_closed(&ring, span, 0.5);
        assert!(orange_near(mid), "span {span} at {mid:?}");
    }
    // Inside the ring and outside it: the plate.
    assert_eq!(drawn.pixel(60, 40), plate.pixel(60, 40));
    assert_eq!(drawn.pixel(5, 5), plate.pixel(5, 5));
}

/// A suggested pair (a feature with a confidence) is drawn in its
/// confidence's colour with the confidence in its label, on both sides,
/// until the artist moves it: then it is drawn as theirs.
#[test]
fn a_suggestion_shows_its_confidence_until_the_artist_moves_it() {
    let inst = morph();
    let text = r#"{"format": "morphfx-scene", "version": 1, "features": [
        {"name": "suggested 1", "type": "point", "a": [[200, 200]], "b": [[210, 205]], "confidence": 0.25}]}"#;
    inst.set_string("scene_text", text).unwrap();
    let ov = overlay(&inst);
    let doubtful = [1.0, 0.625, 0.2];
    let colours = |calls: &[DrawCall]| -> Vec<[f32; 3]> {
        calls
            .iter()
            .filter_map(|c| match c {
                DrawCall::Colour(c) if c[3] == 1.0 && c[..3] != [0.0, 0.0, 0.0] => {
                    Some([c[0], c[1], c[2]])
                }
                _ => None,
            })
            .collect()
    };
    let near = |c: &[f32; 3], d: &[f32; 3]| c.iter().zip(d).all(|(x, y)| (x - y).abs() < 1e-3);
    let calls = ov.draw(0.0, (1.0, 1.0)).unwrap();
    assert!(
        texts(&calls).iter().any(|t| t == "25%"),
        "{:?}",
        texts(&calls)
    );
    assert!(colours(&calls).iter().any(|c| near(c, &doubtful)));
    // The artist drags A's point: the pair is theirs now.
    ov.drag(0.0, (200.0, 200.0), (220.0, 200.0), (1.0, 1.0))
        .unwrap();
    let calls = ov.draw(0.0, (1.0, 1.0)).unwrap();
    assert!(
        texts(&calls).iter().any(|t| t == "suggested 1"),
        "{:?}",
        texts(&calls)
    );
    assert!(!colours(&calls).iter().any(|c| near(c, &doubtful)));
    assert!(!scene_text(&inst).contains("confidence"));
}
