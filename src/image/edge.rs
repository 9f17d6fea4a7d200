//! What a sampler reads past the edges of its source.

use crate::choice::Choice;

/// What lies outside the source image.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum EdgeMode {
    /// Transparent black.
    Black,
    /// The nearest edge pixel (no black borders: the default).
    #[default]
    Clamp,
    /// The image reflected about its edges.
    Mirror,
}

impl Choice for EdgeMode {
    /// In the order the nodes' Edge param has always listed them.
    const ALL: &'static [Self] = &[EdgeMode::Clamp, EdgeMode::Black, EdgeMode::Mirror];
    fn name(self) -> &'static str {
        match self {
            EdgeMode::Black => "black",
            EdgeMode::Clamp => "clamp",
            EdgeMode::Mirror => "mirror",
        }
    }
}

impl EdgeMode {
    /// The in-bounds index `k` reads from, for an axis `[lo, hi)`.
    #[inline]
    pub(crate) fn resolve(self, k: i32, lo: i32, hi: i32) -> Option<i32> {
        if k >= lo && k < hi {
            return Some(k);
        }
        match self {
            EdgeMode::Black => None,
            EdgeMode::Clamp => Some(k.clamp(lo, hi - 1)),
            EdgeMode::Mirror => {
                let n = hi - lo;
                let m = (k - lo).rem_euclid(2 * n);
                Some(lo + if m < n { m } else { 2 * n - 1 - m })
            }
        }
    }

    /// [`Self::resolve`] as an index to read, always inside `[lo, hi)`
    /// (which must not be empty), and whether the tap counts (`false`
    /// where `resolve` drops it): for black and clamp with no branch,
    /// as an edge pixel's taps fall either side of the edge.
    #[inline(always)]
    pub(crate) fn read(self, k: i32, lo: i32, hi: i32) -> (i32, bool) {
        let clamped = k.max(lo).min(hi - 1);
        match self {
            EdgeMode::Black => (clamped, clamped == k),
            EdgeMode::Clamp => (clamped, true),
            EdgeMode::Mirror => (self.resolve(k, lo, hi).unwrap_or(clamped), true),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn edge_modes_resolve_indices() {
        assert_eq!(EdgeMode::Black.resolve(-1, 0, 4), None);
        assert_eq!(EdgeMode::Clamp.resolve(-3, 0, 4), Some(0));
        assert_eq!(EdgeMode::Clamp.resolve(9, 0, 4), Some(3));
        // Mirror: ... 1 0 | 0 1 2 3 | 3 2 ...
        assert_eq!(EdgeMode::Mirror.resolve(-1, 0, 4), Some(0));
        assert_eq!(EdgeMode::Mirror.resolve(-2, 0, 4), Some(1));
        assert_eq!(EdgeMode::Mirror.resolve(4, 0, 4), Some(3));
        assert_eq!(EdgeMode::Mirror.resolve(5, 0, 4), Some(2));
        assert_eq!(EdgeMode::Mirror.resolve(5, 2, 6), Some(5));
    }

    /// `read` is `resolve` with a readable index where it drops the tap.
    #[test]
    fn edge_modes_read_what_they_resolve() {
        for mode in [EdgeMode::Black, EdgeMode::Clamp, EdgeMode::Mirror] {
            for (lo, hi) in [(0, 1), (0, 4), (-3, 5)] {
                for k in -20..20 {
                    let (at, counts) = mode.read(k, lo, hi);
                    assert!((lo..hi).contains(&at), "{mode:?} {k} in [{lo}, {hi}): {at}");
                    match mode.resolve(k, lo, hi) {
                        Some(r) => assert_eq!((at, counts), (r, true), "{mode:?} {k}"),
                        None => assert!(!counts, "{mode:?} {k}"),
                    }
                }
            }
        }
    }
}
