//! Scene text edited in place, as a viewer's pen edits it: one control
//! point moved, a shape added, a point inserted or deleted, the features
//! keyed at a frame. The document is edited as JSON, so every key and number
//! the edit does not touch keeps its value (and keys their order), and the
//! result is checked as a scene before it is accepted.

mod mesh;

use serde_json::{Map, Value};

use super::Scene;
use crate::features::{catmull_rom, catmull_rom_closed, Feature, FeatureKind, Side};
use crate::geom::Vec2;
use crate::warp::mesh::MeshPair;
use crate::{Error, Result};

/// Frames closer than this are the same key.
const SAME_FRAME: f64 = 1e-6;

/// A scene document being edited: its JSON and the scene it reads as.
#[derive(Debug, Clone)]
pub struct Document {
    root: Map<String, Value>,
    scene: Scene,
}

/// The new-document header: what a scene needs to be recognised.
const EMPTY: &str = r#"{"format": "morphfx-scene", "version": 1, "features": []}"#;

impl Document {
    /// `text` as a document: refused, with the scene's own message, when it
    /// is not a valid scene (features may be missing: a node adds its own
    /// lines). Blank text is an empty scene.
    pub fn parse(text: &str) -> Result<Document> {
        let text = if text.trim().is_empty() { EMPTY } else { text };
        let scene = Scene::read(text)?;
        match serde_json::from_str(text) {
            Ok(Value::Object(root)) => Ok(Document { root, scene }),
            _ => Err(Error::scene("scene", "the scene is not a JSON object")),
        }
    }

    /// The scene the document reads as.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// The document as text: objects one key per line, point lists and
    /// numbers kept on one line each.
    pub fn text(&self) -> String {
        let mut out = String::new();
        write_object(&mut out, &self.root, 0);
        out.push('\n');
        out
    }

    /// The frames the features are keyed at, in order (none for a static scene).
    pub fn keyed_frames(&self) -> Vec<f64> {
        self.scene.keyframes.iter().map(|k| k.frame).collect()
    }

    /// Moves point `index` of feature `feature` on `side` to `to` at `frame`
    /// (the key at `frame`, made when there is none, in a keyed scene).
    pub fn set_point(
        &mut self,
        frame: f64,
        feature: usize,
        side: Side,
        index: usize,
        to: Vec2,
    ) -> Result<()> {
        self.edit(|doc| {
            let f = doc.feature_at(frame, feature)?;
            let points = side_points(f, side)?;
            let slot = points
                .get_mut(index)
                .ok_or_else(|| missing(feature, &format!("point {index}")))?;
            *slot = point_json(to);
            forget_confidence(f);
            Ok(())
        })
    }

    /// Sets the points of many features at many frames in one edit (what a
    /// tracker found): `(frame, feature, side, points)`, each keyed like
    /// [`Document::set_point`].
    pub fn set_points(&mut self, keys: &[(f64, usize, Side, Vec<Vec2>)]) -> Result<()> {
        self.edit(|doc| {
            for (frame, feature, side, points) in keys {
                let f = doc.feature_at(*frame, *feature)?;
                let slots = side_points(f, *side)?;
                if slots.len() != points.len() {
                    return Err(missing(*feature, "the points set"));
                }
                for (slot, p) in slots.iter_mut().zip(points) {
                    *slot = point_json(*p);
                }
                forget_track(f);
            }
            Ok(())
        })
    }

    /// Moves every point of feature `feature` on `side` at `frame` to
    /// `from[i] + delta`.
    pub fn move_feature(
        &mut self,
        frame: f64,
        feature: usize,
        side: Side,
        from: &[Vec2],
        delta: Vec2,
    ) -> Result<()> {
        self.edit(|doc| {
            let f = doc.feature_at(frame, feature)?;
            let points = side_points(f, side)?;
            if points.len() != from.len() {
                return Err(missing(feature, "the points moved"));
            }
            for (slot, p) in points.iter_mut().zip(from) {
                *slot = point_json(*p + delta);
            }
            forget_confidence(f);
            Ok(())
        })
    }

    /// Adds `f` as the last feature, at every key of a keyed scene (where it
    /// stays still). Returns its index.
    pub fn add_feature(&mut self, f: &Feature) -> Result<usize> {
        let index = self.scene.features_at(0.0).len();
        self.edit(|doc| {
            for list in doc.lists()? {
                list.push(feature_json(f));
            }
            Ok(())
        })?;
        Ok(index)
    }

    /// Appends a control point at `p` (on A and on B) to feature `feature`
    /// at every key: the next point of a shape being drawn.
    pub fn append_point(&mut self, feature: usize, p: Vec2) -> Result<()> {
        self.edit(|doc| {
            doc.each_key(feature, |points| {
                points.push(point_json(p));
                Ok(())
            })
        })
    }

    /// Inserts a control point into span `span` of feature `feature` at its
    /// parameter `s`: at every key, on A and on B, where that key's shape
    /// passes at `(span, s)`, so the shape does not change.
    pub fn insert_point(&mut self, feature: usize, span: usize, s: f64) -> Result<()> {
        let keyed: Vec<Vec<Feature>> = match self.scene.keyframes.is_empty() {
            true => vec![self.scene.features.clone()],
            false => self
                .scene
                .keyframes
                .iter()
                .map(|k| k.features.clone())
                .collect(),
        };
        let frames = self.keyed_frames();
        self.edit(|doc| {
            for (k, features) in keyed.iter().enumerate() {
                let shape = features
                    .get(feature)
                    .ok_or_else(|| missing(feature, "it"))?;
                let f = match frames.get(k) {
                    Some(&frame) => doc.feature_at(frame, feature)?,
                    None => doc.static_feature(feature)?,
                };
                for side in [Side::A, Side::B] {
                    let p = on_span(shape, side, span, s)?;
                    side_points(f, side)?.insert(span + 1, point_json(p));
                }
                forget_track(f);
                forget_confidence(f);
            }
            Ok(())
        })
    }

    /// Deletes point `index` of feature `feature` at every key; a feature
    /// left with too few points for its kind is deleted whole. Returns
    /// whether the feature is gone.
    pub fn delete_point(&mut self, feature: usize, index: usize) -> Result<bool> {
        let f = self
            .scene
            .features_at(0.0)
            .into_iter()
            .nth(feature)
            .ok_or_else(|| missing(feature, "it"))?;
        let least = if f.closed { 3 } else { f.kind.point_count().0 };
        if f.a.len() <= least {
            self.delete_feature(feature)?;
            return Ok(true);
        }
        self.edit(|doc| {
            doc.each_key(feature, |points| {
                if index >= points.len() {
                    return Err(missing(feature, &format!("point {index}")));
                }
                points.remove(index);
                Ok(())
            })
        })?;
        Ok(false)
    }

    /// Deletes feature `feature` from every key. Transition curves attached
    /// by index to later features follow them down; one attached to this
    /// feature refuses the delete (the curve would be lost or misplaced).
    pub fn delete_feature(&mut self, feature: usize) -> Result<()> {
        self.edit(|doc| {
            renumber_transition_curves(&mut doc.root, feature)?;
            for list in doc.lists()? {
                if feature >= list.len() {
                    return Err(missing(feature, "it"));
                }
                list.remove(feature);
            }
            Ok(())
        })
    }

    /// Closes (or opens) polyline or curve `feature` at every key.
    pub fn set_closed(&mut self, feature: usize, closed: bool) -> Result<()> {
        self.edit(|doc| {
            for list in doc.lists()? {
                let f = list
                    .get_mut(feature)
                    .and_then(Value::as_object_mut)
                    .ok_or_else(|| missing(feature, "it"))?;
                f.insert("closed".into(), Value::Bool(closed));
            }
            Ok(())
        })
    }

    /// Turns a static scene into one keyed at `frame`, or keys a keyed one
    /// at `frame` from its interpolated features; the mesh likewise (its
    /// keys are its own); nothing moves.
    pub fn key_here(&mut self, frame: f64) -> Result<()> {
        self.edit(|doc| {
            doc.key_at(frame)?;
            key_mesh(doc, frame)
        })
    }

    /// Applies `change` to a copy of the JSON and keeps it only if it still
    /// reads as a scene; the document is unchanged on any error.
    fn edit(&mut self, change: impl FnOnce(&mut Editor) -> Result<()>) -> Result<()> {
        let mut editor = Editor {
            root: self.root.clone(),
            scene: &self.scene,
        };
        change(&mut editor)?;
        let scene = Scene::from_json(Value::Object(editor.root.clone()))?;
        self.root = editor.root;
        self.scene = scene;
        Ok(())
    }
}

/// The JSON under edit, with the scene it was before the edit.
struct Editor<'s> {
    root: Map<String, Value>,
    scene: &'s Scene,
}

impl Editor<'_> {
    /// Whether the JSON is keyed now (an earlier step of the same edit may
    /// have keyed a static scene).
    fn is_keyed(&self) -> bool {
        self.root
            .get("keyframes")
            .and_then(Value::as_array)
            .is_some_and(|k| !k.is_empty())
    }

    /// Applies `change` to feature `feature`'s point list on A and on B in
    /// every key (its point count changes: tracking flags go).
    fn each_key(
        &mut self,
        feature: usize,
        mut change: impl FnMut(&mut Vec<Value>) -> Result<()>,
    ) -> Result<()> {
        for list in self.lists()? {
            let f = list
                .get_mut(feature)
                .ok_or_else(|| missing(feature, "it"))?;
            for side in [Side::A, Side::B] {
                change(side_points(f, side)?)?;
            }
            forget_track(f);
            forget_confidence(f);
        }
        Ok(())
    }

    /// Every feature list: each keyframe's, or the static one.
    fn lists(&mut self) -> Result<Vec<&mut Vec<Value>>> {
        if !self.is_keyed() {
            let list = self
                .root
                .entry("features")
                .or_insert_with(|| Value::Array(Vec::new()));
            return Ok(vec![as_list(list, "features")?]);
        }
        let keys = keyframes_json(&mut self.root)?;
        keys.iter_mut()
            .enumerate()
            .map(|(i, k)| {
                let f = k.get_mut("features").ok_or_else(|| bad_key(i))?;
                as_list(f, "keyframes[].features")
            })
            .collect()
    }

    /// The feature as edited at `frame`: its keyframe's in a keyed scene
    /// (the key made first when there is none at `frame`), else the static one.
    fn feature_at(&mut self, frame: f64, feature: usize) -> Result<&mut Value> {
        if !self.is_keyed() {
            return self.static_feature(feature);
        }
        let key = self.key_at(frame)?;
        let keys = keyframes_json(&mut self.root)?;
        let list = keys[key].get_mut("features").ok_or_else(|| bad_key(key))?;
        as_list(list, "keyframes[].features")?
            .get_mut(feature)
            .ok_or_else(|| missing(feature, "it"))
    }

    fn static_feature(&mut self, feature: usize) -> Result<&mut Value> {
        let list = self
            .root
            .get_mut("features")
            .ok_or_else(|| missing(feature, "it"))?;
        as_list(list, "features")?
            .get_mut(feature)
            .ok_or_else(|| missing(feature, "it"))
    }

    /// The index in `keyframes` of the key at `frame`, made from the
    /// features interpolated there when there is none (a static scene
    /// becomes keyed). New keys go after the last earlier one, so a sorted
    /// list stays sorted; each new feature keeps its neighbour key's other
    /// keys (name, closed) and drops tracking flags that no longer apply.
    fn key_at(&mut self, frame: f64) -> Result<usize> {
        if !self.is_keyed() {
            let features = self
                .root
                .remove("features")
                .unwrap_or(Value::Array(Vec::new()));
            let mut key = Map::new();
            key.insert("frame".into(), number(frame));
            key.insert("features".into(), features);
            self.root
                .insert("keyframes".into(), Value::Array(vec![Value::Object(key)]));
            return Ok(0);
        }
        let features = self.scene.features_at(frame);
        let keys = keyframes_json(&mut self.root)?;
        let frame_of = |k: &Value| k.get("frame").and_then(Value::as_f64);
        if let Some(i) = keys
            .iter()
            .position(|k| frame_of(k).is_some_and(|f| (f - frame).abs() < SAME_FRAME))
        {
            return Ok(i);
        }
        let at = keys
            .iter()
            .rposition(|k| frame_of(k).is_some_and(|f| f < frame))
            .map_or(0, |i| i + 1);
        let template = keys[at.min(keys.len() - 1)]
            .get("features")
            .and_then(Value::as_array)
            .cloned()
            .unwrap_or_default();
        let list = template
            .into_iter()
            .zip(&features)
            .map(|(mut json, f)| {
                if let Some(o) = json.as_object_mut() {
                    o.insert("a".into(), points_json(&f.a));
                    o.insert("b".into(), points_json(&f.b));
                    o.remove("track");
                }
                json
            })
            .collect();
        let mut key = Map::new();
        key.insert("frame".into(), number(frame));
        key.insert("features".into(), Value::Array(list));
        keys.insert(at, Value::Object(key));
        Ok(at)
    }
}

/// Keys the mesh at `frame` as [`Document::key_here`] keys the features:
/// a static mesh becomes one key, a keyed one gains the mesh interpolated
/// there.
fn key_mesh(editor: &mut Editor<'_>, frame: f64) -> Result<()> {
    let Some(pair) = editor.scene.mesh_at(frame) else {
        return Ok(());
    };
    let Some(mesh) = editor.root.get_mut("mesh").and_then(Value::as_object_mut) else {
        return Ok(());
    };
    match mesh.get_mut("keyframes").and_then(Value::as_array_mut) {
        Some(keys) if !keys.is_empty() => {
            mesh_key_at(keys, frame, &pair);
        }
        _ => {
            mesh.remove("a");
            mesh.remove("b");
            let mut keys = Vec::new();
            mesh_key_at(&mut keys, frame, &pair);
            mesh.insert("keyframes".into(), Value::Array(keys));
        }
    }
    Ok(())
}

/// The index of the mesh key at `frame`, inserted in frame order from
/// `pair` (the mesh there) when there is none.
fn mesh_key_at(keys: &mut Vec<Value>, frame: f64, pair: &MeshPair) -> usize {
    let frame_of = |k: &Value| k.get("frame").and_then(Value::as_f64);
    if let Some(i) = keys
        .iter()
        .position(|k| frame_of(k).is_some_and(|f| (f - frame).abs() < SAME_FRAME))
    {
        return i;
    }
    let at = keys
        .iter()
        .rposition(|k| frame_of(k).is_some_and(|f| f < frame))
        .map_or(0, |i| i + 1);
    let mut key = Map::new();
    key.insert("frame".into(), number(frame));
    key.insert("a".into(), points_json(pair.a.nodes()));
    key.insert("b".into(), points_json(pair.b.nodes()));
    keys.insert(at, Value::Object(key));
    at
}

fn keyframes_json(root: &mut Map<String, Value>) -> Result<&mut Vec<Value>> {
    root.get_mut("keyframes")
        .and_then(Value::as_array_mut)
        .ok_or_else(|| Error::scene("keyframes", "not a list"))
}

/// Transition curves attached by index (`"feature": k`) to features after
/// `deleted` move down by one; one attached to `deleted` is an error.
fn renumber_transition_curves(root: &mut Map<String, Value>, deleted: usize) -> Result<()> {
    let Some(transition) = root.get_mut("transition").and_then(Value::as_object_mut) else {
        return Ok(());
    };
    for (rate, settings) in transition.iter_mut() {
        let curves = settings.get_mut("curves").and_then(Value::as_array_mut);
        for (i, curve) in curves.into_iter().flatten().enumerate() {
            let Some(k) = curve.get("feature").and_then(Value::as_u64) else {
                continue;
            };
            let k = k as usize;
            if k == deleted {
                return Err(Error::scene(
                    format!("transition.{rate}.curves[{i}]"),
                    format!(
                        "is attached to features[{deleted}]: detach it before deleting the feature"
                    ),
                ));
            }
            if k > deleted {
                curve["feature"] = Value::from(k - 1);
            }
        }
    }
    Ok(())
}

fn as_list<'v>(v: &'v mut Value, at: &str) -> Result<&'v mut Vec<Value>> {
    v.as_array_mut()
        .ok_or_else(|| Error::scene(at, "not a list"))
}

fn side_points(f: &mut Value, side: Side) -> Result<&mut Vec<Value>> {
    let key = match side {
        Side::A => "a",
        Side::B => "b",
    };
    f.get_mut(key)
        .and_then(Value::as_array_mut)
        .ok_or_else(|| Error::scene(key, "not a list of points"))
}

/// Tracking flags describe the points a tracker saw; a changed point list
/// makes them wrong.
fn forget_track(f: &mut Value) {
    if let Some(o) = f.as_object_mut() {
        o.remove("track");
    }
}

/// A suggestion's confidence describes the pair `morphfx suggest` found;
/// once the artist moves a point, the pair is theirs.
fn forget_confidence(f: &mut Value) {
    if let Some(o) = f.as_object_mut() {
        o.remove("confidence");
    }
}

fn missing(feature: usize, what: &str) -> Error {
    Error::scene(
        format!("features[{feature}]"),
        format!("{what} is not in the scene (the scene text changed under the edit?)"),
    )
}

fn bad_key(i: usize) -> Error {
    Error::scene(format!("keyframes[{i}]"), "has no features")
}

/// Where `f`'s span `span` passes at parameter `s` on `side`.
fn on_span(f: &Feature, side: Side, span: usize, s: f64) -> Result<Vec2> {
    let pts = f.points(side);
    let n = pts.len();
    let spans = if f.closed { n } else { n.saturating_sub(1) };
    if span >= spans || !matches!(f.kind, FeatureKind::Polyline | FeatureKind::Curve) {
        return Err(Error::Invalid(format!(
            "a point can be inserted only into a span of a polyline or \
                curve (span {span} of {spans})"
        )));
    }
    Ok(match (f.kind, f.closed) {
        (FeatureKind::Curve, true) => catmull_rom_closed(pts, span, s),
        (FeatureKind::Curve, false) => catmull_rom(pts, span, s),
        _ => pts[span].lerp(pts[(span + 1) % n], s),
    })
}

/// A feature as the scene format writes it.
pub fn feature_json(f: &Feature) -> Value {
    let mut o = Map::new();
    if let Some(name) = &f.name {
        o.insert("name".into(), Value::String(name.clone()));
    }
    o.insert("type".into(), Value::String(f.kind.name().into()));
    if f.closed {
        o.insert("closed".into(), Value::Bool(true));
    }
    o.insert("a".into(), points_json(&f.a));
    o.insert("b".into(), points_json(&f.b));
    if let Some(c) = f.confidence {
        o.insert("confidence".into(), number(c));
    }
    Value::Object(o)
}

fn points_json(points: &[Vec2]) -> Value {
    Value::Array(points.iter().map(|p| point_json(*p)).collect())
}

/// A position as written by an edit: to a thousandth of a pixel, which
/// keeps the text short and is far below what a pen can place.
fn point_json(p: Vec2) -> Value {
    let round = |x: f64| (x * 1000.0).round() / 1000.0;
    Value::Array(vec![number(round(p.x)), number(round(p.y))])
}

/// Whole numbers without a fraction (`412`, not `412.0`).
fn number(x: f64) -> Value {
    if x.fract() == 0.0 && x.abs() < 1e15 {
        Value::from(x as i64)
    } else {
        Value::from(x)
    }
}

/// JSON with objects one key per line and arrays of numbers (points,
/// point lists, progress keys) on one line.
fn write_value(out: &mut String, v: &Value, indent: usize) {
    let pad = |n: usize| "  ".repeat(n);
    match v {
        Value::Object(o) if !o.is_empty() => write_object(out, o, indent),
        Value::Array(items) if !items.is_empty() && !items.iter().all(is_flat) => {
            out.push_str("[\n");
            for (i, v) in items.iter().enumerate() {
                out.push_str(&pad(indent + 1));
                write_value(out, v, indent + 1);
                out.push_str(if i + 1 < items.len() { ",\n" } else { "\n" });
            }
            out.push_str(&pad(indent));
            out.push(']');
        }
        other => write_inline(out, other),
    }
}

/// A non-empty object, one key per line (an empty one is `{}`).
fn write_object(out: &mut String, o: &Map<String, Value>, indent: usize) {
    if o.is_empty() {
        out.push_str("{}");
        return;
    }
    let pad = |n: usize| "  ".repeat(n);
    out.push_str("{\n");
    for (i, (k, v)) in o.iter().enumerate() {
        out.push_str(&pad(indent + 1));
        out.push_str(&Value::String(k.clone()).to_string());
        out.push_str(": ");
        write_value(out, v, indent + 1);
        out.push_str(if i + 1 < o.len() { ",\n" } else { "\n" });
    }
    out.push_str(&pad(indent));
    out.push('}');
}

/// A scalar or a nest of arrays of scalars, on one line: `[[1, 2], [3, 4]]`.
fn write_inline(out: &mut String, v: &Value) {
    match v {
        Value::Array(items) => {
            out.push('[');
            for (i, v) in items.iter().enumerate() {
                if i > 0 {
                    out.push_str(", ");
                }
                write_inline(out, v);
            }
            out.push(']');
        }
        other => out.push_str(&other.to_string()),
    }
}

/// A scalar, or an array of scalars (a point): written on one line.
fn is_flat(v: &Value) -> bool {
    match v {
        Value::Array(items) => items.iter().all(|v| !v.is_array() && !v.is_object()),
        Value::Object(_) => false,
        _ => true,
    }
}
