//! A transition curve (Lee et al. Fig. 2): the rate of transition of a point
//! over progress `t`, from 0 (A) to 1 (B).

use crate::error::{Error, Result};

/// A piecewise-linear transition curve.
#[derive(Debug, Clone, PartialEq)]
pub struct Curve {
    /// `(t, rate)` keys, strictly increasing in `t`, `(0, 0)` and `(1, 1)`
    /// included; linear between keys.
    keys: Vec<(f64, f64)>,
}

impl Curve {
    /// The curve through `keys`. The ends are implied: every curve starts at
    /// A and ends at B, so the end frames of a morph are its plates whatever
    /// the curves; a key at `t = 0` must have rate 0, at `t = 1` rate 1.
    pub fn new(keys: &[(f64, f64)], at: &str) -> Result<Curve> {
        let mut all = vec![(0.0, 0.0)];
        for (k, &(t, r)) in keys.iter().enumerate() {
            let here = format!("{at}.keys[{k}]");
            if !(t.is_finite() && r.is_finite()) {
                return Err(Error::scene(&here, "not a finite number"));
            }
            if !(0.0..=1.0).contains(&t) || !(0.0..=1.0).contains(&r) {
                return Err(Error::scene(
                    &here,
                    format!("[{t}, {r}]: t and rate must both be in [0, 1]"),
                ));
            }
            if (t == 0.0 && r != 0.0) || (t == 1.0 && r != 1.0) {
                return Err(Error::scene(
                    &here,
                    format!("[{t}, {r}]: a curve is at rate 0 at t = 0 and 1 at t = 1 (A and B)"),
                ));
            }
            let last = all.last().map_or(0.0, |k: &(f64, f64)| k.0);
            if t == 0.0 || t == 1.0 {
                continue;
            }
            if t <= last {
                return Err(Error::scene(
                    &here,
                    format!("t = {t} does not come after the previous key (t = {last})"),
                ));
            }
            all.push((t, r));
        }
        all.push((1.0, 1.0));
        Ok(Curve { keys: all })
    }

    /// The rate at progress `t` (held at the ends outside `[0, 1]`).
    pub fn at(&self, t: f64) -> f64 {
        let k = &self.keys;
        if t <= 0.0 {
            return 0.0;
        }
        if t >= 1.0 {
            return 1.0;
        }
        let hi = k.iter().position(|&(kt, _)| kt > t).unwrap_or(k.len() - 1);
        let (t0, r0) = k[hi - 1];
        let (t1, r1) = k[hi];
        r0 + (r1 - r0) * (t - t0) / (t1 - t0)
    }
}
