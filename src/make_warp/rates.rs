//! The transition's rates at a time: how far each point of the frame has
//! gone, for the geometry and for the colour.

use super::reach::feature_bounds;
use super::WarpSettings;
use crate::error::Result;
use crate::features::Feature;
use crate::geom::RectD;
use crate::transition::{Rates, Transition};

impl WarpSettings {
    /// The geometry transition's rates at `t` (uniform unless the scene
    /// asks otherwise), over the frame or the features' bounds.
    pub fn geometry_rates(&self, features: &[Feature], t: f64) -> Result<Rates> {
        self.rates(&self.settings.transition.geometry, features, t)
    }

    /// The colour transition's rates at `t`.
    pub fn colour_rates(&self, features: &[Feature], t: f64) -> Result<Rates> {
        self.rates(self.settings.transition.colour(), features, t)
    }

    fn rates(&self, transition: &Transition, features: &[Feature], t: f64) -> Result<Rates> {
        if transition.is_uniform_at(t) {
            return Ok(Rates::Uniform(t.clamp(0.0, 1.0)));
        }
        let frame = self
            .region
            .or_else(|| feature_bounds(features))
            .unwrap_or(RectD::new(0.0, 0.0, 1.0, 1.0));
        transition.rates(features, self.settings.samples_per_segment, frame, t)
    }
}
