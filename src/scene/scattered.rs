//! The scene keys of the scattered-feature methods and of transition control:
//! `thin-plate`, `mffd`, `hybrid` and `transition` (docs/scene-format.md).

use serde::de::DeserializeOwned;
use serde::Deserialize;
use serde_json::{Map, Value};

use super::range::in_range;
use crate::bspline::mba::MbaSettings;
use crate::choice::Choice;
use crate::error::{Error, Result};
use crate::features::Feature;
use crate::geom::Vec2;
use crate::transition::procedural::{PatternKind, MAX_SPREAD};
use crate::transition::{
    Attach, Attached, Curve, Pattern, Procedural, Propagation, Transition, TransitionSettings,
};
use crate::warp::hybrid::HybridSettings;
use crate::warp::mffd::MffdSettings;
use crate::warp::thin_plate::ThinPlateSettings;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawThinPlate {
    alpha: Option<f64>,
    beta: Option<f64>,
    cell: Option<f64>,
    tolerance: Option<f64>,
    max_cycles: Option<usize>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawMffd {
    coarsest: Option<usize>,
    alpha: Option<f64>,
    tolerance: Option<f64>,
    finest: Option<f64>,
    grid: Option<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawHybrid {
    cell: Option<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawTransitions {
    geometry: Option<RawTransition>,
    colour: Option<RawTransition>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawTransition {
    #[serde(rename = "type")]
    kind: String,
    curves: Option<Vec<RawCurve>>,
    surface: Option<String>,
    coarsest: Option<usize>,
    threshold: Option<f64>,
    finest: Option<f64>,
    pattern: Option<String>,
    spread: Option<f64>,
    angle: Option<f64>,
    cycles: Option<f64>,
    centre: Option<[f64; 2]>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawCurve {
    feature: Option<Value>,
    at: Option<[f64; 2]>,
    keys: Vec<[f64; 2]>,
}

/// The settings the scene gives these methods; their keys are taken out of
/// `extra`.
pub struct Scattered {
    pub thin_plate: ThinPlateSettings,
    pub mffd: MffdSettings,
    pub hybrid: HybridSettings,
    pub transition: TransitionSettings,
}

/// `features`: the scene's features (the first keyframe's when keyed), which
/// curves attached by name or index must name.
pub fn read(extra: &mut Map<String, Value>, features: &[Feature]) -> Result<Scattered> {
    let thin_plate = match take::<RawThinPlate>(extra, "thin-plate")? {
        Some(raw) => thin_plate(raw, "thin-plate")?,
        None => ThinPlateSettings::default(),
    };
    let mffd = match take::<RawMffd>(extra, "mffd")? {
        Some(raw) => mffd(raw)?,
        None => MffdSettings::default(),
    };
    let d = HybridSettings::default();
    let hybrid = HybridSettings {
        cell: match take::<RawHybrid>(extra, "hybrid")? {
            Some(raw) => in_range(raw.cell, d.cell, 2.0..=256.0, "hybrid.cell")?,
            None => d.cell,
        },
    };
    let transition = match take::<RawTransitions>(extra, "transition")? {
        Some(raw) => TransitionSettings {
            geometry: match raw.geometry {
                Some(t) => transition(t, "transition.geometry", features)?,
                None => Transition::Uniform,
            },
            colour: raw
                .colour
                .map(|t| transition(t, "transition.colour", features))
                .transpose()?,
        },
        None => TransitionSettings::default(),
    };
    Ok(Scattered {
        thin_plate,
        mffd,
        hybrid,
        transition,
    })
}

fn take<T: DeserializeOwned>(extra: &mut Map<String, Value>, key: &str) -> Result<Option<T>> {
    extra
        .remove(key)
        .map(|v| serde_json::from_value(v).map_err(|e| Error::scene(key, e.to_string())))
        .transpose()
}

fn positive(v: Option<f64>, default: f64, max: f64, at: &str) -> Result<f64> {
    let x = in_range(v, default, 0.0..=max, at)?;
    if x == 0.0 {
        return Err(Error::scene(at, "must be greater than 0"));
    }
    Ok(x)
}

fn thin_plate(raw: RawThinPlate, at: &str) -> Result<ThinPlateSettings> {
    let d = ThinPlateSettings::default();
    Ok(ThinPlateSettings {
        alpha: positive(raw.alpha, d.alpha, 1e9, &format!("{at}.alpha"))?,
        beta: in_range(raw.beta, d.beta, 0.0..=1e6, &format!("{at}.beta"))?,
        cell: in_range(raw.cell, d.cell, 1.0..=256.0, &format!("{at}.cell"))?,
        tolerance: positive(raw.tolerance, d.tolerance, 0.1, &format!("{at}.tolerance"))?,
        max_cycles: in_range(
            raw.max_cycles,
            d.max_cycles,
            1..=1000,
            &format!("{at}.max_cycles"),
        )?,
    })
}

fn mffd(raw: RawMffd) -> Result<MffdSettings> {
    let d = MffdSettings::default();
    Ok(MffdSettings {
        coarsest: in_range(raw.coarsest, d.coarsest, 1..=64, "mffd.coarsest")?,
        alpha: in_range(raw.alpha, d.alpha, 0.0..=1.0, "mffd.alpha")?,
        tolerance: positive(raw.tolerance, d.tolerance, 100.0, "mffd.tolerance")?,
        finest: in_range(raw.finest, d.finest, 0.25..=256.0, "mffd.finest")?,
        grid: in_range(raw.grid, d.grid, 1.0..=16.0, "mffd.grid")?,
        truncate: true,
    })
}

fn transition(raw: RawTransition, at: &str, features: &[Feature]) -> Result<Transition> {
    let curve_keys = [
        ("curves", raw.curves.is_some()),
        ("surface", raw.surface.is_some()),
        ("coarsest", raw.coarsest.is_some()),
        ("threshold", raw.threshold.is_some()),
        ("finest", raw.finest.is_some()),
    ];
    let pattern_keys = [
        ("pattern", raw.pattern.is_some()),
        ("spread", raw.spread.is_some()),
        ("angle", raw.angle.is_some()),
        ("cycles", raw.cycles.is_some()),
        ("centre", raw.centre.is_some()),
    ];
    let refuse = |keys: &[(&str, bool)]| refuse_keys(keys, at, &raw.kind);
    match raw.kind.as_str() {
        "uniform" => {
            refuse(&curve_keys)?;
            refuse(&pattern_keys)?;
            Ok(Transition::Uniform)
        }
        "curves" => {
            refuse(&pattern_keys)?;
            if raw.surface.as_deref() == Some("thin-plate") {
                // The plate has no lattice to size.
                refuse(&curve_keys[2..])?;
            }
            curves_transition(raw, at, features)
        }
        "procedural" => {
            refuse(&curve_keys)?;
            procedural_transition(raw, at)
        }
        other => Err(Error::scene(
            format!("{at}.type"),
            format!("unknown transition type \"{other}\" (uniform, curves, procedural)"),
        )),
    }
}

/// Refuses the first present key of `keys`: it belongs to another type.
fn refuse_keys(keys: &[(&str, bool)], at: &str, kind: &str) -> Result<()> {
    match keys.iter().find(|(_, present)| *present) {
        Some((k, _)) => Err(Error::scene(
            format!("{at}.{k}"),
            format!("does not apply to type \"{kind}\""),
        )),
        None => Ok(()),
    }
}

/// Type `curves`: transition curves at features, spread by a surface.
fn curves_transition(raw: RawTransition, at: &str, features: &[Feature]) -> Result<Transition> {
    let list = raw.curves.ok_or_else(|| {
        Error::scene(
            format!("{at}.curves"),
            "type \"curves\" needs a list of curves",
        )
    })?;
    let curves = list
        .into_iter()
        .enumerate()
        .map(|(k, c)| curve(c, &format!("{at}.curves[{k}]"), features))
        .collect::<Result<Vec<_>>>()?;
    let d = MbaSettings::default();
    let propagation = match raw.surface.as_deref() {
        None | Some("bspline") => Propagation::BSpline(MbaSettings {
            coarsest: in_range(raw.coarsest, d.coarsest, 1..=64, &format!("{at}.coarsest"))?,
            threshold: positive(raw.threshold, d.threshold, 1.0, &format!("{at}.threshold"))?,
            finest: in_range(raw.finest, d.finest, 0.5..=256.0, &format!("{at}.finest"))?,
        }),
        Some("thin-plate") => Propagation::ThinPlate(ThinPlateSettings {
            cell: 8.0,
            ..ThinPlateSettings::default()
        }),
        Some(other) => {
            return Err(Error::scene(
                format!("{at}.surface"),
                format!("unknown surface \"{other}\" (bspline or thin-plate)"),
            ))
        }
    };
    Ok(Transition::Curves {
        curves,
        propagation,
    })
}

/// Type `procedural`: a pattern over the frame.
fn procedural_transition(raw: RawTransition, at: &str) -> Result<Transition> {
    let cycles = in_range(raw.cycles, 2.0, 0.0..=100.0, &format!("{at}.cycles"))?;
    let angle = in_range(raw.angle, 0.0, -360.0..=360.0, &format!("{at}.angle"))?;
    let name = raw.pattern.as_deref().unwrap_or("ramp");
    let kind = PatternKind::parse(name).ok_or_else(|| {
        Error::scene(
            format!("{at}.pattern"),
            format!(
                "unknown pattern \"{name}\" ({})",
                PatternKind::names().join(", ")
            ),
        )
    })?;
    let pattern = match kind {
        PatternKind::Ramp => Pattern::Ramp { angle },
        PatternKind::SineRows => Pattern::SineRows { cycles },
        PatternKind::SineColumns => Pattern::SineColumns { cycles },
        PatternKind::Radial => Pattern::Radial {
            cycles: in_range(raw.cycles, 0.0, 0.0..=100.0, &format!("{at}.cycles"))?,
            centre: raw.centre.map(Vec2::from),
        },
    };
    if let Some(c) = raw.centre {
        if !matches!(pattern, Pattern::Radial { .. }) {
            return Err(Error::scene(
                format!("{at}.centre"),
                "only the radial pattern has a centre",
            ));
        }
        if !(c[0].is_finite() && c[1].is_finite()) {
            return Err(Error::scene(format!("{at}.centre"), "not a finite number"));
        }
    }
    Ok(Transition::Procedural(Procedural {
        pattern,
        spread: in_range(raw.spread, 0.5, 0.0..=MAX_SPREAD, &format!("{at}.spread"))?,
    }))
}

fn curve(raw: RawCurve, at: &str, features: &[Feature]) -> Result<Attached> {
    let attach = match (raw.feature, raw.at) {
        (Some(_), Some(_)) => {
            return Err(Error::scene(
                at,
                "give either \"feature\" or \"at\", not both",
            ))
        }
        (None, None) => {
            return Err(Error::scene(
                at,
                "attach the curve: \"feature\" (name or index) or \"at\" [x, y]",
            ))
        }
        (None, Some(p)) => {
            if !(p[0].is_finite() && p[1].is_finite()) {
                return Err(Error::scene(format!("{at}.at"), "not a finite number"));
            }
            Attach::At(Vec2::from(p))
        }
        (Some(Value::String(name)), None) => {
            if !features
                .iter()
                .any(|f| f.name.as_deref() == Some(name.as_str()))
            {
                return Err(Error::scene(
                    format!("{at}.feature"),
                    format!("no feature is named \"{name}\""),
                ));
            }
            Attach::Name(name)
        }
        (Some(Value::Number(n)), None) => match n.as_u64() {
            Some(i) if (i as usize) < features.len() => Attach::Index(i as usize),
            _ => {
                return Err(Error::scene(
                    format!("{at}.feature"),
                    format!(
                        "{n} is not the index of a feature (the scene has {})",
                        features.len()
                    ),
                ))
            }
        },
        (Some(other), None) => {
            return Err(Error::scene(
                format!("{at}.feature"),
                format!("{other} is neither a feature name nor an index"),
            ))
        }
    };
    let keys: Vec<(f64, f64)> = raw.keys.iter().map(|k| (k[0], k[1])).collect();
    Ok(Attached {
        attach,
        curve: Curve::new(&keys, at)?,
    })
}
