//! The Snap Lines push-button (Lee, Wolberg et al. §4.2): every enabled line slot, and
//! every line, polyline and curve of Scene Text, slides onto the nearest
//! strong edge of its source at the current frame — A positions on Source
//! A, B positions on Source B (Morph) — and the moved points are keyed
//! there (slots in their params, shapes in Scene Text, one undo step), so
//! the user places features roughly and lets the image finish the job.

use morphfx::features::{Feature, FeatureKind, Side};
use morphfx::geom::{PixelScale, Vec2};
use morphfx::snake::{EdgeEnergy, Snake, SnakeSettings};

use super::overlay::shapes;
use super::params::{slot_ids, Reader, Settings, SlotIds, LINE_COUNT, SNAP_SIGMA};
use super::state::NodeState;
use ofx_layer::clips::{Depth, EffectHandle};
use ofx_layer::{Failure, Outcome};

/// The Snap Lines button, pressed at `time`.
pub fn snap_lines(instance: &NodeState, effect: &EffectHandle, time: f64) -> Outcome {
    let kind = instance.kind;
    let params = instance.params();
    let settings = Settings::read(params, time, kind);
    let r = Reader::new(params, kind, time);
    let sigma = r.double(&SNAP_SIGMA);
    let (a, b) = kind.source_clips(instance.context);
    let energy_a = edge_energy(effect, a, time + settings.offset_a as f64, sigma)?;
    let energy_b = match b {
        Some(b) => Some(edge_energy(
            effect,
            b,
            time + settings.offset_b as f64,
            sigma,
        )?),
        None => None,
    };
    let count = r.int(&LINE_COUNT) as usize;
    // Every endpoint's new key first, then all written as one undo step.
    let mut keys = Vec::new();
    for k in 1..=count {
        let SlotIds { enable, a, b } = slot_ids(k);
        if !r.bool(&enable) {
            continue;
        }
        let sides = std::iter::once((a, &energy_a)).chain(energy_b.as_ref().map(|e| (b, e)));
        for ([start, end], (energy, scale)) in sides {
            let p = Vec2::from(<[f64; 2]>::from(params.point(&start, time)?));
            let q = Vec2::from(<[f64; 2]>::from(params.point(&end, time)?));
            if p == q || !(p.is_finite() && q.is_finite()) {
                continue;
            }
            let [p, q] = snap_line([p, q], energy, *scale);
            keys.extend([(start, p), (end, q)]);
        }
    }
    // Scene Text's shapes, when the viewer may edit them.
    let mut doc = shapes::document(instance, time)
        .ok()
        .filter(|d| d.scene().has_features());
    if let Some(doc) = doc.as_mut() {
        let energies =
            std::iter::once((Side::A, &energy_a)).chain(energy_b.as_ref().map(|e| (Side::B, e)));
        let mut moved = Vec::new();
        let features = doc.scene().features_at(time);
        for (side, (energy, scale)) in energies {
            for (i, f) in features.iter().enumerate() {
                if let Some(points) = snap_shape(f, side, energy, *scale) {
                    moved.push((time, i, side, points));
                }
            }
        }
        doc.set_points(&moved).map_err(shapes::refused)?;
    }
    params.edit_block("Snap Lines", || {
        keys.iter()
            .try_for_each(|(id, p)| params.set_point_at(id, time, (p.x, p.y)))?;
        match &doc {
            Some(doc) => shapes::write(instance, doc),
            None => Ok(()),
        }
    })?;
    instance.purge();
    Ok(())
}

/// The line `p → q` (canonical) snaked on `energy` (pixels at `scale`) and
/// unsnaked back to its two endpoints.
fn snap_line(line: [Vec2; 2], energy: &EdgeEnergy, scale: PixelScale) -> [Vec2; 2] {
    let settings = SnakeSettings::default();
    let px = line.map(|p| scale.to_pixel(p));
    let mut snake = Snake::from_primitive(FeatureKind::Polyline, &px, &settings);
    snake.run(energy, &settings);
    let back = snake.unsnake();
    let moved = [0, 1].map(|k| Vec2::new(back[k].x / scale.x, back[k].y / scale.y));
    // Never key a non-finite position: leave such a line where it was.
    if moved.iter().all(|p| p.is_finite()) {
        moved
    } else {
        line
    }
}

/// Feature `f`'s control points on `side` (canonical) snaked on `energy`
/// and unsnaked; `None` for points, and for a result that is not finite.
/// A closed shape is snaked with its closing span and its first point
/// taken where the snake's start left it.
fn snap_shape(
    f: &Feature,
    side: Side,
    energy: &EdgeEnergy,
    scale: PixelScale,
) -> Option<Vec<Vec2>> {
    let kind = match f.kind {
        FeatureKind::Point => return None,
        FeatureKind::Line => FeatureKind::Polyline,
        k => k,
    };
    let mut px: Vec<Vec2> = f.points(side).iter().map(|p| scale.to_pixel(*p)).collect();
    let n = px.len();
    if f.closed {
        px.push(px[0]);
    }
    let settings = SnakeSettings::default();
    let mut snake = Snake::from_primitive(kind, &px, &settings);
    snake.run(energy, &settings);
    let back: Vec<Vec2> = snake.unsnake()[..n]
        .iter()
        .map(|p| Vec2::new(p.x / scale.x, p.y / scale.y))
        .collect();
    back.iter().all(|p| p.is_finite()).then_some(back)
}

/// The edge energy of clip `name` at `time`, and the pixel scale it is in.
fn edge_energy(
    effect: &EffectHandle,
    name: &str,
    time: f64,
    sigma: f64,
) -> Outcome<(EdgeEnergy, PixelScale)> {
    let clip = effect.clip(name)?;
    if !clip.is_connected() {
        return Err(Failure::BadInput(format!(
            "Snap Lines needs clip {name} connected"
        )));
    }
    let image = clip.image(time)?.ok_or_else(|| {
        Failure::BadInput(format!(
            "Snap Lines: clip {name} has no image at frame {time}"
        ))
    })?;
    let info = image.info();
    let scale = PixelScale::new(info.render_scale.0, info.render_scale.1, info.par);
    let sigma = sigma * scale.y;
    let energy = match info.depth {
        Depth::U8 => EdgeEnergy::new(image.view::<u8>()?, sigma),
        Depth::U16 => EdgeEnergy::new(image.view::<u16>()?, sigma),
        Depth::F32 => EdgeEnergy::new(image.view::<f32>()?, sigma),
    };
    Ok((energy, scale))
}
