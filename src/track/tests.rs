//! Tracking synthetic shots whose motion is known in closed form.

use std::sync::Arc;

use super::*;
use crate::error::Error;
use crate::features::FeatureKind;
use crate::geom::{RectI, Vec2};
use crate::image::Image;
use crate::testing::{shot_frame, texture, ShotMotion};

struct InMemory(Vec<Arc<Pyramid>>);

impl Frames<Error> for InMemory {
    fn pyramid(&mut self, frame: i64) -> Result<Arc<Pyramid>, Error> {
        Ok(self.0[frame as usize].clone())
    }
}

fn shot(frames: &[Image]) -> InMemory {
    let levels = TrackSettings::default().levels;
    InMemory(
        frames
            .iter()
            .map(|f| Arc::new(Pyramid::new(Grey::from_view(&f.view()), levels, 16)))
            .collect(),
    )
}

fn plate(w: usize, h: usize, colour: impl Fn(Vec2) -> [f32; 3]) -> Image {
    Image::from_fn(RectI::from_size(w, h), 3, |i, j, c| {
        colour(Vec2::new(i as f64 + 0.5, j as f64 + 0.5))[c]
    })
}

/// A pure affine motion: rotation 6°, zoom 1.05, drift (12, 7) over 12 frames.
fn affine() -> ShotMotion {
    ShotMotion {
        frames: 12,
        centre: Vec2::new(96.0, 80.0),
        rotate_deg: 6.0,
        zoom: 1.05,
        drift: Vec2::new(12.0, 7.0),
        bend: Vec2::ZERO,
        bend_at: Vec2::ZERO,
        bend_radius: 1.0,
        wave: Vec2::ZERO,
        wavelength: 1.0,
    }
}

fn track(kinds: &[FeatureKind], keys: &[SideKey], frames: &[Image]) -> Vec<Vec<SideEstimate>> {
    let last = frames.len() as i64 - 1;
    track_side(
        kinds,
        keys,
        (0, last),
        &mut shot(frames),
        &TrackSettings::default(),
        &mut |_, _, _| true,
    )
    .unwrap()
}

#[test]
fn points_follow_an_affine_motion_to_a_tenth_of_a_pixel() {
    let m = affine();
    let photo = plate(192, 160, texture);
    let frames: Vec<Image> = (0..=m.frames)
        .map(|f| shot_frame(&photo, &m, f, 0.0, 0.0, 1))
        .collect();
    let points = [
        Vec2::new(60.5, 50.5),
        Vec2::new(120.5, 100.5),
        Vec2::new(90.5, 70.5),
    ];
    let key = SideKey {
        frame: 0,
        points: points.iter().map(|&p| vec![p]).collect(),
    };
    let out = track(&[FeatureKind::Point; 3], &[key], &frames);
    for (f, frame) in out.iter().enumerate() {
        for (p, e) in points.iter().zip(frame) {
            let err = e.points[0].distance(m.at(f, *p));
            assert!(!e.lost[0] && err < 0.1, "frame {f} {p:?}: error {err}");
        }
    }
}

#[test]
fn a_line_moves_with_the_picture_along_it_even_where_its_ends_see_nothing() {
    // Flat grey but for a textured band across the middle: the line's ends
    // lie on flat grey, where no point tracker can hold on.
    let band = |p: Vec2| {
        if (70.0..130.0).contains(&p.x) {
            texture(p)
        } else {
            [0.5; 3]
        }
    };
    let m = affine();
    let photo = plate(200, 160, band);
    let frames: Vec<Image> = (0..=m.frames)
        .map(|f| shot_frame(&photo, &m, f, 0.0, 0.0, 1))
        .collect();
    let line = vec![Vec2::new(50.0, 80.0), Vec2::new(150.0, 84.0)];
    let key = SideKey {
        frame: 0,
        points: vec![line.clone()],
    };
    let out = track(&[FeatureKind::Line], &[key], &frames);
    for (f, frame) in out.iter().enumerate() {
        let e = &frame[0];
        assert!(!e.lost[0], "frame {f}: the line was lost");
        for (k, p) in line.iter().enumerate() {
            let err = e.points[k].distance(m.at(f, *p));
            assert!(err < 0.5, "frame {f}, end {k}: error {err}");
        }
    }
}

#[test]
fn an_occluded_point_is_flagged_and_never_silently_wrong() {
    let m = ShotMotion {
        frames: 16,
        drift: Vec2::new(16.0, 0.0),
        rotate_deg: 0.0,
        zoom: 1.0,
        ..affine()
    };
    let photo = plate(192, 160, texture);
    let point = Vec2::new(80.5, 80.5);
    let frames: Vec<Image> = (0..=m.frames)
        .map(|f| {
            let mut img = shot_frame(&photo, &m, f, 0.0, 0.0, 1);
            if (6..=8).contains(&f) {
                // A flat card over the point.
                let at = m.at(f, point);
                for j in 0..160 {
                    for i in 0..192 {
                        let d = Vec2::new(i as f64 + 0.5, j as f64 + 0.5) - at;
                        if d.x.abs() < 20.0 && d.y.abs() < 20.0 {
                            let k = (j * 192 + i) * 4;
                            img.data[k..k + 3].copy_from_slice(&[0.2, 0.2, 0.2]);
                        }
                    }
                }
            }
            img
        })
        .collect();
    let key = SideKey {
        frame: 0,
        points: vec![vec![point]],
    };
    let out = track(&[FeatureKind::Point], &[key], &frames);
    let mut flagged = Vec::new();
    for (f, frame) in out.iter().enumerate() {
        let e = &frame[0];
        let err = e.points[0].distance(m.at(f, point));
        assert!(
            e.lost[0] || err < 0.5,
            "frame {f}: {err} px off and not flagged"
        );
        if e.lost[0] {
            flagged.push(f);
        }
    }
    assert_eq!(
        flagged,
        [6, 7, 8],
        "flagged while covered, found again after"
    );
}

#[test]
fn two_keys_are_both_kept_exactly_and_the_sweeps_blend_between_them() {
    let m = affine();
    let photo = plate(192, 160, texture);
    let frames: Vec<Image> = (0..=m.frames)
        .map(|f| shot_frame(&photo, &m, f, 0.0, 0.0, 1))
        .collect();
    let p = Vec2::new(90.5, 70.5);
    // The second key is a user's correction 2 px off the true position.
    let corrected = m.at(8, p) + Vec2::new(2.0, 0.0);
    let keys = [
        SideKey {
            frame: 2,
            points: vec![vec![m.at(2, p)]],
        },
        SideKey {
            frame: 8,
            points: vec![vec![corrected]],
        },
    ];
    let out = track(&[FeatureKind::Point], &keys, &frames);
    assert_eq!(out[2][0].points[0], m.at(2, p));
    assert_eq!(out[8][0].points[0], corrected);
    // Halfway, half the correction; before the first key and after the
    // last, the one sweep there follows the motion.
    let mid = out[5][0].points[0] - m.at(5, p);
    assert!((mid.x - 1.0).abs() < 0.15 && mid.y.abs() < 0.15, "{mid:?}");
    for f in [0, 1, 9, 12] {
        let err = out[f][0].points[0].distance(m.at(f, p));
        let off = if f > 8 { 2.0 } else { 0.0 };
        assert!((err - off).abs() < 0.2, "frame {f}: {err}");
    }
}

#[test]
fn no_key_in_range_is_refused_and_cancel_stops() {
    let photo = plate(64, 64, texture);
    let frames = vec![photo.clone(), photo];
    let none = track_side(
        &[FeatureKind::Point],
        &[],
        (0, 1),
        &mut shot(&frames),
        &TrackSettings::default(),
        &mut |_, _, _| true,
    );
    assert!(matches!(none, Err(Error::Invalid(m)) if m.contains("no keyframe")));
    let key = SideKey {
        frame: 0,
        points: vec![vec![Vec2::new(32.0, 32.0)]],
    };
    let stopped = track_side(
        &[FeatureKind::Point],
        &[key],
        (0, 1),
        &mut shot(&frames),
        &TrackSettings::default(),
        &mut |_, _, _| false,
    );
    assert_eq!(stopped, Err(Error::Cancelled));
}
