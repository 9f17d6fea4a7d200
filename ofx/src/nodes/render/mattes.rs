//! The nodes' mattes: the Mask input (where, and with Mix how much, the
//! effect applies) and the Morph node's Timing input (when each point of A
//! has its turn).

use std::sync::Arc;

use morphfx::geom::PixelScale;
use morphfx::image::Sample;
use morphfx::transition::{Matte, Transition, TransitionSettings};

use crate::nodes::kind::TIMING_CLIP;
use crate::nodes::params::{pacing, Settings};
use ofx_layer::clips::{Depth, HostImage};
use ofx_layer::{Failure, Outcome};

/// The timing matte of `image`: its alpha (an RGB matte's mean) per pixel.
pub(super) fn timing_matte(image: &HostImage) -> Outcome<Matte> {
    let info = image.info();
    let scale: PixelScale = info.pixel_scale();
    let alpha = with_depth!(info.depth, S => {
        let view = image.view::<S>()?;
        let b = view.bounds();
        let c = view.channels();
        let mut alpha = Vec::with_capacity(b.area());
        for j in b.y1..b.y2 {
            for px in view.row(j).chunks_exact(c) {
                alpha.push(match c {
                    1 => px[0].to_f32(),
                    3 => (px[0].to_f32() + px[1].to_f32() + px[2].to_f32()) / 3.0,
                    _ => px[c - 1].to_f32(),
                });
            }
        }
        alpha
    });
    Matte::new(info.bounds, scale, alpha)
        .map_err(|e| Failure::BadInput(format!("clip {}: {e}", TIMING_CLIP)))
}

/// The transitions with the timing matte in place of the node's pattern
/// (and a scene's curves): what Affects names is paced by the matte, the
/// rest stays uniform.
pub(super) fn timed(matte: Arc<Matte>, settings: &Settings) -> TransitionSettings {
    let t = Transition::Matte {
        matte,
        spread: settings.spread,
    };
    pacing(t, settings.affects)
}
