//! A render through the plugin against the core doing the same work, in
//! the same run: 1080p RGBA float, 100 line pairs, t = 0.5, the field
//! method. The plugin's path adds the host's images, the param reads, the
//! cache and the copies; this says what they cost.
//!
//! The overlay: 60 shapes of 20 points each in Scene Text drawn through
//! the Draw suite, hovered and dragged, against parsing the same text;
//! and 100 lines (all 64 line slots, 36 more in Scene Text), hovered and
//! a slot's line dragged, with the host reads each event makes printed;
//! and a 32 × 32 mesh (method mesh) drawn, hovered and a node dragged.
//!
//! `cargo xtask bundle --release && cargo bench -p morphfx-harness --features bench --bench plugin`

use std::hint::black_box;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion};

use morphfx::features::{Feature, Side};
use morphfx::geom::{PixelScale, RectI, Vec2};
use morphfx::image::{EdgeMode, Filter, Image, Sampler};
use morphfx::make_warp::{toward, MethodSettings, WarpSettings};
use morphfx::morph::{dissolve, Warped};
use morphfx::testing::Lcg;
use morphfx_harness::host::overlay::Overlay;
use morphfx_harness::host::{Bundle, Frame, FrameSource, HostOptions, OutputSpec};
use openfx::sys::image_effect_v1::interact::*;

const W: usize = 1920;
const H: usize = 1080;

fn plate(seed: f32) -> Image {
    Image::from_fn(RectI::from_size(W, H), 4, |i, j, c| {
        if c == 3 {
            1.0
        } else {
            let (x, y) = (i as f32, j as f32);
            0.5 + 0.5 * ((x * 0.05 + seed) * (c as f32 + 1.0)).sin() * (y * 0.031).cos()
        }
    })
}

/// 100 line pairs spread over the frame, each moved and turned a little.
fn lines() -> Vec<Feature> {
    let mut r = Lcg::new(100);
    (0..100)
        .map(|_| {
            let p = Vec2::new(
                r.range(100.0, W as f64 - 100.0),
                r.range(100.0, H as f64 - 100.0),
            );
            let (len, angle) = (r.range(40.0, 300.0), r.range(0.0, std::f64::consts::TAU));
            let q = p + Vec2::new(angle.cos(), angle.sin()) * len;
            let d = Vec2::new(r.range(-20.0, 20.0), r.range(-20.0, 20.0));
            Feature::line([p, q], [p + d, q + d * 0.8])
        })
        .collect()
}

struct Still(Arc<Frame>);

impl FrameSource for Still {
    fn frame(&self, _: f64) -> Result<Arc<Frame>, String> {
        Ok(self.0.clone())
    }
}

fn scene_json(features: &[Feature]) -> String {
    let pts = |v: &[Vec2]| v.iter().map(|p| vec![p.x, p.y]).collect::<Vec<_>>();
    let list: Vec<serde_json::Value> = features
        .iter()
        .map(|f| {
            serde_json::json!({"type": "line", "a": pts(f.points(Side::A)), "b": pts(f.points(Side::B))})
        })
        .collect();
    serde_json::json!({"format": "morphfx-scene", "version": 1, "method": "field", "features": list})
        .to_string()
}

fn bundle_path() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../target/bundle/MorphFX.ofx.bundle")
}

fn bench_plugin_path(c: &mut Criterion) {
    let (a, b) = (plate(0.0), plate(1.3));
    let features = lines();
    let mut g = c.benchmark_group("render_1080p_100_lines_t0.5");
    g.sample_size(10).measurement_time(Duration::from_secs(10));

    // The core: both maps made afresh, then the dissolve.
    let settings = WarpSettings::new(MethodSettings::default());
    let frame = RectI::from_size(W, H);
    let mut out = Image::new(frame, 4);
    g.bench_function("core_maps_and_dissolve", |bch| {
        bch.iter(|| {
            let wa = toward(&features, Side::A, 0.5, &settings).unwrap();
            let wb = toward(&features, Side::B, 0.5, &settings).unwrap();
            let ma = wa.map_window(frame, PixelScale::UNIT);
            let mb = wb.map_window(frame, PixelScale::UNIT);
            let sa = Sampler::new(
                a.view(),
                PixelScale::UNIT,
                Filter::Bilinear,
                EdgeMode::Clamp,
                true,
            );
            let sb = Sampler::new(
                b.view(),
                PixelScale::UNIT,
                Filter::Bilinear,
                EdgeMode::Clamp,
                true,
            );
            dissolve(
                Warped::Map(&sa, &ma),
                Warped::Map(&sb, &mb),
                0.5,
                out.view_mut().rows(),
            );
            black_box(&out);
        })
    });

    // The plugin: the same scene through the C ABI; caches purged before
    // each render, so the maps are made afresh, as for a keyframed shot.
    let bundle = Bundle::load(&bundle_path()).expect("the bundle (cargo xtask bundle --release)");
    let inst = bundle
        .instance("net.morphfx.Morph", "OfxImageEffectContextGeneral")
        .unwrap();
    for (clip, img) in [("SourceA", &a), ("SourceB", &b)] {
        let f = Arc::new(Frame::from_image(img, "OfxBitDepthFloat", false));
        inst.connect(clip, Arc::new(Still(f))).unwrap();
    }
    inst.set_project(W as f64, H as f64);
    inst.set_string("scene_text", &scene_json(&features))
        .unwrap();
    inst.set_double("progress", &[0.5], None).unwrap();
    inst.set_int("use_scene_progress", 0).unwrap();
    inst.clip_preferences().unwrap();
    g.bench_function("plugin_render", |bch| {
        bch.iter(|| {
            inst.purge_caches().unwrap();
            black_box(inst.render(1.0, OutputSpec::default()).unwrap())
        })
    });
    g.finish();
}

/// 60 curves and polylines of 20 points each (every third closed) spread
/// over a 1080p frame, B a little off A.
fn shapes_json() -> String {
    let mut r = Lcg::new(60);
    let shapes: Vec<serde_json::Value> = (0..60)
        .map(|k| {
            let c = Vec2::new(r.range(150.0, W as f64 - 150.0), r.range(150.0, H as f64 - 150.0));
            let radius = r.range(30.0, 120.0);
            let a: Vec<[f64; 2]> = (0..20)
                .map(|i| {
                    let t = std::f64::consts::TAU * i as f64 / 20.0;
                    [c.x + radius * t.cos(), c.y + radius * 0.7 * t.sin()]
                })
                .collect();
            let b: Vec<[f64; 2]> = a.iter().map(|p| [p[0] + 6.0, p[1] - 4.0]).collect();
            let kind = if k % 2 == 0 { "curve" } else { "polyline" };
            serde_json::json!({"name": format!("s{k}"), "type": kind, "closed": k % 3 == 0, "a": a, "b": b})
        })
        .collect();
    serde_json::json!({"format": "morphfx-scene", "version": 1, "features": shapes}).to_string()
}

/// The bundle in a host with overlays and the Draw suite.
fn overlay_bundle() -> Bundle {
    let options = HostOptions {
        overlays: true,
        draw_suite: true,
    };
    Bundle::load_with(&bundle_path(), options).expect("the bundle")
}

/// A Morph instance in a 1080p project.
fn morph_1080p(bundle: &Bundle) -> morphfx_harness::host::Instance<'_> {
    let inst = bundle
        .instance("net.morphfx.Morph", "OfxImageEffectContextGeneral")
        .unwrap();
    inst.set_project(W as f64, H as f64);
    inst
}

fn bench_overlay(c: &mut Criterion) {
    let text = shapes_json();
    // A drag of one control point: each motion edits and writes Scene
    // Text, then the viewer redraws.
    let start = {
        let v: serde_json::Value = serde_json::from_str(&text).unwrap();
        let p = &v["features"][0]["a"][0];
        (p[0].as_f64().unwrap(), p[1].as_f64().unwrap())
    };
    bench_scene_text_overlay(c, "overlay_60_shapes_x20_points", &text, start);
}

/// Scene Text `text` parsed (the peer), then its overlay drawn, hovered
/// and dragged from `start`, in a 1080p Morph node.
fn bench_scene_text_overlay(c: &mut Criterion, group: &str, text: &str, start: (f64, f64)) {
    let mut g = c.benchmark_group(group);
    g.sample_size(20).measurement_time(Duration::from_secs(5));
    g.bench_function("peer_parse_scene_text_json", |bch| {
        bch.iter(|| black_box(serde_json::from_str::<serde_json::Value>(text).unwrap()))
    });
    let bundle = overlay_bundle();
    let inst = morph_1080p(&bundle);
    inst.set_string("scene_text", text).unwrap();
    let ov = Overlay::new(&inst, true).unwrap().expect("an overlay");
    draw_hover_and_drag(&mut g, &ov, start);
    g.finish();
}

/// The overlay drawn, hovered, and dragged from `start` (each motion, then
/// the redraw the host would ask for).
fn draw_hover_and_drag(
    g: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
    ov: &Overlay<'_>,
    start: (f64, f64),
) {
    g.bench_function("draw", |bch| {
        bch.iter(|| black_box(ov.draw(1.0, (1.0, 1.0)).unwrap()))
    });
    g.bench_function("hover_motion", |bch| {
        bch.iter(|| {
            ov.pen(kOfxInteractActionPenMotion, 1.0, (960.0, 540.0), (1.0, 1.0))
                .unwrap()
        })
    });
    ov.pen(kOfxInteractActionPenDown, 1.0, start, (1.0, 1.0))
        .unwrap();
    let mut k = 0.0;
    g.bench_function("drag_motion_and_redraw", |bch| {
        bch.iter(|| {
            k += 0.01;
            let at = (start.0 + k, start.1);
            ov.pen(kOfxInteractActionPenMotion, 1.0, at, (1.0, 1.0))
                .unwrap();
            black_box(ov.draw(1.0, (1.0, 1.0)).unwrap())
        })
    });
    ov.pen(kOfxInteractActionPenUp, 1.0, start, (1.0, 1.0))
        .unwrap();
}

criterion_group!(
    benches,
    bench_plugin_path,
    bench_overlay,
    bench_overlay_lines,
    bench_overlay_grid
);

/// Host value calls (reads and writes) the instance's params have had.
fn value_calls(inst: &morphfx_harness::host::Instance<'_>) -> usize {
    let names = inst.param_names();
    names.iter().map(|(name, _)| inst.value_calls(name)).sum()
}

/// A 100-line node: the 64 line slots and 36 lines in Scene Text.
fn bench_overlay_lines(c: &mut Criterion) {
    let lines = lines();
    let (slots, text) = lines.split_at(64);
    let bundle = overlay_bundle();
    let inst = morph_1080p(&bundle);
    inst.set_int("line_count", 64).unwrap();
    for (k, f) in slots.iter().enumerate() {
        for (side, which) in [(Side::A, "a"), (Side::B, "b")] {
            let [p, q] = [f.points(side)[0], f.points(side)[1]];
            let name = |end: &str| format!("line{}_{which}_{end}", k + 1);
            inst.set_double(&name("start"), &[p.x, p.y], None).unwrap();
            inst.set_double(&name("end"), &[q.x, q.y], None).unwrap();
        }
    }
    inst.set_string("scene_text", &scene_json(text)).unwrap();
    let ov = Overlay::new(&inst, true).unwrap().expect("an overlay");
    let mut g = c.benchmark_group("overlay_100_lines");
    g.sample_size(20).measurement_time(Duration::from_secs(5));
    let (before, n) = (value_calls(&inst), 50);
    for k in 0..n {
        let at = (100.0 + k as f64, 540.0);
        ov.pen(kOfxInteractActionPenMotion, 1.0, at, (1.0, 1.0))
            .unwrap();
    }
    let per_hover = (value_calls(&inst) - before) / n;
    let before = value_calls(&inst);
    ov.draw(1.0, (1.0, 1.0)).unwrap();
    let per_draw = value_calls(&inst) - before;
    eprintln!("overlay_100_lines: {per_hover} param value calls per hover, {per_draw} per draw");
    // A drag of slot 1's A start: each motion keys the point.
    let p = slots[0].points(Side::A)[0];
    draw_hover_and_drag(&mut g, &ov, (p.x, p.y));
    g.finish();
}

/// A 32 × 32 mesh over the 1080p frame, B's interior nodes a little off
/// A's, method mesh.
fn grid_json() -> String {
    let n = 32;
    let node = |r: usize, c: usize| {
        let (x, y) = (W as f64 * c as f64 / 31.0, H as f64 * r as f64 / 31.0);
        [x, y]
    };
    let a: Vec<[f64; 2]> = (0..n)
        .flat_map(|r| (0..n).map(move |c| node(r, c)))
        .collect();
    let b: Vec<[f64; 2]> = (0..n)
        .flat_map(|r| (0..n).map(move |c| (r, c)))
        .map(|(r, c)| {
            let [x, y] = node(r, c);
            let inner = r > 0 && c > 0 && r + 1 < n && c + 1 < n;
            if inner {
                [
                    x + 5.0 * ((r + c) % 3) as f64,
                    y - 4.0 * ((r * c) % 2) as f64,
                ]
            } else {
                [x, y]
            }
        })
        .collect();
    serde_json::json!({"format": "morphfx-scene", "version": 1, "method": "mesh",
        "mesh": {"rows": n, "cols": n, "a": a, "b": b}})
    .to_string()
}

fn bench_overlay_grid(c: &mut Criterion) {
    // A's node (row 10, col 10).
    let start = (W as f64 * 10.0 / 31.0, H as f64 * 10.0 / 31.0);
    bench_scene_text_overlay(c, "overlay_grid_32x32", &grid_json(), start);
}

criterion_main!(benches);
