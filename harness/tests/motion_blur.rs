//! Motion blur through the C ABI: a blurred frame is the mean of the node
//! rendered at the sample times; blur off, or a still scene, renders
//! exactly as before.

mod common;

use std::sync::Arc;

use common::{bundle, Still};
use morphfx::geom::RectI;
use morphfx::image::Image;
use morphfx_harness::host::{self, Frame, OutputSpec};

const W: usize = 64;
const H: usize = 48;

fn plate() -> Image {
    Image::from_fn(RectI::from_size(W, H), 4, |i, j, c| {
        if c == 3 {
            1.0
        } else {
            0.5 + 0.4 * (i as f32 * 0.31 + j as f32 * 0.17 + c as f32).sin()
        }
    })
}

/// A Warp node on the plate, line 1's B end keyed to swing from frame 0
/// to frame 10 (the warp moves), or left still.
fn warp(moving: bool) -> host::Instance<'static> {
    let inst = bundle()
        .instance("net.morphfx.Warp", "OfxImageEffectContextFilter")
        .unwrap();
    inst.set_project(W as f64, H as f64);
    let frame = Frame::from_image(&plate(), "OfxBitDepthFloat", false);
    inst.connect("Source", Arc::new(Still(Arc::new(frame))))
        .unwrap();
    inst.set_int("line_count", 1).unwrap();
    for (id, xy) in [
        ("line1_a_start", [10.0, 10.0]),
        ("line1_a_end", [50.0, 14.0]),
        ("line1_b_start", [16.0, 6.0]),
    ] {
        inst.set_double(id, &xy, None).unwrap();
    }
    if moving {
        inst.set_double("line1_b_end", &[40.0, 10.0], Some(0.0))
            .unwrap();
        inst.set_double("line1_b_end", &[56.0, 30.0], Some(10.0))
            .unwrap();
    } else {
        inst.set_double("line1_b_end", &[55.0, 20.0], None).unwrap();
    }
    inst.set_double("progress", &[1.0], None).unwrap();
    inst
}

fn render(inst: &host::Instance<'_>, time: f64) -> Image {
    let spec = OutputSpec {
        depth: "OfxBitDepthFloat",
        identity: false,
        ..OutputSpec::default()
    };
    inst.render(time, spec).unwrap().to_image()
}

/// Four samples over a one-frame shutter centred on frame 5: the mean of
/// the node rendered, unblurred, at 4.625, 4.875, 5.125 and 5.375 (the
/// midpoints of the shutter's quarters), within 1e-5.
#[test]
fn a_blurred_frame_is_the_mean_of_renders_at_the_sample_times() {
    let inst = warp(true);
    let singles: Vec<Image> = [4.625, 4.875, 5.125, 5.375]
        .iter()
        .map(|t| render(&inst, *t))
        .collect();
    inst.set_int("motion_blur", 4).unwrap();
    inst.set_double("shutter", &[1.0], None).unwrap();
    let blurred = render(&inst, 5.0);
    let mut worst: f32 = 0.0;
    let mut moved: f32 = 0.0;
    for (k, v) in blurred.data.iter().enumerate() {
        let mean = singles.iter().map(|s| s.data[k]).sum::<f32>() / 4.0;
        worst = worst.max((v - mean).abs());
        moved = moved.max((singles[0].data[k] - singles[3].data[k]).abs());
    }
    assert!(worst <= 1e-5, "{worst} from the mean of the samples");
    assert!(
        moved > 0.05,
        "the samples differ ({moved}): there is motion to blur"
    );
    // Start and end shutters sample after and before the frame.
    inst.set_choice("shutter_offset", "end").unwrap();
    let end = render(&inst, 5.0);
    let earlier: Vec<Image> = [4.125, 4.375, 4.625, 4.875]
        .iter()
        .map(|t| {
            inst.set_int("motion_blur", 0).unwrap();
            let one = render(&inst, *t);
            inst.set_int("motion_blur", 4).unwrap();
            one
        })
        .collect();
    let worst = end
        .data
        .iter()
        .enumerate()
        .map(|(k, v)| (v - earlier.iter().map(|s| s.data[k]).sum::<f32>() / 4.0).abs())
        .fold(0.0f32, f32::max);
    assert!(
        worst <= 1e-5,
        "an end shutter {worst} from its samples' mean"
    );
}

/// Blur off, or a scene that does not move within the shutter: the frame
/// as it renders without blur, bit for bit; and an ST map is never
/// blurred.
#[test]
fn without_blur_or_motion_a_frame_renders_as_before() {
    for moving in [true, false] {
        let inst = warp(moving);
        let plain = render(&inst, 5.0);
        inst.set_double("shutter", &[1.0], None).unwrap();
        assert_eq!(render(&inst, 5.0).data, plain.data, "motion blur 0");
        if !moving {
            inst.set_int("motion_blur", 8).unwrap();
            assert_eq!(render(&inst, 5.0).data, plain.data, "a still scene");
        }
    }
    // A view that is not a picture is never blurred: the ST map of the
    // moving warp with blur on is the frame's own.
    let inst = warp(true);
    inst.set_choice("view", "stmap").unwrap();
    let plain = render(&inst, 5.0);
    inst.set_int("motion_blur", 4).unwrap();
    inst.set_double("shutter", &[1.0], None).unwrap();
    assert_eq!(render(&inst, 5.0).data, plain.data, "the ST map view");
}

/// A frame is an identity of its source only where every sample is: with
/// progress keyed from 0 at frame 5 to 1 at frame 6, frame 5 is the
/// source unblurred, but not with a centred shutter (its later samples
/// are warped).
#[test]
fn a_blurred_frame_is_an_identity_only_when_every_sample_is() {
    let inst = warp(true);
    inst.set_double("progress", &[0.0], Some(5.0)).unwrap();
    inst.set_double("progress", &[1.0], Some(6.0)).unwrap();
    let window = RectI::from_size(W, H);
    assert_eq!(
        inst.identity(5.0, window, (1.0, 1.0)).unwrap(),
        Some(("Source".to_string(), 5.0))
    );
    inst.set_int("motion_blur", 4).unwrap();
    assert_eq!(inst.identity(5.0, window, (1.0, 1.0)).unwrap(), None);
    // An end shutter closes at frame 5: every sample is before it, at
    // progress 0 (the first key holds).
    inst.set_choice("shutter_offset", "end").unwrap();
    assert_eq!(
        inst.identity(5.0, window, (1.0, 1.0)).unwrap(),
        Some(("Source".to_string(), 5.0))
    );
}
