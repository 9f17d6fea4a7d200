//! Developer tasks: `cargo xtask bundle [--release]`, `cargo xtask demo [-o DIR]`,
//! `cargo xtask test`, `cargo xtask refhost` (the reference host check alone),
//! `cargo xtask farm` (the Open Job Description check alone), `cargo xtask
//! python` (the Python module's check alone), `cargo xtask wheel` (the
//! Python module's wheel).
//! Builds the plugin bundle first so the harness finds it.

use std::path::{Path, PathBuf};
use std::process::{exit, Command};
use std::time::Instant;

mod farm;
mod python;
mod refhost;
mod tools;
mod workspace;

use workspace::{root, target_dir};

/// `cargo run ... --bin morphfx -- --bundle BUNDLE`, ready for a subcommand.
fn morphfx(release: bool, bundle: &Path) -> Command {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let mut c = Command::new(cargo);
    c.args([
        "run",
        "--quiet",
        "--package",
        "morphfx-harness",
        "--bin",
        "morphfx",
    ])
    .current_dir(root());
    if release {
        c.arg("--release");
    }
    c.arg("--").arg("--bundle").arg(bundle);
    c
}

/// The Python module's crate: built by maturin (`pip install ./python`),
/// which links it as an extension module; a plain cargo build of the
/// workspace leaves it out (it would link libpython), and the Python check
/// builds and tests it.
const PYTHON: &str = "morphfx-python";

fn cargo(args: &[&str]) {
    let mut c = cargo_command();
    c.args(args);
    run_cargo(c);
}

/// `cargo build --package morphfx-ofx`, for baseline x86-64 or, with
/// `fast`, for x86-64-v3 in its own target folder. Returns the `.so`.
fn build_plugin(release: bool, fast: bool) -> PathBuf {
    let profile = if release { "release" } else { "debug" };
    let (mut c, dir) = if fast {
        fast_cargo()
    } else {
        (cargo_command(), target_dir())
    };
    c.args(["build", "--package", "morphfx-ofx"]);
    if release {
        c.arg("--release");
    }
    run_cargo(c);
    plugin_binary(&dir, profile)
}

/// The plugin library cargo leaves in target folder `dir` for `profile`.
fn plugin_binary(dir: &Path, profile: &str) -> PathBuf {
    dir.join(profile).join("libmorphfx_ofx.so")
}

fn cargo_command() -> Command {
    let mut c = Command::new(std::env::var("CARGO").unwrap_or_else(|_| "cargo".into()));
    c.current_dir(root());
    c
}

/// Cargo building x86-64-v3 code (AVX2, FMA) in its own target folder
/// (other RUSTFLAGS would otherwise rebuild the baseline's artefacts each
/// time), and that folder.
fn fast_cargo() -> (Command, PathBuf) {
    let dir = target_dir().join("x86-64-v3");
    let flags = std::env::var("RUSTFLAGS").unwrap_or_default();
    let mut c = cargo_command();
    c.env("RUSTFLAGS", format!("{flags} -C target-cpu=x86-64-v3"))
        .env("CARGO_TARGET_DIR", &dir);
    (c, dir)
}

fn run_cargo(mut c: Command) {
    let status = c.status().expect("cargo runs");
    if !status.success() {
        exit(status.code().unwrap_or(1));
    }
}

/// The core's unit tests again as x86-64-v3 code, which is what the
/// bundle's fast build runs: with FMA the resampling kernels take paths
/// (two bilinear pixels per vector) that baseline code leaves out, and
/// their bit-exactness tests must see them. Only the core: its kernels are
/// what the CPU level changes, and a v3 build of the plugin's own tests
/// would compile the OpenFX layer and its bindings once more for nothing.
/// Skipped on a CPU without AVX2 and FMA, which could not run that code.
fn core_tests_fast() {
    if !cpu_runs_fast_build() {
        println!("core tests as x86-64-v3 code: skipped, this CPU lacks AVX2 or FMA");
        return;
    }
    let (mut c, _) = fast_cargo();
    c.args([
        "test",
        "--package",
        "morphfx",
        "--lib",
        "--features",
        "testing",
    ]);
    run_cargo(c);
}

/// The OFX architecture folders a build for this machine goes into. The
/// reference host (and hosts built on it) scans `Linux-x86-64` on every
/// 64-bit Linux, ARM included, so ARM builds go there as well as into
/// `Linux-arm-64`.
fn arch_folders() -> &'static [&'static str] {
    if cfg!(target_arch = "aarch64") {
        &["Linux-arm-64", "Linux-x86-64"]
    } else {
        &["Linux-x86-64"]
    }
}

/// Builds the plugin and lays out `target/bundle/MorphFX.ofx.bundle`: the
/// baseline build as `MorphFX.ofx` and, on x86-64, the x86-64-v3 build beside
/// it, which the baseline build hands over to on CPUs with AVX2 and FMA.
fn bundle(release: bool) -> PathBuf {
    let baseline = build_plugin(release, false);
    let fast = cfg!(target_arch = "x86_64").then(|| build_plugin(release, true));
    lay_out("bundle", &baseline, fast.as_deref())
}

/// Lays out `target/FOLDER/MorphFX.ofx.bundle` from built plugin binaries:
/// `plugin` as `MorphFX.ofx` and, when given, the x86-64-v3 build beside it.
fn lay_out(folder: &str, plugin: &Path, fast: Option<&Path>) -> PathBuf {
    let bundle = target_dir().join(folder).join("MorphFX.ofx.bundle");
    for arch in arch_folders() {
        let bin_dir = bundle.join("Contents").join(arch);
        std::fs::create_dir_all(&bin_dir).expect("create bundle folders");
        std::fs::copy(plugin, bin_dir.join("MorphFX.ofx")).expect("copy the plugin binary");
        let fast_path = bin_dir.join("MorphFX-x86-64-v3.so");
        match fast {
            Some(fast) => {
                std::fs::copy(fast, &fast_path).expect("copy the x86-64-v3 plugin binary");
            }
            // A stale fast build would take over from this one.
            None => {
                let _ = std::fs::remove_file(&fast_path);
            }
        }
    }
    let plist =
        std::fs::read_to_string(root().join("bundle/Info.plist")).expect("bundle/Info.plist");
    std::fs::write(bundle.join("Contents").join("Info.plist"), plist).expect("write Info.plist");
    // Node icons, named by plugin identifier as hosts look them up.
    let resources = bundle.join("Contents").join("Resources");
    std::fs::create_dir_all(&resources).expect("create Resources");
    for icon in std::fs::read_dir(root().join("bundle/Resources")).expect("bundle/Resources") {
        let icon = icon.expect("list bundle/Resources").path();
        let name = icon.file_name().expect("a file name").to_owned();
        std::fs::copy(&icon, resources.join(name)).expect("copy an icon");
    }
    bundle
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match args.first().map(String::as_str) {
        Some("bundle") => {
            let b = bundle(args.iter().any(|a| a == "--release"));
            println!("bundle: {}", b.display());
        }
        Some("refhost") => {
            refhost::check(&bundle(false));
        }
        Some("farm") => {
            farm::check(&morphfx_binary(), &bundle(false));
        }
        Some("demo") => {
            let b = bundle(true);
            let status = morphfx(true, &b)
                .arg("demo")
                .args(&args[1..])
                .status()
                .expect("cargo runs");
            if !status.success() {
                exit(status.code().unwrap_or(1));
            }
        }
        Some("python") => {
            let morphfx = morphfx_binary();
            python::check(&morphfx, &bundle(false));
        }
        Some("wheel") => {
            println!("wheel: {}", python::wheel().display());
        }
        Some("test") => test(&args[1..]),
        _ => {
            eprintln!(
                "usage: cargo xtask bundle [--release] | demo [-o DIR] | test \
                    [cargo test args] | refhost | farm | python | wheel"
            );
            exit(2);
        }
    }
}

/// The README's test command: every test, then the checks against tools
/// and hosts we did not write.
fn test(cargo_args: &[String]) {
    let started = Instant::now();
    let b = timed("build", build_for_tests);
    // Tests find the bundle through this variable.
    unsafe_env("MORPHFX_BUNDLE", &b);
    let mut skipped = timed("tools", ensure_tools);
    let mut run = vec!["test", "--workspace", "--exclude", PYTHON];
    run.extend(cargo_args.iter().map(String::as_str));
    timed("cargo test", || cargo(&run));
    timed("core tests as x86-64-v3 code", core_tests_fast);
    timed("release concurrency", || release_concurrency(&b));
    timed("cargo doc", docs);
    skipped.extend(timed("reference host", || refhost::check(&b)));
    let morphfx = dev_morphfx();
    skipped.extend(timed("farm", || farm::check(&morphfx, &b)));
    skipped.extend(timed("python module", || python::check(&morphfx, &b)));
    timed("cmake install", || cmake_install_check(&morphfx));
    timed("cargo install", || morphfx_install_check(&b));
    summary(&skipped);
    let s = started.elapsed().as_secs();
    println!("xtask test: {} min {} s in all", s / 60, s % 60);
}

/// Runs `step`, then says how long it took: where a run's time goes.
fn timed<T>(what: &str, step: impl FnOnce() -> T) -> T {
    let started = Instant::now();
    let out = step();
    println!(
        "xtask test: {what}: {:.0} s",
        started.elapsed().as_secs_f64()
    );
    out
}

/// The outside tools tests run, installed where this machine can; each
/// one present is required of its test (`MORPHFX_REQUIRE_TOOLS`), so a
/// test cannot skip what is there. What cannot be had is returned, for
/// the summary.
fn ensure_tools() -> Vec<String> {
    let tools: [(&str, &[&str], &[&str], &str); 3] = [
        (
            "oiiotool",
            &["--version"],
            &["openimageio-tools"],
            "the EXR cross-check",
        ),
        (
            "qemu-x86_64",
            &["--version"],
            &["qemu-user"],
            "the emulated-CPU run",
        ),
        (
            "cmake",
            &["--version"],
            &["cmake"],
            "the CMake install check",
        ),
    ];
    let mut present = Vec::new();
    let mut skipped = Vec::new();
    for (tool, probe, packages, what) in tools {
        if tools::runs(tool, probe)
            || (tools::apt_install(packages, what) && tools::runs(tool, probe))
        {
            present.push(tool);
        } else {
            println!("note: {tool} unavailable; {what} will be skipped");
            skipped.push(format!("{what} ({tool} not installed)"));
        }
    }
    // SAFETY: single-threaded here, before cargo is spawned.
    unsafe { std::env::set_var("MORPHFX_REQUIRE_TOOLS", present.join(",")) };
    skipped
}

/// The last lines of a test run: every check that did not run, and why.
/// Under `CI=true` a check skipped on a machine that could have installed
/// its tool (root, apt-get) fails the run: a green run there has run
/// everything.
fn summary(skipped: &[String]) {
    if skipped.is_empty() {
        println!("skipped: nothing; every check ran");
        return;
    }
    println!("skipped:");
    for s in skipped {
        println!("  - {s}");
    }
    let ci = std::env::var("CI").is_ok_and(|v| v == "true");
    if skips_fail(skipped, ci, tools::can_apt()) {
        eprintln!("under CI=true on a machine that installs with apt-get, nothing may be skipped");
        exit(1);
    }
}

/// Whether skipped checks fail the run: under CI, where the machine could
/// have installed what they need.
fn skips_fail(skipped: &[String], ci: bool, can_apt: bool) -> bool {
    !skipped.is_empty() && ci && can_apt
}

/// Builds what the tests run and lays out the dev bundle: the workspace's
/// test build (one cargo call: cargo unifies features over the packages
/// and targets of a call, and the test targets' dev-dependencies change
/// them, so building the plugin alone and then the tests compiled the
/// core, the plugin and the `morphfx` binary twice), and beside its plugin
/// the release x86-64-v3 build, which CPUs with AVX2 and FMA hand over to.
/// That release build is the one users' hosts run on such CPUs, and the
/// same artefact the CMake install check and the release concurrency check
/// use: the plugin is compiled three times in a cold run (v3 release,
/// baseline dev, baseline release for CMake), not four.
fn build_for_tests() -> PathBuf {
    let fast = cfg!(target_arch = "x86_64").then(|| build_plugin(true, true));
    cargo(&[
        "build",
        "--workspace",
        "--exclude",
        PYTHON,
        "--lib",
        "--bins",
        "--tests",
    ]);
    let baseline = plugin_binary(&target_dir(), "debug");
    lay_out("bundle", &baseline, fast.as_deref())
}

/// The `morphfx` binary of the dev profile, built if need be.
fn morphfx_binary() -> PathBuf {
    cargo(&[
        "build",
        "--quiet",
        "--package",
        "morphfx-harness",
        "--bin",
        "morphfx",
    ]);
    dev_morphfx()
}

/// Where the dev profile's `morphfx` binary lies (the test build makes it).
fn dev_morphfx() -> PathBuf {
    target_dir().join("debug").join("morphfx")
}

/// The concurrency test on the plugin built in the release profile:
/// optimised code reorders and inlines more, and has no overflow checks, so
/// races and arithmetic a debug build hides show here. Where this CPU runs
/// the bundle's x86-64-v3 build, the dev bundle already hands over to its
/// release build and the test run's concurrency test ran on it; elsewhere
/// the baseline release build is made (the one the CMake check reuses) and
/// the test is run again on it.
fn release_concurrency(dev_bundle: &Path) {
    if cpu_runs_fast_build() {
        println!(
            "release concurrency: ran in the test run (this CPU runs the bundle's release \
             x86-64-v3 build)"
        );
        return;
    }
    let plugin = build_plugin(true, false);
    let b = lay_out("bundle-release", &plugin, None);
    unsafe_env("MORPHFX_BUNDLE", &b);
    // `--workspace`, as the test build: the same features, nothing rebuilt.
    cargo(&[
        "test",
        "--workspace",
        "--exclude",
        PYTHON,
        "--test",
        "concurrency",
    ]);
    unsafe_env("MORPHFX_BUNDLE", dev_bundle);
}

/// Whether this CPU has AVX2 and FMA, so that the bundle runs its x86-64-v3
/// build here.
fn cpu_runs_fast_build() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma")
    }
    #[cfg(not(target_arch = "x86_64"))]
    false
}

/// `cargo doc --no-deps` with rustdoc's warnings denied: a broken link or
/// a malformed doc comment fails the tests like a failing test does.
///
/// The harness's `morphfx` binary and the core library share a doc folder
/// (cargo's known collision, rust-lang/cargo#6313), and in one invocation
/// two rustdocs writing it at once can fail on each other's files. So the
/// harness goes first on its own, then the rest, whose core library docs
/// are the ones left in `target/doc/morphfx`.
fn docs() {
    let flags = std::env::var("RUSTDOCFLAGS").unwrap_or_default();
    let parts: [&[&str]; 2] = [
        &["--package", "morphfx-harness"],
        &[
            "--workspace",
            "--exclude",
            "morphfx-harness",
            "--exclude",
            PYTHON,
        ],
    ];
    for part in parts {
        let mut c = cargo_command();
        c.args(["doc", "--no-deps", "--quiet"])
            .args(part)
            .env("RUSTDOCFLAGS", format!("{flags} -D warnings"));
        let status = c.status().expect("cargo runs");
        if !status.success() {
            eprintln!("cargo doc: rustdoc found the problems above");
            exit(status.code().unwrap_or(1));
        }
    }
    println!("cargo doc: documentation builds with no warnings");
}

/// `cmake -S . -B build && cmake --build build && cmake --install build --prefix P`
/// must leave a bundle under `P/OFX/Plugins` that a host can load: checked by
/// listing its plugins through the C ABI with `morphfx` (the dev binary the
/// tests ran). cargo builds into the workspace's `target`, where the release
/// concurrency check left the x86-64-v3 plugin, rather than compiling both
/// release plugins afresh in the build folder.
fn cmake_install_check(morphfx: &Path) {
    if !tools::runs("cmake", &["--version"]) {
        // ensure_tools puts it in the summary.
        println!("cmake install check: skipped (cmake is not installed)");
        return;
    }
    let dir = target_dir().join("cmake-check");
    let _ = std::fs::remove_dir_all(dir.join("prefix"));
    let (build, prefix) = (dir.join("build"), dir.join("prefix"));
    let run = |args: &[&std::ffi::OsStr]| {
        let status = Command::new("cmake")
            .args(args)
            .current_dir(root())
            .status()
            .expect("cmake runs");
        if !status.success() {
            eprintln!("cmake install check failed: cmake {args:?}");
            exit(1);
        }
    };
    let cargo_target = format!("-DMORPHFX_TARGET_DIR={}", target_dir().display());
    run(&[
        "-S".as_ref(),
        ".".as_ref(),
        "-B".as_ref(),
        build.as_os_str(),
        cargo_target.as_ref(),
    ]);
    run(&["--build".as_ref(), build.as_os_str()]);
    run(&[
        "--install".as_ref(),
        build.as_os_str(),
        "--prefix".as_ref(),
        prefix.as_os_str(),
    ]);
    let installed = prefix.join("OFX/Plugins/MorphFX.ofx.bundle");
    let out = Command::new(morphfx)
        .arg("--bundle")
        .arg(&installed)
        .arg("plugins")
        .output()
        .expect("morphfx runs");
    let listing = String::from_utf8_lossy(&out.stdout);
    if !out.status.success()
        || !listing.contains("net.morphfx.Morph")
        || !listing.contains("net.morphfx.Warp")
        || !installed
            .join("Contents/Resources/net.morphfx.Morph.png")
            .is_file()
    {
        eprintln!(
            "cmake install check failed: {} lists\n{listing}{}",
            installed.display(),
            String::from_utf8_lossy(&out.stderr)
        );
        exit(1);
    }
    println!(
        "cmake install check: {} loads and lists both plugins",
        installed.display()
    );
}

/// The README's `cargo install --path harness`, into a prefix of its own
/// (the dev profile, in the workspace's target folder, so it reuses what
/// the tests built): the installed command, run from elsewhere, finds the
/// bundle in `bundle`'s folder through `OFX_PLUGIN_PATH` and lists both
/// plugins.
fn morphfx_install_check(bundle: &Path) {
    let prefix = target_dir().join("install-check");
    let _ = std::fs::remove_dir_all(&prefix);
    let mut c = cargo_command();
    c.args([
        "install", "--quiet", "--locked", "--debug", "--path", "harness", "--root",
    ])
    .arg(&prefix)
    .env("CARGO_TARGET_DIR", target_dir());
    run_cargo(c);
    let installed = prefix.join("bin").join("morphfx");
    let folder = bundle.parent().expect("the bundle lies in a folder");
    let out = Command::new(&installed)
        .arg("plugins")
        .env("OFX_PLUGIN_PATH", folder)
        .current_dir(&prefix)
        .output()
        .expect("the installed morphfx runs");
    let listing = String::from_utf8_lossy(&out.stdout);
    if !out.status.success() || !listing.contains("net.morphfx.Morph") {
        eprintln!(
            "morphfx install check failed: {} lists\n{listing}{}",
            installed.display(),
            String::from_utf8_lossy(&out.stderr)
        );
        exit(1);
    }
    println!(
        "morphfx install check: cargo install --path harness gives {}, which finds the \
         bundle through OFX_PLUGIN_PATH",
        installed.display()
    );
}

fn unsafe_env(key: &str, value: &Path) {
    // SAFETY: single-threaded here: setting the variable before spawning cargo is sound.
    unsafe { std::env::set_var(key, value) };
}

#[cfg(test)]
mod tests {
    use super::skips_fail;

    #[test]
    fn a_skipped_check_fails_only_under_ci_where_apt_could_have_helped() {
        let one = ["the EXR cross-check (oiiotool not installed)".to_string()];
        assert!(skips_fail(&one, true, true));
        assert!(!skips_fail(&one, false, true));
        assert!(!skips_fail(&one, true, false));
        assert!(!skips_fail(&[], true, true));
    }
}
