//! The Catmull-Rom (a = −0.5) filter's weights, shared by the general
//! sampler and the direct float RGBA path.

use wide::f32x8;

/// [`catmull_rom_weights`] for eight fractions at once.
#[inline(always)]
pub(crate) fn catmull_rom_weights8(t: f32x8) -> [f32x8; 4] {
    let h = f32x8::splat(0.5);
    let c = f32x8::splat;
    let t2 = t * t;
    let t3 = t2 * t;
    [
        h * (-t3 + c(2.0) * t2 - t),
        h * (c(3.0) * t3 - c(5.0) * t2 + c(2.0)),
        h * (c(-3.0) * t3 + c(4.0) * t2 + t),
        h * (t3 - t2),
    ]
}

/// Catmull-Rom weights for taps at offsets −1, 0, 1, 2 from the fraction `t`.
#[inline]
pub(crate) fn catmull_rom_weights(t: f32) -> [f32; 4] {
    let t2 = t * t;
    let t3 = t2 * t;
    [
        0.5 * (-t3 + 2.0 * t2 - t),
        0.5 * (3.0 * t3 - 5.0 * t2 + 2.0),
        0.5 * (-3.0 * t3 + 4.0 * t2 + t),
        0.5 * (t3 - t2),
    ]
}
