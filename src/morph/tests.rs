use super::*;
use crate::features::{Feature, Side};
use crate::geom::{PixelScale, RectI, Vec2};
use crate::image::{EdgeMode, Filter, Image, Sampler};
use crate::warp::{self, WarpSettings};

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
    let wa = warp::toward(features, Side::A, t, &s)
        .unwrap()
        .map_window(a.bounds, PixelScale::UNIT);
    let wb = warp::toward(features, Side::B, t, &s)
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
