//! Feature tracking: accuracy on a real photograph moved by a known motion,
//! lines, occlusion, and `morphfx track` as a user runs it.

mod common;

use common::{percentile, pyramids};

use std::path::Path;
use std::sync::Arc;

use morphfx::features::FeatureKind;
use morphfx::geom::Vec2;
use morphfx::image::Image;
use morphfx::testing::{corners, shot_frame, ShotMotion};
use morphfx::track::{track_side, SideKey, TrackSettings};
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
        wave: Vec2::ZERO,
        wavelength: 1.0,
    }
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

/// A shot of a textured plate under an affine motion, frames 0 ..= 10, as a
/// host clip that knows its range.
struct Shot {
    frames: Vec<Arc<morphfx_harness::host::Frame>>,
}

impl morphfx_harness::host::FrameSource for Shot {
    fn frame(&self, time: f64) -> Result<Arc<morphfx_harness::host::Frame>, String> {
        self.frames
            .get(time as usize)
            .cloned()
            .ok_or_else(|| format!("no frame {time}"))
    }
    fn range(&self) -> Option<(f64, f64)> {
        Some((0.0, self.frames.len() as f64 - 1.0))
    }
}

fn button_motion() -> ShotMotion {
    ShotMotion {
        frames: 10,
        centre: Vec2::new(96.0, 80.0),
        rotate_deg: 5.0,
        zoom: 1.04,
        drift: Vec2::new(10.0, 6.0),
        bend: Vec2::ZERO,
        bend_at: Vec2::ZERO,
        bend_radius: 1.0,
        wave: Vec2::ZERO,
        wavelength: 1.0,
    }
}

fn shot(depth: &str, motion: &ShotMotion) -> Arc<Shot> {
    covered_shot(depth, motion, |_, _| false)
}

/// As `shot`, flat grey wherever `covered(frame, position)`.
fn covered_shot(
    depth: &str,
    motion: &ShotMotion,
    covered: impl Fn(usize, Vec2) -> bool,
) -> Arc<Shot> {
    let plate = Image::from_fn(morphfx::geom::RectI::from_size(192, 160), 3, |i, j, c| {
        morphfx::testing::texture(Vec2::new(i as f64 + 0.5, j as f64 + 0.5))[c]
    });
    Arc::new(Shot {
        frames: (0..=motion.frames)
            .map(|f| {
                let mut img = shot_frame(&plate, motion, f, 0.0, 0.0, 3);
                for j in 0..160 {
                    for i in 0..192 {
                        if covered(f, Vec2::new(i as f64 + 0.5, j as f64 + 0.5)) {
                            let k = (j * 192 + i) * 4;
                            img.data[k..k + 3].copy_from_slice(&[0.3; 3]);
                        }
                    }
                }
                Arc::new(morphfx_harness::host::Frame::from_image(&img, depth, false))
            })
            .collect(),
    })
}

/// `text` into Scene Text, Track Forward pressed: one write in one undo
/// step; the scene it wrote.
fn track_scene_text(
    inst: &morphfx_harness::host::Instance<'_>,
    text: &str,
) -> morphfx::scene::Scene {
    inst.set_string("scene_text", text).unwrap();
    morphfx_harness::host::params::take_edit_log();
    inst.instance_changed("track_forward", 0.0).unwrap();
    let log = morphfx_harness::host::params::take_edit_log();
    assert_eq!(log, ["begin Track Forward", "set scene_text", "end"]);
    morphfx::scene::Scene::read(&inst.string("scene_text").unwrap()).unwrap()
}

/// A Morph node with the same float shot of `motion` on both sources.
fn morph_on(motion: &ShotMotion) -> morphfx_harness::host::Instance<'static> {
    let inst = common::bundle()
        .instance("net.morphfx.Morph", "OfxImageEffectContextGeneral")
        .unwrap();
    let source = shot("OfxBitDepthFloat", motion);
    inst.connect("SourceA", source.clone()).unwrap();
    inst.connect("SourceB", source).unwrap();
    inst
}

fn point_at(inst: &morphfx_harness::host::Instance<'_>, id: &str, t: f64) -> Vec2 {
    let v = inst.doubles_at(id, t).unwrap();
    Vec2::new(v[0], v[1])
}

#[test]
fn track_forward_keys_both_sides_to_the_end_of_the_clip_with_progress() {
    for depth in ["OfxBitDepthByte", "OfxBitDepthFloat"] {
        let motion = button_motion();
        let inst = common::bundle()
            .instance("net.morphfx.Morph", "OfxImageEffectContextGeneral")
            .unwrap();
        let source = shot(depth, &motion);
        inst.connect("SourceA", source.clone()).unwrap();
        inst.connect("SourceB", source).unwrap();
        inst.set_int("line_count", 1).unwrap();
        let (a, b) = (
            [Vec2::new(60.0, 50.0), Vec2::new(120.0, 95.0)],
            [Vec2::new(70.0, 110.0), Vec2::new(130.0, 60.0)],
        );
        for (id, p) in [
            ("a_start", a[0]),
            ("a_end", a[1]),
            ("b_start", b[0]),
            ("b_end", b[1]),
        ] {
            inst.set_double(&format!("line1_{id}"), &[p.x, p.y], Some(0.0))
                .unwrap();
        }
        morphfx_harness::host::params::take_edit_log();
        inst.instance_changed("track_forward", 0.0).unwrap();
        // One undo step holding a key per end per frame 1 ..= 10.
        let log = morphfx_harness::host::params::take_edit_log();
        assert_eq!(
            log.first().map(String::as_str),
            Some("begin Track Forward"),
            "{log:?}"
        );
        assert_eq!(log.len(), 2 + 4 * 10, "{log:?}");
        for (id, key) in [
            ("a_start", a[0]),
            ("a_end", a[1]),
            ("b_start", b[0]),
            ("b_end", b[1]),
        ] {
            let id = format!("line1_{id}");
            let times = inst.key_times(&id).unwrap();
            assert_eq!(times, (0..=10).map(f64::from).collect::<Vec<_>>(), "{id}");
            for f in 1..=10 {
                let err = point_at(&inst, &id, f as f64).distance(motion.at(f, key));
                assert!(err < 0.3, "{depth} {id} frame {f}: {err} px off");
            }
        }
        let (progress, open) = inst.progress_log();
        assert!(!open, "the progress task was closed");
        assert!(progress.windows(2).all(|w| w[0] < w[1]), "{progress:?}");
        assert_eq!(progress.last(), Some(&1.0));
    }
}

#[test]
fn track_stops_before_the_next_key_goes_backward_and_cancel_keeps_what_was_made() {
    let motion = button_motion();
    let inst = common::bundle()
        .instance("net.morphfx.Warp", "OfxImageEffectContextFilter")
        .unwrap();
    inst.connect("Source", shot("OfxBitDepthFloat", &motion))
        .unwrap();
    inst.set_int("line_count", 1).unwrap();
    let line = [Vec2::new(60.0, 50.0), Vec2::new(120.0, 95.0)];
    for (id, p) in [("a_start", line[0]), ("a_end", line[1])] {
        // Keys at 3 (tracked from) and 8 (a user's, kept).
        for f in [3usize, 8] {
            let q = motion.at(f, p);
            inst.set_double(&format!("line1_{id}"), &[q.x, q.y], Some(f as f64))
                .unwrap();
        }
    }
    inst.instance_changed("track_forward", 3.0).unwrap();
    assert_eq!(
        inst.key_times("line1_a_end").unwrap(),
        [3.0, 4.0, 5.0, 6.0, 7.0, 8.0]
    );
    inst.instance_changed("track_backward", 3.0).unwrap();
    let times = inst.key_times("line1_a_start").unwrap();
    assert_eq!(times, [0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0]);
    for f in [0usize, 1, 2, 5] {
        let err = point_at(&inst, "line1_a_start", f as f64).distance(motion.at(f, line[0]));
        assert!(err < 0.3, "frame {f}: {err}");
    }
    // From 8 to the clip's end, 10: cancel pressed as the first of the two
    // frames reports; its keys stay, frame 10 is never keyed.
    inst.cancel_progress_at(Some(0.3));
    inst.instance_changed("track_forward", 8.0).unwrap();
    let after = inst.key_times("line1_a_end").unwrap();
    assert_eq!(after.last(), Some(&9.0), "{after:?}");
    assert_eq!(inst.progress_log().0.last(), Some(&0.5));
    inst.cancel_progress_at(None);
}

#[test]
fn track_keys_no_further_than_a_line_is_seen_and_names_where_it_lost_it() {
    let motion = button_motion();
    let line = [Vec2::new(60.0, 50.0), Vec2::new(120.0, 95.0)];
    // From frame 6 on, a flat card covers the whole line.
    let card = |f: usize, p: Vec2| f >= 6 && p.x > 40.0 && p.x < 150.0 && p.y > 30.0 && p.y < 125.0;
    let inst = common::bundle()
        .instance("net.morphfx.Warp", "OfxImageEffectContextFilter")
        .unwrap();
    inst.connect("Source", covered_shot("OfxBitDepthFloat", &motion, card))
        .unwrap();
    inst.set_int("line_count", 1).unwrap();
    for (id, p) in [("a_start", line[0]), ("a_end", line[1])] {
        inst.set_double(&format!("line1_{id}"), &[p.x, p.y], Some(0.0))
            .unwrap();
    }
    inst.take_messages();
    inst.instance_changed("track_forward", 0.0).unwrap();
    assert_eq!(
        inst.key_times("line1_a_start").unwrap(),
        [0.0, 1.0, 2.0, 3.0, 4.0, 5.0]
    );
    let said: Vec<String> = inst.take_messages().into_iter().map(|m| m.text).collect();
    assert!(
        said.iter().any(|t| t.contains("line 1 on A at frame 6")),
        "{said:?}"
    );
}

#[test]
fn track_forward_keys_scene_text_shapes_at_every_frame_in_one_write() {
    let motion = button_motion();
    let inst = morph_on(&motion);
    // A static scene: a closed curve through four points, and a point.
    let curve_a = [(60.0, 50.0), (120.0, 55.0), (125.0, 100.0), (65.0, 105.0)];
    let curve_b = [(70.0, 60.0), (110.0, 50.0), (130.0, 95.0), (60.0, 110.0)];
    let json = |pts: &[(f64, f64)]| {
        let v: Vec<String> = pts.iter().map(|(x, y)| format!("[{x}, {y}]")).collect();
        format!("[{}]", v.join(", "))
    };
    let text = format!(
        r#"{{"features": [
            {{"name": "face", "type": "curve", "closed": true, "a": {}, "b": {}}},
            {{"type": "point", "a": [[90, 80]], "b": [[95, 82]]}}
        ]}}"#,
        json(&curve_a),
        json(&curve_b)
    );
    let scene = track_scene_text(&inst, &text);
    let frames: Vec<f64> = scene.keyframes.iter().map(|k| k.frame).collect();
    assert_eq!(frames, (0..=10).map(f64::from).collect::<Vec<_>>());
    let v = |(x, y): (f64, f64)| Vec2::new(x, y);
    let face = &scene.keyframes[0].features[0];
    assert!(face.closed && face.name.as_deref() == Some("face"));
    assert_eq!(face.a, curve_a.map(v), "frame 0 keeps the user's shape");
    let mut worst = 0.0f64;
    for (f, key) in scene.keyframes.iter().enumerate() {
        for (tracked, (a, b)) in [
            (&key.features[0], (&curve_a.map(v)[..], &curve_b.map(v)[..])),
            (
                &key.features[1],
                (&[v((90.0, 80.0))][..], &[v((95.0, 82.0))][..]),
            ),
        ] {
            for (side_points, start) in [(&tracked.a, a), (&tracked.b, b)] {
                for (p, s) in side_points.iter().zip(start) {
                    worst = worst.max(p.distance(motion.at(f, *s)));
                }
            }
        }
    }
    assert!(worst < 0.3, "worst {worst} px off the true motion");
}

/// The Morph node's Suggest Features button: pairs between its two sources
/// at the frame, added to Scene Text after the user's own features (kept
/// exactly), each where the source truly moved, with its confidence; a
/// cancel leaves Scene Text as it was.
#[test]
fn suggest_features_adds_sure_pairs_to_scene_text_and_cancel_adds_none() {
    let shift = Vec2::new(3.0, -2.0);
    let plate = |d: Vec2| {
        let img = Image::from_fn(morphfx::geom::RectI::from_size(192, 160), 3, |i, j, c| {
            let p = Vec2::new(i as f64 + 0.5, j as f64 + 0.5) - d;
            morphfx::testing::texture(p * 1.3)[c]
        });
        let frame = morphfx_harness::host::Frame::from_image(&img, "OfxBitDepthFloat", false);
        Arc::new(common::Still(Arc::new(frame)))
    };
    let inst = common::bundle()
        .instance("net.morphfx.Morph", "OfxImageEffectContextGeneral")
        .unwrap();
    inst.connect("SourceA", plate(Vec2::ZERO)).unwrap();
    inst.connect("SourceB", plate(shift)).unwrap();
    let mine = r#"{"format": "morphfx-scene", "version": 1, "features": [
        {"name": "mine", "type": "point", "a": [[96, 80]], "b": [[99, 78]]}]}"#;
    inst.set_string("scene_text", mine).unwrap();
    inst.set_int("suggest_count", 15).unwrap();

    inst.cancel_progress_at(Some(0.2));
    inst.instance_changed("suggest_features", 0.0).unwrap();
    inst.cancel_progress_at(None);
    assert_eq!(
        inst.string("scene_text").unwrap(),
        mine,
        "a cancel adds nothing"
    );

    inst.instance_changed("suggest_features", 0.0).unwrap();
    let text = inst.string("scene_text").unwrap();
    let scene: serde_json::Value = serde_json::from_str(&text).unwrap();
    let features = scene["features"].as_array().unwrap();
    assert_eq!(features[0]["name"], "mine");
    assert!(features[0].get("confidence").is_none());
    let point = |v: &serde_json::Value| Vec2::new(v[0].as_f64().unwrap(), v[1].as_f64().unwrap());
    let suggested = &features[1..];
    assert!(
        (8..=15).contains(&suggested.len()),
        "{} suggestions",
        suggested.len()
    );
    for f in suggested {
        let c = f["confidence"].as_f64().unwrap();
        assert!((0.5..=1.0).contains(&c), "{f}");
        let (a, b) = (point(&f["a"][0]), point(&f["b"][0]));
        assert!(b.distance(a + shift) < 0.3, "{f}");
        assert!(
            a.distance(Vec2::new(96.0, 80.0)) >= 10.0,
            "{f} on the user's point"
        );
    }
    let (progress, open) = inst.progress_log();
    assert!(!open && progress.last() == Some(&1.0), "{progress:?}");
}

/// Track Forward carries Scene Text's mesh: every interior node keyed at
/// every frame where the picture under it went (the textured plate's
/// nodes are all followed by their own patches), the frozen border where
/// it was, in the same one write as the shapes.
#[test]
fn track_forward_carries_the_grids_nodes_with_the_picture() {
    let motion = button_motion();
    let inst = morph_on(&motion);
    let (rows, cols) = (5usize, 5usize);
    let node = |r: usize, c: usize| Vec2::new(48.0 * c as f64, 40.0 * r as f64);
    let a: Vec<Vec2> = (0..rows * cols).map(|i| node(i / cols, i % cols)).collect();
    // B's middle node a little off A's.
    let mut b = a.clone();
    b[2 * cols + 2] += Vec2::new(6.0, -4.0);
    let list =
        |nodes: &[Vec2]| serde_json::json!(nodes.iter().map(|p| [p.x, p.y]).collect::<Vec<_>>());
    let text = serde_json::json!({"format": "morphfx-scene", "version": 1, "method": "mesh",
        "mesh": {"rows": rows, "cols": cols, "a": list(&a), "b": list(&b)}})
    .to_string();
    let scene = track_scene_text(&inst, &text);
    let frames: Vec<f64> = scene.meshes.iter().map(|m| m.0).collect();
    assert_eq!(frames, (0..=10).map(f64::from).collect::<Vec<_>>());
    let mut worst = 0.0f64;
    for (f, (_, pair)) in scene.meshes.iter().enumerate() {
        for (mesh, start) in [(&pair.a, &a), (&pair.b, &b)] {
            for (i, p) in mesh.nodes().iter().enumerate() {
                let (r, c) = (i / cols, i % cols);
                if r == 0 || c == 0 || r + 1 == rows || c + 1 == cols {
                    assert_eq!(*p, start[i], "border node {i} at frame {f}");
                } else {
                    worst = worst.max(p.distance(motion.at(f, start[i])));
                }
            }
        }
    }
    assert!(worst < 0.3, "worst {worst} px off the true motion");
}
