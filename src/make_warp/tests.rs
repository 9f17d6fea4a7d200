//! The layer's own promises: scattered methods refuse features beyond their
//! reach by name, before any grid is sized.

use super::{toward, MethodSettings, WarpSettings, REACH};
use crate::features::{Feature, Side};
use crate::geom::{RectD, Vec2};
use crate::make_warp::Method;

/// Finite but absurd coordinates (a mutated scene, a stray keyframe) must
/// never size a grid: the methods that solve over the features' span refuse
/// a point beyond their reach of the frame, naming it, at once.
#[test]
fn features_far_outside_the_frame_are_refused_by_name_not_solved() {
    let frame = RectD::new(0.0, 0.0, 96.0, 64.0);
    let near = Feature::point(Vec2::new(30.0, 20.0), Vec2::new(34.0, 22.0));
    for method in [
        Method::ThinPlate,
        Method::Mffd,
        Method::Hybrid,
        Method::Triangles,
    ] {
        let settings = WarpSettings {
            region: Some(frame),
            ..WarpSettings::new(MethodSettings {
                method,
                ..MethodSettings::default()
            })
        };
        for far in [9.2e18, 1e308, -1e18, 96.0 * (1.0 + REACH) + 1.0] {
            let stray = Feature::point(Vec2::new(40.0, 30.0), Vec2::new(far, 30.0)).named("stray");
            let err = toward(&[near.clone(), stray], Side::B, 0.5, &settings)
                .err()
                .unwrap_or_else(|| panic!("{method:?} accepted a point at {far}"));
            let message = err.to_string();
            assert!(message.contains("feature 2 \"stray\""), "{message}");
            assert!(message.contains("B point"), "{message}");
        }
        // Within reach (half a frame outside) still solves.
        let outside = Feature::point(Vec2::new(40.0, 30.0), Vec2::new(-40.0, 30.0));
        assert!(
            toward(&[near.clone(), outside], Side::B, 0.5, &settings).is_ok(),
            "{method:?}"
        );
        // With no frame, the features' own span is bounded instead.
        let no_frame = WarpSettings {
            region: None,
            ..settings.clone()
        };
        let stray = Feature::point(Vec2::new(40.0, 30.0), Vec2::new(1e9, 30.0));
        let err = toward(&[near.clone(), stray], Side::B, 0.5, &no_frame).err();
        assert!(
            err.is_some_and(|e| e.to_string().contains("span")),
            "{method:?}"
        );
    }
}
