//! Reading a scene: serde for the shape, then every rule of docs/scene-format.md with a
//! message that names the feature or keyframe at fault.

use serde::Deserialize;
use serde_json::{Map, Value};

use super::range::in_range;
use super::{Keyframe, Scene};
use crate::choice::Choice;
use crate::error::{Error, Result};
use crate::features::{Feature, FeatureKind};
use crate::geom::Vec2;
use crate::make_warp::{Method, MethodSettings};
use crate::warp::auto::grid::MAX_LEVEL;
use crate::warp::auto::{AutoSettings, Coefficients, Grid};
use crate::warp::field::{Evaluation, FieldSettings, LineInterpolation};
use crate::warp::mesh::{Mesh, MeshPair, MeshSettings, Pass};

/// The value of a scene file's `format` key.
pub const FORMAT: &str = "morphfx-scene";

#[derive(Deserialize)]
struct RawScene {
    format: Option<String>,
    version: Option<u64>,
    method: Option<String>,
    field: Option<RawField>,
    sampling: Option<RawSampling>,
    mesh: Option<RawMesh>,
    auto: Option<RawAuto>,
    features: Option<Vec<RawFeature>>,
    keyframes: Option<Vec<RawKeyframe>>,
    progress: Option<Vec<[f64; 2]>>,
    #[serde(flatten)]
    extra: Map<String, Value>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawField {
    a: Option<f64>,
    b: Option<f64>,
    p: Option<f64>,
    interpolation: Option<String>,
    evaluation: Option<String>,
    tolerance: Option<f64>,
    curve_samples: Option<usize>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawSampling {
    samples_per_segment: usize,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawMesh {
    rows: usize,
    cols: usize,
    a: Option<Vec<[f64; 2]>>,
    b: Option<Vec<[f64; 2]>>,
    pass: Option<String>,
    keyframes: Option<Vec<RawMeshKey>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawMeshKey {
    frame: f64,
    a: Vec<[f64; 2]>,
    b: Vec<[f64; 2]>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawAuto {
    levels: Option<u32>,
    colour: Option<f64>,
    stretch: Option<f64>,
    angle: Option<f64>,
    anchors: Option<f64>,
    warm_start: Option<bool>,
    warm_iterations: Option<usize>,
    initial: Option<Vec<[f64; 2]>>,
}

#[derive(Deserialize)]
struct RawFeature {
    name: Option<String>,
    #[serde(rename = "type")]
    kind: String,
    a: Vec<[f64; 2]>,
    b: Vec<[f64; 2]>,
    closed: Option<bool>,
    /// How sure `morphfx suggest` was of the pair, `[0, 1]`: checked, then
    /// read past (it guides the artist, not the warp).
    confidence: Option<f64>,
}

#[derive(Deserialize)]
struct RawKeyframe {
    frame: f64,
    features: Vec<RawFeature>,
}

impl Scene {
    /// Parse and validate a scene document: [`Scene::read`], and a method
    /// that needs features must have some.
    pub fn parse(text: &str) -> Result<Scene> {
        let scene = Scene::read(text)?;
        scene.check_has_features()?;
        Ok(scene)
    }

    /// Refuses a scene whose method needs features when it has none.
    pub fn check_has_features(&self) -> Result<()> {
        let method = self.settings.method;
        if method.needs_features() && !self.has_features() {
            return Err(Error::scene(
                "features",
                format!(
                    "method \"{}\" needs at least one feature; the scene has none",
                    method.name()
                ),
            ));
        }
        Ok(())
    }

    /// Parse and validate a scene document that may lack features (a node
    /// adds the lines of its own params to them).
    pub fn read(text: &str) -> Result<Scene> {
        let raw: RawScene = serde_json::from_str(text).map_err(|e| {
            Error::scene(
                format!("line {} column {}", e.line(), e.column()),
                e.to_string(),
            )
        })?;
        Scene::from_raw(raw)
    }

    /// [`Scene::read`] of a document already parsed as JSON (an edited
    /// one): the same checks, with no text written or read.
    pub fn from_json(value: serde_json::Value) -> Result<Scene> {
        let raw: RawScene =
            serde_json::from_value(value).map_err(|e| Error::scene("scene", e.to_string()))?;
        Scene::from_raw(raw)
    }

    fn from_raw(raw: RawScene) -> Result<Scene> {
        check_header(&raw)?;
        let method = method(raw.method.as_deref())?;
        let field = match raw.field {
            Some(f) => field_settings(f)?,
            None => FieldSettings::default(),
        };
        let samples_per_segment = samples_per_segment(raw.sampling.as_ref())?;

        let (mesh, meshes) = match raw.mesh {
            Some(m) => mesh(m)?,
            None => (MeshSettings::default(), Vec::new()),
        };
        if method == Method::Mesh && meshes.is_empty() {
            return Err(Error::scene(
                "mesh",
                "method \"mesh\" needs a mesh: {\"rows\": R, \"cols\": C, \
                    \"a\": [...], \"b\": [...]}",
            ));
        }
        let auto = match raw.auto {
            Some(a) => auto_settings(a)?,
            None => AutoSettings::default(),
        };
        let features = match raw.features {
            Some(list) => features(list, "")?,
            None => Vec::new(),
        };
        let keyframes = match raw.keyframes {
            Some(keys) => keyframes(keys)?,
            None => Vec::new(),
        };
        let progress = match raw.progress {
            Some(keys) => progress(keys)?,
            None => Vec::new(),
        };
        let mut extra = raw.extra;
        let scattered = super::scattered::read(
            &mut extra,
            keyframes.first().map_or(&features, |k| &k.features),
        )?;
        let scene = Scene {
            settings: MethodSettings {
                method,
                field,
                mesh,
                auto,
                thin_plate: scattered.thin_plate,
                mffd: scattered.mffd,
                hybrid: scattered.hybrid,
                transition: scattered.transition,
                samples_per_segment,
            },
            meshes,
            features,
            keyframes,
            progress,
            extra,
        };
        Ok(scene)
    }
}

/// The document says it is a MorphFX scene of a version this build reads.
fn check_header(raw: &RawScene) -> Result<()> {
    if let Some(f) = &raw.format {
        if f != FORMAT {
            return Err(Error::scene(
                "format",
                format!("expected \"{FORMAT}\", found \"{f}\""),
            ));
        }
    }
    if let Some(v) = raw.version {
        if v != 1 {
            return Err(Error::scene(
                "version",
                format!("version {v} is not supported (this build reads version 1)"),
            ));
        }
    }
    Ok(())
}

/// The scene's `method`, `field` when absent.
fn method(name: Option<&str>) -> Result<Method> {
    let Some(m) = name else {
        return Ok(Method::Field);
    };
    Method::parse(m).ok_or_else(|| {
        Error::scene(
            "method",
            format!(
                "unknown method \"{m}\" (one of {})",
                Method::names().join(", ")
            ),
        )
    })
}

/// `sampling.samples_per_segment`, within 1..=1000.
fn samples_per_segment(sampling: Option<&RawSampling>) -> Result<usize> {
    match sampling {
        Some(s) if s.samples_per_segment == 0 || s.samples_per_segment > 1000 => Err(Error::scene(
            "sampling.samples_per_segment",
            "must be between 1 and 1000",
        )),
        Some(s) => Ok(s.samples_per_segment),
        None => Ok(crate::features::DEFAULT_SAMPLES_PER_SEGMENT),
    }
}

/// The `auto` key: each number in its range, the initial warp a legal grid.
fn auto_settings(raw: RawAuto) -> Result<AutoSettings> {
    let d = AutoSettings::default();
    let weight = |v: Option<f64>, default: f64, key: &str| {
        in_range(v, default, 0.0..=1000.0, &format!("auto.{key}"))
    };
    let levels = raw
        .levels
        .map(|l| in_range(Some(l), l, 1..=MAX_LEVEL, "auto.levels"))
        .transpose()?;
    let warm_iterations = in_range(
        raw.warm_iterations,
        d.warm_iterations,
        1..=10,
        "auto.warm_iterations",
    )?;
    let initial = match raw.initial {
        None => None,
        Some(pts) => {
            let pts: Vec<Vec2> = pts.into_iter().map(Vec2::from).collect();
            // Convexity does not change under the frame's (positive) scaling,
            // so the grid can be checked in pixels, before any frame is known.
            Grid::from_points(pts.clone())
                .map_err(|e| Error::scene("auto.initial", e.to_string()))?;
            Some(pts)
        }
    };
    let c = d.coefficients;
    Ok(AutoSettings {
        levels,
        coefficients: Coefficients {
            colour: weight(raw.colour, c.colour, "colour")?,
            stretch: weight(raw.stretch, c.stretch, "stretch")?,
            angle: weight(raw.angle, c.angle, "angle")?,
            anchor: weight(raw.anchors, c.anchor, "anchors")?,
        },
        warm_start: raw.warm_start.unwrap_or(d.warm_start),
        warm_iterations,
        initial,
    })
}

fn field_settings(raw: RawField) -> Result<FieldSettings> {
    let d = FieldSettings::default();
    let num =
        |v: Option<f64>, default: f64, key: &str, ok: fn(f64) -> bool, rule: &str| -> Result<f64> {
            match v {
                None => Ok(default),
                Some(x) if x.is_finite() && ok(x) => Ok(x),
                Some(x) => Err(Error::scene(
                    format!("field.{key}"),
                    format!("{x} is out of range: {rule}"),
                )),
            }
        };
    let interpolation = match raw.interpolation.as_deref() {
        None => d.interpolation,
        Some(s) => LineInterpolation::parse(s).ok_or_else(|| {
            Error::scene(
                "field.interpolation",
                format!("unknown interpolation \"{s}\" (endpoints or center-angle)"),
            )
        })?,
    };
    let tolerance = num(
        raw.tolerance,
        Evaluation::DEFAULT_TOLERANCE,
        "tolerance",
        |x| x > 0.0,
        "must be > 0",
    )?;
    let evaluation = match raw.evaluation.as_deref() {
        None | Some("adaptive") => Evaluation::Adaptive { tolerance },
        Some("exact") => Evaluation::Exact,
        Some(s) => {
            return Err(Error::scene(
                "field.evaluation",
                format!("unknown evaluation \"{s}\" (exact or adaptive)"),
            ))
        }
    };
    let curve_samples = in_range(
        raw.curve_samples,
        d.curve_samples,
        1..=100,
        "field.curve_samples",
    )?;
    Ok(FieldSettings {
        a: num(
            raw.a,
            d.a,
            "a",
            |x| x > 0.0,
            "a must be > 0 (a = 0 is undefined where lines cross)",
        )?,
        b: num(raw.b, d.b, "b", |x| x >= 0.0, "b must be >= 0")?,
        p: num(raw.p, d.p, "p", |x| x >= 0.0, "p must be >= 0")?,
        interpolation,
        evaluation,
        curve_samples,
    })
}

/// The mesh settings and the mesh pair(s), keyed or static, each checked by
/// the rules of [`MeshPair::new`] with the place named.
fn mesh(raw: RawMesh) -> Result<(MeshSettings, Vec<(f64, MeshPair)>)> {
    let pass = match raw.pass.as_deref() {
        None => Pass::default(),
        Some(p) => Pass::parse(p).ok_or_else(|| {
            Error::scene(
                "mesh.pass",
                format!("unknown pass \"{p}\" (two-pass or one-pass)"),
            )
        })?,
    };
    let (rows, cols) = (raw.rows, raw.cols);
    let pair = |a: Vec<[f64; 2]>, b: Vec<[f64; 2]>, at: &str| -> Result<MeshPair> {
        let side = |pts: Vec<[f64; 2]>, name: &str| {
            Mesh::new(rows, cols, pts.into_iter().map(Vec2::from).collect())
                .map_err(|e| Error::scene(format!("{at}.{name}"), e.to_string()))
        };
        MeshPair::new(side(a, "a")?, side(b, "b")?).map_err(|e| Error::scene(at, e.to_string()))
    };
    let mut keys = Vec::new();
    match (raw.keyframes, raw.a, raw.b) {
        (Some(list), _, _) if !list.is_empty() => {
            for (i, k) in list.into_iter().enumerate() {
                let at = format!("mesh.keyframes[{i}] (frame {})", k.frame);
                if !k.frame.is_finite() {
                    return Err(Error::scene(
                        format!("mesh.keyframes[{i}]"),
                        "frame is not a finite number",
                    ));
                }
                keys.push((k.frame, pair(k.a, k.b, &at)?));
            }
            keys.sort_by(|a, b| a.0.total_cmp(&b.0));
            if let Some(w) = keys.windows(2).find(|w| w[0].0 == w[1].0) {
                return Err(Error::scene(
                    "mesh.keyframes",
                    format!("frame {} is keyed twice", w[0].0),
                ));
            }
        }
        (_, Some(a), Some(b)) => keys.push((0.0, pair(a, b, "mesh")?)),
        _ => {
            return Err(Error::scene(
                "mesh",
                "needs node positions: \"a\" and \"b\" (rows × cols points \
                    each, bottom row first), or \"keyframes\"",
            ))
        }
    }
    Ok((MeshSettings { pass }, keys))
}

fn features(list: Vec<RawFeature>, prefix: &str) -> Result<Vec<Feature>> {
    list.into_iter()
        .enumerate()
        .map(|(i, raw)| feature(raw, i, prefix))
        .collect()
}

fn feature(raw: RawFeature, index: usize, prefix: &str) -> Result<Feature> {
    let at = match &raw.name {
        Some(n) => format!("{prefix}features[{index}] \"{n}\""),
        None => format!("{prefix}features[{index}]"),
    };
    let kind = FeatureKind::parse(&raw.kind).ok_or_else(|| {
        Error::scene(
            &at,
            format!(
                "unknown type \"{}\" (point, line, polyline or curve)",
                raw.kind
            ),
        )
    })?;
    if raw.a.len() != raw.b.len() {
        return Err(Error::scene(
            &at,
            format!(
                "a has {} points but b has {}; they must correspond one to one",
                raw.a.len(),
                raw.b.len()
            ),
        ));
    }
    if let Some(c) = raw.confidence.filter(|c| !(0.0..=1.0).contains(c)) {
        return Err(Error::scene(
            &at,
            format!("confidence {c} must be between 0 and 1"),
        ));
    }
    let closed = raw.closed.unwrap_or(false);
    let (min, max) = kind.point_count();
    let min = if closed { 3 } else { min };
    let n = raw.a.len();
    if closed && !matches!(kind, FeatureKind::Polyline | FeatureKind::Curve) {
        return Err(Error::scene(
            &at,
            format!(
                "a {} cannot be closed (only polylines and curves take \"closed\")",
                kind.name()
            ),
        ));
    }
    if n < min || n > max {
        let want = if min == max {
            format!("exactly {min}")
        } else {
            format!("at least {min}")
        };
        return Err(Error::scene(
            &at,
            format!(
                "a {}{} needs {want} points, found {n}",
                if closed { "closed " } else { "" },
                kind.name()
            ),
        ));
    }
    let side = |pts: Vec<[f64; 2]>, side: &str| -> Result<Vec<Vec2>> {
        let pts: Vec<Vec2> = pts.into_iter().map(Vec2::from).collect();
        if let Some(i) = pts.iter().position(|p| !p.is_finite()) {
            return Err(Error::scene(
                &at,
                format!("{side}[{i}] is not a finite number"),
            ));
        }
        if kind != FeatureKind::Point {
            if let Some(i) = pts.windows(2).position(|w| w[0] == w[1]) {
                let what = if kind == FeatureKind::Line {
                    "the line has zero length"
                } else {
                    "two consecutive points coincide"
                };
                return Err(Error::scene(
                    &at,
                    format!("{side}[{i}] and {side}[{}]: {what}", i + 1),
                ));
            }
            if closed && pts.first() == pts.last() {
                return Err(Error::scene(
                    &at,
                    format!(
                        "{side}[{}] repeats {side}[0]: a closed shape returns to its \
                            first point by itself",
                        pts.len() - 1
                    ),
                ));
            }
        }
        Ok(pts)
    };
    Ok(Feature {
        name: raw.name.clone(),
        kind,
        a: side(raw.a, "a")?,
        b: side(raw.b, "b")?,
        closed,
        confidence: raw.confidence,
    })
}

fn keyframes(raw: Vec<RawKeyframe>) -> Result<Vec<Keyframe>> {
    let mut keys = Vec::with_capacity(raw.len());
    for (i, k) in raw.into_iter().enumerate() {
        let at = format!("keyframes[{i}] (frame {})", k.frame);
        if !k.frame.is_finite() {
            return Err(Error::scene(
                format!("keyframes[{i}]"),
                "frame is not a finite number",
            ));
        }
        let features = features(k.features, &format!("{at} "))?;
        if let Some(first) = keys.first() {
            same_feature_list(first, &features, &at)?;
        }
        keys.push(Keyframe {
            frame: k.frame,
            features,
        });
    }
    keys.sort_by(|a, b| a.frame.total_cmp(&b.frame));
    if let Some(w) = keys.windows(2).find(|w| w[0].frame == w[1].frame) {
        return Err(Error::scene(
            "keyframes",
            format!("frame {} is keyed twice", w[0].frame),
        ));
    }
    Ok(keys)
}

/// Every keyframe must hold the same features in the same order, so that
/// interpolation between keys pairs like with like.
fn same_feature_list(first: &Keyframe, features: &[Feature], at: &str) -> Result<()> {
    let reference = &first.features;
    if reference.len() != features.len() {
        return Err(Error::scene(
            at,
            format!(
                "has {} features but keyframe at frame {} has {}; every \
                    keyframe must hold the same features",
                features.len(),
                first.frame,
                reference.len()
            ),
        ));
    }
    for (i, (r, f)) in reference.iter().zip(features).enumerate() {
        if r.kind != f.kind || r.a.len() != f.a.len() || r.name != f.name || r.closed != f.closed {
            return Err(Error::scene(
                format!("{at} {}", f.label(i)),
                format!(
                    "differs from {} of frame {} ({} with {} points vs {} with \
                        {}); every keyframe must hold the same features in the same \
                        order",
                    r.label(i),
                    first.frame,
                    f.kind.name(),
                    f.a.len(),
                    r.kind.name(),
                    r.a.len()
                ),
            ));
        }
    }
    Ok(())
}

fn progress(raw: Vec<[f64; 2]>) -> Result<Vec<(f64, f64)>> {
    let mut keys = Vec::with_capacity(raw.len());
    for (i, [frame, t]) in raw.into_iter().enumerate() {
        if !frame.is_finite() || !t.is_finite() {
            return Err(Error::scene(
                format!("progress[{i}]"),
                "frame and t must be finite numbers",
            ));
        }
        if !(0.0..=1.0).contains(&t) {
            return Err(Error::scene(
                format!("progress[{i}]"),
                format!("t = {t} is outside [0, 1]"),
            ));
        }
        keys.push((frame, t));
    }
    keys.sort_by(|a, b| a.0.total_cmp(&b.0));
    if let Some(w) = keys.windows(2).find(|w| w[0].0 == w[1].0) {
        return Err(Error::scene(
            "progress",
            format!("frame {} is keyed twice", w[0].0),
        ));
    }
    Ok(keys)
}
