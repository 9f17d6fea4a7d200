//! Generated content with known properties, shared by this project's tests
//! and benchmarks (the core's, the harness's and the bundle's).

use crate::geom::Vec2;

/// A smooth colour field with texture everywhere (no flat region), values in
/// [0, 1]: what `auto` needs to find a warp, and what 8-bit plates can hold.
/// Canonical pixel position in, RGB out.
pub fn texture(p: Vec2) -> [f32; 3] {
    let (x, y) = (p.x, p.y);
    [
        (0.5 + 0.25 * (x / 7.0).sin() * (y / 9.0).cos() + 0.2 * ((x + y) / 13.0).sin()) as f32,
        (0.5 + 0.3 * ((x - 0.5 * y) / 11.0).cos() + 0.15 * (y / 5.0).sin()) as f32,
        (0.4 + 0.3 * ((x * x + y * y).sqrt() / 8.0).sin()) as f32,
    ]
}
