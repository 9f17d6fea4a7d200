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

mod common;

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
/// sequences of them.
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
