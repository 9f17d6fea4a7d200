//! One point followed frame after frame: always matched against its patch at
//! the key (so errors do not add up into drift), started from where it was
//! in the previous frame and how fast it was moving (so fast motion is found).

use crate::geom::Vec2;

use super::grey::Pyramid;
use super::template::{Affine, Template, TrackSettings};

/// A point's position in one frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Estimate {
    /// Where (the best guess even when lost).
    pub at: Vec2,
    /// The local affine motion since the key.
    pub warp: Affine,
    /// Normalised correlation with the key's patch, clamped to `[0, 1]`.
    pub confidence: f64,
    /// Not found: occluded, off the frame, or changed beyond recognition.
    pub lost: bool,
}

/// A point tracked away from its key.
pub struct PointTracker {
    template: Template,
    /// The last frame's warp where the point was found.
    last: Affine,
    velocity: Vec2,
}

impl PointTracker {
    /// Starts at `at` in the key frame.
    pub fn new(key: &Pyramid, at: Vec2, settings: &TrackSettings) -> PointTracker {
        PointTracker {
            template: Template::new(key, at, settings),
            last: Affine::at(at),
            velocity: Vec2::ZERO,
        }
    }

    /// How firmly the key's patch fixes translation, `[xx, xy, yy]`.
    pub fn information(&self) -> [f64; 3] {
        self.template.information
    }

    /// The point in the next frame of the sweep.
    pub fn step(&mut self, frame: &Pyramid, settings: &TrackSettings) -> Estimate {
        let predicted = Affine {
            c: self.last.c + self.velocity,
            ..self.last
        };
        let mut found = self.template.find(frame, predicted, settings);
        if !found.ok && self.velocity != Vec2::ZERO {
            // A sudden stop: try from where it last was.
            let still = self.template.find(frame, self.last, settings);
            if still.ok || still.correlation > found.correlation {
                found = still;
            }
        }
        if found.ok && !steady(&self.last, &found.warp) {
            // Real footage does not reshape a patch this much between two
            // frames: a wrong lock (a patch half on flat ground stretched
            // over it still correlates).
            found.ok = false;
        }
        if found.ok {
            self.velocity = found.warp.c - self.last.c;
            self.last = found.warp;
        } else {
            // Keep the last good warp to start again from when it reappears,
            // and stop extrapolating a motion no longer seen.
            self.velocity = Vec2::ZERO;
        }
        let warp = if found.ok { found.warp } else { self.last };
        Estimate {
            at: warp.c,
            warp,
            confidence: found.correlation.clamp(0.0, 1.0),
            lost: !found.ok,
        }
    }
}

/// The largest change of a patch's linear motion from one frame to the next
/// still believed.
const MAX_RESHAPE: f64 = 0.15;

fn steady(last: &Affine, now: &Affine) -> bool {
    last.m
        .iter()
        .zip(&now.m)
        .all(|(a, b)| (a - b).abs() <= MAX_RESHAPE)
}
