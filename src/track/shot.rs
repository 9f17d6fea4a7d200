//! A whole range of frames tracked from the keys inside it: forward and
//! backward from each key, the two sweeps between a pair of keys blended so
//! that each key is kept exactly (the forward sweep counts fully at the key
//! it starts from, the backward one at the key it starts from, linearly in
//! between); before the first key and after the last, the one sweep there.

use std::sync::Arc;

use rayon::prelude::*;

use crate::error::{Error, Result};
use crate::features::FeatureKind;
use crate::geom::Vec2;

use super::feature::{SideEstimate, SideTracker};
use super::grey::Pyramid;
use super::template::TrackSettings;

/// Where a sweep's frames come from (a reader, a cache, a host's clip).
pub trait Frames<E> {
    /// The pyramid of `frame`.
    fn pyramid(&mut self, frame: i64) -> Result<Arc<Pyramid>, E>;
}

/// The control points of every feature on one side, keyed at a frame.
#[derive(Debug, Clone, PartialEq)]
pub struct SideKey {
    /// The frame.
    pub frame: i64,
    /// Per feature, its control points on this side.
    pub points: Vec<Vec<Vec2>>,
}

/// Tracks one side of `kinds` through `first..=last` from `keys` (sorted,
/// inside the range, at least one); one entry per frame, each with one
/// estimate per feature. `step` is called after each frame tracked with
/// `(done, total, frame)` and returns false to stop (then `Error::Cancelled`).
pub fn track_side<E: From<Error>>(
    kinds: &[FeatureKind],
    keys: &[SideKey],
    (first, last): (i64, i64),
    frames: &mut dyn Frames<E>,
    settings: &TrackSettings,
    step: &mut dyn FnMut(usize, usize, i64) -> bool,
) -> Result<Vec<Vec<SideEstimate>>, E> {
    if keys.is_empty() {
        return Err(Error::Invalid(format!(
            "no keyframe in frames {first}-{last} to track from"
        ))
        .into());
    }
    let len = (last - first + 1) as usize;
    let total = len - keys.len() + swept_twice(keys);
    let mut done = 0usize;
    let mut forward: Vec<Option<Vec<SideEstimate>>> = vec![None; len];
    let mut backward: Vec<Option<Vec<SideEstimate>>> = vec![None; len];
    for (i, key) in keys.iter().enumerate() {
        let ahead = keys.get(i + 1).map_or(last, |k| k.frame - 1);
        let behind = if i == 0 { first } else { keys[i - 1].frame + 1 };
        for (to, out, dir) in [(ahead, &mut forward, 1i64), (behind, &mut backward, -1)] {
            if (to - key.frame) * dir <= 0 {
                continue;
            }
            let mut trackers = start(kinds, key, frames, settings)?;
            let mut f = key.frame + dir;
            while (f - to) * dir <= 0 {
                let pyramid = frames.pyramid(f)?;
                out[(f - first) as usize] = Some(
                    trackers
                        .par_iter_mut()
                        .map(|t| t.step(&pyramid, settings))
                        .collect(),
                );
                done += 1;
                if !step(done, total, f) {
                    return Err(Error::Cancelled.into());
                }
                f += dir;
            }
        }
    }
    Ok((first..=last)
        .map(|f| {
            let at = (f - first) as usize;
            if let Some(key) = keys.iter().find(|k| k.frame == f) {
                return exact(key);
            }
            let before = keys.iter().rev().find(|k| k.frame < f).map(|k| k.frame);
            let after = keys.iter().find(|k| k.frame > f).map(|k| k.frame);
            match (&forward[at], &backward[at], before, after) {
                (Some(fw), Some(bw), Some(b), Some(a)) => {
                    let w = (f - b) as f64 / (a - b) as f64;
                    fw.iter().zip(bw).map(|(x, y)| blend(x, y, w)).collect()
                }
                (Some(fw), _, _, _) => fw.clone(),
                (_, Some(bw), _, _) => bw.clone(),
                _ => unreachable!("every frame between keys is swept"),
            }
        })
        .collect())
}

/// Frames swept twice: those between two keys.
fn swept_twice(keys: &[SideKey]) -> usize {
    keys.windows(2)
        .map(|w| (w[1].frame - w[0].frame - 1) as usize)
        .sum()
}

fn start<E>(
    kinds: &[FeatureKind],
    key: &SideKey,
    frames: &mut dyn Frames<E>,
    settings: &TrackSettings,
) -> Result<Vec<SideTracker>, E> {
    let pyramid = frames.pyramid(key.frame)?;
    Ok(kinds
        .iter()
        .zip(&key.points)
        .map(|(&kind, pts)| SideTracker::new(kind, pts, &pyramid, settings))
        .collect())
}

fn exact(key: &SideKey) -> Vec<SideEstimate> {
    key.points
        .iter()
        .map(|pts| SideEstimate {
            points: pts.clone(),
            confidence: vec![1.0; pts.len()],
            lost: vec![false; pts.len()],
        })
        .collect()
}

/// The forward sweep's estimate `x` and the backward one's `y`, weighted
/// `1 - w` and `w`; where one of them lost the point, the other alone.
fn blend(x: &SideEstimate, y: &SideEstimate, w: f64) -> SideEstimate {
    let mut out = x.clone();
    for i in 0..x.points.len() {
        let (lx, ly) = (x.lost[i], y.lost[i]);
        let (p, c, lost) = match (lx, ly) {
            (false, true) => (x.points[i], x.confidence[i], false),
            (true, false) => (y.points[i], y.confidence[i], false),
            _ => (
                x.points[i].lerp(y.points[i], w),
                x.confidence[i] * (1.0 - w) + y.confidence[i] * w,
                lx && ly,
            ),
        };
        out.points[i] = p;
        out.confidence[i] = c;
        out.lost[i] = lost;
    }
    out
}
