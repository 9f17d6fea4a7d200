//! The law every per-point transition shares (Lee et al. §4.2): a point
//! whose turn is `g ∈ [0, 1]` crosses from A to B over `1 − spread` of the
//! progress, starting at `spread · g`, so every point is exactly A at
//! `t = 0` and exactly B at `t = 1`, and `spread = 0` is the uniform
//! dissolve. Procedural patterns compute `g`; a timing matte paints it.

/// The largest `spread`: at 1 the first point would finish before the last began.
pub const MAX_SPREAD: f64 = 0.99;

/// The rate of a point whose turn is `g` at progress `t`:
/// `clamp((t − spread · g) / (1 − spread), 0, 1)`, exactly 0 at `t = 0`
/// and 1 at `t = 1`.
pub fn paced(g: f64, t: f64, spread: f64) -> f64 {
    if t <= 0.0 {
        return 0.0;
    }
    if t >= 1.0 {
        return 1.0;
    }
    let s = spread.clamp(0.0, MAX_SPREAD);
    ((t - s * g) / (1.0 - s)).clamp(0.0, 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pacing_is_the_closed_form_with_exact_ends() {
        assert_eq!(paced(0.7, 0.0, 0.5), 0.0);
        assert_eq!(paced(0.7, 1.0, 0.5), 1.0);
        // s = 0.5, g = 0.2, t = 0.4: (0.4 - 0.1) / 0.5 = 0.6.
        assert!((paced(0.2, 0.4, 0.5) - 0.6).abs() < 1e-12);
        assert_eq!(paced(1.0, 0.4, 0.5), 0.0);
        assert_eq!(paced(0.3, 0.4, 0.0), 0.4);
    }
}
