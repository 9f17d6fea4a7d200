//! Dragging a line in a viewer: interactive renders after each move redo
//! the `field` maps from the last ones (through the plugin and its caches),
//! stay within the adaptive tolerance of the exact map, and leave every other
//! render (on demand or in sequence) exactly what a fresh instance makes.

use std::sync::Arc;

mod common;

use morphfx::geom::RectI;
use morphfx::image::Image;
use morphfx::testing::Lcg;
use morphfx_harness::host::{Frame, Instance, OutputSpec};

use common::{bundle, Still};

const W: usize = 320;
const H: usize = 180;
/// The adaptive evaluation's default tolerance, output pixels.
const TOLERANCE: f64 = 0.05;

/// 24 lines over the frame, line 0's A start moved `dx` pixels right.
fn scene(dx: f64, evaluation: &str) -> String {
    let mut lcg = Lcg::new(24);
    let mut next = move || lcg.unit();
    let lines: Vec<serde_json::Value> = (0..24)
        .map(|k| {
            let (x, y) = (20.0 + 280.0 * next(), 15.0 + 150.0 * next());
            let (len, angle) = (15.0 + 40.0 * next(), std::f64::consts::TAU * next());
            let q = [x + len * angle.cos(), y + len * angle.sin()];
            let d = [6.0 * next() - 3.0, 6.0 * next() - 3.0];
            let shift = if k == 0 { dx } else { 0.0 };
            serde_json::json!({
                "type": "line",
                "a": [[x + shift, y], q],
                "b": [[x + d[0], y + d[1]], [q[0] + d[0], q[1] + d[1]]]
            })
        })
        .collect();
    serde_json::json!({
        "format": "morphfx-scene", "version": 1, "method": "field",
        "field": {"evaluation": evaluation}, "features": lines
    })
    .to_string()
}

fn plate(seed: f32) -> Arc<Still> {
    let img = Image::from_fn(RectI::from_size(W, H), 4, |i, j, c| {
        let (x, y) = (i as f32, j as f32);
        0.5 + 0.4 * ((x * 0.05 + seed) * (c as f32 + 1.0)).sin() * (y * 0.07).cos()
    });
    Arc::new(Still(Arc::new(Frame::from_image(
        &img,
        "OfxBitDepthFloat",
        false,
    ))))
}

fn instance(view: &str) -> Instance<'static> {
    let inst = bundle()
        .instance("net.morphfx.Morph", "OfxImageEffectContextGeneral")
        .unwrap();
    inst.connect("SourceA", plate(0.0)).unwrap();
    inst.connect("SourceB", plate(2.1)).unwrap();
    inst.set_project(W as f64, H as f64);
    inst.set_double("progress", &[0.5], None).unwrap();
    inst.set_choice("view", view).unwrap();
    inst
}

/// How a host asks for a render.
#[derive(Clone, Copy, Debug)]
enum Render {
    /// For a viewer while the instance is manipulated (interactive).
    Viewer,
    /// Neither interactive nor in sequence: a host's frame on demand.
    Plain,
    /// Frame after frame in order, to disk.
    Sequence,
}

fn render(inst: &Instance<'_>, text: &str, how: Render) -> Image {
    inst.set_string("scene_text", text).unwrap();
    let spec = OutputSpec {
        identity: false,
        interactive: matches!(how, Render::Viewer),
        sequential: matches!(how, Render::Sequence),
        ..OutputSpec::default()
    };
    inst.render(1.0, spec).unwrap().to_image()
}

/// The largest distance between two ST maps' positions, in pixels.
fn worst_px(a: &Image, b: &Image) -> f64 {
    let mut worst = 0.0f64;
    for (p, q) in a.data.chunks_exact(4).zip(b.data.chunks_exact(4)) {
        let dx = (p[0] - q[0]) as f64 * W as f64;
        let dy = (p[1] - q[1]) as f64 * H as f64;
        worst = worst.max(dx.hypot(dy));
    }
    worst
}

#[test]
fn viewer_renders_while_a_line_is_dragged_stay_within_tolerance_of_the_exact_map() {
    for view in ["stmap-a", "stmap-b"] {
        let viewer = instance(view);
        let exact = instance(view);
        let fresh = instance(view);
        render(&viewer, &scene(0.0, "adaptive"), Render::Viewer);
        for step in 1..=3 {
            let dx = 1.5 * step as f64;
            let dragged = render(&viewer, &scene(dx, "adaptive"), Render::Viewer);
            let truth = render(&exact, &scene(dx, "exact"), Render::Plain);
            let err = worst_px(&dragged, &truth);
            assert!(
                err <= TOLERANCE,
                "{view}, drag {step}: {err} px from the exact map"
            );
            // A fresh adaptive map rounds differently: the viewer's was redone.
            let made_afresh = render(&fresh, &scene(dx, "adaptive"), Render::Plain);
            assert_ne!(dragged.data, made_afresh.data, "{view}, drag {step}");
        }
    }
}

#[test]
fn other_renders_do_not_depend_on_what_a_viewer_rendered_before() {
    for how in [Render::Plain, Render::Sequence] {
        let viewer = instance("morph");
        for step in 0..3 {
            render(
                &viewer,
                &scene(2.0 * step as f64, "adaptive"),
                Render::Viewer,
            );
        }
        let text = scene(6.0, "adaptive");
        let after_drags = render(&viewer, &text, how);
        let fresh = render(&instance("morph"), &text, how);
        assert_eq!(after_drags.data, fresh.data, "{how:?}");
    }
}
