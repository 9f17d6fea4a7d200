//! Feature tracking: accuracy on a real photograph moved by a known motion,
//! lines, occlusion, and `morphfx track` as a user runs it.

mod common;

use std::path::Path;
use std::sync::Arc;

use morphfx::features::FeatureKind;
use morphfx::geom::Vec2;
use morphfx::image::Image;
use morphfx::testing::{corners, shot_frame, ShotMotion};
use morphfx::track::{track_side, Frames, Grey, Pyramid, SideKey, TrackSettings};
use morphfx_harness::io;

/// Venice at dusk (Poly Haven, CC0): 512 × 256, half-float HDR.
fn photo() -> Image {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/venice.exr");
    io::read(&path).expect("the test photo reads").image
}

/// 20 frames: 8° of rotation, 8 % zoom, a drift of (10, -6) px and a local
/// bend of 3 px.
fn motion() -> ShotMotion {
    ShotMotion {
        frames: 20,
        centre: Vec2::new(256.0, 128.0),
        rotate_deg: 8.0,
        zoom: 1.08,
        drift: Vec2::new(10.0, -6.0),
        bend: Vec2::new(3.0, 1.5),
        bend_at: Vec2::new(200.0, 100.0),
        bend_radius: 60.0,
    }
}

struct InMemory(Vec<Arc<Pyramid>>);

impl Frames<morphfx::Error> for InMemory {
    fn pyramid(&mut self, frame: i64) -> morphfx::Result<Arc<Pyramid>> {
        Ok(self.0[frame as usize].clone())
    }
}

fn pyramids(frames: &[Image], settings: &TrackSettings) -> InMemory {
    InMemory(
        frames
            .iter()
            .map(|f| {
                Arc::new(Pyramid::new(
                    Grey::from_view(&f.view()),
                    settings.levels,
                    16,
                ))
            })
            .collect(),
    )
}

fn percentile(sorted: &[f64], p: f64) -> f64 {
    sorted[((sorted.len() - 1) as f64 * p).round() as usize]
}

#[test]
fn corners_of_a_real_photo_under_smooth_non_rigid_motion_flicker_and_grain() {
    let photo = photo();
    let motion = motion();
    let frames: Vec<Image> = (0..=motion.frames)
        .map(|f| shot_frame(&photo, &motion, f, 0.05, 0.02, 7))
        .collect();
    // Corners that stay 24 px inside the frame all shot long.
    let points: Vec<Vec2> = corners(&frames[0], 40, 24.0, 48.0)
        .into_iter()
        .filter(|&p| {
            (0..=motion.frames).all(|f| {
                let q = motion.at(f, p);
                q.x > 24.0 && q.x < 488.0 && q.y > 24.0 && q.y < 232.0
            })
        })
        .take(24)
        .collect();
    assert!(points.len() >= 16, "{} corners", points.len());
    let settings = TrackSettings::default();
    let key = SideKey {
        frame: 0,
        points: points.iter().map(|&p| vec![p]).collect(),
    };
    let kinds = vec![FeatureKind::Point; points.len()];
    let tracked = track_side(
        &kinds,
        &[key],
        (0, motion.frames as i64),
        &mut pyramids(&frames, &settings),
        &settings,
        &mut |_, _, _| true,
    )
    .unwrap();
    let mut errors = Vec::new();
    for (f, estimates) in tracked.iter().enumerate().skip(1) {
        for (p, e) in points.iter().zip(estimates) {
            assert!(!e.lost[0], "corner {p:?} lost at frame {f}");
            errors.push(e.points[0].distance(motion.at(f, *p)));
        }
    }
    errors.sort_by(f64::total_cmp);
    let (median, p90, worst) = (
        percentile(&errors, 0.5),
        percentile(&errors, 0.9),
        errors[errors.len() - 1],
    );
    eprintln!(
        "{} corners x {} frames: median {median:.3} px, 90 % {p90:.3} px, worst {worst:.3} px",
        points.len(),
        motion.frames
    );
    assert!(median <= 0.25, "median {median}");
    assert!(p90 <= 0.5, "90 % {p90}");
    assert!(worst <= 1.0, "worst {worst}");
}

/// The shot written as float EXRs `plate.1001.exr` ... in `dir`; returns
/// the frames.
fn write_shot(dir: &Path, motion: &ShotMotion) -> Vec<Image> {
    use morphfx_harness::io::{ExrPrecision, Plate};
    let photo = photo();
    (0..=motion.frames)
        .map(|f| {
            let frame = shot_frame(&photo, motion, f, 0.05, 0.02, 11);
            let plate = Plate::new(frame.clone(), (512, 256));
            let path = dir.join(format!("plate.{}.exr", 1001 + f));
            io::write(&path, &plate, ExrPrecision::Float).unwrap();
            frame
        })
        .collect()
}

fn scene_json(frame: i64, features: &[(&str, Vec<Vec2>, Vec<Vec2>)]) -> String {
    let pts =
        |v: &[Vec2]| serde_json::Value::from(v.iter().map(|p| vec![p.x, p.y]).collect::<Vec<_>>());
    let list: Vec<serde_json::Value> = features
        .iter()
        .map(|(kind, a, b)| serde_json::json!({"type": kind, "a": pts(a), "b": pts(b)}))
        .collect();
    serde_json::json!({
        "format": "morphfx-scene", "version": 1, "method": "field",
        "keyframes": [{"frame": frame, "features": list}],
    })
    .to_string()
}

fn points_of(v: &serde_json::Value) -> Vec<Vec2> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|p| Vec2::new(p[0].as_f64().unwrap(), p[1].as_f64().unwrap()))
        .collect()
}

#[test]
fn morphfx_track_keys_every_frame_of_a_and_b_and_keeps_the_key() {
    let dir = common::scratch("track-cli");
    let motion = motion();
    let frames = write_shot(&dir, &motion);
    let found = corners(&frames[0], 6, 30.0, 60.0);
    let (p, q, r) = (found[0], found[1], found[2]);
    // A line between two corners on A; on B a point and the line held
    // elsewhere (B is tracked through the same footage).
    let line_a = vec![p, q];
    let scene = dir.join("s.morph.json");
    std::fs::write(
        &scene,
        scene_json(
            1001,
            &[
                ("point", vec![r], vec![p]),
                ("line", line_a.clone(), vec![q, r]),
            ],
        ),
    )
    .unwrap();
    let plates = dir.join("plate.####.exr");
    let out = dir.join("tracked.morph.json");
    let args = [
        "track",
        "--scene",
        scene.to_str().unwrap(),
        "--a",
        plates.to_str().unwrap(),
        "--b",
        plates.to_str().unwrap(),
        "--frames",
        "1001-1021",
        "-o",
        out.to_str().unwrap(),
    ];
    let run = common::run_morphfx(&args);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(run.status.success(), "{stderr}");
    assert!(stderr.contains("feature 2 (line), A: tracked"), "{stderr}");
    let doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    let keys = doc["keyframes"].as_array().unwrap();
    assert_eq!(keys.len(), 21);
    // The key itself, exactly; unmarked.
    assert_eq!(points_of(&keys[0]["features"][1]["a"]), line_a);
    assert!(keys[0]["features"][1].get("track").is_none());
    let mut worst: f64 = 0.0;
    for (f, key) in keys.iter().enumerate() {
        assert_eq!(key["frame"].as_i64(), Some(1001 + f as i64));
        let feats = &key["features"];
        let checks = [
            (&feats[0]["a"], vec![r]),
            (&feats[0]["b"], vec![p]),
            (&feats[1]["a"], line_a.clone()),
            (&feats[1]["b"], vec![q, r]),
        ];
        for (got, keyed) in checks {
            for (g, k) in points_of(got).iter().zip(&keyed) {
                worst = worst.max(g.distance(motion.at(f, *k)));
            }
        }
        if f > 0 {
            let marks = &feats[1]["track"]["a"];
            assert_eq!(
                marks["lost"],
                serde_json::json!([false, false]),
                "frame {f}"
            );
            assert!(marks["confidence"][0].as_f64().unwrap() > 0.9);
        }
    }
    assert!(
        worst < 1.0,
        "worst tracked position {worst} px from the truth"
    );
    // The output is a scene morphfx reads.
    morphfx::scene::Scene::parse(&std::fs::read_to_string(&out).unwrap()).unwrap();
}

#[test]
fn morphfx_track_refuses_bad_input_with_exit_2_and_writes_nothing() {
    let dir = common::scratch("track-bad");
    let motion = ShotMotion {
        frames: 3,
        ..motion()
    };
    write_shot(&dir, &motion);
    let scene = dir.join("s.morph.json");
    let p = Vec2::new(100.5, 100.5);
    std::fs::write(&scene, scene_json(1001, &[("point", vec![p], vec![p])])).unwrap();
    let plates = dir.join("plate.####.exr");
    let out = dir.join("out.morph.json");
    let run = |frames: &str, scene: &Path| {
        let args = [
            "track",
            "--scene",
            scene.to_str().unwrap(),
            "--a",
            plates.to_str().unwrap(),
            "--frames",
            frames,
            "-o",
            out.to_str().unwrap(),
        ];
        let o = common::run_morphfx(&args);
        (
            o.status.code(),
            String::from_utf8_lossy(&o.stderr).into_owned(),
        )
    };
    // No keyframe inside the range.
    let (code, msg) = run("1002-1004", &scene);
    assert_eq!(code, Some(2), "{msg}");
    assert!(
        msg.contains("no keyframe in frames 1002-1004") && msg.contains("1001"),
        "{msg}"
    );
    // A frame missing in the middle: named, before any work.
    std::fs::remove_file(dir.join("plate.1003.exr")).unwrap();
    let (code, msg) = run("1001-1004", &scene);
    assert_eq!(code, Some(2), "{msg}");
    assert!(msg.contains("plate.1003.exr: no such file"), "{msg}");
    // A scene without keyframes.
    let still = dir.join("still.morph.json");
    std::fs::write(
        &still,
        r#"{"format": "morphfx-scene", "version": 1, "features": [{"type": "point", "a": [[1, 2]], "b": [[1, 2]]}]}"#,
    )
    .unwrap();
    let (code, msg) = run("1001-1002", &still);
    assert_eq!(code, Some(2), "{msg}");
    assert!(msg.contains("no keyframes"), "{msg}");
    assert!(!out.exists(), "nothing written on failure");
}
