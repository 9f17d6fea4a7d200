use super::*;
use crate::features::{Feature, Side};
use crate::geom::{PixelScale, RectI, Vec2};
use crate::image::{EdgeMode, Filter, Image, Sampler};
use crate::make_warp::{self, WarpSettings};

fn plates() -> (Image, Image) {
    let b = RectI::from_size(40, 30);
    let a = Image::from_fn(b, 4, |i, j, c| {
        ((i * 5 + j * 3 + c as i32) % 17) as f32 * 0.1
    });
    let bb = Image::from_fn(b, 4, |i, j, c| {
        ((i * 2 + j * 11 + c as i32) % 13) as f32 * 0.3 - 0.5
    });
    (a, bb)
}

fn render(t: f64, features: &[Feature]) -> Image {
    let (a, b) = plates();
    let s = WarpSettings::default();
    let wa = make_warp::toward(features, Side::A, t, &s)
        .unwrap()
        .map_window(a.bounds, PixelScale::UNIT);
    let wb = make_warp::toward(features, Side::B, t, &s)
        .unwrap()
        .map_window(a.bounds, PixelScale::UNIT);
    let sa = Sampler::new(
        a.view(),
        PixelScale::UNIT,
        Filter::Bicubic,
        EdgeMode::Clamp,
        true,
    );
    let sb = Sampler::new(
        b.view(),
        PixelScale::UNIT,
        Filter::Bicubic,
        EdgeMode::Clamp,
        true,
    );
    let mut out = Image::new(a.bounds, 4);
    dissolve(
        Warped::Map(&sa, &wa),
        Warped::Map(&sb, &wb),
        t,
        out.view_mut().rows(),
    );
    out
}

#[test]
fn t0_is_exactly_a_and_t1_exactly_b() {
    let f = vec![Feature::line(
        [Vec2::new(5.0, 5.0), Vec2::new(30.0, 8.0)],
        [Vec2::new(9.0, 12.0), Vec2::new(25.0, 25.0)],
    )];
    let (a, b) = plates();
    assert_eq!(render(0.0, &f), a);
    assert_eq!(render(1.0, &f), b);
}

#[test]
fn without_motion_the_midpoint_is_the_plain_average() {
    let f = vec![Feature::point(Vec2::new(5.0, 5.0), Vec2::new(5.0, 5.0))];
    let (a, b) = plates();
    let mid = render(0.5, &f);
    for k in 0..a.data.len() {
        assert!((mid.data[k] - 0.5 * (a.data[k] + b.data[k])).abs() < 1e-6);
    }
}

/// The dissolve samples both float RGBA sources of a pixel in one pass; it
/// must give bit for bit what resampling each source and blending gives,
/// wherever the positions fall (edges, centres, NaN), with each source
/// bottom row first or top row first in memory (each pair of the two is
/// its own instance of the kernel), and where a map's window does not
/// cover the output.
#[test]
fn one_pass_dissolve_equals_resampling_each_source_then_blending() {
    use crate::image::resample::through;
    use crate::image::ImageView;
    use crate::testing::awkward_positions;
    let bounds = RectI::new(-5, 2, 41, 31);
    let (a, b) = (
        Image::from_fn(bounds, 4, |i, j, c| {
            ((i * 5 + j * 3 + c as i32) % 17) as f32 * 0.1
        }),
        Image::from_fn(bounds, 4, |i, j, c| {
            ((i * 2 + j * 11 + c as i32) % 13) as f32 * 0.3 - 0.5
        }),
    );
    // Each plate top row first in memory too.
    let top_down = |img: &Image| crate::testing::top_down(&img.data, bounds, 4, (0, 0), 0.0);
    let ((a_down, layout), (b_down, _)) = (top_down(&a), top_down(&b));
    let a_views = [a.view(), ImageView::new(&a_down, layout).unwrap()];
    let b_views = [b.view(), ImageView::new(&b_down, layout).unwrap()];
    let storages = a_views
        .iter()
        .flat_map(|&va| b_views.iter().map(move |&vb| (va, vb)));
    let map = |window: RectI, seed| {
        WarpMap::new(
            window,
            PixelScale::UNIT,
            awkward_positions(bounds, window.area(), seed),
        )
    };
    let narrow = RectI::new(0, 2, 30, 31);
    let maps = [
        (map(bounds, 1), map(bounds, 2)),
        (map(bounds, 3), map(narrow, 4)),
    ];
    let cases = storages.flat_map(|views| {
        maps.iter()
            .flat_map(move |m| [Filter::Bilinear, Filter::Bicubic].map(|f| (views, m, f)))
    });
    for ((va, vb), (ma, mb), filter) in cases {
        let sampler = |view| Sampler::new(view, PixelScale::UNIT, filter, EdgeMode::Clamp, true);
        let (sa, sb) = (sampler(va), sampler(vb));
        for t in [0.3, 0.75] {
            let mut got = Image::new(bounds, 4);
            dissolve(
                Warped::Map(&sa, ma),
                Warped::Map(&sb, mb),
                t,
                got.view_mut().rows(),
            );
            let (mut ra, mut rb) = (Image::new(bounds, 4), Image::new(bounds, 4));
            through(&sa, ma, ra.view_mut().rows());
            through(&sb, mb, rb.view_mut().rows());
            let (wa, wb) = ((1.0 - t) as f32, t as f32);
            for (k, g) in got.data.iter().enumerate() {
                let want = wb.mul_add(rb.data[k], wa * ra.data[k]);
                assert!(
                    g.to_bits() == want.to_bits(),
                    "{filter:?} t {t}, sample {k}: {g} vs {want}"
                );
            }
        }
    }
}
