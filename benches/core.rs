//! Core engine benchmarks: the field map at 1080p, resampling, a whole morph
//! frame, the mesh warp (two-pass and one-pass), triangles, snakes and
//! `auto`. Numbers and the machine go in docs/PERFORMANCE.md.
//!
//! `cargo bench --features bench --bench core` (add `-- field` etc. to pick a group).

use std::hint::black_box;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion};

use morphfx::choice::Choice;
use morphfx::features::{Feature, FeatureKind, Side};
use morphfx::geom::{PixelScale, RectD, RectI, Vec2};
use morphfx::image::resample::{resample, ResampleSettings};
use morphfx::image::WarpMap;
use morphfx::image::{EdgeMode, Filter, Image, Sampler};
use morphfx::morph::{dissolve, Warped};
use morphfx::snake::{EdgeEnergy, Snake, SnakeSettings};
use morphfx::testing::texture;
use morphfx::warp::auto::{self, AutoSettings, WorkImage};
use morphfx::warp::field::{Evaluation, FieldSettings, FieldWarp, LinePair};
use morphfx::warp::mesh::{self, Mesh, MeshWarp};
use morphfx::warp::triangles::TriangleWarp;
use morphfx::warp::Warp;

const W: i32 = 1920;
const H: i32 = 1080;

fn frame() -> RectI {
    RectI::new(0, 0, W, H)
}

/// Deterministic line pairs spread over the frame like a keyed face or body:
/// 40-300 px long, each moved and turned a little between the two images.
fn line_pairs(n: usize, seed: u64) -> Vec<LinePair> {
    let mut s = seed;
    let mut r = move || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    (0..n)
        .map(|_| {
            let p = Vec2::new(r() * W as f64, r() * H as f64);
            let angle = r() * std::f64::consts::TAU;
            let len = 40.0 + r() * 260.0;
            let q = p + Vec2::new(angle.cos(), angle.sin()) * len;
            let mut jitter = || Vec2::new(r() * 40.0 - 20.0, r() * 40.0 - 20.0);
            let (jp, jq) = (jitter(), jitter());
            LinePair {
                dst: (p, q),
                src: (p + jp, q + jq),
            }
        })
        .collect()
}

fn field(n: usize, evaluation: Evaluation) -> FieldWarp {
    let settings = FieldSettings {
        evaluation,
        ..FieldSettings::default()
    };
    FieldWarp::new(line_pairs(n, n as u64), &settings)
}

/// A plate with detail everywhere, so resampling cannot shortcut.
fn plate(seed: f32) -> Image {
    Image::from_fn(frame(), 4, |i, j, c| {
        if c == 3 {
            1.0
        } else {
            let (x, y) = (i as f32, j as f32);
            0.5 + 0.5 * ((x * 0.05 + seed) * (c as f32 + 1.0)).sin() * (y * 0.031).cos()
        }
    })
}

fn bench_field(c: &mut Criterion) {
    let mut g = c.benchmark_group("field_map_1080p");
    g.sample_size(10).measurement_time(Duration::from_secs(8));
    for n in [10, 100] {
        let exact = field(n, Evaluation::Exact);
        g.bench_function(format!("exact_{n}_lines"), |b| {
            b.iter(|| black_box(exact.map_window(frame(), PixelScale::UNIT)))
        });
        let adaptive = field(n, Evaluation::default());
        g.bench_function(format!("adaptive_{n}_lines"), |b| {
            b.iter(|| black_box(adaptive.map_window(frame(), PixelScale::UNIT)))
        });
    }
    // A line being dragged: the map redone from the one before the move.
    let before = field(100, Evaluation::default());
    let kept = before.field_map(frame(), PixelScale::UNIT);
    let mut pairs = before.pairs().to_vec();
    pairs[0].dst.0 += Vec2::new(0.5, 0.0);
    pairs[0].src.0 += Vec2::new(1.0, 0.0);
    let moved = FieldWarp::new(pairs, &FieldSettings::default());
    g.bench_function("adaptive_100_lines_one_moved", |b| {
        b.iter(|| black_box(moved.field_map_after(frame(), PixelScale::UNIT, Some(&kept))))
    });
    // The same, the map before handed over and edited in place (as the
    // plugin does while a line is dragged).
    g.bench_function("adaptive_100_lines_one_moved_in_place", |b| {
        b.iter_batched(
            || before.field_map(frame(), PixelScale::UNIT),
            |kept| black_box(moved.field_map_from(frame(), PixelScale::UNIT, kept)),
            criterion::BatchSize::LargeInput,
        )
    });
    g.finish();
}

/// With `MORPHFX_MAP_DUMP=DIR`, writes `DIR/map_a.f32` and `DIR/map_b.f32`
/// (the reverse maps of the resample and morph benches, as pixel indices
/// x, y per output pixel, bottom row first, little-endian f32) for a peer
/// such as `benches/remap_peer.py` to time the same maps.
fn dump_map(name: &str, map: &WarpMap) {
    let Some(dir) = std::env::var_os("MORPHFX_MAP_DUMP") else {
        return;
    };
    let mut bytes = Vec::with_capacity(map.window.area() * 8);
    for j in map.window.y1..map.window.y2 {
        for p in map.row(j).unwrap_or_default() {
            for v in [
                p[0] * map.scale.x as f32 - 0.5,
                p[1] * map.scale.y as f32 - 0.5,
            ] {
                bytes.extend_from_slice(&v.to_le_bytes());
            }
        }
    }
    let path = std::path::Path::new(&dir).join(format!("{name}.f32"));
    std::fs::write(&path, bytes).expect("the map dump is written");
}

fn bench_resample(c: &mut Criterion) {
    let src = plate(0.0);
    let map: WarpMap = field(100, Evaluation::default()).map_window(frame(), PixelScale::UNIT);
    dump_map("map_a", &map);
    let mut dst = Image::new(frame(), 4);
    let mut g = c.benchmark_group("resample_1080p_rgba_f32");
    g.sample_size(20);
    // The memory floor: one plain copy of a frame (read 33 MB, write 33 MB),
    // rows in parallel as the resampler writes them.
    g.bench_function("copy_floor", |b| {
        b.iter(|| {
            use rayon::prelude::*;
            dst.data
                .par_chunks_mut(W as usize * 4)
                .zip(src.data.par_chunks(W as usize * 4))
                .for_each(|(d, s)| d.copy_from_slice(s))
        })
    });
    // The copy's two halves: reading a frame (summed in eight lanes, which
    // vectorise) and writing one. With the map's read (8 of a pixel's 16
    // bytes, half a `read_floor`) they give what a resample costs when
    // memory streams at its best: the model docs/PERFORMANCE.md compares
    // `bilinear` and `bilinear_shift` with.
    g.bench_function("read_floor", |b| {
        b.iter(|| {
            use rayon::prelude::*;
            let lanes = |s: &[f32]| {
                let mut acc = [0.0f32; 8];
                for c in s.as_chunks::<8>().0 {
                    for (a, v) in acc.iter_mut().zip(c) {
                        *a += v;
                    }
                }
                acc.iter().sum::<f32>()
            };
            black_box(src.data.par_chunks(W as usize * 4).map(lanes).sum::<f32>())
        })
    });
    g.bench_function("write_floor", |b| {
        b.iter(|| {
            use rayon::prelude::*;
            dst.data
                .par_chunks_mut(W as usize * 4)
                .for_each(|d| d.fill(black_box(0.5)))
        })
    });
    for filter in [Filter::Bilinear, Filter::Bicubic] {
        let settings = ResampleSettings {
            filter,
            edge: EdgeMode::Clamp,
            premultiplied: true,
        };
        g.bench_function(filter.name(), |b| {
            b.iter(|| {
                resample(
                    src.view(),
                    PixelScale::UNIT,
                    &map,
                    dst.view_mut().rows(),
                    settings,
                )
            })
        });
    }
    // The same kernel through a uniform sub-pixel shift: every tap row
    // streams, which the hardware prefetchers follow, so the gap from
    // `bilinear` is what the warp's wandering taps cost in memory latency.
    let shift = WarpMap::new(
        frame(),
        PixelScale::UNIT,
        (0..H)
            .flat_map(|j| (0..W).map(move |i| [i as f32 + 0.8, j as f32 + 0.8]))
            .collect(),
    );
    let settings = ResampleSettings {
        filter: Filter::Bilinear,
        edge: EdgeMode::Clamp,
        premultiplied: true,
    };
    g.bench_function("bilinear_shift", |b| {
        b.iter(|| {
            resample(
                src.view(),
                PixelScale::UNIT,
                &shift,
                dst.view_mut().rows(),
                settings,
            )
        })
    });
    g.finish();
    // The same map and plate as 8- and 16-bit RGBA, what Resolve and Natron
    // send, into float rows as the nodes resample them.
    let mut g = c.benchmark_group("resample_1080p_rgba_int");
    g.sample_size(20);
    let layout = morphfx::image::Layout::packed(frame(), 4);
    let bytes: Vec<u8> = src
        .data
        .iter()
        .map(|v| (v.clamp(0.0, 1.0) * 255.0) as u8)
        .collect();
    let shorts: Vec<u16> = src
        .data
        .iter()
        .map(|v| (v.clamp(0.0, 1.0) * 65535.0) as u16)
        .collect();
    let settings = ResampleSettings {
        filter: Filter::Bilinear,
        edge: EdgeMode::Clamp,
        premultiplied: true,
    };
    let view8 = morphfx::image::ImageView::new(&bytes, layout).unwrap();
    let view16 = morphfx::image::ImageView::new(&shorts, layout).unwrap();
    g.bench_function("bilinear_u8", |b| {
        b.iter(|| {
            resample(
                view8,
                PixelScale::UNIT,
                &map,
                dst.view_mut().rows(),
                settings,
            )
        })
    });
    g.bench_function("bilinear_u16", |b| {
        b.iter(|| {
            resample(
                view16,
                PixelScale::UNIT,
                &map,
                dst.view_mut().rows(),
                settings,
            )
        })
    });
    g.finish();
}

fn bench_morph(c: &mut Criterion) {
    let (a, b) = (plate(0.0), plate(1.7));
    // The cached warps: what a host's second render of the frame reuses.
    let warp_a = field(100, Evaluation::default());
    let mut warp_b = field(100, Evaluation::default());
    // B's warp pulls the other way.
    warp_b = FieldWarp::new(
        warp_b
            .pairs()
            .iter()
            .map(|l| LinePair {
                dst: l.src,
                src: l.dst,
            })
            .collect(),
        &FieldSettings::default(),
    );
    let map_a = warp_a.map_window(frame(), PixelScale::UNIT);
    let map_b = warp_b.map_window(frame(), PixelScale::UNIT);
    dump_map("map_b", &map_b);
    let mut dst = Image::new(frame(), 4);
    let mut g = c.benchmark_group("morph_frame_1080p_rgba_f32");
    g.sample_size(20);
    for filter in [Filter::Bilinear, Filter::Bicubic] {
        let sa = Sampler::new(a.view(), PixelScale::UNIT, filter, EdgeMode::Clamp, true);
        let sb = Sampler::new(b.view(), PixelScale::UNIT, filter, EdgeMode::Clamp, true);
        g.bench_function(format!("cached_warp_{}", filter.name()), |bch| {
            bch.iter(|| {
                dissolve(
                    Warped::Map(&sa, &map_a),
                    Warped::Map(&sb, &map_b),
                    0.37,
                    dst.view_mut().rows(),
                )
            })
        });
    }
    g.finish();
}

/// A 20 × 20 mesh on the frame, interior nodes pushed up to 25 px by a smooth
/// field (border frozen), as a hand-placed face mesh moves.
fn mesh_pair() -> (Mesh, Mesh) {
    let src = Mesh::regular(20, 20, 0.0, 0.0, W as f64, H as f64).unwrap();
    let dst = src.map_nodes(|r, c, p| {
        if r == 0 || c == 0 || r == 19 || c == 19 {
            p
        } else {
            p + Vec2::new(25.0 * (p.y * 0.004).sin(), 18.0 * (p.x * 0.003).cos())
        }
    });
    (src, dst)
}

fn bench_mesh(c: &mut Criterion) {
    let src = plate(0.0);
    let (from, to) = mesh_pair();
    let sampler = Sampler::new(
        src.view(),
        PixelScale::UNIT,
        Filter::Bilinear,
        EdgeMode::Clamp,
        true,
    );
    let mut g = c.benchmark_group("mesh_1080p_rgba_f32_20x20");
    g.sample_size(10).measurement_time(Duration::from_secs(6));
    // A sequence render reuses its output plane; a fresh one costs ~13 ms
    // more here (first touch of 33 MB).
    let mut plane = mesh::two_pass(&sampler, &from, &to, frame(), PixelScale::UNIT);
    g.bench_function("two_pass", |b| {
        b.iter(|| mesh::two_pass_into(&sampler, &from, &to, PixelScale::UNIT, &mut plane))
    });
    g.bench_function("two_pass_fresh_output", |b| {
        b.iter(|| {
            black_box(mesh::two_pass(
                &sampler,
                &from,
                &to,
                frame(),
                PixelScale::UNIT,
            ))
        })
    });
    // What renders use: the error-checked grid within MeshWarp::TOLERANCE.
    let warp = MeshWarp::new(&from, &to).within(MeshWarp::TOLERANCE);
    g.bench_function("one_pass_map", |b| {
        b.iter(|| black_box(warp.map_window(frame(), PixelScale::UNIT)))
    });
    // Newton at every pixel, the reference the grid is held to.
    let exact = MeshWarp::new(&from, &to);
    g.bench_function("one_pass_map_exact", |b| {
        b.iter(|| black_box(exact.map_window(frame(), PixelScale::UNIT)))
    });
    g.finish();
}

fn bench_triangles(c: &mut Criterion) {
    let features: Vec<Feature> = line_pairs(100, 7)
        .into_iter()
        .flat_map(|l| {
            [
                Feature::point(l.src.0, l.dst.0),
                Feature::point(l.src.1, l.dst.1),
            ]
        })
        .collect();
    let full = RectD::new(0.0, 0.0, W as f64, H as f64);
    let mut g = c.benchmark_group("triangles_1080p_200_points");
    g.sample_size(20);
    g.bench_function("triangulate_and_map", |b| {
        b.iter(|| {
            let w = TriangleWarp::toward(&features, Side::A, 0.5, 20, full).unwrap();
            black_box(w.map_window(frame(), PixelScale::UNIT))
        })
    });
    g.finish();
}

fn bench_snakes(c: &mut Criterion) {
    let src = plate(0.0);
    let mut g = c.benchmark_group("snakes_1080p");
    g.sample_size(10);
    g.bench_function("edge_energy_sigma3", |b| {
        b.iter(|| black_box(EdgeEnergy::new(src.view(), 3.0)))
    });
    let energy = EdgeEnergy::new(src.view(), 3.0);
    let settings = SnakeSettings::default();
    // 20 three-point polylines (41 snake points each) spread over the frame.
    let polylines: Vec<Vec<Vec2>> = line_pairs(20, 3)
        .into_iter()
        .map(|l| {
            vec![
                l.dst.0,
                (l.dst.0 + l.dst.1) * 0.5 + Vec2::new(3.0, -2.0),
                l.dst.1,
            ]
        })
        .collect();
    g.bench_function("20_polylines_200_iterations", |b| {
        b.iter(|| {
            for p in &polylines {
                let mut snake = Snake::from_primitive(FeatureKind::Polyline, p, &settings);
                snake.run(&energy, &settings);
                black_box(&snake.points);
            }
        })
    });
    g.finish();
}

/// A textured plate pair of `w x h` where B is A under a smooth warp of up
/// to 2% of the frame (the kind of pair `auto` is for). The texture is
/// drawn at the scale of a `detail`-pixel-wide plate, whatever the size.
#[derive(Clone, Copy)]
struct BentTexture {
    w: f64,
    h: f64,
    detail: f64,
}

impl BentTexture {
    fn new(w: usize, h: usize, detail: f64) -> Self {
        BentTexture {
            w: w as f64,
            h: h as f64,
            detail,
        }
    }

    /// A's colour at canonical `(x, y)`.
    fn a(&self, x: f64, y: f64) -> [f32; 3] {
        texture(Vec2::new(x, y) * (self.detail / self.w))
    }

    /// B's: A's where the warp takes the point.
    fn b(&self, x: f64, y: f64) -> [f32; 3] {
        let (u, v) = (x / self.w, y / self.h);
        let bump = (std::f64::consts::PI * u).sin() * (std::f64::consts::PI * v).sin();
        let m = 0.02 * self.w;
        self.a(
            x + m * bump * (2.0 * v).cos(),
            y - m * bump * (3.0 * u).sin(),
        )
    }
}

/// [`BentTexture`]'s pair at the scale of a 256-wide plate, as `auto`
/// reads plates.
fn auto_pair(w: usize, h: usize) -> (WorkImage, WorkImage) {
    let t = BentTexture::new(w, h, 256.0);
    (
        WorkImage::from_fn(w, h, |i, j| t.a(i as f64 + 0.5, j as f64 + 0.5)),
        WorkImage::from_fn(w, h, |i, j| t.b(i as f64 + 0.5, j as f64 + 0.5)),
    )
}

fn bench_auto(c: &mut Criterion) {
    let mut g = c.benchmark_group("auto");
    g.sample_size(10);
    for (name, w, h) in [("256", 256, 256), ("512", 512, 512), ("1080p", 1920, 1080)] {
        let (a, b) = auto_pair(w, h);
        let settings = AutoSettings::default();
        g.bench_function(format!("solve_{name}"), |bench| {
            bench.iter(|| {
                black_box(auto::solve(&a, &b, &[], &settings, auto::Start::Identity).unwrap())
            })
        });
        if name == "1080p" {
            let first = auto::solve(&a, &b, &[], &settings, auto::Start::Identity).unwrap();
            g.bench_function("warm_1080p", |bench| {
                bench.iter(|| {
                    black_box(
                        auto::solve(&a, &b, &[], &settings, auto::Start::Warm(&first.grid))
                            .unwrap(),
                    )
                })
            });
            let corr = auto::Correspondence::new(
                first.grid,
                RectD::new(0.0, 0.0, w as f64, h as f64),
                RectD::new(0.0, 0.0, w as f64, h as f64),
            );
            g.bench_function("map_1080p_t0.5", |bench| {
                bench.iter(|| {
                    black_box(
                        corr.toward(Side::A, 0.5)
                            .map_window(frame(), PixelScale::UNIT),
                    )
                })
            });
        }
    }
    g.finish();
}

/// 500 non-crossing constraints over the 1080p frame (up to 12 px moves).
fn scattered_pairs() -> Vec<(Vec2, Vec2)> {
    morphfx::testing::smooth_pairs(11, 500, W as f64, H as f64, 12.0, 30.0)
}

fn bench_scattered(c: &mut Criterion) {
    use morphfx::warp::mffd::{Mffd, MffdSettings, MffdWarp};
    use morphfx::warp::thin_plate::{ThinPlate, ThinPlateSettings, ThinPlateWarp};
    use morphfx::warp::{hybrid, Warp};
    let pairs = scattered_pairs();
    assert_eq!(pairs.len(), 500);
    let full = RectD::new(0.0, 0.0, W as f64, H as f64);
    let mut g = c.benchmark_group("scattered_1080p_500_points");
    g.sample_size(10);
    g.bench_function("thin_plate_solve_and_map", |b| {
        b.iter(|| {
            let p = ThinPlate::solve(&pairs, full, &ThinPlateSettings::default(), None);
            black_box(ThinPlateWarp::new(p).map_window(frame(), PixelScale::UNIT))
        })
    });
    let cold = ThinPlate::solve(&pairs, full, &ThinPlateSettings::default(), None);
    let moved: Vec<(Vec2, Vec2)> = pairs
        .iter()
        .map(|(p, q)| (*p, *q + Vec2::new(0.3, -0.2)))
        .collect();
    g.bench_function("thin_plate_warm_solve", |b| {
        b.iter(|| {
            black_box(ThinPlate::solve(
                &moved,
                full,
                &ThinPlateSettings::default(),
                Some(&cold),
            ))
        })
    });
    g.bench_function("mffd_solve_and_map", |b| {
        b.iter(|| {
            let m = Mffd::solve(&pairs, full, &MffdSettings::default());
            black_box(MffdWarp { mffd: m }.map_window(frame(), PixelScale::UNIT))
        })
    });
    g.bench_function("hybrid_solve_and_map", |b| {
        b.iter(|| {
            let m = hybrid::solve(
                &pairs,
                full,
                &hybrid::HybridSettings::default(),
                &morphfx::warp::thin_plate::ThinPlateSettings::default(),
                &morphfx::warp::mffd::MffdSettings::default(),
            );
            black_box(MffdWarp { mffd: m }.map_window(frame(), PixelScale::UNIT))
        })
    });
    g.finish();
}

fn bench_transition(c: &mut Criterion) {
    use morphfx::transition::{Attach, Attached, Curve, Propagation, Transition};
    // 20 polylines across the frame, each with its own curve.
    let features: Vec<Feature> = (0..20)
        .map(|k| {
            let (x, y) = (100.0 + 85.0 * k as f64, 200.0 + 30.0 * (k % 5) as f64 * 6.0);
            let pts = vec![
                Vec2::new(x, y),
                Vec2::new(x + 40.0, y + 60.0),
                Vec2::new(x + 10.0, y + 140.0),
            ];
            Feature::new(FeatureKind::Polyline, pts.clone(), pts).named(format!("f{k}"))
        })
        .collect();
    let curves = (0..20)
        .map(|k| Attached {
            attach: Attach::Index(k),
            curve: Curve::new(&[(0.5, (k as f64 / 19.0).clamp(0.05, 0.95))], "bench").unwrap(),
        })
        .collect();
    let transition = Transition::Curves {
        curves,
        propagation: Propagation::default(),
    };
    let full = RectD::new(0.0, 0.0, W as f64, H as f64);
    let mut g = c.benchmark_group("transition_1080p_20_curves");
    g.sample_size(20);
    g.bench_function("bspline_surface_and_dense_rates", |b| {
        b.iter(|| {
            let rates = transition.rates(&features, 20, full, 0.5).unwrap();
            let morphfx::transition::Rates::Surface { delta, .. } = &rates else {
                panic!("a surface")
            };
            black_box(delta.eval_window(frame(), PixelScale::UNIT))
        })
    });
    g.finish();
}

/// `suggest` on a 1080p textured pair (B: A under `auto_pair`'s bend),
/// guide included, beside converting both plates to grey (the least any
/// matcher does first).
fn bench_suggest(c: &mut Criterion) {
    use morphfx::geom::RectD;
    use morphfx::suggest::{suggest, work_guide, SuggestSettings};
    use morphfx::track::Grey;
    let (w, h) = (1920, 1080);
    // Texture at every scale a 1080p plate has it, down to a few pixels.
    let t = BentTexture::new(w, h, w as f64);
    let at = |i: usize, j: usize| (i as f64 + 0.5, j as f64 + 0.5);
    let wa = WorkImage::from_fn(w, h, |i, j| t.a(at(i, j).0, at(i, j).1));
    let wb = WorkImage::from_fn(w, h, |i, j| t.b(at(i, j).0, at(i, j).1));
    let grey = |side_b: bool| {
        Grey::from_fn(morphfx::geom::RectI::from_size(w, h), |i, j| {
            let (x, y) = (i as f64 + 0.5, j as f64 + 0.5);
            let [r, g, b] = if side_b { t.b(x, y) } else { t.a(x, y) };
            0.2126 * r + 0.7152 * g + 0.0722 * b
        })
    };
    let frame = RectD::new(0.0, 0.0, w as f64, h as f64);
    let mut g = c.benchmark_group("suggest_1080p");
    g.sample_size(10);
    g.bench_function("peer_grey_of_both", |b| {
        b.iter(|| black_box((grey(false), grey(true))))
    });
    g.bench_function("guide_and_40_pairs", |b| {
        b.iter(|| {
            let (ga, gb) = (grey(false), grey(true));
            let map = work_guide(&wa, frame, &wb, frame, &[]).unwrap();
            let guide = move |p: Vec2| map.map_a_to_b(p);
            black_box(suggest(&ga, &gb, &guide, &[], &SuggestSettings::default()).unwrap())
        })
    });
    g.finish();
}

criterion_group!(
    benches,
    bench_suggest,
    bench_scattered,
    bench_transition,
    bench_auto,
    bench_snakes,
    bench_field,
    bench_resample,
    bench_morph,
    bench_mesh,
    bench_triangles
);
criterion_main!(benches);
