//! `morphfx suggest`: feature pairs proposed between plate A and plate B,
//! written as a scene the artist then keeps, moves or deletes. The core's
//! `suggest` finds them (corners of A matched on B, checked both ways);
//! this reads the plates, keeps the user's own features, and writes the
//! scene.

use std::path::Path;

use morphfx::choice::Choice;
use morphfx::features::FeatureKind;
use morphfx::geom::{RectD, Vec2};
use morphfx::make_warp::Method;
use morphfx::scene::Scene;
use morphfx::suggest::{perceptual, suggest, work_guide, SuggestSettings, Suggestion};
use morphfx::track::{Grey, TrackSettings};
use morphfx::warp::auto::WorkImage;
use serde_json::{json, Value};

use crate::commands::track::track_job;
use crate::error::HostError;
use crate::io;
use crate::plate::Plate;
use crate::sequence::{frame_path, is_sequence, parse_frames};

/// The method a suggested scene renders with when the base scene names
/// none. Points at corners drive every scattered-point method; on real
/// photographs under a smooth bend (the suggest tests' plates, forest's
/// ghost against a plain dissolve's) hybrid ghosted least, 0.29, with
/// thin-plate 0.30, MFFD 0.40 and triangles 0.57 (which leaves everything
/// outside the points' hull unwarped); and its MFFD stage keeps the warp
/// one to one, so a wrong suggestion cannot fold the picture.
pub const DEFAULT_METHOD: Method = Method::Hybrid;

/// What `suggest` was asked to do.
pub struct Suggest<'a> {
    /// Plate A, or sequence A (`#`-numbered) with `frames`.
    pub a: &'a str,
    pub b: &'a str,
    pub output: &'a Path,
    /// Sequences: the range every suggested feature is tracked through,
    /// and the frame the suggestions are made at (default its first).
    pub frames: Option<&'a str>,
    pub at: Option<i64>,
    /// The user's scene: its features are kept exactly and suggestions
    /// keep clear of them.
    pub scene: Option<&'a Path>,
    pub method: Option<Method>,
    pub settings: SuggestSettings,
}

impl Suggest<'_> {
    /// Suggests and writes the scene; returns the line the command prints.
    pub fn run(&self) -> Result<String, HostError> {
        let base = self.base()?;
        check(&self.settings)?;
        let at = self.frame()?;
        let plate = |pattern: &str| match at {
            Some((frame, _)) => io::read(&frame_path(pattern, frame)),
            None => io::read(Path::new(pattern)),
        };
        let (pa, pb) = (plate(self.a)?, plate(self.b)?);
        let (ga, gb) = (grey(&pa), grey(&pb));
        let (fa, fb) = (frame(&pa), frame(&pb));
        let features = base
            .as_ref()
            .map_or_else(Vec::new, |(scene, _)| scene.features_at(0.0));
        // Each plate in its own coordinates; the search on B starts where
        // the least-work warp of A onto B (the user's features held) puts
        // the point, which finds a second subject's eyes on its eyes.
        let (wa, wb) = (
            WorkImage::from_view(&pa.image.view()),
            WorkImage::from_view(&pb.image.view()),
        );
        let map = work_guide(&wa, fa, &wb, fb, &features)
            .map_err(|e| HostError::bad(format!("{} and {}: {e}", self.a, self.b)))?;
        let guide = move |p: Vec2| map.map_a_to_b(p);
        let user: Vec<Vec2> = features.iter().flat_map(|f| f.a.clone()).collect();
        let found = suggest(&ga, &gb, &guide, &user, &self.settings)
            .map_err(|e| HostError::bad(format!("{} and {}: {e}", self.a, self.b)))?;
        let mut doc = self.scene_with(base.map(|(_, doc)| doc), &found)?;
        if let Some((frame, _)) = at {
            keyed_at(&mut doc, frame);
        }
        let out = serde_json::to_string_pretty(&doc)
            .map_err(|e| HostError::failed(format!("cannot write the scene: {e}")))?;
        Scene::parse(&out)
            .map_err(|e| HostError::failed(format!("the suggested scene is invalid: {e}")))?;
        match at {
            Some((_, frames)) => self.track(&out, frames)?,
            None => io::write_text(self.output, &out)?,
        }
        let (lo, hi) = found.iter().fold((1.0f64, 0.0f64), |(lo, hi), s| {
            (lo.min(s.confidence), hi.max(s.confidence))
        });
        let lines = found.iter().filter(|s| s.kind == FeatureKind::Line).count();
        Ok(format!(
            "suggest: {} pair(s) ({lines} line(s), {} point(s)), confidence {lo:.2} to {hi:.2} \
             -> {}",
            found.len(),
            found.len() - lines,
            self.output.display()
        ))
    }

    /// With `--frames`: the frame suggestions are made at, and the range.
    fn frame(&self) -> Result<Option<(i64, &str)>, HostError> {
        let Some(frames) = self.frames else {
            if self.at.is_some() {
                return Err(HostError::bad("--at names a frame of --frames: give both"));
            }
            return Ok(None);
        };
        for pattern in [self.a, self.b] {
            if !is_sequence(pattern) {
                return Err(HostError::bad(format!(
                    "{pattern}: with --frames, A and B are #-numbered sequences (plate.####.exr)"
                )));
            }
        }
        let range = parse_frames(frames)?;
        let at = self.at.unwrap_or(range[0]);
        if !range.contains(&at) {
            return Err(HostError::bad(format!(
                "--at {at}: not a frame of --frames {frames}"
            )));
        }
        Ok(Some((at, frames)))
    }

    /// Follows the suggested scene (keyed at one frame) through both
    /// sequences with the tracker, as `morphfx track` does, into the
    /// output; the scene in between lies beside the output and goes.
    fn track(&self, scene: &str, frames: &str) -> Result<(), HostError> {
        let name = self
            .output
            .file_name()
            .map_or("scene".into(), |n| n.to_string_lossy());
        let folder = self.output.parent().filter(|p| !p.as_os_str().is_empty());
        let keyed = folder
            .unwrap_or(Path::new("."))
            .join(format!(".{name}.suggested-{}", std::process::id()));
        io::write_text(&keyed, scene)?;
        let defaults = TrackSettings::default();
        let tracked = track_job(
            &keyed,
            self.a,
            Some(self.b),
            frames,
            Some(self.output),
            defaults.radius,
            defaults.min_correlation,
        );
        let _ = std::fs::remove_file(&keyed);
        tracked
    }

    /// The base scene, parsed and as JSON; a keyed one is refused (its
    /// features move, and suggestions are made at one frame).
    fn base(&self) -> Result<Option<(Scene, Value)>, HostError> {
        let Some(path) = self.scene else {
            return Ok(None);
        };
        let bad = |e: String| HostError::bad(format!("scene {}: {e}", path.display()));
        let text = std::fs::read_to_string(path).map_err(|e| bad(e.to_string()))?;
        let scene = Scene::read(&text).map_err(|e| bad(e.to_string()))?;
        if !scene.keyframes.is_empty() {
            return Err(bad(
                "it has keyframes; suggest adds to a scene of static features".into(),
            ));
        }
        let doc: Value = serde_json::from_str(&text).map_err(|e| bad(e.to_string()))?;
        Ok(Some((scene, doc)))
    }

    /// `base` (or a new scene) with the suggestions after its own features,
    /// and a method when it names none.
    fn scene_with(&self, base: Option<Value>, found: &[Suggestion]) -> Result<Value, HostError> {
        let mut doc = base.unwrap_or_else(|| json!({"format": "morphfx-scene", "version": 1}));
        let Some(root) = doc.as_object_mut() else {
            return Err(HostError::bad("the scene is not a JSON object"));
        };
        let method = self.method.unwrap_or(DEFAULT_METHOD);
        if self.method.is_some() || !root.contains_key("method") {
            root.insert("method".into(), Value::from(method.name()));
        }
        let list = root
            .entry("features")
            .or_insert_with(|| Value::Array(Vec::new()));
        let Some(list) = list.as_array_mut() else {
            return Err(HostError::bad("the scene's features are not a list"));
        };
        let first = list.len();
        for (k, s) in found.iter().enumerate() {
            let points = |side: &[Vec2]| -> Vec<[f64; 2]> {
                side.iter().map(|p| [round(p.x), round(p.y)]).collect()
            };
            list.push(json!({
                "name": format!("suggested {}", first + k + 1),
                "type": s.kind.name(),
                "a": points(&s.a),
                "b": points(&s.b),
                "confidence": (s.confidence * 1000.0).round() / 1000.0,
            }));
        }
        Ok(doc)
    }
}

/// The scene's features moved into one keyframe at `frame`.
fn keyed_at(doc: &mut Value, frame: i64) {
    if let Some(root) = doc.as_object_mut() {
        let features = root.remove("features").unwrap_or_else(|| json!([]));
        root.insert(
            "keyframes".into(),
            json!([{"frame": frame, "features": features}]),
        );
    }
}

/// Thousandths of a pixel: what a match is good to, and readable.
fn round(v: f64) -> f64 {
    (v * 1000.0).round() / 1000.0
}

fn check(s: &SuggestSettings) -> Result<(), HostError> {
    if s.count == 0 || s.count > 10_000 {
        return Err(HostError::bad(format!(
            "--count {}: must be between 1 and 10000",
            s.count
        )));
    }
    if !(0.0..=1.0).contains(&s.min_confidence) {
        return Err(HostError::bad(format!(
            "--min-confidence {}: must be between 0 and 1",
            s.min_confidence
        )));
    }
    Ok(())
}

/// A plate as the matcher sees it.
fn grey(plate: &Plate) -> Grey {
    perceptual(&Grey::from_view(&plate.image.view()))
}

/// A plate's frame (canonical: its display window from the origin).
fn frame(plate: &Plate) -> RectD {
    RectD::new(0.0, 0.0, plate.size.0 as f64, plate.size.1 as f64)
}
