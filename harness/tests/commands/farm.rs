//! What `morphfx` gives a render farm: `--extra-args` (how a job template
//! passes a job's further options) and `morphfx job openjd`'s job bundles,
//! through the binary. The bundles are run by the Open Job Description
//! runtime itself in `cargo xtask test` (xtask/src/farm.rs).

use crate::common;

use std::path::Path;

use morphfx::geom::RectI;
use morphfx::image::Image;
use morphfx_harness::io::{self, ExrPrecision, Plate};

const SCENE: &str = r#"{"format": "morphfx-scene", "version": 1, "method": "field",
  "features": [{"type": "line", "a": [[10, 10], [40, 10]], "b": [[14, 6], [44, 8]]}]}"#;

fn shot(dir: &Path) {
    let img = Image::from_fn(RectI::from_size(48, 32), 4, |i, j, c| {
        ((i * 3 + j * 5 + c as i32) % 17) as f32 / 16.0
    });
    io::write(
        &dir.join("a.exr"),
        &Plate::new(img, (48, 32)),
        ExrPrecision::Float,
    )
    .unwrap();
    std::fs::write(dir.join("s.morph.json"), SCENE).unwrap();
}

fn s(p: &Path) -> String {
    p.to_string_lossy().into_owned()
}

#[test]
fn extra_args_are_the_options_they_spell() {
    let d = common::scratch("extra-args");
    shot(&d);
    let warp = |out: &str, extra: &[&str]| {
        let mut args = vec![
            "warp".to_owned(),
            "--scene".into(),
            s(&d.join("s.morph.json")),
            "--input".into(),
            s(&d.join("a.exr")),
            "-o".into(),
            s(&d.join(out)),
        ];
        args.extend(extra.iter().map(|e| e.to_string()));
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let out = common::run_morphfx(&args);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
    };
    warp("spelt.exr", &["--t", "0.3", "--half"]);
    warp("extra.exr", &["--extra-args", " --t 0.3  --half "]);
    warp("empty.exr", &["--t", "0.3", "--half", "--extra-args", ""]);
    let read = |f: &str| std::fs::read(d.join(f)).unwrap();
    assert_eq!(read("spelt.exr"), read("extra.exr"));
    assert_eq!(read("spelt.exr"), read("empty.exr"));
    // And they are not a no-op: t = 0.3 moves pixels, half halves the file.
    warp("plain.exr", &[]);
    assert_ne!(read("spelt.exr"), read("plain.exr"));
}

#[test]
fn a_job_bundle_holds_the_command_line_as_the_template_takes_it() {
    let d = common::scratch("job-bundle");
    shot(&d);
    let job = d.join("job");
    let out = common::run_morphfx(&[
        "job",
        "openjd",
        "-o",
        &s(&job),
        "--chunk-size",
        "4",
        "--",
        "warp",
        "--scene",
        &s(&d.join("s.morph.json")),
        "--input",
        &s(&d.join("a.exr")),
        "--frames",
        "1-9:2",
        "--t",
        "0.3",
        "--mask",
        "shot/mask.exr",
        "-o",
        &s(&d.join("out.####.exr")),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // The project's own template, unchanged.
    let template = std::fs::read_to_string(job.join("template.yaml")).unwrap();
    let ours = Path::new(env!("CARGO_MANIFEST_DIR")).join("../farm/openjd/warp.template.yaml");
    assert_eq!(template, std::fs::read_to_string(ours).unwrap());
    // The values as openjd reads them: absolute paths, the options the
    // template has no parameter for as extra arguments.
    let values: serde_json::Value =
        serde_json::from_slice(&std::fs::read(job.join("openjd_parameters.json")).unwrap())
            .unwrap();
    assert_eq!(values["Frames"], "1-9:2");
    assert_eq!(values["ChunkSize"], 4);
    assert_eq!(values["ChunkTargetRuntime"], 0);
    // A file among them is made absolute too: workers start elsewhere.
    let mask = std::path::absolute("shot/mask.exr").unwrap();
    let extra = format!("--t 0.3 --mask {}", mask.display());
    assert_eq!(values["ExtraArgs"], extra.as_str());
    assert_eq!(values["Morphfx"], "morphfx");
    assert_eq!(values["Input"], s(&d.join("a.exr")));
    assert_eq!(values["Output"], s(&d.join("out.####.exr")));
    assert!(Path::new(values["Scene"].as_str().unwrap()).is_absolute());
    // And as Deadline Cloud reads them.
    let deadline = std::fs::read_to_string(job.join("parameter_values.yaml")).unwrap();
    assert!(deadline.starts_with("parameterValues:\n  - name: Morphfx\n    value: \"morphfx\"\n"));
    assert!(deadline.contains(&format!("  - name: ExtraArgs\n    value: \"{extra}\"\n")));
}

#[test]
fn a_job_no_template_can_carry_is_refused_and_nothing_is_written() {
    let d = common::scratch("job-refused");
    let job = d.join("job");
    let j = s(&job);
    for (command, why) in [
        (
            &["morph", "--scene", "s", "--a", "a", "--b", "b", "-o", "o"][..],
            "needs --frames",
        ),
        (
            &[
                "warp", "--scene", "s", "--a", "a", "--input", "i", "--frames", "1", "-o", "o",
            ],
            "--a is not an option",
        ),
        (&["track", "--scene", "s"], "a farm job runs morph or warp"),
        (
            &[
                "morph", "--scene", "s", "--a", "a", "--b", "b", "--frames", "1-3x0", "-o", "o",
            ],
            "the step must be 1 or more",
        ),
        (
            &[
                "morph", "--scene", "s", "--a", "a", "--b", "b", "--frames", "1", "-o", "o",
                "--view", "stmap a",
            ],
            "holds white space",
        ),
        (
            &[
                "morph", "--scene", "s", "--scene", "t", "--a", "a", "--b", "b", "--frames", "1",
                "-o", "o",
            ],
            "--scene is given twice",
        ),
    ] {
        let mut args = vec!["job", "openjd", "-o", &j, "--"];
        args.extend(command);
        let out = common::run_morphfx(&args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{command:?}: {err}");
        assert!(err.contains(why), "{command:?}: {err}");
        assert!(!job.exists(), "{command:?} wrote {}", job.display());
    }
    let out = common::run_morphfx(&[
        "job",
        "openjd",
        "-o",
        &j,
        "--chunk-size",
        "0",
        "--",
        "warp",
        "--scene",
        "s",
        "--input",
        "i",
        "--frames",
        "1",
        "-o",
        "o",
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("--chunk-size must be at least 1"), "{err}");
    assert!(!job.exists());
}

/// What a worker would refuse is refused at submission, nothing written:
/// a scene that is not there, a param the node does not have, a value out
/// of its range, a shot written to one file. A stepped range in OpenCue's
/// and Nuke's form is written in the form OpenJD reads.
#[test]
fn a_job_is_checked_as_a_worker_would_before_it_is_written() {
    let d = common::scratch("job-checked");
    shot(&d);
    let job = d.join("job");
    let (scene, a) = (s(&d.join("s.morph.json")), s(&d.join("a.exr")));
    let out = s(&d.join("out.####.exr"));
    let submit = |extra: &[&str], frames: &str, output: &str| {
        let mut args = vec![
            "job",
            "openjd",
            "-o",
            job.to_str().unwrap(),
            "--",
            "warp",
            "--scene",
        ];
        args.extend([extra.first().copied().unwrap_or(&scene)]);
        args.extend(["--input", &a, "--frames", frames, "-o", output]);
        args.extend(extra.iter().skip(1));
        common::run_morphfx(&args)
    };
    let missing = s(&d.join("nowhere.morph.json"));
    for (extra, output, why) in [
        (vec![missing.as_str()], out.as_str(), "nowhere.morph.json"),
        (
            vec![scene.as_str(), "--param", "no_such=1"],
            &out,
            "no_such",
        ),
        (vec![scene.as_str(), "--param", "mix=7"], &out, "mix"),
        (
            vec![scene.as_str()],
            &s(&d.join("one.exr")),
            "would overwrite one file",
        ),
    ] {
        let r = submit(&extra, "1001-1011x5", output);
        let err = String::from_utf8_lossy(&r.stderr);
        assert_eq!(r.status.code(), Some(2), "{extra:?}: {err}");
        assert!(err.contains(why), "{extra:?}: {err}");
        assert!(!job.exists(), "{extra:?} wrote the job");
    }
    // Paths reach the workers absolute and without `..`.
    let roundabout = format!(
        "{}/../{}/out.####.exr",
        d.display(),
        d.file_name().unwrap().to_string_lossy()
    );
    let r = submit(&[&scene], "1001-1011x5", &roundabout);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let values: serde_json::Value =
        serde_json::from_slice(&std::fs::read(job.join("openjd_parameters.json")).unwrap())
            .unwrap();
    assert_eq!(values["Frames"], "1001-1011:5");
    assert_eq!(values["Output"], out.as_str());
}
