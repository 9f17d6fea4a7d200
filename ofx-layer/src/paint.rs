//! What an overlay draws through, whatever the host offers: the [`Painter`]
//! calls, which the Draw suite (`draw.rs`) and OpenGL (`gl.rs`) each carry
//! out. Points are canonical coordinates; widths and label sizes are screen
//! pixels.

use morphfx::geom::Vec2;

/// Line patterns the overlay uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stipple {
    /// Unbroken.
    Solid,
    /// Dashes: the in-between lines.
    Dash,
}

/// Where the overlay's drawing goes. Points are canonical coordinates.
pub trait Painter {
    /// Colour (straight RGBA) of what follows.
    fn colour(&mut self, rgba: [f32; 4]);
    /// Line width in screen pixels of what follows.
    fn width(&mut self, px: f32);
    /// Line pattern of what follows.
    fn stipple(&mut self, stipple: Stipple);
    /// Separate segments: points in pairs.
    fn lines(&mut self, points: &[Vec2]);
    /// One connected polyline.
    fn strip(&mut self, points: &[Vec2]);
    /// A label whose baseline starts at `at`.
    fn text(&mut self, at: Vec2, text: &str);
}

/// A label's cap height in screen pixels, for painters that draw text
/// themselves (OpenGL has none).
pub const LABEL_PX: f64 = 10.0;
