//! Hosts that send what the spec does not allow get a failure status and a
//! message, never a crash: here, render windows no machine could hold.

use std::sync::Arc;

mod common;

use morphfx::geom::RectI;
use morphfx::image::Image;
use morphfx_harness::host::{Frame, OutputSpec};

use common::{bundle, Still};

#[test]
fn a_render_window_beyond_any_machine_is_refused_before_any_allocation() {
    let inst = bundle()
        .instance("net.morphfx.Warp", "OfxImageEffectContextFilter")
        .unwrap();
    let img = Image::from_fn(RectI::from_size(32, 24), 4, |_, _, _| 0.5);
    let frame = Arc::new(Frame::from_image(&img, "OfxBitDepthFloat", false));
    inst.connect("Source", Arc::new(Still(frame))).unwrap();
    inst.set_project(32.0, 24.0);
    inst.set_int("line_count", 1).unwrap();
    for (id, v) in [
        ("a_start", [4.0, 4.0]),
        ("a_end", [20.0, 6.0]),
        ("b_start", [5.0, 4.0]),
        ("b_end", [21.0, 7.0]),
    ] {
        inst.set_double(&format!("line1_{id}"), &v, None).unwrap();
    }
    for window in [
        RectI::new(0, 0, 200_000, 200_000),
        RectI::new(i32::MIN, i32::MIN, i32::MAX, i32::MAX),
    ] {
        let spec = OutputSpec {
            identity: false,
            window: Some(window),
            ..OutputSpec::default()
        };
        let err = inst.render(0.0, spec).expect_err("refused");
        assert!(
            err.message.contains("render window") && err.message.contains("limit"),
            "{window:?}: {}",
            err.message
        );
    }
    // The instance is unharmed: a proper render still works.
    inst.render(0.0, OutputSpec::default()).unwrap();
}
