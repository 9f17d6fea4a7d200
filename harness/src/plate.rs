//! A plate as the harness holds it, and the sample layouts writers share.

use morphfx::image::Image;

/// A plate: pixels in canonical coordinates (bottom-up) plus the frame it sits in.
#[derive(Debug, Clone, PartialEq)]
pub struct Plate {
    pub image: Image,
    /// Width and height of the display window (the canonical frame).
    pub size: (usize, usize),
    /// Where the display window's top-left corner lies in the file's own
    /// pixel coordinates (EXR: y grows downwards); 0,0 but in EXRs that say
    /// otherwise. Canonical coordinates start at the window's bottom-left
    /// whatever this is, so it only travels from input to output.
    pub origin: (i32, i32),
}

impl Plate {
    /// A plate whose display window starts at the file's origin.
    pub fn new(image: Image, size: (usize, usize)) -> Plate {
        Plate {
            image,
            size,
            origin: (0, 0),
        }
    }
}

/// Output sample type of EXR files.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ExrPrecision {
    #[default]
    Float,
    Half,
}

/// A pixel of 1 to 4 channels as RGBA, the way every writer stores it: one
/// channel in all four, grey and alpha, RGB opaque.
pub(crate) fn rgba(px: &[f32]) -> [f32; 4] {
    match *px {
        [v] => [v; 4],
        [g, a] => [g, g, g, a],
        [r, g, b] => [r, g, b, 1.0],
        [r, g, b, a, ..] => [r, g, b, a],
        [] => [0.0; 4],
    }
}
