//! The warp's motion through the C ABI. Motion blur: a blurred frame is
//! the mean of the node rendered at the sample times; blur off, or a still
//! scene, renders exactly as before. Motion vectors: what the ST maps of
//! this frame and the next say, inverted numerically here.

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

/// Bilinear sample of an ST map's source position (canonical: the map's
/// normalised red and green times the plate's size) at canonical `p`.
fn source_at(st: &Image, p: [f64; 2]) -> [f64; 2] {
    let (u, v) = (p[0] - 0.5, p[1] - 0.5);
    let (i, j) = (u.floor() as i32, v.floor() as i32);
    let (fx, fy) = (u - u.floor(), v - v.floor());
    let at = |i: i32, j: i32, c: usize| {
        let (i, j) = (i.clamp(0, W as i32 - 1), j.clamp(0, H as i32 - 1));
        st.pixel(i, j)[c] as f64
    };
    let lerp = |c: usize| {
        let top = at(i, j, c) * (1.0 - fx) + at(i + 1, j, c) * fx;
        let bottom = at(i, j + 1, c) * (1.0 - fx) + at(i + 1, j + 1, c) * fx;
        top * (1.0 - fy) + bottom * fy
    };
    [lerp(0) * W as f64, lerp(1) * H as f64]
}

/// The point `q` where `st` samples `target`, by Newton on the bilinear
/// map from `start`.
fn where_shown(st: &Image, target: [f64; 2], start: [f64; 2]) -> Option<[f64; 2]> {
    let mut q = start;
    for _ in 0..40 {
        let s = source_at(st, q);
        let e = [target[0] - s[0], target[1] - s[1]];
        if e[0].hypot(e[1]) < 1e-6 {
            return Some(q);
        }
        let h = 0.5;
        let d = |dx: f64, dy: f64| {
            let (a, b) = (
                source_at(st, [q[0] + dx, q[1] + dy]),
                source_at(st, [q[0] - dx, q[1] - dy]),
            );
            [(a[0] - b[0]) / (2.0 * h), (a[1] - b[1]) / (2.0 * h)]
        };
        let (jx, jy) = (d(h, 0.0), d(0.0, h));
        let det = jx[0] * jy[1] - jx[1] * jy[0];
        q = [
            q[0] + (e[0] * jy[1] - e[1] * jy[0]) / det,
            q[1] + (jx[0] * e[1] - jx[1] * e[0]) / det,
        ];
    }
    None
}

/// The vectors view against the ST maps of frames 4, 5 and 6: where the
/// source point pixel p shows at frame 5 is shown at frames 6 and 4,
/// found by inverting those frames' ST maps here, within 0.05 px, at every
/// pixel away from the plate's edges; and the motion is real (over a
/// pixel somewhere).
#[test]
fn vectors_are_the_motion_the_st_maps_of_the_next_and_previous_frames_say() {
    let inst = warp(true);
    inst.set_choice("view", "stmap").unwrap();
    let [prev, now, next] = [4.0, 5.0, 6.0].map(|t| render(&inst, t));
    inst.set_choice("view", "vectors").unwrap();
    let vectors = render(&inst, 5.0);
    let (mut worst, mut largest, mut found) = (0.0f64, 0.0f64, 0);
    for j in 4..H as i32 - 4 {
        for i in 4..W as i32 - 4 {
            let p = [i as f64 + 0.5, j as f64 + 0.5];
            let source = source_at(&now, p);
            let v = vectors.pixel(i, j);
            for (st, got) in [(&next, [v[0], v[1]]), (&prev, [v[2], v[3]])] {
                let Some(q) = where_shown(st, source, p) else {
                    continue;
                };
                found += 1;
                let want = [q[0] - p[0], q[1] - p[1]];
                let miss = (got[0] as f64 - want[0]).hypot(got[1] as f64 - want[1]);
                worst = worst.max(miss);
                largest = largest.max(want[0].hypot(want[1]));
            }
        }
    }
    eprintln!(
        "vectors: worst {worst:.4} px off the ST maps' motion, largest motion {largest:.2} px"
    );
    assert!(worst <= 0.05, "{worst} px off");
    assert!(largest > 1.0, "largest motion {largest} px");
    let inner = 2 * (W - 8) * (H - 8);
    assert!(
        found * 10 >= inner * 9,
        "{found} of {inner} found in the ST maps"
    );
}
