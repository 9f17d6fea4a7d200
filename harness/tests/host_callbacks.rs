//! A panic inside one of our host's callbacks (our bug, or an assertion on
//! what the plugin sent) is caught in the callback: the plugin gets a
//! failure status and handles it, nothing unwinds through its C frames, and
//! the process goes on (an unwind out of an `extern "C"` function would
//! abort it).

use std::sync::Arc;

mod common;

use morphfx::geom::{RectI, Vec2};
use morphfx::image::Image;
use morphfx_harness::host::guard::panic_in;
use morphfx_harness::host::{take_violations, Frame, OutputSpec};

use common::{bundle, Still};

#[test]
fn a_panicking_callback_is_a_failure_status_and_the_render_after_it_works() {
    let inst = bundle()
        .instance("net.morphfx.Warp", "OfxImageEffectContextFilter")
        .unwrap();
    let img = Image::from_fn(RectI::from_size(32, 24), 4, |i, j, c| {
        (i + j + c as i32) as f32 * 0.01
    });
    let frame = Arc::new(Frame::from_image(&img, "OfxBitDepthFloat", false));
    inst.connect("Source", Arc::new(Still(frame))).unwrap();
    inst.set_project(32.0, 24.0);
    inst.set_int("line_count", 1).unwrap();
    let (p, q) = (Vec2::new(4.0, 4.0), Vec2::new(20.0, 6.0));
    for (id, v) in [("a_start", p), ("a_end", q), ("b_start", p), ("b_end", q)] {
        inst.set_double(&format!("line1_{id}"), &[v.x, v.y], None)
            .unwrap();
    }
    take_violations();
    for callback in ["clip_get_image", "get_double", "mfx_param_get"] {
        panic_in(Some(callback));
        let failed = inst.render(0.0, OutputSpec::default());
        panic_in(None);
        let seen = take_violations();
        assert!(
            seen.iter()
                .any(|v| v.contains(&format!("host callback {callback} panicked"))),
            "{callback}: {seen:?}"
        );
        // Without its source image the render fails, with a status (a
        // failed property or param read the plugin may survive); the next
        // render, with nothing armed, is whole.
        if callback == "clip_get_image" {
            assert!(failed.is_err(), "a render without its source succeeded");
        }
        let out = inst.render(0.0, OutputSpec::default()).unwrap();
        assert_eq!(
            out.to_image().bounds,
            RectI::from_size(32, 24),
            "{callback}"
        );
    }
}
