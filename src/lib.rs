//! MorphFX core: everything a morph needs, with no knowledge of hosts or FFI.
//!
//! Data flows one way, and modules form layers (docs/architecture.md):
//! scene → [`features`] at time → warp generator ([`warp`]) → warp field
//! → resampling ([`image`]) → dissolve ([`morph`]).
//!
//! Coordinates are canonical pixel coordinates of the full-resolution image:
//! x right, **y up**, origin at the bottom-left corner, pixel `(i, j)` centred
//! at `(i + 0.5, j + 0.5)` (docs/coordinates.md).
#![forbid(unsafe_code)]
// Every public item says what it is: the core is the API the plugin and
// the harness are written against.
#![deny(missing_docs)]

pub mod bspline;
pub mod choice;
pub mod error;
pub mod features;
pub mod geom;
pub mod image;
pub mod make_warp;
pub mod morph;
mod prefetch;
pub mod scene;
pub mod shutter;
pub mod snake;
pub mod strokes;
pub mod suggest;
#[cfg(any(test, feature = "testing"))]
pub mod testing;
pub mod track;
pub mod transition;
pub mod views;
pub mod warp;

pub use error::{Error, Result};
pub use geom::Vec2;
