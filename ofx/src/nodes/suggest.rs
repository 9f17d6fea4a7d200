//! The Suggest Features push-button: feature pairs proposed between Source
//! A and Source B at the current frame (the core's `suggest`: corners of A
//! found on B and checked both ways) and added to Scene Text as one undo
//! step, each with its confidence, clear of the user's own features. A
//! cancel, or anything refused, leaves Scene Text as it was.

use morphfx::features::Feature;
use morphfx::geom::{PixelScale, RectD, Vec2};
use morphfx::suggest::{perceptual, suggest, work_guide, SuggestSettings};
use morphfx::track::Grey;
use morphfx::warp::auto::WorkImage;

use super::overlay::shapes;
use super::params::{Reader, Settings, MIN_CONFIDENCE, SUGGEST_COUNT};
use super::state::NodeState;
use ofx_layer::clips::{Depth, EffectHandle};
use ofx_layer::{Failure, Outcome};

/// One source at a time: its grey plane and colour (pixels), and the
/// scale its pixels are at.
struct Plate {
    grey: Grey,
    work: WorkImage,
    scale: PixelScale,
}

impl Plate {
    /// The plate's frame, canonical.
    fn frame(&self) -> RectD {
        let b = self.grey.bounds;
        let s = self.scale;
        RectD::new(
            b.x1 as f64 / s.x,
            b.y1 as f64 / s.y,
            b.x2 as f64 / s.x,
            b.y2 as f64 / s.y,
        )
    }
}

/// The Suggest Features button, pressed at `time`.
pub fn suggest_features(instance: &NodeState, effect: &EffectHandle, time: f64) -> Outcome {
    let (kind, params) = (instance.kind, instance.params());
    let settings = Settings::read(params, time, kind);
    let r = Reader::new(params, kind, time);
    let wanted = SuggestSettings {
        count: r.int(&SUGGEST_COUNT).max(1) as usize,
        min_confidence: r.double(&MIN_CONFIDENCE),
        ..SuggestSettings::default()
    };
    let (a, b) = kind.source_clips(instance.context);
    let b = b.ok_or_else(|| Failure::BadInput("Suggest Features needs two sources".into()))?;
    // Refused up front when Scene Text cannot be edited.
    let mut doc = shapes::document(instance, time)?;
    effect.progress_start("Suggest Features");
    let found = (|| {
        let pa = plate(effect, a, time + settings.offset_a as f64)?;
        let pb = plate(effect, b, time + settings.offset_b as f64)?;
        if !effect.progress_update(0.3) {
            return Ok(None);
        }
        let mut mine = doc.scene().features_at(time);
        mine.extend(settings.lines.iter().cloned());
        let map = work_guide(&pa.work, pa.frame(), &pb.work, pb.frame(), &mine)?;
        if !effect.progress_update(0.6) {
            return Ok(None);
        }
        let (sa, sb) = (pa.scale, pb.scale);
        let guide = move |p: Vec2| sb.to_pixel(map.map_a_to_b(sa.to_canonical(p)));
        let clear: Vec<Vec2> = mine
            .iter()
            .flat_map(|f| f.a.iter().map(|p| sa.to_pixel(*p)))
            .collect();
        let pairs = suggest(&pa.grey, &pb.grey, &guide, &clear, &wanted)?;
        Ok::<_, Failure>(Some((pairs, sa, sb)))
    })();
    let cancelled = !effect.progress_update(1.0);
    effect.progress_end();
    let Some((pairs, sa, sb)) = found? else {
        return Ok(());
    };
    if cancelled {
        return Ok(());
    }
    let first = doc.scene().features_at(time).len();
    for (k, s) in pairs.iter().enumerate() {
        let f = Feature {
            name: Some(format!("suggested {}", first + k + 1)),
            confidence: Some((s.confidence * 1000.0).round() / 1000.0),
            ..Feature::new(
                s.kind,
                s.a.iter().map(|p| sa.to_canonical(*p)).collect(),
                s.b.iter().map(|p| sb.to_canonical(*p)).collect(),
            )
        };
        doc.add_feature(&f).map_err(shapes::refused)?;
    }
    params.edit_block("Suggest Features", || shapes::write(instance, &doc))?;
    instance.purge();
    Ok(())
}

/// Clip `name` at `time`: grey and colour planes, and its pixel scale.
fn plate(effect: &EffectHandle, name: &str, time: f64) -> Outcome<Plate> {
    let clip = effect.clip(name)?;
    if !clip.is_connected() {
        return Err(Failure::BadInput(format!(
            "Suggest Features needs clip {name} connected"
        )));
    }
    let image = clip.image(time)?.ok_or_else(|| {
        Failure::BadInput(format!(
            "Suggest Features: clip {name} has no image at frame {time}"
        ))
    })?;
    let scale = image.info().pixel_scale();
    let (grey, work) = match image.info().depth {
        Depth::U8 => {
            let v = image.view::<u8>()?;
            (perceptual(&Grey::from_view(&v)), WorkImage::from_view(&v))
        }
        Depth::U16 => {
            let v = image.view::<u16>()?;
            (perceptual(&Grey::from_view(&v)), WorkImage::from_view(&v))
        }
        Depth::F32 => {
            let v = image.view::<f32>()?;
            (perceptual(&Grey::from_view(&v)), WorkImage::from_view(&v))
        }
    };
    Ok(Plate { grey, work, scale })
}
