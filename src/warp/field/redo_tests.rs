//! Redone field maps against fresh and exact ones.

use super::tests::{exact, spread_pairs, v};
use super::*;
use crate::warp::Warp;

fn adaptive() -> FieldSettings {
    FieldSettings {
        evaluation: Evaluation::Adaptive {
            tolerance: Evaluation::DEFAULT_TOLERANCE,
        },
        ..exact(0.001)
    }
}

/// Line `k` with its destination and source start moved by `by`, as
/// dragging a line's A end moves the in-between line and A's.
fn drag(pairs: &[LinePair], k: usize, by: Vec2) -> Vec<LinePair> {
    let mut pairs = pairs.to_vec();
    pairs[k].dst.0 += by * 0.5;
    pairs[k].src.0 += by;
    pairs
}

/// The largest distance between the two maps' positions, in output pixels.
fn worst_px(a: &WarpMap, b: &WarpMap) -> f64 {
    assert_eq!((a.window, a.scale), (b.window, b.scale));
    let mut worst = 0.0f64;
    for j in a.window.y1..a.window.y2 {
        for i in a.window.x1..a.window.x2 {
            let (pa, pb) = (a.scale.to_pixel(a.get(i, j)), a.scale.to_pixel(b.get(i, j)));
            worst = worst.max(pa.distance(pb));
        }
    }
    worst
}

/// Holds `map` within the adaptive tolerance of the exact map of `pairs`.
fn assert_within_tolerance(map: &WarpMap, pairs: Vec<LinePair>) {
    let truth = FieldWarp::new(pairs, &exact(0.001)).map_window(map.window, map.scale);
    let err = worst_px(map, &truth);
    assert!(err <= Evaluation::DEFAULT_TOLERANCE, "{err} px from exact");
}

fn window_at(scale: f64) -> (RectI, PixelScale) {
    let s = PixelScale::new(scale, scale, 1.0);
    (
        RectI::new(0, 0, (640.0 * scale) as i32, (360.0 * scale) as i32),
        s,
    )
}

#[test]
fn a_full_field_map_is_map_window_bit_for_bit() {
    let (window, scale) = window_at(1.0);
    for settings in [adaptive(), exact(0.001)] {
        let warp = FieldWarp::new(spread_pairs(4, 30, 640.0, 360.0), &settings);
        let kept = warp.field_map(window, scale);
        assert_eq!(kept.redos(), 0);
        assert_eq!(**kept.map(), warp.map_window(window, scale));
    }
}

/// Drags line `line(step)` of `n` spread lines by `by` for `steps` redos in
/// a row at `scale`, and every `check_every` steps holds the redone map
/// within tolerance of the exact one.
fn drag_within_tolerance(
    (seed, n, scale): (u64, usize, f64),
    steps: u32,
    line: impl Fn(u32) -> usize,
    by: Vec2,
    check_every: u32,
) {
    let tolerance = Evaluation::DEFAULT_TOLERANCE;
    let (window, scale) = window_at(scale);
    let mut pairs = spread_pairs(seed, n, 640.0, 360.0);
    let mut kept = FieldWarp::new(pairs.clone(), &adaptive()).field_map(window, scale);
    for step in 1..=steps {
        pairs = drag(&pairs, line(step), by);
        let warp = FieldWarp::new(pairs.clone(), &adaptive());
        kept = warp.field_map_after(window, scale, Some(&kept));
        assert_eq!(kept.redos(), step, "seed {seed}: a redo, not a fresh map");
        if step % check_every == 0 {
            let truth = FieldWarp::new(pairs.clone(), &exact(0.001)).map_window(window, scale);
            let err = worst_px(kept.map(), &truth);
            assert!(
                err <= tolerance,
                "seed {seed}, {n} lines, scale {}, drag {step}: {err} px from exact > {tolerance}",
                scale.x
            );
        }
    }
}

#[test]
fn redos_while_a_line_is_dragged_stay_within_tolerance_of_the_exact_map() {
    for (seed, n, scale) in [(1, 60, 1.0), (2, 40, 0.5), (5, 4, 1.0)] {
        drag_within_tolerance(
            (seed, n, scale),
            4,
            |step| step as usize % n,
            v(3.0, -2.0),
            1,
        );
    }
}

/// Blocks the dragged line comes near are shifted too, not made afresh:
/// a line dragged across the frame, in and out of many blocks' near sets,
/// through many redos in a row, keeps the map within tolerance.
#[test]
fn a_line_dragged_across_many_blocks_stays_within_tolerance() {
    for (seed, scale) in [(7, 1.0), (8, 0.5)] {
        drag_within_tolerance((seed, 30, scale), 24, |_| 2, v(14.0, 9.0), 6);
    }
}

#[test]
fn an_exact_redo_matches_the_fresh_exact_map() {
    let (window, scale) = window_at(1.0);
    let mut pairs = spread_pairs(3, 50, 640.0, 360.0);
    let mut kept = FieldWarp::new(pairs.clone(), &exact(0.001)).field_map(window, scale);
    for step in 1..=10 {
        pairs = drag(&pairs, 7, v(-1.0, 2.5));
        let warp = FieldWarp::new(pairs.clone(), &exact(0.001));
        kept = warp.field_map_after(window, scale, Some(&kept));
        assert_eq!(kept.redos(), step);
        let err = worst_px(kept.map(), &warp.map_window(window, scale));
        assert!(err < 1e-3, "drag {step}: {err} px from the fresh exact map");
    }
}

#[test]
fn maps_are_made_afresh_when_the_setup_or_many_lines_change() {
    let (window, scale) = window_at(1.0);
    let pairs = spread_pairs(6, 20, 640.0, 360.0);
    let kept = FieldWarp::new(pairs.clone(), &adaptive()).field_map(window, scale);
    let one_moved = drag(&pairs, 0, v(1.0, 0.0));
    let redo = |pairs: &[LinePair], settings: &FieldSettings, window: RectI| {
        FieldWarp::new(pairs.to_vec(), settings)
            .field_map_after(window, scale, Some(&kept))
            .redos()
    };
    assert_eq!(redo(&one_moved, &adaptive(), window), 1);
    let six_moved = (0..6).fold(pairs.clone(), |p, k| drag(&p, k, v(1.0, 0.0)));
    assert_eq!(
        redo(&six_moved, &adaptive(), window),
        0,
        "over a quarter moved"
    );
    assert_eq!(
        redo(&one_moved, &exact(0.001), window),
        0,
        "another evaluation"
    );
    let wider = FieldSettings {
        b: 1.5,
        ..adaptive()
    };
    assert_eq!(redo(&one_moved, &wider, window), 0, "another weight");
    let tile = RectI::new(0, 0, 320, 360);
    assert_eq!(redo(&one_moved, &adaptive(), tile), 0, "another window");
    assert_eq!(
        redo(&one_moved[1..], &adaptive(), window),
        0,
        "a line fewer"
    );
}

/// Long drags of many lines at both scales, with small and large steps:
/// `check(case, map, warp, step)` after every redo, `case` naming the drag.
fn long_drags(mut check: impl FnMut(&str, &FieldMap, &FieldWarp, u32)) {
    for seed in 0..6u64 {
        let steps = [
            (1.0, v(0.7, 0.3)),
            (0.5, v(-3.0, 5.0)),
            (1.0, v(14.0, 9.0)),
            (0.5, v(0.5, 0.5)),
        ];
        for (scale, by) in steps {
            let (window, scale) = window_at(scale);
            let n = 10 + (seed as usize * 7) % 50;
            let mut pairs = spread_pairs(seed + 100, n, 640.0, 360.0);
            let mut kept = FieldWarp::new(pairs.clone(), &adaptive()).field_map(window, scale);
            for step in 1..=30u32 {
                pairs = drag(&pairs, (seed as usize + step as usize / 10) % n, by);
                let warp = FieldWarp::new(pairs.clone(), &adaptive());
                assert!(warp.redoes(window, scale, &kept));
                kept = warp.field_map_from(window, scale, kept);
                let case = format!("seed {seed}, scale {}, step {by:?} × {step}", scale.x);
                check(&case, &kept, &warp, step);
            }
        }
    }
}

/// What waits in the blocks' lags, and what their pixels took from a grid,
/// keeps every map of long drags within tolerance of the exact one.
#[test]
fn long_drags_with_changes_waiting_far_away_stay_within_tolerance() {
    let tolerance = Evaluation::DEFAULT_TOLERANCE;
    long_drags(|case, kept, warp, step| {
        if step % 10 == 0 {
            let exact = FieldWarp::new(warp.pairs().to_vec(), &exact(0.001));
            let err = worst_px(
                kept.map(),
                &exact.map_window(kept.map().window, kept.map().scale),
            );
            assert!(err <= tolerance, "{case}: {err} px > {tolerance}");
        }
    });
}

/// What a block's pixels owe is checked in sums against their weights,
/// and a line dragged close past the block changes those weights (its
/// terms are swapped in exactly), so the same sums come to move the
/// positions by more. After every redo of long drags, every block's check
/// points still owe no more than its allowance.
#[test]
fn what_blocks_owe_stays_within_their_allowance_as_lines_pass() {
    long_drags(|case, kept, warp, _| {
        assert!(kept.owes_within_allowance(warp), "{case}");
    });
}

/// A nudge of one line among many rewrites the pixels near it and leaves
/// those far from it as they were, bit for bit: their share of the change
/// waits in their blocks' lags.
#[test]
fn a_nudge_leaves_pixels_far_from_the_line_untouched() {
    let (window, scale) = (RectI::new(0, 0, 1280, 720), PixelScale::UNIT);
    let pairs = spread_pairs(11, 80, 1280.0, 720.0);
    let before = FieldWarp::new(pairs.clone(), &adaptive()).field_map(window, scale);
    let nudged = drag(&pairs, 5, v(0.2, 0.1));
    let warp = FieldWarp::new(nudged.clone(), &adaptive());
    let after = warp.field_map_after(window, scale, Some(&before));
    assert_eq!(after.redos(), 1);
    let (old, new) = (pairs[5].dst, nudged[5].dst);
    let (mut far, mut far_moved, mut near_moved) = (0, 0, 0);
    for j in window.y1..window.y2 {
        for i in window.x1..window.x2 {
            let c = scale.pixel_centre(i, j);
            let d = c
                .distance_to_segment(old.0, old.1)
                .min(c.distance_to_segment(new.0, new.1));
            let moved = before.map().get(i, j) != after.map().get(i, j);
            if d > 400.0 {
                far += 1;
                far_moved += usize::from(moved);
            } else if d < 20.0 {
                near_moved += usize::from(moved);
            }
        }
    }
    assert!(
        far > 100_000,
        "the test needs pixels far from the line: {far}"
    );
    assert_eq!(far_moved, 0, "of {far} pixels over 400 px from the line");
    assert!(
        near_moved > 1000,
        "the pixels near the line moved: {near_moved}"
    );
    assert_within_tolerance(after.map(), nudged);
}

/// Handing the map over edits it in place into the map a redo of a copy
/// of it makes.
#[test]
fn a_map_handed_over_is_redone_as_a_copy_of_it_is() {
    let (window, scale) = window_at(1.0);
    let pairs = spread_pairs(12, 40, 640.0, 360.0);
    let make = || FieldWarp::new(pairs.clone(), &adaptive()).field_map(window, scale);
    let (mut copied, mut handed) = (make(), make());
    let mut moved = pairs.clone();
    for step in 0..8 {
        moved = drag(&moved, step % 3, v(1.5, -0.5));
        let warp = FieldWarp::new(moved.clone(), &adaptive());
        copied = warp.field_map_after(window, scale, Some(&copied));
        handed = warp.field_map_from(window, scale, handed);
        assert_eq!(copied.redos(), handed.redos());
        assert_eq!(**copied.map(), **handed.map(), "step {step}");
    }
}

/// A long drag is never made in full again: each block that redos wrote
/// 64 times (less its place in the stagger) is made afresh in its turn, so
/// rounding kept from one redo to the next stays bounded, no redo renews
/// more than a few blocks, and the map stays within tolerance.
#[test]
fn a_long_drag_renews_its_blocks_in_turn_and_never_the_whole_map() {
    let (window, scale) = (RectI::new(0, 0, 192, 96), PixelScale::UNIT);
    let mut pairs = spread_pairs(13, 8, 192.0, 96.0);
    let mut kept = FieldWarp::new(pairs.clone(), &adaptive()).field_map(window, scale);
    let blocks = kept.swaps().len();
    let mut renewed_at_once = Vec::new();
    for step in 1..=200u32 {
        pairs = drag(&pairs, 0, v(0.25, if step % 2 == 0 { 0.1 } else { -0.1 }));
        let before = kept.swaps();
        kept = FieldWarp::new(pairs.clone(), &adaptive()).field_map_from(window, scale, kept);
        assert_eq!(kept.redos(), step, "map {step}: a redo, not a full map");
        let after = kept.swaps();
        assert!(after.iter().all(|&n| n <= 64), "map {step}: {after:?}");
        let worn = before
            .iter()
            .zip(&after)
            .filter(|(b, a)| **b >= 49 && **a == 0);
        renewed_at_once.push(worn.count());
    }
    assert!(
        renewed_at_once.iter().sum::<usize>() >= blocks,
        "every block renewed at least once in 200 redos: {renewed_at_once:?}"
    );
    assert!(
        renewed_at_once.iter().all(|&n| n <= blocks.div_ceil(8)),
        "{blocks} blocks, renewed at once: {renewed_at_once:?}"
    );
    assert_within_tolerance(kept.map(), pairs);
}

/// A block made from a grid reports the largest error its check points
/// found, per axis, against the exact map (a redo's lag takes only what
/// that leaves of their allowance); a block made exactly reports none.
#[test]
fn a_made_block_reports_its_check_points_largest_error() {
    let proxy = window_at(0.5);
    let small = (RectI::new(0, 0, 160, 96), PixelScale::UNIT);
    let (mut from_grid, mut exactly) = (0, 0);
    for (n, (window, scale)) in [(40, proxy), (3, small)] {
        let size = window.width() as f64 / scale.x;
        let pairs = spread_pairs(14, n, size, window.height() as f64 / scale.y);
        let (grid, exact) = check_reported_errors(pairs, window, scale);
        (from_grid, exactly) = (from_grid + grid, exactly + exact);
    }
    assert!(
        from_grid > 10 && exactly > 0,
        "{from_grid} from a grid, {exactly} exactly"
    );
}

/// Holds each block's reported error to the exact map's at its check
/// points; how many blocks were made from a grid and how many exactly.
fn check_reported_errors(pairs: Vec<LinePair>, window: RectI, scale: PixelScale) -> (usize, usize) {
    use super::split::{check_points, Setup};
    let warp = FieldWarp::new(pairs.clone(), &adaptive());
    let truth = FieldWarp::new(pairs, &exact(0.001)).map_window(window, scale);
    let setup = Setup::new(&warp, window, scale, Some(Evaluation::DEFAULT_TOLERANCE));
    let mut pos = vec![[0f32; 2]; window.area()];
    let mut made = vec![(RectI::default(), [0f32; 2]); setup.block_count()];
    setup.each_band(&mut pos, None, &mut made, |band, made| {
        for (k, made) in made.iter_mut().enumerate() {
            *made = (band.rect(k), band.block(k).fill());
        }
    });
    let map = WarpMap::new(window, scale, pos);
    let (mut from_grid, mut exactly) = (0, 0);
    for (block, reported) in made {
        let mut worst = [0f32; 2];
        for (i, j) in check_points(block) {
            let (got, want) = (map.get(i, j), truth.get(i, j));
            worst[0] = worst[0].max((got.x - want.x).abs() as f32);
            worst[1] = worst[1].max((got.y - want.y).abs() as f32);
        }
        let exact_block = (block.y1..block.y2)
            .all(|j| (block.x1..block.x2).all(|i| map.get(i, j) == truth.get(i, j)));
        if exact_block {
            assert_eq!(reported, [0.0; 2], "{block:?}");
            exactly += 1;
            continue;
        }
        for axis in 0..2 {
            let slack = 1e-5 * (1.0 + worst[axis]);
            assert!(
                (reported[axis] - worst[axis]).abs() <= slack,
                "{block:?} axis {axis}: reported {} against {}",
                reported[axis],
                worst[axis]
            );
        }
        from_grid += 1;
    }
    (from_grid, exactly)
}
