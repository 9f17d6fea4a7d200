//! The bound on every scattered method's work: the features may lie only
//! so far outside the frame the warp covers.

use super::WarpSettings;
use crate::choice::Choice;
use crate::error::{Error, Result};
use crate::features::Feature;
use crate::geom::RectD;

/// How far outside the frame a feature point may lie, in frame extents, for
/// the methods that solve on a grid or triangulation covering every point
/// (thin-plate, mffd, hybrid, triangles): their work and memory grow with the
/// area the points span, so a point beyond this is refused rather than
/// allowed to ask for a grid of any size.
pub const REACH: f64 = 1.0;

/// The largest area (canonical px along either side) the features may span
/// when no frame is given.
pub const MAX_FEATURE_SPAN: f64 = 65536.0;

impl WarpSettings {
    /// The frame a scattered-data or triangulated warp covers: the host's
    /// frame, else the features' bounds. Every feature point must lie within
    /// [`REACH`] frame extents of it, so the work stays bounded by the frame.
    pub(super) fn scattered_frame(&self, features: &[Feature]) -> Result<RectD> {
        let frame = match self.region {
            Some(f) => f,
            None => {
                let f = feature_bounds(features).ok_or_else(|| {
                    Error::Invalid(format!(
                        "method \"{}\" needs at least one feature point",
                        self.method().name()
                    ))
                })?;
                if !(f.width() <= MAX_FEATURE_SPAN && f.height() <= MAX_FEATURE_SPAN) {
                    return Err(Error::Invalid(format!(
                        "method \"{}\": the features span {:.3e} x {:.3e} px, more \
                            than {MAX_FEATURE_SPAN} px",
                        self.method().name(),
                        f.width(),
                        f.height()
                    )));
                }
                return Ok(f);
            }
        };
        let extent = frame.width().max(frame.height()).max(1.0);
        let reach = RectD::new(
            frame.x1 - REACH * extent,
            frame.y1 - REACH * extent,
            frame.x2 + REACH * extent,
            frame.y2 + REACH * extent,
        );
        for (i, f) in features.iter().enumerate() {
            for (side, points) in [("A", &f.a), ("B", &f.b)] {
                if let Some(p) = points.iter().find(|p| !reach.contains_point(**p)) {
                    let name = f
                        .name
                        .as_deref()
                        .map(|n| format!(" \"{n}\""))
                        .unwrap_or_default();
                    return Err(Error::Invalid(format!(
                        "feature {}{name}: its {side} point ({}, {}) lies more than \
                            {REACH}× the frame's width outside the frame ({}, {}) - ({}, \
                            {}); method \"{}\" cannot reach it",
                        i + 1,
                        p.x,
                        p.y,
                        frame.x1,
                        frame.y1,
                        frame.x2,
                        frame.y2,
                        self.method().name()
                    )));
                }
            }
        }
        Ok(frame)
    }
}

/// The bounds of every feature point on both sides, grown by half their size
/// on each side (at least 16 px).
pub(super) fn feature_bounds(features: &[Feature]) -> Option<RectD> {
    let mut pts = features
        .iter()
        .flat_map(|f| f.a.iter().chain(&f.b))
        .copied();
    let first = pts.next()?;
    let b = RectD::new(first.x, first.y, first.x, first.y).including(pts);
    let (mx, my) = ((b.width() * 0.5).max(16.0), (b.height() * 0.5).max(16.0));
    Some(RectD::new(b.x1 - mx, b.y1 - my, b.x2 + mx, b.y2 + my))
}
