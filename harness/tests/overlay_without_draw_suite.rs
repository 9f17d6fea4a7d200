//! The overlay in a host with overlays but no Draw suite, and no OpenGL
//! context on the calling thread (a process of its own: the plugin keeps
//! one host's suites). Draw must return without drawing or crashing, and
//! the pen must still edit.

mod common;

use morphfx_harness::host::overlay::Overlay;
use morphfx_harness::host::{take_violations, Bundle, HostOptions};

#[test]
fn without_a_draw_suite_or_gl_context_draw_is_a_no_op_and_editing_works() {
    let options = HostOptions {
        overlays: true,
        draw_suite: false,
        multi_plane: false,
    };
    let bundle = Bundle::load_with(&common::bundle_path(), options).unwrap();
    let inst = bundle
        .instance("net.morphfx.Warp", "OfxImageEffectContextFilter")
        .unwrap();
    // No V2 entry: this host offers no Draw suite.
    let v2 = inst
        .descriptor_props()
        .get("OfxImageEffectPluginPropOverlayInteractV2");
    assert!(v2.is_none(), "{v2:?}");
    inst.set_int("line_count", 1).unwrap();
    inst.set_double("line1_a_start", &[10.0, 10.0], None)
        .unwrap();
    inst.set_double("line1_a_end", &[90.0, 10.0], None).unwrap();
    let ov = Overlay::new(&inst, false).unwrap().expect("a V1 overlay");
    assert_eq!(ov.draw(0.0, (1.0, 1.0)).unwrap(), []);
    ov.drag(0.0, (90.0, 10.0), (95.0, 40.0), (1.0, 1.0))
        .unwrap();
    assert_eq!(inst.doubles_at("line1_a_end", 0.0).unwrap(), [95.0, 40.0]);
    assert!(take_violations().is_empty());
}
