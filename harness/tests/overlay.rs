//! The viewer overlay through the C ABI, in a host with overlays and the
//! Draw suite: what it draws, and how the pen edits the line params.

mod common;

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

/// Slot 1 keyed at frames 0 and 10 (A moves right by 20), slot 2 static.
fn two_lines(inst: &Instance<'_>) {
    inst.set_int("line_count", 2).unwrap();
    inst.set_double("line1_a_start", &[100.0, 100.0], Some(0.0))
        .unwrap();
    inst.set_double("line1_a_start", &[120.0, 100.0], Some(10.0))
        .unwrap();
    inst.set_double("line1_a_end", &[200.0, 100.0], Some(0.0))
        .unwrap();
    inst.set_double("line1_a_end", &[220.0, 100.0], Some(10.0))
        .unwrap();
    inst.set_double("line1_b_start", &[100.0, 150.0], None)
        .unwrap();
    inst.set_double("line1_b_end", &[200.0, 150.0], None)
        .unwrap();
    inst.set_double("line2_a_start", &[50.0, 300.0], None)
        .unwrap();
    inst.set_double("line2_a_end", &[50.0, 400.0], None)
        .unwrap();
    inst.set_double("line2_b_start", &[60.0, 300.0], None)
        .unwrap();
    inst.set_double("line2_b_end", &[60.0, 420.0], None)
        .unwrap();
}

fn overlay<'i>(inst: &'i Instance<'i>) -> Overlay<'i> {
    common::overlay(inst)
}

/// Every segment drawn (pairs of `Lines` draws), in the colour pass (the
/// shadow pass comes first and is offset by one pixel).
fn segments(calls: &[DrawCall]) -> Vec<[[f64; 2]; 2]> {
    let mut out = Vec::new();
    for c in calls {
        if let DrawCall::Draw { primitive, points } = c {
            if *primitive == kOfxDrawPrimitiveLines {
                out.extend(points.chunks(2).map(|p| [p[0], p[1]]));
            }
        }
    }
    out
}

use common::texts;

#[test]
fn draw_shows_every_enabled_line_at_its_values_at_the_time_with_labels() {
    let inst = morph();
    two_lines(&inst);
    let ov = overlay(&inst);
    let calls = ov.draw(5.0, (1.0, 1.0)).unwrap();
    let segs = segments(&calls);
    // At frame 5 slot 1's A line is halfway between its keys.
    for line in [
        [[110.0, 100.0], [210.0, 100.0]],
        [[100.0, 150.0], [200.0, 150.0]],
        [[50.0, 300.0], [50.0, 400.0]],
        [[60.0, 300.0], [60.0, 420.0]],
    ] {
        assert!(segs.contains(&line), "{line:?} drawn: {segs:?}");
        // and its shadow, one pixel right and down
        let shadow = line.map(|[x, y]| [x + 1.0, y - 1.0]);
        assert!(segs.contains(&shadow), "{shadow:?} shadow drawn");
    }
    // Labels: each slot's number beside its A and its B line, twice (shadow).
    let mut labels = texts(&calls);
    labels.sort();
    assert_eq!(labels, ["1", "1", "1", "1", "2", "2", "2", "2"]);
    // The in-between lines are dashed.
    assert!(calls.contains(&DrawCall::Stipple(kOfxDrawLineStipplePatternDash)));
    assert!(take_violations().is_empty());
}

#[test]
fn disabled_slots_and_slots_past_the_count_are_not_drawn_and_off_draws_nothing() {
    let inst = morph();
    two_lines(&inst);
    inst.set_int("line2_enable", 0).unwrap();
    inst.set_double("line3_a_start", &[700.0, 700.0], None)
        .unwrap();
    let ov = overlay(&inst);
    let segs = segments(&ov.draw(0.0, (1.0, 1.0)).unwrap());
    assert!(!segs.iter().any(|s| s[0] == [50.0, 300.0]), "slot 2 is off");
    assert!(
        !segs.iter().flatten().any(|p| p[0] >= 699.0),
        "slot 3 is unused"
    );
    inst.set_choice("overlay_show", "off").unwrap();
    assert_eq!(ov.draw(0.0, (1.0, 1.0)).unwrap(), []);
}

#[test]
fn the_hit_radius_is_in_screen_pixels() {
    let inst = morph();
    two_lines(&inst);
    let ov = overlay(&inst);
    // 20 canonical px right of slot 2's A end, nothing else near.
    let pen = (50.0 + 20.0, 400.0);
    let motion = |pixel| {
        let before = ov.redraws();
        ov.pen(kOfxInteractActionPenMotion, 0.0, pen, pixel)
            .unwrap();
        ov.redraws() - before
    };
    assert_eq!(motion((1.0, 1.0)), 0, "20 screen px away: nothing hovered");
    assert_eq!(
        motion((4.0, 4.0)),
        1,
        "5 screen px away: the end is hovered"
    );
    assert_eq!(
        motion((4.0, 4.0)),
        0,
        "the same hover asks for no second redraw"
    );
    assert_eq!(
        motion((2.0, 1.0)),
        1,
        "10 screen px in x: out of reach again"
    );
}

#[test]
fn a_drag_keys_only_the_grabbed_end_at_the_pen_and_is_one_undo_step() {
    let inst = morph();
    two_lines(&inst);
    let ov = overlay(&inst);
    take_edit_log();
    // Slot 1's A start is at (110, 100) at frame 5; drag it to (130, 90).
    let answer = ov
        .drag(5.0, (111.0, 101.0), (130.0, 90.0), (1.0, 1.0))
        .unwrap();
    assert_eq!(answer, Answer::Trapped);
    assert_eq!(
        inst.doubles_at("line1_a_start", 5.0).unwrap(),
        [130.0, 90.0]
    );
    // The keys at 0 and 10 stay; a third now sits at 5.
    assert_eq!(
        inst.doubles_at("line1_a_start", 0.0).unwrap(),
        [100.0, 100.0]
    );
    assert_eq!(
        inst.doubles_at("line1_a_start", 10.0).unwrap(),
        [120.0, 100.0]
    );
    // Nothing else moved.
    assert_eq!(inst.doubles_at("line1_a_end", 5.0).unwrap(), [210.0, 100.0]);
    assert_eq!(
        inst.doubles_at("line1_b_start", 5.0).unwrap(),
        [100.0, 150.0]
    );
    let log = take_edit_log();
    assert_eq!(log.first().map(String::as_str), Some("begin Move Line 1"));
    assert_eq!(log.last().map(String::as_str), Some("end"));
    assert_eq!(log.iter().filter(|l| l.starts_with("begin")).count(), 1);
    assert!(
        log[1..log.len() - 1]
            .iter()
            .all(|l| l == "set line1_a_start@5"),
        "{log:?}"
    );
    assert!(take_violations().is_empty());
}

#[test]
fn dragging_a_middle_moves_the_whole_line_and_unkeyed_params_are_set() {
    let inst = morph();
    two_lines(&inst);
    let ov = overlay(&inst);
    take_edit_log();
    // Slot 2's B line (60, 300)-(60, 420): grab its middle, move by (+10, -5).
    ov.drag(3.0, (61.0, 360.0), (71.0, 355.0), (1.0, 1.0))
        .unwrap();
    assert_eq!(
        inst.doubles_at("line2_b_start", 0.0).unwrap(),
        [70.0, 295.0]
    );
    assert_eq!(inst.doubles_at("line2_b_end", 99.0).unwrap(), [70.0, 415.0]);
    let log = take_edit_log();
    assert!(
        log.iter().all(|l| !l.contains('@')),
        "no keys made: {log:?}"
    );
}

#[test]
fn a_drag_in_empty_space_draws_a_new_line_into_the_next_slot() {
    let inst = morph();
    two_lines(&inst);
    let ov = overlay(&inst);
    ov.drag(0.0, (400.0, 400.0), (500.0, 450.0), (1.0, 1.0))
        .unwrap();
    let slot3 = |id: &str| inst.doubles_at(&format!("line3_{id}"), 0.0).unwrap();
    assert_eq!(slot3("a_start"), [400.0, 400.0]);
    assert_eq!(slot3("a_end"), [500.0, 450.0]);
    assert_eq!(slot3("b_start"), [400.0, 400.0]);
    assert_eq!(slot3("b_end"), [500.0, 450.0]);
    let calls = ov.draw(0.0, (1.0, 1.0)).unwrap();
    assert!(segments(&calls).contains(&[[400.0, 400.0], [500.0, 450.0]]));
    // A's and B's starts coincide; their two labels "3" do not: A's above
    // the start, B's below, each at least a label's height (10 px) apart.
    let threes: Vec<[f64; 2]> = calls
        .iter()
        .filter_map(|c| match c {
            DrawCall::Text { text, at, .. } if text == "3" => Some(*at),
            _ => None,
        })
        .collect();
    assert_eq!(threes.len(), 4, "A and B, each with its shadow");
    let (above, below): (Vec<[f64; 2]>, Vec<[f64; 2]>) =
        threes.iter().partition(|at| at[1] > 400.0);
    assert_eq!((above.len(), below.len()), (2, 2), "{threes:?}");
    assert!(above
        .iter()
        .all(|a| below.iter().all(|b| a[1] - b[1] >= 10.0)));
    // A click (no drag) makes no line.
    ov.drag(0.0, (600.0, 600.0), (600.5, 600.0), (1.0, 1.0))
        .unwrap();
    let segs = segments(&ov.draw(0.0, (1.0, 1.0)).unwrap());
    assert!(!segs.iter().flatten().any(|p| p[0] >= 599.0));
}

#[test]
fn pen_events_never_draw_and_unused_events_go_back_to_the_host() {
    let inst = morph();
    two_lines(&inst);
    let ov = overlay(&inst);
    ov.draw(0.0, (1.0, 1.0)).unwrap();
    take_violations();
    let far = (900.0, 50.0);
    let motion = ov
        .pen(kOfxInteractActionPenMotion, 0.0, far, (1.0, 1.0))
        .unwrap();
    assert_eq!(motion, Answer::Default, "a motion with nothing dragged");
    let up = ov
        .pen(kOfxInteractActionPenUp, 0.0, far, (1.0, 1.0))
        .unwrap();
    assert_eq!(up, Answer::Default, "a pen up without a pen down");
    let key = ov.key(kOfxInteractActionKeyDown, 0.0, 'x' as i32).unwrap();
    assert_eq!(key, Answer::Default);
    // Any use of the closed draw context would be a violation.
    assert!(take_violations().is_empty());
}

#[test]
fn delete_on_a_hovered_line_and_the_clear_button_clear_it() {
    let inst = morph();
    two_lines(&inst);
    let ov = overlay(&inst);
    ov.pen(kOfxInteractActionPenMotion, 0.0, (50.0, 350.0), (1.0, 1.0))
        .unwrap();
    let delete = 0xffff;
    let answer = ov.key(kOfxInteractActionKeyDown, 0.0, delete).unwrap();
    assert_eq!(answer, Answer::Trapped);
    let segs = segments(&ov.draw(0.0, (1.0, 1.0)).unwrap());
    assert!(
        !segs.iter().any(|s| s[0] == [50.0, 300.0]),
        "slot 2 cleared"
    );
    // Slot 1 by its button: its keys go, and the count shrinks to 0.
    inst.instance_changed("line1_clear", 0.0).unwrap();
    assert!(segments(&ov.draw(0.0, (1.0, 1.0)).unwrap()).is_empty());
    // Its ends lost their keys: the same value at every time.
    let at = |t| inst.doubles_at("line1_a_start", t).unwrap();
    assert_eq!(at(0.0), at(10.0));
}

#[test]
fn the_interact_is_slaved_to_the_line_params() {
    let inst = morph();
    let ov = overlay(&inst);
    let slaved = ov.props().strs(kOfxInteractPropSlaveToParam);
    for id in [
        "line_count",
        "overlay_show",
        "line1_a_start",
        "line64_b_end",
    ] {
        assert!(slaved.iter().any(|s| s == id), "{id}");
    }
}

#[test]
fn sixty_four_slots_grouped_with_a_clear_button_each() {
    let inst = morph();
    let names = inst.param_names();
    for k in [1, 17, 64] {
        for suffix in [
            "group", "enable", "a_start", "a_end", "b_start", "b_end", "clear",
        ] {
            let id = format!("line{k}_{suffix}");
            assert!(names.iter().any(|(n, _)| *n == id), "{id}");
        }
    }
    assert!(!names.iter().any(|(n, _)| n == "line65_enable"));
}

/// `morphfx overlay`: the plugin's own overlay, rasterised over the plate.
#[test]
fn morphfx_overlay_draws_the_lines_over_the_plate_and_refuses_bad_options() {
    let dir = common::scratch("overlay-cli");
    let (a, b, out) = (dir.join("a.exr"), dir.join("b.exr"), dir.join("out.exr"));
    let grey = |_| [0.2f32, 0.2, 0.2];
    let plate = common::colour_plate(&a, 120, 80, grey);
    common::colour_plate(&b, 120, 80, grey);
    let s = |p: &std::path::Path| p.to_string_lossy().into_owned();
    // One horizontal A line at y = 40.5 from x 10 to 110; B far off it.
    let line = "1=10,40.5,110,40.5,10,70.5,110,70.5";
    let args = [
        "overlay",
        "--a",
        &s(&a),
        "--b",
        &s(&b),
        "--line",
        line,
        "--show",
        "a",
    ];
    let run = common::run_morphfx(&[&args[..], &["-o", &s(&out), "--float"]].concat());
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let drawn = morphfx_harness::io::read(&out).unwrap().image;
    // On the line: A's orange (red well above blue); well away: the plate.
    let on = drawn.pixel(60, 40);
    assert!(on[0] > 0.8 && on[2] < 0.4, "{on:?}");
    assert_eq!(drawn.pixel(60, 10), plate.pixel(60, 10));
    // B's line is not shown with --show a.
    assert_eq!(drawn.pixel(60, 70), plate.pixel(60, 70));
    let bad =
        common::run_morphfx(&[&args[..7], &["--show", "c", "-o", &s(&dir.join("x.exr"))]].concat());
    assert_eq!(bad.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("--show c"));
    assert!(!dir.join("x.exr").exists());
}

/// Param value calls of the instance so far, by param.
fn value_calls(inst: &Instance<'_>) -> std::collections::HashMap<String, usize> {
    let names = inst.param_names().into_iter().map(|(name, _)| name);
    names.map(|n| (n.clone(), inst.value_calls(&n))).collect()
}

/// The params read between two counts, with how often.
fn read_between(
    before: &std::collections::HashMap<String, usize>,
    after: &std::collections::HashMap<String, usize>,
) -> std::collections::BTreeMap<String, usize> {
    let calls = after.iter().map(|(n, &k)| (n.clone(), k - before[n]));
    calls.filter(|(_, k)| *k > 0).collect()
}

/// A pen hover reads only what places the features it can grab: the
/// used slots (each param once), Line Count, the scene's two params and
/// the edit sides; a draw adds what the in-between shapes need. Neither
/// reads a render setting, nor a slot past Line Count.
#[test]
fn hover_and_draw_read_only_what_the_overlay_shows() {
    let inst = morph();
    inst.set_int("line_count", 40).unwrap();
    for k in 1..=40 {
        let y = 10.0 * k as f64;
        for which in ["a", "b"] {
            inst.set_double(&format!("line{k}_{which}_start"), &[10.0, y], None)
                .unwrap();
            inst.set_double(&format!("line{k}_{which}_end"), &[90.0, y], None)
                .unwrap();
        }
    }
    let ov = overlay(&inst);
    let before = value_calls(&inst);
    ov.pen(kOfxInteractActionPenMotion, 0.0, (500.0, 500.0), (1.0, 1.0))
        .unwrap();
    let hover = read_between(&before, &value_calls(&inst));
    let mut wanted: Vec<String> = ["line_count", "scene_file", "scene_text"]
        .into_iter()
        .chain(["overlay_edit", "overlay_show"])
        .map(String::from)
        .collect();
    for k in 1..=40 {
        for p in ["enable", "a_start", "a_end", "b_start", "b_end"] {
            wanted.push(format!("line{k}_{p}"));
        }
    }
    let extra: Vec<_> = hover.keys().filter(|n| !wanted.contains(n)).collect();
    let unread: Vec<_> = wanted.iter().filter(|n| !hover.contains_key(*n)).collect();
    assert!(extra.is_empty(), "a hover reads {extra:?} too");
    assert!(unread.is_empty(), "a hover does not read {unread:?}");
    assert!(hover.values().all(|&k| k == 1), "each once: {hover:?}");
    assert_eq!(hover.values().sum::<usize>(), 205);

    let before = value_calls(&inst);
    ov.draw(0.0, (1.0, 1.0)).unwrap();
    let draw = read_between(&before, &value_calls(&inst));
    for render_only in ["mix", "filter", "edge", "view", "method", "line41_enable"] {
        assert!(
            !draw.contains_key(render_only),
            "a draw reads {render_only}"
        );
    }
    for shown in ["progress", "field_a", "line_interpolation", "line40_b_end"] {
        assert!(draw.contains_key(shown), "a draw needs {shown}");
    }
    assert!(draw.values().all(|&k| k == 1), "each once: {draw:?}");
}
