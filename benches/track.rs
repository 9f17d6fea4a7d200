//! Tracking throughput: 16 line features through 100 frames of 1080p, from
//! one key, grey conversion and pyramids included (the frames are in
//! memory: reading plates is the harness's part, timed separately in
//! docs/PERFORMANCE.md).
//!
//! `cargo bench --features bench --bench track`

use std::hint::black_box;
use std::sync::Arc;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion};
use rayon::prelude::*;

use morphfx::features::FeatureKind;
use morphfx::geom::{RectI, Vec2};
use morphfx::image::Image;
use morphfx::testing::texture;
use morphfx::track::{track_side, Frames, Grey, Pyramid, SideKey, TrackSettings};

const W: usize = 1920;
const H: usize = 1080;
const FRAMES: usize = 100;

/// Frame `f`: a textured picture turned by up to 3°, zoomed by up to 3 %
/// and drifted by up to (40, 15) px about the centre (the inverse in closed
/// form), one grey channel.
fn frame(f: usize) -> Image {
    let s = f as f64 / FRAMES as f64;
    let (sin, cos) = (3.0f64 * s).to_radians().sin_cos();
    let zoom = 1.0 + 0.03 * s;
    let centre = Vec2::new(W as f64 / 2.0, H as f64 / 2.0);
    let drift = Vec2::new(40.0, 15.0) * s;
    let mut img = Image::new(RectI::from_size(W, H), 1);
    img.data.par_chunks_mut(W).enumerate().for_each(|(j, row)| {
        for (i, v) in row.iter_mut().enumerate() {
            let x = Vec2::new(i as f64 + 0.5, j as f64 + 0.5) - centre - drift;
            let p = Vec2::new(cos * x.x + sin * x.y, -sin * x.x + cos * x.y) * (1.0 / zoom);
            let [r, g, b] = texture(p + centre);
            *v = 0.2126 * r + 0.7152 * g + 0.0722 * b;
        }
    });
    img
}

struct InMemory<'a>(&'a [Image], usize);

impl Frames<morphfx::Error> for InMemory<'_> {
    fn pyramid(&mut self, f: i64) -> morphfx::Result<Arc<Pyramid>> {
        let grey = Grey::from_view(&self.0[f as usize].view());
        Ok(Arc::new(Pyramid::new(grey, self.1, 16)))
    }
}

/// 16 lines 80-200 px long on a 4 × 4 grid over the frame.
fn lines() -> Vec<Vec<Vec2>> {
    (0..16)
        .map(|k| {
            let (gx, gy) = ((k % 4) as f64, (k / 4) as f64);
            let p = Vec2::new(300.0 + gx * 400.0, 200.0 + gy * 220.0);
            let len = 80.0 + 8.0 * k as f64;
            let (sin, cos) = (k as f64 * 0.4).sin_cos();
            vec![p, p + Vec2::new(cos, sin) * len]
        })
        .collect()
}

fn bench_track(c: &mut Criterion) {
    let frames: Vec<Image> = (0..FRAMES).map(frame).collect();
    let settings = TrackSettings::default();
    let key = SideKey {
        frame: 0,
        points: lines(),
    };
    let kinds = vec![FeatureKind::Line; 16];
    let mut g = c.benchmark_group("track");
    g.sample_size(10).measurement_time(Duration::from_secs(30));
    g.bench_function("16_lines_100_frames_1080p", |b| {
        b.iter(|| {
            let out = track_side(
                &kinds,
                std::slice::from_ref(&key),
                (0, FRAMES as i64 - 1),
                &mut InMemory(&frames, settings.levels),
                &settings,
                &mut |_, _, _| true,
            )
            .unwrap();
            black_box(out)
        })
    });
    g.bench_function("grey_and_pyramid_1080p", |b| {
        let mut source = InMemory(&frames, settings.levels);
        b.iter(|| black_box(source.pyramid(7).unwrap()))
    });
    g.finish();
}

criterion_group!(benches, bench_track);
criterion_main!(benches);
