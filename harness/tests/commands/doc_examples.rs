//! Every `morphfx` command the README and docs show in a shell block runs as
//! shown and exits 0, in a folder holding the files the commands name (the
//! demo's plates and scene, a face scene, plate sequences); and the pictures
//! in `docs/images` are what the user guide's commands draw today.
//!
//! PERFORMANCE.md's commands are benchmarks, run by hand on 1080p shots:
//! their figures are never pass or fail; the README's `morphfx bench` runs
//! here over 4 of its 48 frames. Synopses (with `[--option]`) live in
//! untagged blocks and are not commands.
//!
//! `MORPHFX_BLESS_DOC_IMAGES=1` writes the pictures the commands drew into
//! `docs/images` instead of comparing: how they are remade after a change
//! to the overlay.

use crate::common;

use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// The docs whose shell blocks are run.
fn docs() -> Vec<PathBuf> {
    let mut docs = vec![root().join("README.md")];
    for entry in std::fs::read_dir(root().join("docs")).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        if name.ends_with(".md") && name != "PERFORMANCE.md" {
            docs.push(path);
        }
    }
    docs.sort();
    docs
}

/// The `morphfx` command lines of `text`'s ```sh blocks: continued lines
/// joined, trailing comments dropped.
fn commands(text: &str) -> Vec<String> {
    let mut found = Vec::new();
    let mut block: Option<String> = None;
    for line in text.lines() {
        match (&mut block, line.trim_start()) {
            (None, l) if l.starts_with("```sh") => block = Some(String::new()),
            (Some(b), l) if l.starts_with("```") => {
                let joined = b.replace("\\\n", " ");
                for cmd in joined.lines() {
                    let cmd = cmd.split(" #").next().unwrap_or("").trim();
                    if cmd.starts_with("morphfx ") {
                        found.push(cmd.split_whitespace().collect::<Vec<_>>().join(" "));
                    }
                }
                block = None;
            }
            (Some(b), _) => {
                b.push_str(line);
                b.push('\n');
            }
            (None, _) => {}
        }
    }
    found
}

#[test]
fn the_parser_finds_commands_and_joins_their_lines() {
    let text =
        "x\n```sh\nmorphfx a \\\n    --b c   # note\ncargo x\n```\n```\nmorphfx [--s]\n```\n";
    assert_eq!(commands(text), vec!["morphfx a --b c"]);
}

/// What the commands name: the demo's output, the face scene (its shapes
/// keyed once at 1001, progress over 1001-1048), single plates and 48-frame
/// sequences of them, the face grid, the bend scene and the real
/// photograph it bends.
fn prepare(dir: &Path, run: &dyn Fn(&[&str])) {
    run(&["demo", "-o", "morphfx-demo"]);
    let plates = dir.join("morphfx-demo/plates");
    for side in ["a", "b"] {
        let plate = plates.join(format!("{side}.exr"));
        std::fs::copy(&plate, dir.join(format!("{side}.exr"))).unwrap();
        for f in 1001..=1048 {
            std::fs::copy(&plate, dir.join(format!("{side}.{f}.exr"))).unwrap();
        }
    }
    let shapes = root().join("docs/examples/face-shapes.morph.json");
    let mut scene: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&shapes).unwrap()).unwrap();
    let features = scene["features"].take();
    let scene = scene.as_object_mut().unwrap();
    scene.remove("features");
    scene.insert(
        "keyframes".into(),
        serde_json::json!([{"frame": 1001, "features": features}]),
    );
    scene.insert("progress".into(), serde_json::json!([[1001, 0], [1048, 1]]));
    std::fs::write(
        dir.join("face.morph.json"),
        serde_json::to_string_pretty(scene).unwrap(),
    )
    .unwrap();
    std::fs::create_dir_all(dir.join("docs/examples")).unwrap();
    std::fs::copy(&shapes, dir.join("docs/examples/face-shapes.morph.json")).unwrap();
    for example in ["bend", "face-grid"] {
        let path = format!("docs/examples/{example}.morph.json");
        std::fs::copy(root().join(&path), dir.join(&path)).unwrap();
    }
    // An object-ID pass as flat colours, one per 40-px block.
    common::colour_plate(&dir.join("ids.exr"), 320, 240, |p| id_colour(p.x, p.y));
    // The real photograph the user guide's suggestions are shown on.
    let venice = "harness/tests/data/venice.exr";
    std::fs::create_dir_all(dir.join("harness/tests/data")).unwrap();
    std::fs::copy(root().join(venice), dir.join(venice)).unwrap();
}

/// The flat colour of the ID block holding canonical position (x, y).
fn id_colour(x: f64, y: f64) -> [f32; 3] {
    const PALETTE: [[f32; 3]; 6] = [
        [0.9, 0.2, 0.2],
        [0.2, 0.7, 0.3],
        [0.2, 0.3, 0.9],
        [0.9, 0.8, 0.2],
        [0.7, 0.3, 0.8],
        [0.2, 0.8, 0.8],
    ];
    let k = (x / 40.0) as usize + 3 * (y / 40.0) as usize;
    PALETTE[k % PALETTE.len()]
}

/// The user guide's ID pictures: nearest keeps every pixel one of the
/// source's colours; bilinear makes colours no block has along borders.
fn check_id_pictures(dir: &Path) {
    let palette: Vec<[u8; 3]> = (0..6)
        .map(|k| {
            let c = id_colour(40.0 * (k % 3) as f64 + 1.0, 40.0 * (k / 3) as f64 + 1.0);
            c.map(|v| (morphfx_harness::io::linear_to_srgb(v) * 255.0).round() as u8)
        })
        .collect();
    let foreign = |name: &str| {
        let img = image::open(dir.join(name)).unwrap().to_rgb8();
        img.pixels()
            .filter(|p| {
                !palette
                    .iter()
                    .any(|c| c.iter().zip(p.0).all(|(a, b)| a.abs_diff(b) <= 1))
            })
            .count()
    };
    assert_eq!(
        foreign("ids-nearest.png"),
        0,
        "nearest: only the source's colours"
    );
    assert!(
        foreign("ids-bilinear.png") > 500,
        "bilinear: blended borders"
    );
}

#[test]
fn every_documented_command_runs_and_the_pictures_are_what_it_draws() {
    let d = common::scratch("doc-examples");
    let bundle = common::bundle_path();
    let folder = bundle.parent().unwrap().to_path_buf();
    let run = |args: &[&str]| {
        let started = std::time::Instant::now();
        let out = Command::new(env!("CARGO_BIN_EXE_morphfx"))
            .args(args)
            .current_dir(&d)
            .env("OFX_PLUGIN_PATH", &folder)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "morphfx {}: {}",
            args.join(" "),
            String::from_utf8_lossy(&out.stderr)
        );
        eprintln!(
            "{:6.1} s  morphfx {}",
            started.elapsed().as_secs_f64(),
            args.join(" ")
        );
    };
    prepare(&d, &run);
    let mut ran = 0;
    for doc in docs() {
        for cmd in commands(&std::fs::read_to_string(&doc).unwrap()) {
            // farm.md's example names a studio's bundle path: this one's.
            let cmd = cmd.replace("/studio/ofx/MorphFX.ofx.bundle", &bundle.to_string_lossy());
            let mut words: Vec<&str> = cmd.split(' ').skip(1).collect();
            if words == ["bench"] {
                // A timing, not a result: its 48 1080p frames (a minute
                // here) shortened to 4, the same code throughout.
                words.extend(["--frames", "4"]);
            }
            run(&words);
            ran += 1;
        }
    }
    assert!(ran >= 15, "only {ran} documented commands found");
    check_id_pictures(&d);
    let bless = std::env::var_os("MORPHFX_BLESS_DOC_IMAGES").is_some();
    let images = root().join("docs/images");
    for entry in std::fs::read_dir(&images).unwrap() {
        let shown = entry.unwrap().path();
        let name = shown.file_name().unwrap().to_owned();
        let drawn = d.join(&name);
        assert!(drawn.is_file(), "no documented command draws {name:?}");
        if bless {
            std::fs::copy(&drawn, &shown).unwrap();
            continue;
        }
        let (a, b) = (
            image::open(&shown).unwrap().to_rgba8(),
            image::open(&drawn).unwrap().to_rgba8(),
        );
        assert_eq!(a.dimensions(), b.dimensions(), "{name:?}");
        let worst = a
            .as_raw()
            .iter()
            .zip(b.as_raw())
            .map(|(x, y)| x.abs_diff(*y))
            .max()
            .unwrap_or(0);
        assert!(
            worst <= 1,
            "docs/images/{name:?} is not what its command draws (off by {worst} code values): \
             remake it with MORPHFX_BLESS_DOC_IMAGES=1"
        );
    }
}

/// The default a user-guide param row states: `(default V`, `` `V` (default``,
/// `` `V` (…, default`` or `V (default)`; `off`/`on` as booleans.
fn stated_default(text: &str) -> Option<String> {
    let word = |s: &str| {
        let v = s.trim().to_string();
        match v.as_str() {
            "off" => "false".to_string(),
            "on" => "true".to_string(),
            "empty" => String::new(),
            _ => v,
        }
    };
    if let Some(k) = text.find("(default ") {
        let rest = &text[k + "(default ".len()..];
        let end = rest
            .find([';', ':', ')', ','])
            .unwrap_or(rest.len())
            .min(rest.find(" each").unwrap_or(rest.len()));
        return Some(word(&rest[..end]));
    }
    let k = text.find("default")?;
    let before = &text[..k];
    // The last `code` before it, if the default's parenthesis follows it.
    if let Some(close) = before.rfind("` (") {
        let open = before[..close].rfind('`')?;
        return Some(word(&before[open + 1..close]));
    }
    let before = before.strip_suffix('(')?.trim_end();
    Some(word(before.rsplit(' ').next()?))
}

#[test]
fn every_default_the_user_guide_states_is_the_nodes() {
    use morphfx_harness::host::props::PropertySet;
    use openfx::sys::generic::core::kOfxPropLabel;
    use openfx::sys::image_effect_v1::param::*;
    let guide = std::fs::read_to_string(root().join("docs/user-guide.md")).unwrap();
    let params = guide.split("## Params").nth(1).unwrap();
    let params = params.split("\n## ").next().unwrap();
    let inst = common::bundle()
        .instance("net.morphfx.Morph", "OfxImageEffectContextGeneral")
        .unwrap();
    let declared = |label: &str| -> Option<(String, &PropertySet)> {
        // Groups share labels with params (Transition › Transition): only
        // params that hold a value count.
        inst.param_names().into_iter().find_map(|(id, kind)| {
            let p = inst.param_props(&id)?;
            let holds = !matches!(
                kind.as_str(),
                "OfxParamTypeGroup" | "OfxParamTypePushButton" | "OfxParamTypePage"
            );
            (holds && p.str(kOfxPropLabel).as_deref() == Some(label)).then_some((id, p))
        })
    };
    let mut checked = 0;
    for row in params.lines().filter(|l| l.starts_with("| **")) {
        let name = row[4..].split("**").next().unwrap();
        let text = row.split(" | ").nth(1).unwrap_or("");
        let Some(stated) = stated_default(text) else {
            continue;
        };
        let last = name.rsplit(" › ").next().unwrap();
        for label in last.split(" / ") {
            let (id, p) = declared(label).unwrap_or_else(|| panic!("no param labelled {label}"));
            let kind = p.str(kOfxParamPropType).unwrap_or_default();
            let actual = match kind.as_str() {
                "OfxParamTypeChoice" => {
                    let k = p.ints(kOfxParamPropDefault)[0] as usize;
                    p.strs(kOfxParamPropChoiceOption)[k].clone()
                }
                "OfxParamTypeBoolean" => (p.ints(kOfxParamPropDefault)[0] == 1).to_string(),
                "OfxParamTypeInteger" => p.ints(kOfxParamPropDefault)[0].to_string(),
                "OfxParamTypeString" => p.strs(kOfxParamPropDefault)[0].clone(),
                _ => p.doubles(kOfxParamPropDefault)[0].to_string(),
            };
            let same = match (stated.parse::<f64>(), actual.parse::<f64>()) {
                (Ok(s), Ok(a)) => (s - a).abs() < 1e-12,
                _ => stated == actual,
            };
            assert!(
                same,
                "{label} ({id}): the guide says {stated}, the node {actual}"
            );
            checked += 1;
        }
    }
    assert!(checked >= 18, "only {checked} defaults found in the guide");
}

#[test]
fn defaults_are_read_from_each_way_the_guide_words_them() {
    for (text, want) in [
        ("in pixels (default 0.05).", "0.05"),
        ("coefficients (default 1 each).", "1"),
        ("in order (default off): about", "false"),
        ("`adaptive` (default) is within", "adaptive"),
        ("`two-pass` (default; the classic", "two-pass"),
        ("`clamp` (edge pixels, default — no", "clamp"),
        ("quads per side; 0 (default) picks", "0"),
    ] {
        assert_eq!(stated_default(text).as_deref(), Some(want), "{text}");
    }
    assert_eq!(stated_default("no such word here"), None);
}
