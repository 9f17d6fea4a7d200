//! Feature tracking: features keyed on one frame followed through the
//! footage, so a sequence morph needs keys only where tracking goes wrong
//! (Beier & Neely §5 have animators key lines every few frames by hand).
//!
//! The method is a template tracker ([`template`]): each point's patch at
//! the key, found again in every frame under an affine warp and a gain and
//! offset of brightness, coarse to fine. Matching against the key (not the
//! previous frame) keeps it from drifting; starting from the previous frame
//! keeps it fast; the brightness fit makes it blind to flicker; a normalised
//! correlation below a threshold says honestly when a point is lost.
//! docs/tracking.md compares it with the alternatives, with measurements.
//!
//! Layers: [`grey`] (frames) → [`template`] → [`point`] → [`feature`] (a
//! side of a feature; lines fitted along their length) and [`grid`] (a
//! mesh's grid; nodes on flat ground move with their neighbours) →
//! [`shot`] (a range of frames from its keys).

pub mod feature;
pub mod grey;
pub mod grid;
mod linear;
pub mod point;
pub mod shot;
pub mod template;

pub use feature::{SideEstimate, SideTracker};
pub use grey::{Grey, Pyramid};
pub use grid::{GridEstimate, GridTracker};
pub use point::{Estimate, PointTracker};
pub use shot::{track_side, Frames, SideKey};
pub use template::{Affine, TrackSettings};

#[cfg(test)]
mod tests;
