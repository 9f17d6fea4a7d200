//! `morphfx bench --drag`: what a compositor feels while dragging a line —
//! the render after one of 100 lines moves, through the bundle in this
//! process, at full size and at proxy scale, beside the render of the same
//! frame when nothing moved (the cached warps: the morph frame alone).

use std::sync::Arc;
use std::time::Instant;

use morphfx::geom::RectI;
use morphfx::image::Image;

use crate::commands::job::MORPH_ID;
use crate::host::{Bundle, Frame, FrameSource, HostError, OutputSpec};

/// Lines in the scene: a face's worth and more.
const LINES: usize = 100;

struct Still(Arc<Frame>);

impl FrameSource for Still {
    fn frame(&self, _: f64) -> Result<Arc<Frame>, String> {
        Ok(self.0.clone())
    }
}

/// A scene of [`LINES`] lines over a `w` × `h` frame, line 0's A end
/// shifted `dx` pixels right (the line being dragged).
fn scene((w, h): (usize, usize), dx: f64) -> String {
    // The same lines every call: a fixed xorshift sequence.
    let mut seed = 0x9e37_79b9_7f4a_7c15u64;
    let mut next = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut range = |lo: f64, hi: f64| lo + (hi - lo) * next();
    let (w, h) = (w as f64, h as f64);
    let lines: Vec<serde_json::Value> = (0..LINES)
        .map(|k| {
            let (x, y) = (range(0.05 * w, 0.95 * w), range(0.05 * h, 0.95 * h));
            let (len, angle) = (range(0.02 * w, 0.15 * w), range(0.0, std::f64::consts::TAU));
            let q = [x + len * angle.cos(), y + len * angle.sin()];
            let d = [range(-0.01 * w, 0.01 * w), range(-0.01 * w, 0.01 * w)];
            let shift = if k == 0 { dx } else { 0.0 };
            serde_json::json!({
                "type": "line",
                "a": [[x, y], [q[0] + shift, q[1]]],
                "b": [[x + d[0], y + d[1]], [q[0] + d[0], q[1] + d[1]]]
            })
        })
        .collect();
    serde_json::json!({"format": "morphfx-scene", "version": 1, "method": "field", "features": lines})
        .to_string()
}

fn plate((w, h): (usize, usize), seed: f32) -> Image {
    Image::from_fn(RectI::from_size(w, h), 4, |i, j, c| {
        if c == 3 {
            1.0
        } else {
            let (x, y) = (i as f32, j as f32);
            0.5 + 0.4 * ((x * 0.013 + seed) * (c as f32 + 1.0)).sin() * (y * 0.021).cos()
        }
    })
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Drags line 0 of the scene's lines by a pixel per render, `moves` times, at each
/// render scale, and prints the median render (and the slowest) beside the
/// unchanged one.
pub fn drag(
    bundle_path: &std::path::Path,
    size: (usize, usize),
    moves: usize,
) -> Result<(), HostError> {
    if moves == 0 || size.0 < 16 || size.1 < 16 {
        return Err(HostError::bad(
            "bench --drag needs at least 1 move of a 16x16 frame",
        ));
    }
    let bundle = Bundle::load(bundle_path)?;
    let inst = bundle.instance(MORPH_ID, "OfxImageEffectContextGeneral")?;
    for (clip, seed) in [("SourceA", 0.0), ("SourceB", 2.1)] {
        let frame = Frame::from_image(&plate(size, seed), "OfxBitDepthFloat", false);
        inst.connect(clip, Arc::new(Still(Arc::new(frame))))?;
    }
    inst.set_project(size.0 as f64, size.1 as f64);
    inst.set_double("progress", &[0.5], None)?;
    inst.clip_preferences()?;
    let mut step = 0.0;
    eprintln!(
        "drag: one of {LINES} lines moved a pixel before each render, \
            {}x{} RGBA float, field method (adaptive), median of {moves}; \
            the bundle's {} ran",
        size.0,
        size.1,
        inst.build_that_ran()
    );
    for scale in [1.0, 0.5] {
        let spec = OutputSpec {
            render_scale: (scale, scale),
            identity: false,
            // A viewer's render while the line is dragged.
            interactive: true,
            ..OutputSpec::default()
        };
        let time = |f: &mut dyn FnMut() -> Result<(), HostError>| -> Result<f64, HostError> {
            let started = Instant::now();
            f()?;
            Ok(started.elapsed().as_secs_f64() * 1000.0)
        };
        inst.set_string("scene_text", &scene(size, step))?;
        inst.render(1.0, spec)?;
        let mut moved = Vec::new();
        let mut still = Vec::new();
        for _ in 0..moves {
            step += 1.0;
            // The scene's text is the host's (a param it holds), not part
            // of what the plugin does after the move: made before the clock.
            let text = scene(size, step);
            // Each frame is handed back, as a viewer reuses its buffers.
            moved.push(time(&mut || {
                inst.set_string("scene_text", &text)?;
                inst.render(1.0, spec).map(|f| inst.recycle(f))
            })?);
            still.push(time(&mut || {
                inst.render(1.0, spec).map(|f| inst.recycle(f))
            })?);
        }
        // What a compositor feels is every render of the drag: the
        // slowest beside the median.
        let slowest = moved.iter().copied().fold(0.0, f64::max);
        let (m, s) = (median(moved), median(still));
        eprintln!(
            "render scale {scale}: {m:.1} ms after a move (slowest {slowest:.1}); \
                {s:.1} ms with nothing moved (the morph frame alone, cached warps): {:.2}x",
            m / s.max(1e-9)
        );
    }
    Ok(())
}
