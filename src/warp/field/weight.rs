//! Beier-Neely eq. (4): `weight = (length^p / (a + dist))^b`.

/// Beier-Neely eq. (4)'s constants.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Weight {
    /// Added to the distance: barely above zero pins pixels on a line to it.
    pub a: f64,
    /// How fast a line's influence falls off with distance.
    pub b: f64,
    /// How much longer lines outweigh shorter ones.
    pub p: f64,
}

impl Weight {
    /// The weight with constants `a`, `b`, `p`.
    pub fn new(a: f64, b: f64, p: f64) -> Self {
        Weight { a, b, p }
    }

    /// The weight of a line of `length` for a pixel `dist` from it.
    pub fn of(&self, length: f64, dist: f64) -> f64 {
        (length.powf(self.p) / (self.a + dist)).powf(self.b)
    }

    /// The exponent `b` in a form the vector kernel can specialise on: the
    /// common values avoid a `pow` per pixel and line.
    pub fn exponent(&self) -> Exponent {
        if self.b == 0.0 {
            Exponent::Zero
        } else if self.b == 0.5 {
            Exponent::Half
        } else if self.b == 1.0 {
            Exponent::One
        } else if self.b == 2.0 {
            Exponent::Two
        } else {
            Exponent::General(self.b as f32)
        }
    }
}

/// The exponent `b`, with the common values named.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Exponent {
    /// `b = 0`: every line weighs one.
    Zero,
    /// `b = 0.5`: a square root.
    Half,
    /// `b = 1`.
    One,
    /// `b = 2`: a square.
    Two,
    /// Any other `b`.
    General(f32),
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weight_follows_equation_4() {
        let w = Weight::new(0.5, 2.0, 1.0);
        // (10^1 / (0.5 + 2))^2 = 16
        assert!((w.of(10.0, 2.0) - 16.0).abs() < 1e-12);
        // p = 0: all lines weigh the same regardless of length.
        let w0 = Weight::new(1.0, 1.0, 0.0);
        assert_eq!(w0.of(3.0, 1.0), w0.of(300.0, 1.0));
        // b = 0: every line counts equally at every distance.
        let flat = Weight::new(1.0, 0.0, 0.5);
        assert_eq!(flat.of(5.0, 0.0), flat.of(5.0, 1000.0));
    }

    #[test]
    fn weight_falls_with_distance() {
        let w = Weight::new(0.001, 2.0, 0.5);
        assert!(w.of(20.0, 1.0) > w.of(20.0, 2.0));
        assert!((w.of(20.0, 0.0) - 2e7).abs() < 1.0);
    }
}
