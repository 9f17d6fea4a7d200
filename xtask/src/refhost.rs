//! The reference host check: builds `xtask/refhost` (our small conformance
//! host) on the OpenFX reference host library, HostSupport, from the openfx
//! sources the `openfx-sys` crate carries in the cargo registry, and runs it
//! on the bundle. Hosts built on that library load plugins exactly this way,
//! and it is not our code agreeing with itself.

use std::path::{Path, PathBuf};
use std::process::{exit, Command};

use crate::tools;
use crate::workspace::{root, target_dir};

/// The crate whose package holds the openfx tree (HostSupport included).
const OPENFX_SYS: &str = "openfx-sys-0.1.0";

/// Builds and runs the reference host on `bundle`; exits the test command on
/// any failure, and says plainly when the check (or a part of it) cannot
/// run here: what was skipped, for the test command's summary.
pub fn check(bundle: &Path) -> Vec<String> {
    let built = openfx_tree().and_then(|tree| {
        toolchain()?;
        offscreen_gl();
        build(&tree)
    });
    let exe = match built {
        Ok(exe) => exe,
        Err(Skip(why)) => {
            println!("reference host check: SKIPPED ({why})");
            return vec![format!("the reference host check ({why})")];
        }
    };
    let folder = bundle.parent().expect("the bundle lies in a folder");
    let out = Command::new(&exe)
        .arg(folder)
        .output()
        .expect("the reference host runs");
    let text = String::from_utf8_lossy(&out.stdout) + String::from_utf8_lossy(&out.stderr);
    if !out.status.success() {
        eprintln!("{text}");
        eprintln!("reference host check FAILED ({})", out.status);
        exit(1);
    }
    let skipped: Vec<String> = text
        .lines()
        .filter(|l| l.contains("SKIPPED"))
        .map(str::to_owned)
        .collect();
    for line in &skipped {
        println!("{line}");
    }
    // Our own last line: the plugin may say things on stderr after it.
    let summary = String::from_utf8_lossy(&out.stdout)
        .lines()
        .rev()
        .find(|l| l.starts_with("refhost: "))
        .unwrap_or_default()
        .to_owned();
    println!("reference host check (OpenFX HostSupport): {summary}");
    skipped
}

/// Why the check could not run on this machine.
struct Skip(String);

/// The openfx source tree, fetched into the cargo registry by resolving a
/// throwaway package that depends on `openfx-sys` (its build script, which
/// needs libclang, never runs: nothing is built).
fn openfx_tree() -> Result<PathBuf, Skip> {
    let dir = target_dir().join("refhost").join("sources");
    std::fs::create_dir_all(&dir).expect("create target/refhost/sources");
    let manifest =
        "[package]\nname = \"refhost-sources\"\nversion = \"0.0.0\"\nedition = \"2021\"\n\
         publish = false\n\n[lib]\npath = \"lib.rs\"\n\n[dependencies]\nopenfx-sys = \"=0.1.0\"\n\n\
         [workspace]\n";
    std::fs::write(dir.join("Cargo.toml"), manifest).expect("write the sources manifest");
    std::fs::write(dir.join("lib.rs"), "").expect("write the sources lib.rs");
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let out = Command::new(cargo)
        .args(["metadata", "--format-version", "1", "--manifest-path"])
        .arg(dir.join("Cargo.toml"))
        .output()
        .map_err(|e| Skip(format!("cargo metadata: {e}")))?;
    if !out.status.success() {
        return Err(Skip(format!(
            "could not fetch {OPENFX_SYS}: {}",
            String::from_utf8_lossy(&out.stderr).trim()
        )));
    }
    let json = String::from_utf8_lossy(&out.stdout);
    let manifest_path = json
        .split("\"manifest_path\":\"")
        .skip(1)
        .filter_map(|rest| rest.split('"').next())
        .find(|p| p.contains(OPENFX_SYS))
        .ok_or_else(|| Skip(format!("{OPENFX_SYS} not in cargo metadata")))?;
    let tree = Path::new(manifest_path)
        .parent()
        .expect("a manifest lies in a folder")
        .join("openfx");
    if !tree.join("HostSupport").join("src").is_dir() {
        return Err(Skip(format!("no HostSupport in {}", tree.display())));
    }
    Ok(tree)
}

/// A C++ compiler and expat's headers (HostSupport reads and writes its
/// plugin cache as XML), installed when missing and this machine can.
fn toolchain() -> Result<(), Skip> {
    let ready =
        || tools::runs("c++", &["--version"]) && Path::new("/usr/include/expat.h").is_file();
    if ready()
        || (tools::apt_install(&["g++", "libexpat1-dev"], "the reference host check") && ready())
    {
        Ok(())
    } else {
        Err(Skip(
            "needs a C++ compiler and expat's headers (apt-get install g++ libexpat1-dev)".into(),
        ))
    }
}

/// Mesa's EGL and software GL, for the overlay drawn in an offscreen GL
/// context; installed when missing and this machine can. Without them that
/// one check says SKIPPED and the others run.
fn offscreen_gl() {
    let ready = || {
        Command::new("ldconfig")
            .arg("-p")
            .output()
            .is_ok_and(|o| String::from_utf8_lossy(&o.stdout).contains("libEGL_mesa.so.0"))
    };
    if !ready() {
        let mesa = ["libegl1", "libgl1", "libegl-mesa0", "libgl1-mesa-dri"];
        tools::apt_install(&mesa, "the overlay's OpenGL check");
    }
}

/// Compiles HostSupport once (its sources never change for a version) and
/// our host every time; returns the executable.
fn build(tree: &Path) -> Result<PathBuf, Skip> {
    let out = target_dir().join("refhost");
    let objects = out.join("obj");
    std::fs::create_dir_all(&objects).expect("create target/refhost/obj");
    let includes = [
        tree.join("include"),
        tree.join("HostSupport").join("include"),
    ];
    // The library predates C++17 (dynamic exception specifications).
    let compile = |source: &Path, object: &Path, own: bool| {
        let mut c = Command::new("c++");
        c.args(["-std=c++11", "-O1", "-c"]);
        if own {
            c.args(["-Wall", "-Wno-deprecated"]);
        } else {
            c.arg("-w");
        }
        for i in &includes {
            c.arg("-I").arg(i);
        }
        c.arg(source).arg("-o").arg(object);
        run(c, &format!("compile {}", source.display()));
    };
    let mut sources: Vec<PathBuf> = std::fs::read_dir(tree.join("HostSupport").join("src"))
        .expect("list HostSupport/src")
        .map(|e| e.expect("a HostSupport source").path())
        .filter(|p| p.extension().is_some_and(|e| e == "cpp"))
        .collect();
    sources.sort();
    let object_of = |s: &Path| {
        objects
            .join(s.file_stem().expect("a file name"))
            .with_extension("o")
    };
    let missing: Vec<&PathBuf> = sources.iter().filter(|s| !object_of(s).is_file()).collect();
    if !missing.is_empty() {
        println!(
            "building the OpenFX reference host library ({} files)...",
            missing.len()
        );
    }
    // Two at a time: CI machines have two cores.
    for pair in missing.chunks(2) {
        std::thread::scope(|scope| {
            for s in pair {
                scope.spawn(|| compile(s, &object_of(s), false));
            }
        });
    }
    let own = root().join("xtask").join("refhost");
    let mut linked = Vec::new();
    for name in ["refhost", "glcontext", "main"] {
        let object = out.join(format!("{name}.o"));
        compile(&own.join(format!("{name}.cpp")), &object, true);
        linked.push(object);
    }
    let exe = out.join("morphfx-refhost");
    let mut link = Command::new("c++");
    link.args(&linked)
        .args(sources.iter().map(|s| object_of(s)))
        .args(["-lexpat", "-ldl", "-o"])
        .arg(&exe);
    run(link, "link the reference host");
    Ok(exe)
}

/// Runs a build step; a failure is ours to fix, so it fails the test command.
fn run(mut c: Command, what: &str) {
    let status = c.status().expect("the C++ compiler runs");
    if !status.success() {
        eprintln!("reference host check FAILED: could not {what}");
        exit(1);
    }
}
