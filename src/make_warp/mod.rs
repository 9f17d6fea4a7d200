//! Settings into a warp: the layer above the warp generators and the
//! transitions that picks the generator a method names, gives it the
//! in-between feature positions (at one rate, or each point at its own under
//! a geometry transition) and bounds its work by the frame.

mod method;
mod rates;
mod reach;
mod settings;
#[cfg(test)]
mod tests;

pub use method::Method;
pub use reach::{MAX_FEATURE_SPAN, REACH};
pub use settings::{MethodSettings, WarpSettings};

use std::sync::Arc;

use crate::error::{Error, Result};
use crate::features::{Feature, Side, Tween};
use crate::geom::Vec2;
use crate::warp::field::FieldWarp;
use crate::warp::hybrid;
use crate::warp::mesh::MeshWarp;
use crate::warp::mffd::{Mffd, MffdWarp};
use crate::warp::thin_plate::{ThinPlate, ThinPlateWarp};
use crate::warp::triangles::TriangleWarp;
use crate::warp::Warp;

/// The warp of the image on `side` toward the features' positions at `t`
/// (`t = 0`: A's positions, `t = 1`: B's), as a reverse map. With a geometry
/// transition each feature point travels at its own rate. For `mesh` this is
/// the one-pass map; the two-pass warp makes pixels ([`crate::warp::mesh::two_pass`]).
pub fn toward(
    features: &[Feature],
    side: Side,
    t: f64,
    settings: &WarpSettings,
) -> Result<Arc<dyn Warp>> {
    with_tween(features, t, settings, |tween| {
        let pairs =
            || point_pairs_toward(features, side, tween, settings.settings.samples_per_segment);
        match settings.method() {
            Method::Field => Ok(Arc::new(FieldWarp::toward(
                features,
                side,
                tween,
                &settings.settings.field,
            )) as Arc<dyn Warp>),
            Method::Mesh => Ok(Arc::new(MeshWarp::toward(
                settings.mesh_pair()?,
                side,
                tween,
            ))),
            Method::Triangles => Ok(Arc::new(TriangleWarp::toward(
                features,
                side,
                tween,
                settings.settings.samples_per_segment,
                settings.scattered_frame(features)?,
            )?)),
            Method::ThinPlate => Ok(Arc::new(thin_plate_with(
                features, side, tween, settings, None,
            )?)),
            Method::Mffd => Ok(Arc::new(MffdWarp {
                mffd: Mffd::solve(
                    &pairs(),
                    settings.scattered_frame(features)?,
                    &settings.settings.mffd,
                ),
            })),
            Method::Hybrid => Ok(Arc::new(MffdWarp {
                mffd: hybrid::solve(
                    &pairs(),
                    settings.scattered_frame(features)?,
                    &settings.settings.hybrid,
                    &settings.settings.thin_plate,
                    &settings.settings.mffd,
                ),
            })),
            Method::Auto => {
                let c = settings.correspondence.as_ref().ok_or_else(|| {
                    Error::Invalid(
                        "method \"auto\" needs both images: its correspondence is \
                            solved from A and B (the Morph node, morphfx morph)"
                            .into(),
                    )
                })?;
                Ok(Arc::new(c.toward(side, tween)))
            }
        }
    })
}

/// The `field` warp as [`toward`] makes it, as its own type: a host redoes
/// its map cheaply after a line moves ([`FieldWarp::field_map_after`]).
pub fn field_toward(
    features: &[Feature],
    side: Side,
    t: f64,
    settings: &WarpSettings,
) -> Result<FieldWarp> {
    with_tween(features, t, settings, |tween| {
        Ok(FieldWarp::toward(
            features,
            side,
            tween,
            &settings.settings.field,
        ))
    })
}

/// The `thin-plate` warp as [`toward`] makes it, its plates solved from
/// `warm` (the same side's plates at a sequence's previous frame; a plate on
/// another grid is ignored): a host rendering frame after frame keeps each
/// frame's plates to start the next from.
pub fn thin_plate_toward(
    features: &[Feature],
    side: Side,
    t: f64,
    settings: &WarpSettings,
    warm: Option<&ThinPlate>,
) -> Result<ThinPlateWarp> {
    with_tween(features, t, settings, |tween| {
        thin_plate_with(features, side, tween, settings, warm)
    })
}

fn thin_plate_with(
    features: &[Feature],
    side: Side,
    tween: Tween<'_>,
    settings: &WarpSettings,
    warm: Option<&ThinPlate>,
) -> Result<ThinPlateWarp> {
    let pairs = point_pairs_toward(features, side, tween, settings.settings.samples_per_segment);
    let frame = settings.scattered_frame(features)?;
    Ok(ThinPlateWarp::new(ThinPlate::solve(
        &pairs,
        frame,
        &settings.settings.thin_plate,
        warm,
    )))
}

/// `f` with the in-between positions at `t`: one `t` for every point, or
/// each point's own rate under a geometry transition.
fn with_tween<R>(
    features: &[Feature],
    t: f64,
    settings: &WarpSettings,
    f: impl FnOnce(Tween<'_>) -> Result<R>,
) -> Result<R> {
    let rates = settings.geometry_rates(features, t)?;
    let rate = |p: Vec2| rates.at(p);
    match rates.uniform() {
        Some(t) => f(Tween::uniform(t)),
        None => f(Tween::with_rates(t, &rate)),
    }
}

/// Every feature's corresponding points (polylines and curves sampled
/// `per_segment` times per span, Lee, Wolberg et al. §4.2) as `(in-between, source)`
/// pairs for the scattered-data methods: the reverse map carries each
/// in-between position to its place on `side`.
pub fn point_pairs_toward(
    features: &[Feature],
    side: Side,
    t: Tween<'_>,
    per_segment: usize,
) -> Vec<(Vec2, Vec2)> {
    features
        .iter()
        .flat_map(|f| f.point_pairs(per_segment))
        .map(|pair| {
            let source = match side {
                Side::A => pair.a,
                Side::B => pair.b,
            };
            (t.between(pair.a, pair.b), source)
        })
        .collect()
}
