//! `morphfx track`: follows a scene's keyed features through the footage and
//! writes the scene with a keyframe at every frame of the range. A feature
//! tool, not a render: it runs the core's tracker on the plates directly.
//!
//! The scene is validated and its frames checked for presence before any
//! tracking; the output is written atomically, so a failure leaves nothing.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use morphfx::features::{Feature, FeatureKind, Side};
use morphfx::scene::Scene;
use morphfx::track::{track_side, Frames, Grey, Pyramid, SideEstimate, SideKey, TrackSettings};
use serde_json::{json, Value};

use crate::commands::snap::to_json;
use crate::error::HostError;
use crate::io;
use crate::pipeline::ReadAhead;
use crate::progress::Progress;
use crate::sequence::{frame_path, is_sequence};

/// What `track` was asked to do.
pub struct Track<'a> {
    pub scene: &'a Path,
    pub a: &'a str,
    pub b: Option<&'a str>,
    pub frames: Vec<i64>,
    /// `None`: standard output.
    pub output: Option<&'a Path>,
    pub settings: TrackSettings,
}

/// Pyramids of one sequence, read on demand. The next frame of a sweep is
/// read ahead on another thread while this one is tracked; frames a later
/// sweep comes back to (those between two keys) are kept until then.
struct Reader {
    pattern: String,
    levels: usize,
    /// Frames a later sweep comes back to: the keys, and the frames
    /// between two keys.
    revisited: Vec<(i64, i64)>,
    cache: HashMap<i64, Arc<Pyramid>>,
    ahead: ReadAhead<Arc<Pyramid>>,
    last: Option<i64>,
    range: (i64, i64),
}

impl Reader {
    fn new(pattern: &str, levels: usize, keys: &[i64], range: (i64, i64)) -> Reader {
        Reader {
            pattern: pattern.to_string(),
            levels,
            // Keys start a sweep each way; frames between keys are swept
            // forward, then backward.
            revisited: keys
                .iter()
                .map(|&k| (k, k))
                .chain(keys.windows(2).map(|w| (w[0] + 1, w[1] - 1)))
                .collect(),
            cache: HashMap::new(),
            ahead: ReadAhead::default(),
            last: None,
            range,
        }
    }

    fn load(pattern: &str, frame: i64, levels: usize) -> Result<Arc<Pyramid>, HostError> {
        let plate = io::read(&frame_path(pattern, frame))?;
        let grey = Grey::from_view(&plate.image.view());
        Ok(Arc::new(Pyramid::new(grey, levels, 16)))
    }

    fn revisited(&self, frame: i64) -> bool {
        self.revisited
            .iter()
            .any(|&(a, b)| (a..=b).contains(&frame))
    }
}

impl Frames<HostError> for Reader {
    fn pyramid(&mut self, frame: i64) -> Result<Arc<Pyramid>, HostError> {
        let pyramid = match self.cache.get(&frame) {
            Some(p) => p.clone(),
            None => match self.ahead.take(frame) {
                Some(read) => read?,
                None => Reader::load(&self.pattern, frame, self.levels)?,
            },
        };
        if self.revisited(frame) {
            self.cache.insert(frame, pyramid.clone());
        }
        // The sweep goes on in the same direction: read its next frame now.
        let next = frame + self.last.map_or(1, |l| (frame - l).signum());
        self.last = Some(frame);
        let (lo, hi) = self.range;
        if (lo..=hi).contains(&next) && !self.cache.contains_key(&next) {
            let (pattern, levels) = (self.pattern.clone(), self.levels);
            self.ahead
                .start(next, move || Reader::load(&pattern, next, levels));
        }
        Ok(pyramid)
    }
}

impl From<morphfx::Error> for HostError {
    fn from(e: morphfx::Error) -> Self {
        match e {
            // Only Ctrl-C or SIGTERM cancels a track here.
            morphfx::Error::Cancelled => {
                HostError::bad("interrupted before tracking finished: nothing was written")
            }
            e => HostError::bad(e.to_string()),
        }
    }
}

impl Track<'_> {
    pub fn run(&self) -> Result<(), HostError> {
        let text = std::fs::read_to_string(self.scene)
            .map_err(|e| HostError::bad(format!("scene {}: {e}", self.scene.display())))?;
        let at_scene = |e: &dyn std::fmt::Display| {
            HostError::bad(format!("scene {}: {e}", self.scene.display()))
        };
        let scene = Scene::parse(&text).map_err(|e| at_scene(&e))?;
        let mut doc: Value = serde_json::from_str(&text).map_err(|e| at_scene(&e))?;
        let (first, last) = self.range()?;
        let keys = self.keys_in_range(&scene, first, last)?;
        let sides: Vec<(Side, &str)> = std::iter::once((Side::A, self.a))
            .chain(self.b.map(|b| (Side::B, b)))
            .collect();
        for (_, pattern) in &sides {
            check_present(pattern, first, last)?;
        }

        let kinds: Vec<FeatureKind> = keys[0].1.iter().map(|f| f.kind).collect();
        let mut tracked: Vec<(Side, Vec<Vec<SideEstimate>>)> = Vec::new();
        let per_side = (last - first + 1) as usize - keys.len()
            + keys
                .windows(2)
                .map(|w| (w[1].0 - w[0].0 - 1) as usize)
                .sum::<usize>();
        let progress = Progress::new(per_side * sides.len());
        let mut done_before = 0;
        for (side, pattern) in &sides {
            let side_keys: Vec<SideKey> = keys
                .iter()
                .map(|(frame, features)| SideKey {
                    frame: *frame,
                    points: features.iter().map(|f| f.points(*side).to_vec()).collect(),
                })
                .collect();
            let key_frames: Vec<i64> = keys.iter().map(|k| k.0).collect();
            let mut reader = Reader::new(pattern, self.settings.levels, &key_frames, (first, last));
            let estimates = track_side(
                &kinds,
                &side_keys,
                (first, last),
                &mut reader,
                &self.settings,
                &mut |done, _, frame| {
                    progress.tick(done_before + done, frame);
                    !crate::interrupt::requested()
                },
            )?;
            done_before += per_side;
            tracked.push((*side, estimates));
        }
        progress.done("tracked");

        summarise(&scene, &kinds, &tracked, first);
        self.write(&mut doc, &scene, &tracked, first, last)
    }

    fn range(&self) -> Result<(i64, i64), HostError> {
        let (first, last) = (self.frames[0], self.frames[self.frames.len() - 1]);
        if self.frames.windows(2).any(|w| w[1] != w[0] + 1) {
            return Err(HostError::bad(format!(
                "--frames: track needs one unbroken range FIRST-LAST, not a \
                    list ({} frames from {first} to {last})",
                self.frames.len()
            )));
        }
        Ok((first, last))
    }

    /// The scene's keyframes inside the range, at whole frames.
    fn keys_in_range(
        &self,
        scene: &Scene,
        first: i64,
        last: i64,
    ) -> Result<Vec<(i64, Vec<Feature>)>, HostError> {
        if scene.keyframes.is_empty() {
            return Err(HostError::bad(format!(
                "scene {}: no keyframes; track starts from the features keyed at a frame: \
                 put them in \"keyframes\": [{{\"frame\": {first}, \"features\": [...]}}]",
                self.scene.display()
            )));
        }
        let mut keys = Vec::new();
        for k in &scene.keyframes {
            if k.frame < first as f64 || k.frame > last as f64 {
                continue;
            }
            if k.frame.fract() != 0.0 {
                return Err(HostError::bad(format!(
                    "scene {}: keyframe at frame {} is not a whole frame; track keys whole frames",
                    self.scene.display(),
                    k.frame
                )));
            }
            keys.push((k.frame as i64, k.features.clone()));
        }
        if keys.is_empty() {
            let at: Vec<String> = scene
                .keyframes
                .iter()
                .map(|k| k.frame.to_string())
                .collect();
            return Err(HostError::bad(format!(
                "scene {}: no keyframe in frames {first}-{last} to track from (keyframes at {})",
                self.scene.display(),
                at.join(", ")
            )));
        }
        if keys[0].1.is_empty() {
            return Err(HostError::bad(format!(
                "scene {}: the keyframes hold no features to track",
                self.scene.display()
            )));
        }
        Ok(keys)
    }

    /// The scene with a keyframe at every frame of the range (keys outside
    /// it kept), each tracked feature marked with its confidence.
    fn write(
        &self,
        doc: &mut Value,
        scene: &Scene,
        tracked: &[(Side, Vec<Vec<SideEstimate>>)],
        first: i64,
        last: i64,
    ) -> Result<(), HostError> {
        let originals = doc["keyframes"].as_array().cloned().unwrap_or_default();
        let template = originals
            .iter()
            .find(|k| k["frame"].as_f64().is_some_and(|f| f >= first as f64))
            .or(originals.first())
            .map(|k| k["features"].clone())
            .unwrap_or(Value::Null);
        let mut keys: Vec<Value> = originals
            .iter()
            .filter(|k| {
                k["frame"]
                    .as_f64()
                    .is_some_and(|f| f < first as f64 || f > last as f64)
            })
            .cloned()
            .collect();
        for frame in first..=last {
            let at = (frame - first) as usize;
            let keyed = scene.keyframes.iter().any(|k| k.frame == frame as f64);
            let interpolated = scene.features_at(frame as f64);
            let mut features = template.clone();
            for (i, f) in features.as_array_mut().into_iter().flatten().enumerate() {
                f["a"] = to_json(interpolated[i].points(Side::A));
                f["b"] = to_json(interpolated[i].points(Side::B));
                if let Some(map) = f.as_object_mut() {
                    map.remove("track");
                }
                let mut marks = serde_json::Map::new();
                for (side, per_frame) in tracked {
                    let e = &per_frame[at][i];
                    let key = side_key(*side);
                    f[key] = to_json(&e.points);
                    if !keyed {
                        let conf: Vec<f64> = e
                            .confidence
                            .iter()
                            .map(|c| (c * 1000.0).round() / 1000.0)
                            .collect();
                        marks.insert(key.into(), json!({ "confidence": conf, "lost": e.lost }));
                    }
                }
                if !marks.is_empty() {
                    f["track"] = Value::Object(marks);
                }
            }
            keys.push(json!({ "frame": frame, "features": features }));
        }
        let frame_of = |k: &Value| k["frame"].as_f64().unwrap_or(f64::NAN);
        keys.sort_by(|x, y| frame_of(x).total_cmp(&frame_of(y)));
        doc["keyframes"] = Value::from(keys);
        if let Some(map) = doc.as_object_mut() {
            map.remove("features");
        }
        let out = serde_json::to_string_pretty(doc)
            .map_err(|e| HostError::failed(format!("cannot write the scene: {e}")))?;
        Scene::parse(&out)
            .map_err(|e| HostError::failed(format!("tracked scene is invalid: {e}")))?;
        match self.output {
            Some(path) => io::write_text(path, &out),
            None => {
                println!("{out}");
                Ok(())
            }
        }
    }
}

fn side_key(side: Side) -> &'static str {
    match side {
        Side::A => "a",
        Side::B => "b",
    }
}

/// Every frame of a sequence is there before any work (a single file for a
/// pattern without `#` is a still, the same plate at every frame).
fn check_present(pattern: &str, first: i64, last: i64) -> Result<(), HostError> {
    let missing: Vec<PathBuf> = if is_sequence(pattern) {
        (first..=last)
            .map(|f| frame_path(pattern, f))
            .filter(|p| !p.is_file())
            .collect()
    } else {
        return Err(HostError::bad(format!(
            "{pattern}: track follows features through a sequence: give a \
                #-numbered pattern such as plate.####.exr"
        )));
    };
    match missing.as_slice() {
        [] => Ok(()),
        [one] => Err(HostError::bad(format!("{}: no such file", one.display()))),
        [one, ..] => Err(HostError::bad(format!(
            "{}: no such file (and {} more frames of {pattern} missing in {first}-{last})",
            one.display(),
            missing.len() - 1
        ))),
    }
}

/// Per feature and side on standard error: mean confidence, and the frames
/// where it lost track, as ranges.
fn summarise(
    scene: &Scene,
    kinds: &[FeatureKind],
    tracked: &[(Side, Vec<Vec<SideEstimate>>)],
    first: i64,
) {
    let names = &scene.keyframes[0].features;
    for (i, kind) in kinds.iter().enumerate() {
        let name = names[i]
            .name
            .as_deref()
            .map(|n| format!(" \"{n}\""))
            .unwrap_or_default();
        for (side, per_frame) in tracked {
            let conf: Vec<f64> = per_frame
                .iter()
                .map(|f| f[i].confidence.iter().copied().fold(1.0, f64::min))
                .collect();
            let mean = conf.iter().sum::<f64>() / conf.len().max(1) as f64;
            let lost: Vec<i64> = per_frame
                .iter()
                .enumerate()
                .filter(|(_, f)| f[i].lost.iter().any(|l| *l))
                .map(|(k, _)| first + k as i64)
                .collect();
            let side = side_key(*side).to_uppercase();
            if lost.is_empty() {
                eprintln!(
                    "feature {}{name} ({}), {side}: tracked, mean confidence {mean:.3}",
                    i + 1,
                    kind.name()
                );
            } else {
                eprintln!(
                    "feature {}{name} ({}), {side}: LOST TRACK at frames {} \
                        (marked \"lost\" in the scene; key it there), mean \
                        confidence {mean:.3}",
                    i + 1,
                    kind.name(),
                    ranges(&lost)
                );
            }
        }
    }
}

/// `1001-1003, 1007`.
fn ranges(frames: &[i64]) -> String {
    let mut out: Vec<String> = Vec::new();
    let mut k = 0;
    while k < frames.len() {
        let start = frames[k];
        while k + 1 < frames.len() && frames[k + 1] == frames[k] + 1 {
            k += 1;
        }
        out.push(if frames[k] == start {
            start.to_string()
        } else {
            format!("{start}-{}", frames[k])
        });
        k += 1;
    }
    out.join(", ")
}
