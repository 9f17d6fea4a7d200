//! Motion blur: a frame rendered at times spread over the shutter and
//! averaged. Each sample takes the params, the scene and so the warps at
//! its time; the source images stay the frame's (it is the warp's motion
//! that blurs, as an animated distortion's does in a transform node). A
//! frame whose warps do not move within the shutter renders once, exactly
//! as without blur.

use morphfx::image::resample::fill;
use morphfx::image::Image;

use super::{correspond, draw_rows, mask_of, prepare, Lent, Request};
use crate::cache::Key;
use crate::nodes::kind::NodeKind;
use crate::nodes::state::NodeState;
use ofx_layer::clips::{Depth, EffectHandle};
use ofx_layer::Outcome;

/// The requests of a blurred frame, one per sample time; `None` when the
/// frame renders once: no blur asked, a view that is not a picture, or a
/// still scene (every sample's warps and mix as the frame's).
pub(super) fn samples(
    instance: &NodeState,
    effect: &EffectHandle,
    request: &Request,
) -> Outcome<Option<Vec<Request>>> {
    let times = request.settings.shutter.times(request.time);
    if times.len() < 2 || !request.settings.view.is_picture() {
        return Ok(None);
    }
    let samples = times
        .iter()
        .map(|t| request.at(instance.kind, effect, instance, *t))
        .collect::<Outcome<Vec<Request>>>()?;
    let what = |r: &Request| Key::of(&(&r.inputs, r.settings.mix.to_bits()));
    let frame = what(request);
    if samples.iter().all(|r| what(r) == frame) {
        return Ok(None);
    }
    Ok(Some(samples))
}

/// Renders each sample in float, then writes their mean to the output
/// window at the output's depth (rounded once).
pub(super) fn render(
    kind: &'static NodeKind,
    instance: &NodeState,
    effect: &EffectHandle,
    samples: Vec<Request>,
    lent: &mut Lent,
) -> Outcome {
    let (window, channels) = (samples[0].window, lent.out.info().channels);
    let mask = lent.mask.as_ref().map(mask_of).transpose()?;
    let mut sum = Image::new(window, channels);
    let n = samples.len();
    for mut request in samples {
        if effect.aborted() {
            return Ok(());
        }
        correspond(instance, &mut request)?;
        let job = prepare(kind, instance, &request)?;
        let mut one = Image::new(window, channels);
        draw_rows::<f32>(
            kind,
            &job,
            &request,
            (&lent.sources, &mask),
            one.view_mut().rows(),
        )?;
        for (s, v) in sum.data.iter_mut().zip(&one.data) {
            *s += v;
        }
    }
    let k = 1.0 / n as f32;
    with_depth!(lent.out.info().depth, D => {
        let rows = lent.out.rows_mut::<D>(window)?;
        fill(rows, channels, |i, j, px| {
            for (p, v) in px.iter_mut().zip(sum.pixel(i, j)) {
                *p = v * k;
            }
        });
    });
    Ok(())
}
