//! `morphfx snap`: refines a scene's polylines and curves on both images with
//! snakes (Lee, Wolberg et al. §4.2) and writes the refined scene. A feature tool, not a
//! render: it runs the core's snakes on the plates directly.
//!
//! Each polyline or curve is sampled into snake points on A and on B (the
//! same sampling, so the sides still correspond point for point), the snakes
//! slither onto nearby edges, and the feature is written back as a polyline
//! through the snake points. Points and lines are left as they are.

use std::path::Path;

use morphfx::features::FeatureKind;
use morphfx::geom::Vec2;
use morphfx::scene::Scene;
use morphfx::snake::{EdgeEnergy, Snake, SnakeSettings};
use serde_json::Value;

use crate::error::HostError;
use crate::io;
use crate::sequence::{frame_path, is_sequence};

/// What `snap` was asked to do.
pub struct Snap<'a> {
    pub scene: &'a Path,
    pub a: &'a str,
    pub b: &'a str,
    pub output: &'a Path,
    /// The keyframe to refine (scenes with keyframes), and the frame of
    /// `#`-numbered plates.
    pub frame: Option<f64>,
    /// Gaussian σ of the edge energy, pixels: edges attract from about 2σ.
    pub sigma: f64,
    pub settings: SnakeSettings,
}

impl Snap<'_> {
    /// Refines and writes the scene; returns the line the command prints.
    pub fn run(&self) -> Result<String, HostError> {
        let text = std::fs::read_to_string(self.scene)
            .map_err(|e| HostError::bad(format!("scene {}: {e}", self.scene.display())))?;
        // The whole scene is validated first; edits go to the JSON itself so
        // every key this tool does not touch is written back unchanged.
        let scene = Scene::parse(&text)
            .map_err(|e| HostError::bad(format!("scene {}: {e}", self.scene.display())))?;
        let mut doc: Value = serde_json::from_str(&text)
            .map_err(|e| HostError::bad(format!("scene {}: {e}", self.scene.display())))?;
        let at = self.frame_in(&scene);
        let features = self.features_to_refine(&scene, at, &mut doc)?;

        let frame = at.unwrap_or(0.0).round() as i64;
        let plate = |pattern: &str| {
            let path = if is_sequence(pattern) {
                if at.is_none() {
                    return Err(HostError::bad(format!(
                        "{pattern}: a numbered sequence needs --frame"
                    )));
                }
                frame_path(pattern, frame)
            } else {
                pattern.into()
            };
            io::read(&path)
        };
        let (pa, pb) = (plate(self.a)?, plate(self.b)?);
        if !(self.sigma.is_finite() && self.sigma > 0.0 && self.sigma <= 100.0) {
            return Err(HostError::bad(format!(
                "--sigma {}: must be between 0 and 100 pixels",
                self.sigma
            )));
        }
        let energy_a = EdgeEnergy::new(pa.image.view(), self.sigma);
        let energy_b = EdgeEnergy::new(pb.image.view(), self.sigma);

        let mut refined = 0;
        let mut moved = 0.0f64;
        for f in features.as_array_mut().into_iter().flatten() {
            let kind = f
                .get("type")
                .and_then(Value::as_str)
                .and_then(FeatureKind::parse);
            if !matches!(kind, Some(FeatureKind::Polyline | FeatureKind::Curve)) {
                continue;
            }
            let kind = kind.expect("checked above");
            let closed = f.get("closed").and_then(Value::as_bool) == Some(true);
            let mut side = |key: &str, energy: &EdgeEnergy| -> Vec<Vec2> {
                let mut controls = points(&f[key]);
                // A closed shape is snaked with its closing span, and stays
                // closed: the snake's second visit of the first point goes.
                if closed {
                    controls.extend(controls.first().copied());
                }
                let mut snake = Snake::from_primitive(kind, &controls, &self.settings);
                let before = snake.points.clone();
                snake.run(energy, &self.settings);
                moved = before
                    .iter()
                    .zip(&snake.points)
                    .map(|(a, b)| a.distance(*b))
                    .fold(moved, f64::max);
                if closed {
                    snake.points.pop();
                }
                snake.points
            };
            let (a, b) = (side("a", &energy_a), side("b", &energy_b));
            let (a, b) = without_coinciding(a, b, closed);
            f["type"] = Value::from("polyline");
            f["a"] = to_json(&a);
            f["b"] = to_json(&b);
            refined += 1;
        }
        let out = serde_json::to_string_pretty(&doc)
            .map_err(|e| HostError::failed(format!("cannot write the scene: {e}")))?;
        // The result must be a valid scene before it replaces anything.
        Scene::parse(&out)
            .map_err(|e| HostError::failed(format!("refined scene is invalid: {e}")))?;
        io::write_text(self.output, &out)?;
        Ok(format!(
            "snap: refined {refined} polyline/curve feature(s) on both \
                images (largest move {moved:.2} px) -> {}",
            self.output.display()
        ))
    }

    /// The frame refined: `--frame`, else a scene's only keyframe (there is
    /// no choice to make).
    fn frame_in(&self, scene: &Scene) -> Option<f64> {
        match scene.keyframes.as_slice() {
            [only] => self.frame.or(Some(only.frame)),
            _ => self.frame,
        }
    }

    /// The feature list to edit: the static features, or the keyframe at
    /// `frame` when the scene has keyframes.
    fn features_to_refine<'d>(
        &self,
        scene: &Scene,
        frame: Option<f64>,
        doc: &'d mut Value,
    ) -> Result<&'d mut Value, HostError> {
        if scene.keyframes.is_empty() {
            return Ok(&mut doc["features"]);
        }
        let Some(frame) = frame else {
            let keys: Vec<String> = scene
                .keyframes
                .iter()
                .map(|k| k.frame.to_string())
                .collect();
            return Err(HostError::bad(format!(
                "the scene has keyframes ({}): say which to refine with --frame",
                keys.join(", ")
            )));
        };
        let keys = doc["keyframes"]
            .as_array_mut()
            .expect("validated keyframes");
        keys.iter_mut()
            .find(|k| k["frame"].as_f64() == Some(frame))
            .map(|k| &mut k["features"])
            .ok_or_else(|| HostError::bad(format!("--frame {frame}: no keyframe at that frame")))
    }
}

fn points(v: &Value) -> Vec<Vec2> {
    v.as_array()
        .into_iter()
        .flatten()
        .filter_map(|p| Some(Vec2::new(p.get(0)?.as_f64()?, p.get(1)?.as_f64()?)))
        .collect()
}

/// Points as a scene file holds them, to a thousandth of a pixel (which
/// keeps the file readable).
pub fn to_json(points: &[Vec2]) -> Value {
    let r = |v: f64| (v * 1000.0).round() / 1000.0;
    Value::from(
        points
            .iter()
            .map(|p| Value::from(vec![r(p.x), r(p.y)]))
            .collect::<Vec<_>>(),
    )
}

/// A snake can pull two neighbouring samples onto one point (a tight
/// corner), which no scene allows: such a sample is dropped from both
/// sides, so they still correspond point for point.
fn without_coinciding(a: Vec<Vec2>, b: Vec<Vec2>, closed: bool) -> (Vec<Vec2>, Vec<Vec2>) {
    // Points are written to 1/1000 px (`to_json`): any two that round to
    // one are under 0.0015 px apart.
    const SAME: f64 = 0.0015;
    let (mut ka, mut kb): (Vec<Vec2>, Vec<Vec2>) = (Vec::new(), Vec::new());
    for (p, q) in a.into_iter().zip(b) {
        let repeats = |kept: &[Vec2], p: Vec2| kept.last().is_some_and(|l| l.distance(p) < SAME);
        if !(repeats(&ka, p) || repeats(&kb, q)) {
            ka.push(p);
            kb.push(q);
        }
    }
    // A closed shape's last point meets its first again.
    while closed && ka.len() > 3 {
        let (la, lb) = (ka[ka.len() - 1], kb[kb.len() - 1]);
        if la.distance(ka[0]) < SAME || lb.distance(kb[0]) < SAME {
            ka.pop();
            kb.pop();
        } else {
            break;
        }
    }
    (ka, kb)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn coinciding_samples_go_from_both_sides() {
        let p = |x: f64| Vec2::new(x, 0.0);
        // b[1] and b[2] coincide: sample 2 goes from A too.
        let a = vec![p(0.0), p(1.0), p(2.0), p(3.0)];
        let b = vec![p(0.0), p(5.0), p(5.0), p(7.0)];
        let (a2, b2) = without_coinciding(a, b, false);
        assert_eq!(a2, vec![p(0.0), p(1.0), p(3.0)]);
        assert_eq!(b2, vec![p(0.0), p(5.0), p(7.0)]);
        // Closed: a last point back on the first goes.
        let a = vec![p(0.0), p(1.0), p(2.0), p(3.0), p(0.0)];
        let b = vec![p(0.0), p(1.0), p(2.0), p(3.0), p(4.0)];
        let (a2, b2) = without_coinciding(a, b, true);
        assert_eq!((a2.len(), b2.len()), (4, 4));
    }
}
