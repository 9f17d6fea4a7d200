//! The farm check: the Open Job Description templates in `farm/openjd/`,
//! validated and run by the reference runtime (`openjd-cli` from PyPI, in a
//! virtual environment under `target/`) exactly as a farm worker runs them,
//! a 12-frame shot in chunks of 5 held pixel for pixel (byte for byte) to
//! one `morphfx` call over the same frames; and the job bundle `morphfx job
//! openjd` writes, run as it says.

use std::path::{Path, PathBuf};
use std::process::{exit, Command, Output};

use crate::tools;
use crate::workspace::{root, target_dir};

/// The reference runtime, pinned: what this check was written against.
const OPENJD: [&str; 3] = [
    "openjd-cli==0.8.0",
    "openjd-model==0.13.0",
    "openjd-sessions==0.13.0",
];

/// Frames of the generated shot, and the chunk size the farm run uses.
const FRAMES: &str = "1-12";
const CHUNK: &str = "5";

/// Runs the check; says SKIPPED (and why, which it returns) when Python or
/// PyPI cannot be had, and exits the test command on any failure.
pub fn check(morphfx: &Path, bundle: &Path) -> Option<String> {
    let openjd = match runtime() {
        Ok(openjd) => openjd,
        Err(why) => {
            println!("farm check (Open Job Description): SKIPPED ({why})");
            return Some(format!("the farm check ({why})"));
        }
    };
    let templates = root().join("farm").join("openjd");
    for name in ["morph", "warp"] {
        let template = templates.join(format!("{name}.template.yaml"));
        expect_ok(
            &run(&openjd, &["check".as_ref(), template.as_os_str()]),
            "openjd check",
        );
    }
    let dir = target_dir().join("farm-check");
    let _ = std::fs::remove_dir_all(&dir);
    let shot = Shot::make(morphfx, bundle, &dir);
    let folder = bundle.parent().expect("the bundle lies in a folder");
    let mut chunks = 0;
    for (node, inputs) in [
        ("morph", vec![("A", shot.a.clone()), ("B", shot.b.clone())]),
        ("warp", vec![("Input", shot.a.clone())]),
    ] {
        let single = dir.join(format!("{node}-single"));
        shot.single(node, &single);
        let farm = dir.join(format!("{node}-farm"));
        let template = templates.join(format!("{node}.template.yaml"));
        let mut params = shot.params(folder, &farm);
        params.extend(inputs);
        let out = openjd_run(&openjd, &template, &params);
        expect_ok(&out, &format!("openjd run {node}"));
        chunks += count_chunks(&out);
        same_frames(&single, &farm, node);
    }
    // Every method: a warm start or cache that carried one frame's solve
    // into the next would make a chunk's first frame differ.
    for method in METHODS {
        let shot = shot.with_method(method, &dir);
        let single = dir.join(format!("{method}-single"));
        shot.single("morph", &single);
        let farm = dir.join(format!("{method}-farm"));
        let mut params = shot.params(folder, &farm);
        params.extend([("A", shot.a.clone()), ("B", shot.b.clone())]);
        let template = templates.join("morph.template.yaml");
        let out = openjd_run(&openjd, &template, &params);
        expect_ok(&out, &format!("openjd run morph, method {method}"));
        chunks += count_chunks(&out);
        same_frames(&single, &farm, method);
    }
    chunks += job_bundle(&openjd, &shot, &dir);
    refusals(
        &openjd,
        &templates.join("morph.template.yaml"),
        &shot,
        folder,
        &dir,
    );
    println!(
        "farm check (Open Job Description {}): both templates valid; a {FRAMES} shot in \
         chunks of {CHUNK} ({chunks} chunks: morph, warp, morph by each of the {} methods, \
         and a `morphfx job openjd` bundle with an extra option) equals one morphfx call \
         byte for byte; a failing chunk and a \
         bad ChunkSize fail the run",
        OPENJD[0],
        METHODS.len()
    );
    None
}

/// `morphfx job openjd` for a morph with an option the template carries as
/// an extra argument (`--half`), run as its bundle says: the same bytes as
/// one call with that option. The chunks it ran.
fn job_bundle(openjd: &Path, shot: &Shot, dir: &Path) -> usize {
    let (job, farm, single) = (
        dir.join("job"),
        dir.join("job-farm"),
        dir.join("job-single"),
    );
    let out = Command::new(&shot.morphfx)
        .arg("--bundle")
        .arg(&shot.bundle)
        .args(["job", "openjd", "--chunk-size", CHUNK, "--morphfx"])
        .arg(&shot.morphfx)
        .arg("-o")
        .arg(&job)
        .args(["--", "morph", "--scene"])
        .arg(&shot.scene)
        .arg("--a")
        .arg(&shot.a)
        .arg("--b")
        .arg(&shot.b)
        .args(["--frames", FRAMES, "--half", "-o"])
        .arg(farm.join("f.####.exr"))
        .output()
        .expect("morphfx runs");
    expect_ok(&out, "morphfx job openjd");
    let params = format!("file://{}", job.join("openjd_parameters.json").display());
    let out = Command::new(openjd)
        .arg("run")
        .arg(job.join("template.yaml"))
        .args(["-p", &params])
        .output()
        .expect("openjd runs");
    expect_ok(&out, "openjd run of the job bundle");
    shot.single_with("morph", &single, &["--half"]);
    same_frames(&single, &farm, "job bundle");
    count_chunks(&out)
}

/// A failing chunk fails the run, and a parameter outside the template's
/// own constraints is refused before anything runs.
fn refusals(openjd: &Path, template: &Path, shot: &Shot, folder: &Path, dir: &Path) {
    let missing = dir.join("missing");
    let mut params = shot.params(folder, &missing);
    params.push(("A", dir.join("no-such-plate.####.exr")));
    params.push(("B", shot.b.clone()));
    let out = openjd_run(openjd, template, &params);
    if out.status.success() {
        fail(
            "openjd run succeeded though every chunk's morphfx call failed",
            &out,
        );
    }
    let mut params = shot.params(folder, &missing);
    params.retain(|(k, _)| *k != "ChunkSize");
    params.push(("ChunkSize", PathBuf::from("0")));
    params.push(("A", shot.a.clone()));
    params.push(("B", shot.b.clone()));
    let out = openjd_run(openjd, template, &params);
    let text = String::from_utf8_lossy(&out.stdout) + String::from_utf8_lossy(&out.stderr);
    if out.status.success() || !text.contains("must be at least 1") {
        fail(
            "openjd run took ChunkSize=0, which the template's minValue forbids",
            &out,
        );
    }
    if missing.exists() && std::fs::read_dir(&missing).is_ok_and(|mut d| d.next().is_some()) {
        eprintln!(
            "farm check FAILED: a refused run wrote into {}",
            missing.display()
        );
        exit(1);
    }
}

/// The methods besides `field` (the bench scene's own), each run on the
/// farm too.
const METHODS: [&str; 6] = ["mesh", "triangles", "thin-plate", "mffd", "hybrid", "auto"];

/// A 3 × 3 mesh on the 96 × 64 shot, keyed at its first and last frame:
/// B's centre node moves.
const MESH: &str = r#""mesh": {"rows": 3, "cols": 3, "keyframes": [
  {"frame": 1, "a": [[0,0],[48,0],[96,0],[0,32],[48,32],[96,32],[0,64],[48,64],[96,64]],
               "b": [[0,0],[48,0],[96,0],[0,32],[53,29],[96,32],[0,64],[48,64],[96,64]]},
  {"frame": 12, "a": [[0,0],[48,0],[96,0],[0,32],[48,32],[96,32],[0,64],[48,64],[96,64]],
                "b": [[0,0],[48,0],[96,0],[0,32],[42,37],[96,32],[0,64],[48,64],[96,64]]}]}"#;

/// The shot both runs render: plate sequences A and B and a keyframed
/// scene, made by `morphfx bench` at a small size.
#[derive(Clone)]
struct Shot {
    morphfx: PathBuf,
    bundle: PathBuf,
    scene: PathBuf,
    a: PathBuf,
    b: PathBuf,
}

impl Shot {
    fn make(morphfx: &Path, bundle: &Path, dir: &Path) -> Shot {
        let out = Command::new(morphfx)
            .arg("--bundle")
            .arg(bundle)
            .args([
                "bench", "--frames", "12", "--width", "96", "--height", "64", "-o",
            ])
            .arg(dir.join("shot"))
            .output()
            .expect("morphfx runs");
        expect_ok(&out, "morphfx bench (making the shot)");
        let plates = dir.join("shot").join("plates");
        Shot {
            morphfx: morphfx.to_path_buf(),
            bundle: bundle.to_path_buf(),
            scene: dir.join("shot").join("bench.morph.json"),
            a: plates.join("a.####.exr"),
            b: plates.join("b.####.exr"),
        }
    }

    /// The shot with its scene rendered by `method` (a mesh added for
    /// `mesh`), written into `dir`.
    fn with_method(&self, method: &str, dir: &Path) -> Shot {
        let text = std::fs::read_to_string(&self.scene).expect("the bench scene");
        let field = r#""method":"field""#;
        if !text.contains(field) {
            eprintln!("farm check FAILED: the bench scene names no field method: {text}");
            exit(1);
        }
        let with = match method {
            "mesh" => format!(r#""method":"mesh",{MESH}"#),
            other => format!(r#""method":"{other}""#),
        };
        let scene = dir.join(format!("{method}.morph.json"));
        std::fs::write(&scene, text.replace(field, &with)).expect("write a scene");
        Shot {
            scene,
            ..self.clone()
        }
    }

    /// One `morphfx` call over every frame, as a user runs it.
    fn single(&self, node: &str, out: &Path) {
        self.single_with(node, out, &[]);
    }

    /// The same with `extra` options.
    fn single_with(&self, node: &str, out: &Path, extra: &[&str]) {
        let mut c = Command::new(&self.morphfx);
        c.arg("--bundle")
            .arg(&self.bundle)
            .arg(node)
            .arg("--scene")
            .arg(&self.scene);
        if node == "morph" {
            c.arg("--a").arg(&self.a).arg("--b").arg(&self.b);
        } else {
            c.arg("--input").arg(&self.a);
        }
        c.args(extra)
            .args(["--frames", FRAMES, "-o"])
            .arg(out.join("f.####.exr"));
        expect_ok(
            &c.output().expect("morphfx runs"),
            &format!("morphfx {node}"),
        );
    }

    /// The job parameters every run shares (inputs aside).
    fn params(&self, plugin_path: &Path, out: &Path) -> Vec<(&'static str, PathBuf)> {
        vec![
            ("Morphfx", self.morphfx.clone()),
            ("PluginPath", plugin_path.to_path_buf()),
            ("Scene", self.scene.clone()),
            ("Output", out.join("f.####.exr")),
            ("Frames", PathBuf::from(FRAMES)),
            ("ChunkSize", PathBuf::from(CHUNK)),
        ]
    }
}

/// `openjd` in a virtual environment under `target/`, installed from PyPI
/// with pinned versions the first time.
fn runtime() -> Result<PathBuf, String> {
    let bin = tools::venv(&target_dir().join("openjd-venv"), &OPENJD)?;
    Ok(bin.join("openjd"))
}

fn run(openjd: &Path, args: &[&std::ffi::OsStr]) -> Output {
    Command::new(openjd)
        .args(args)
        .current_dir(root())
        .output()
        .expect("openjd runs")
}

fn openjd_run(openjd: &Path, template: &Path, params: &[(&str, PathBuf)]) -> Output {
    let mut c = Command::new(openjd);
    c.arg("run").arg(template);
    for (k, v) in params {
        c.arg("-p").arg(format!("{k}={}", v.display()));
    }
    c.current_dir(root()).output().expect("openjd runs")
}

/// How many chunks a local session ran, from its summary.
fn count_chunks(out: &Output) -> usize {
    String::from_utf8_lossy(&out.stdout)
        .lines()
        .find_map(|l| l.trim().strip_prefix("Chunks run:"))
        .and_then(|n| n.trim().parse().ok())
        .unwrap_or(0)
}

/// Every frame of the single run, and no other, written by the farm run
/// with the same bytes.
fn same_frames(single: &Path, farm: &Path, node: &str) {
    let names = |dir: &Path| -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(dir)
            .map(|d| {
                d.flatten()
                    .map(|e| e.file_name().to_string_lossy().into_owned())
                    .collect()
            })
            .unwrap_or_default();
        v.sort();
        v
    };
    let (a, b) = (names(single), names(farm));
    if a.len() != 12 || a != b {
        eprintln!("farm check FAILED ({node}): one call wrote {a:?}, the farm run {b:?}");
        exit(1);
    }
    for f in &a {
        let (x, y) = (std::fs::read(single.join(f)), std::fs::read(farm.join(f)));
        if x.ok() != y.ok() {
            eprintln!("farm check FAILED ({node}): {f} differs between one call and the farm run");
            exit(1);
        }
    }
}

fn expect_ok(out: &Output, what: &str) {
    if !out.status.success() {
        fail(&format!("{what} failed ({})", out.status), out);
    }
}

fn fail(what: &str, out: &Output) -> ! {
    eprintln!("{}", String::from_utf8_lossy(&out.stdout));
    eprintln!("{}", String::from_utf8_lossy(&out.stderr));
    eprintln!("farm check FAILED: {what}");
    exit(1);
}
