//! Numbers of the scene format checked against their ranges.

use crate::error::{Error, Result};

/// `v` (`default` when absent) if it lies in `range` (NaN never does), else
/// the error that names `at` and the range.
pub(super) fn in_range<T: PartialOrd + Copy + std::fmt::Display>(
    v: Option<T>,
    default: T,
    range: std::ops::RangeInclusive<T>,
    at: &str,
) -> Result<T> {
    match v {
        None => Ok(default),
        Some(x) if range.contains(&x) => Ok(x),
        Some(x) => Err(Error::scene(
            at,
            format!("{x} is out of range: {} to {}", range.start(), range.end()),
        )),
    }
}
