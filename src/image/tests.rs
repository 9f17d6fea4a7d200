use super::*;
use crate::geom::{PixelScale, RectI};
use crate::warp::{field::FieldWarp, Identity, Warp};

fn ramp(bounds: RectI) -> Image {
    Image::from_fn(bounds, 4, |i, j, c| {
        (i * 3 + j * 7) as f32 + c as f32 * 0.25
    })
}

#[test]
fn negative_stride_views_read_the_same_pixels() {
    let img = ramp(RectI::new(5, -3, 13, 4));
    // Same pixels, top row first in memory.
    let (flipped, layout) = crate::testing::top_down(&img.data, img.bounds, 4, (0, 0), 0.0);
    let view = ImageView::new(&flipped, layout).unwrap();
    for j in img.bounds.y1..img.bounds.y2 {
        for i in img.bounds.x1..img.bounds.x2 {
            assert_eq!(view.pixel(i, j), img.pixel(i, j));
        }
    }
}

#[test]
fn layouts_that_leave_their_buffer_are_refused() {
    let data = vec![0f32; 10];
    let layout = Layout::packed(RectI::from_size(3, 2), 2);
    assert!(ImageView::new(&data, layout).is_err());
}

#[test]
fn rows_mut_splits_negative_strides() {
    let mut data = vec![0u8; 2 * 3 * 4];
    let layout = Layout {
        bounds: RectI::new(0, 0, 2, 3),
        channels: 4,
        base: 16,
        row_stride: -8,
    };
    let mut view = ImageViewMut::new(&mut data, layout).unwrap();
    for (j, row) in view.rows_mut() {
        row.fill(j as u8 + 1);
    }
    assert_eq!(&data[16..24], &[1u8; 8]);
    assert_eq!(&data[0..8], &[3u8; 8]);
}

#[test]
fn identity_resampling_is_bit_exact_for_every_filter_and_edge() {
    let img = ramp(RectI::new(-4, 2, 20, 17));
    let map = Identity.map_window(img.bounds, PixelScale::UNIT);
    for filter in [Filter::Bilinear, Filter::Bicubic] {
        for edge in [EdgeMode::Black, EdgeMode::Clamp, EdgeMode::Mirror] {
            let mut out = Image::new(img.bounds, 4);
            let s = ResampleSettings {
                filter,
                edge,
                premultiplied: true,
            };
            resample(img.view(), PixelScale::UNIT, &map, out.view_mut().rows(), s);
            assert_eq!(out, img, "{filter:?} {edge:?}");
        }
    }
}

#[test]
fn bilinear_half_pixel_shift_averages_neighbours() {
    let img = Image::from_fn(RectI::from_size(8, 1), 1, |i, _, _| i as f32);
    let shift = crate::warp::field::FieldWarp::new(
        vec![crate::warp::field::LinePair {
            dst: (crate::Vec2::new(0.0, 0.0), crate::Vec2::new(10.0, 0.0)),
            src: (crate::Vec2::new(0.5, 0.0), crate::Vec2::new(10.5, 0.0)),
        }],
        &crate::warp::field::FieldSettings {
            evaluation: crate::warp::field::Evaluation::Exact,
            ..Default::default()
        },
    );
    let map = shift.map_window(img.bounds, PixelScale::UNIT);
    let mut out = Image::new(img.bounds, 1);
    resample(
        img.view(),
        PixelScale::UNIT,
        &map,
        out.view_mut().rows(),
        ResampleSettings::default(),
    );
    for i in 0..7 {
        assert!(
            (out.data[i] - (i as f32 + 0.5)).abs() < 1e-4,
            "{i}: {}",
            out.data[i]
        );
    }
    // Clamp edge: the last pixel reads itself and its clamped neighbour.
    assert!((out.data[7] - 7.0).abs() < 1e-4);
    let _ = FieldWarp::new(Vec::new(), &Default::default());
}

#[test]
fn eight_and_sixteen_bit_round_trip_through_float() {
    for v in [0u8, 1, 127, 128, 254, 255] {
        assert_eq!(u8::from_f32(v.to_f32()), v);
    }
    for v in [0u16, 1, 32767, 65534, 65535] {
        assert_eq!(u16::from_f32(v.to_f32()), v);
    }
    assert_eq!(u8::from_f32(7.5), 255);
    assert_eq!(u8::from_f32(-1.0), 0);
}

#[test]
fn straight_alpha_filtering_does_not_bleed_transparent_colour() {
    // Left pixel: opaque red; right pixel: transparent but green (garbage colour).
    let img = Image::from_fn(RectI::from_size(2, 1), 4, |i, _, c| match (i, c) {
        (0, 0) | (0, 3) => 1.0,
        (1, 1) => 1.0,
        _ => 0.0,
    });
    let s = Sampler::new(
        img.view(),
        PixelScale::UNIT,
        Filter::Bilinear,
        EdgeMode::Clamp,
        false,
    );
    let mut px = [0.0; 4];
    s.sample(1.0, 0.5, &mut px);
    assert_eq!(px, [1.0, 0.0, 0.0, 0.5]);
}

/// The direct float RGBA path addresses taps from the buffer's origin and
/// stride: a top-down, padded buffer with an offset must give exactly what a
/// packed one gives, and both what each position's bilinear blend (or
/// Catmull-Rom sum) is.
#[test]
fn direct_float_rgba_sampling_reads_any_layout_exactly() {
    let bounds = RectI::new(-7, 3, 30, 25);
    let img = Image::from_fn(bounds, 4, |i, j, c| {
        ((i * 37 + j * 101 + c as i32 * 7) % 97) as f32 / 97.0 - 0.3
    });
    // Top row first, 5 pixels of padding per row, 11 samples of lead-in.
    let (flipped, layout) = crate::testing::top_down(&img.data, bounds, 4, (20, 11), f32::NAN);
    let flipped = ImageView::new(&flipped, layout).unwrap();
    let positions = crate::testing::awkward_positions(bounds, 1003, 5);
    let filters = [Filter::Bilinear, Filter::Bicubic];
    let cases = filters
        .into_iter()
        .flat_map(|f| [EdgeMode::Black, EdgeMode::Clamp, EdgeMode::Mirror].map(|edge| (f, edge)));
    for (filter, edge) in cases {
        let sampler = |view| Sampler::new(view, PixelScale::UNIT, filter, edge, true);
        let (packed, top_down) = (sampler(img.view()), sampler(flipped));
        let mut want = vec![[0f32; 4]; positions.len()];
        let mut got = want.clone();
        packed.sample_row(&positions, &mut want);
        top_down.sample_row(&positions, &mut got);
        for ((p, g), w) in positions.iter().zip(&got).zip(&want) {
            let same = g.iter().zip(w).all(|(g, w)| g.to_bits() == w.to_bits());
            assert!(same, "{filter:?} {edge:?} at {p:?}: {g:?} vs {w:?}");
            let mut one = [0f32; 4];
            packed.sample(p[0], p[1], &mut one);
            for c in 0..4 {
                let ok = (g[c] - one[c]).abs() <= 1e-5 || (g[c].is_nan() && one[c].is_nan());
                let at = format!("{filter:?} {edge:?} at {p:?}");
                assert!(ok, "{at}: {g:?} vs one sample {one:?}");
            }
        }
    }
}

/// A row sampled whole and the same row in two pieces split at every
/// point (a host's tiles split rows anywhere) give every pixel the same
/// bits, bilinear and bicubic, for one source and for the dissolve of
/// two: a row's last pixels take the direct path as full groups do.
#[test]
fn a_row_split_anywhere_samples_the_same_bits() {
    let bounds = RectI::new(0, 0, 40, 30);
    let img = Image::from_fn(bounds, 4, |i, j, c| {
        ((i * 37 + j * 101 + c as i32 * 7) % 97) as f32 / 97.0
    });
    // Inside the image, off the pixel centres: the direct path's ground;
    // more than the groups the direct path places ahead of their turn.
    let positions: Vec<[f32; 2]> = (0..45)
        .map(|k| [5.3 + 0.67 * k as f32, 4.6 + 0.5 * k as f32])
        .collect();
    let n = positions.len();
    for filter in [Filter::Bilinear, Filter::Bicubic] {
        let s = Sampler::new(img.view(), PixelScale::UNIT, filter, EdgeMode::Clamp, true);
        let mut whole = vec![[0f32; 4]; n];
        s.sample_row(&positions, &mut whole);
        let taps = s.direct_taps().expect("float RGBA takes the direct path");
        let slow = |k: usize| {
            let mut v = [0f32; 4];
            s.sample(positions[k][0], positions[k][1], &mut v);
            v
        };
        let mut blended = vec![[0f32; 4]; n];
        let side = (&taps, &positions[..], 0.37, slow);
        super::direct_rgba::blend_row(side, (&taps, &positions[..], 0.63, slow), &mut blended);
        for split in 1..n {
            let mut parts = vec![[0f32; 4]; n];
            let (left, right) = parts.split_at_mut(split);
            s.sample_row(&positions[..split], left);
            s.sample_row(&positions[split..], right);
            let bits = |v: &[[f32; 4]]| {
                v.as_flattened()
                    .iter()
                    .map(|x| x.to_bits())
                    .collect::<Vec<_>>()
            };
            assert_eq!(bits(&parts), bits(&whole), "{filter:?} split at {split}");
            let mut parts = vec![[0f32; 4]; n];
            for (range, out) in [(0..split, 0), (split..n, split)] {
                let p = &positions[range.clone()];
                let slow = |k: usize| slow(out + k);
                let len = p.len();
                super::direct_rgba::blend_row(
                    (&taps, p, 0.37, slow),
                    (&taps, p, 0.63, slow),
                    &mut parts[out..out + len],
                );
            }
            assert_eq!(
                bits(&parts),
                bits(&blended),
                "{filter:?} dissolve split at {split}"
            );
        }
    }
}
