//! The Python module's check: the README's `pip install ./python` into a
//! virtual environment under `target/` (maturin comes from PyPI, as on a
//! user's machine), then the module's pytest suite there: its renders held
//! to the `morphfx` command line's through the test bundle, its tools to
//! the commands', its type stubs to the module by mypy's stubtest.
//! `cargo xtask wheel` builds the wheel a pipeline installs.

use std::path::{Path, PathBuf};
use std::process::{exit, Command};

use crate::tools;
use crate::workspace::{root, target_dir};

/// What the tests run with, pinned: what they were written against.
const TEST_TOOLS: [&str; 3] = ["pytest==9.2.0", "mypy==2.4.1", "maturin==1.16.0"];

fn venv() -> Result<PathBuf, String> {
    tools::venv(&target_dir().join("python-venv"), &TEST_TOOLS)
}

/// Runs the check with `morphfx` and `bundle` as the command line the
/// module is held to; says SKIPPED (and why, which it returns) when Python
/// or PyPI cannot be had, and exits the test command on any failure.
pub fn check(morphfx: &Path, bundle: &Path) -> Option<String> {
    let bin = match venv() {
        Ok(bin) => bin,
        Err(why) => {
            println!("python module check: SKIPPED ({why})");
            return Some(format!("the Python module check ({why})"));
        }
    };
    // The README's words, run where the README runs them.
    let install = Command::new(bin.join("pip"))
        .args([
            "install",
            "--quiet",
            "--disable-pip-version-check",
            "./python",
        ])
        .current_dir(root())
        .status()
        .expect("pip runs");
    if !install.success() {
        eprintln!("python module check failed: pip install ./python");
        exit(1);
    }
    let tests = Command::new(bin.join("python"))
        .args([
            "-m",
            "pytest",
            "-q",
            "-p",
            "no:cacheprovider",
            "python/tests",
        ])
        .env("MORPHFX_CLI", morphfx)
        .env("MORPHFX_BUNDLE", bundle)
        .current_dir(root())
        .status()
        .expect("pytest runs");
    if !tests.success() {
        eprintln!("python module check failed: the pytest suite above");
        exit(1);
    }
    let wheels = wheel();
    let abi3 = std::fs::read_dir(&wheels)
        .into_iter()
        .flatten()
        .flatten()
        .map(|w| w.path())
        .find(|w| w.to_string_lossy().contains("-cp39-abi3-"));
    let Some(abi3) = abi3 else {
        eprintln!(
            "python module check failed: no stable-ABI (cp39-abi3) wheel in {}",
            wheels.display()
        );
        exit(1);
    };
    // On x86-64 the wheel carries the plugin's x86-64-v3 build beside the module.
    if cfg!(target_arch = "x86_64") && !wheel_holds(&bin, &abi3, "morphfx/MorphFX-x86-64-v3.so") {
        eprintln!(
            "python module check failed: {} lacks the plugin's x86-64-v3 build",
            abi3.display()
        );
        exit(1);
    }
    println!(
        "python module check: pip install ./python, its tests pass, and `cargo xtask wheel` \
         makes an abi3 wheel with the plugin's x86-64-v3 build"
    );
    None
}

/// Whether the wheel (a zip) at `wheel` holds `name`, asked of Python's
/// own zipfile module.
fn wheel_holds(bin: &Path, wheel: &Path, name: &str) -> bool {
    Command::new(bin.join("python"))
        .args([
            "-c",
            "import sys, zipfile; sys.exit(sys.argv[2] not in zipfile.ZipFile(sys.argv[1]).namelist())",
        ])
        .arg(wheel)
        .arg(name)
        .status()
        .is_ok_and(|s| s.success())
}

/// `cargo xtask wheel`: the module's wheel (release build, abi3: one wheel
/// for CPython 3.9 on) in `target/wheels`.
pub fn wheel() -> PathBuf {
    let bin = venv().unwrap_or_else(|why| {
        eprintln!("cargo xtask wheel: {why}");
        exit(1)
    });
    let out = target_dir().join("wheels");
    let _ = std::fs::remove_dir_all(&out);
    let status = Command::new(bin.join("maturin"))
        .args([
            "build",
            "--release",
            "--quiet",
            "-m",
            "python/Cargo.toml",
            "-o",
        ])
        .arg(&out)
        .current_dir(root())
        .status()
        .expect("maturin runs");
    if !status.success() {
        exit(status.code().unwrap_or(1));
    }
    out
}
