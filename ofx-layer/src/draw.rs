//! The overlay's painter on the OFX 1.5 Draw suite.

use std::ffi::CString;

use morphfx::geom::Vec2;
use openfx::sys::generic::core::OfxPointD;
use openfx::sys::image_effect_v1::draw_suite::*;
use openfx::sys::image_effect_v1::pixels::OfxRGBAColourF;

use super::paint::{Painter, Stipple};

/// Draws through the host's Draw suite into one draw action's context.
pub struct DrawSuitePainter {
    suite: &'static OfxDrawSuiteV1,
    context: OfxDrawContextHandle,
    points: Vec<OfxPointD>,
}

impl DrawSuitePainter {
    /// A painter on `context`.
    ///
    /// # Safety
    /// `context` must be the draw context of the draw action now running,
    /// and the painter must not outlive that action.
    pub unsafe fn new(suite: &'static OfxDrawSuiteV1, context: OfxDrawContextHandle) -> Self {
        DrawSuitePainter {
            suite,
            context,
            points: Vec::new(),
        }
    }

    fn draw(&mut self, primitive: OfxDrawPrimitive, points: &[Vec2]) {
        let Some(draw) = self.suite.draw else { return };
        self.points.clear();
        self.points
            .extend(points.iter().map(|p| OfxPointD { x: p.x, y: p.y }));
        let Ok(n) = i32::try_from(self.points.len()) else {
            return;
        };
        // SAFETY: the live draw context (constructor's contract) and `n`
        // points in our own buffer.
        unsafe { draw(self.context, primitive, self.points.as_ptr(), n) };
    }
}

impl Painter for DrawSuitePainter {
    fn colour(&mut self, [r, g, b, a]: [f32; 4]) {
        if let Some(set) = self.suite.setColour {
            let c = OfxRGBAColourF { r, g, b, a };
            // SAFETY: the live draw context and a colour on our stack.
            unsafe { set(self.context, &c) };
        }
    }

    fn width(&mut self, px: f32) {
        if let Some(set) = self.suite.setLineWidth {
            // SAFETY: the live draw context.
            unsafe { set(self.context, px) };
        }
    }

    fn stipple(&mut self, stipple: Stipple) {
        if let Some(set) = self.suite.setLineStipple {
            let pattern = match stipple {
                Stipple::Solid => kOfxDrawLineStipplePatternSolid,
                Stipple::Dash => kOfxDrawLineStipplePatternDash,
            };
            // SAFETY: the live draw context.
            unsafe { set(self.context, pattern) };
        }
    }

    fn lines(&mut self, points: &[Vec2]) {
        self.draw(kOfxDrawPrimitiveLines, points);
    }

    fn strip(&mut self, points: &[Vec2]) {
        self.draw(kOfxDrawPrimitiveLineStrip, points);
    }

    fn text(&mut self, at: Vec2, text: &str) {
        let (Some(draw_text), Ok(text)) = (self.suite.drawText, CString::new(text)) else {
            return;
        };
        let pos = OfxPointD { x: at.x, y: at.y };
        let align = (kOfxDrawTextAlignmentLeft | kOfxDrawTextAlignmentBaseline) as i32;
        // SAFETY: the live draw context, a NUL-terminated string and a
        // point on our stack.
        unsafe { draw_text(self.context, text.as_ptr(), &pos, align) };
    }
}
