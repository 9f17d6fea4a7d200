//! Developer tasks: `cargo xtask bundle [--release]`, `cargo xtask demo [-o DIR]`,
//! `cargo xtask test`. Builds the plugin bundle first so the harness finds it.

use std::path::{Path, PathBuf};
use std::process::{exit, Command};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("xtask lives in the workspace")
        .to_path_buf()
}

fn cargo(args: &[&str]) {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let status = Command::new(cargo)
        .args(args)
        .current_dir(root())
        .status()
        .expect("cargo runs");
    if !status.success() {
        exit(status.code().unwrap_or(1));
    }
}

/// Builds the cdylib and lays out `target/bundle/MorphFX.ofx.bundle`.
fn bundle(release: bool) -> PathBuf {
    let profile = if release { "release" } else { "debug" };
    let mut args = vec!["build", "--package", "morphfx-ofx"];
    if release {
        args.push("--release");
    }
    cargo(&args);
    let target = std::env::var("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|_| root().join("target"));
    let bundle = target.join("bundle").join("MorphFX.ofx.bundle");
    let bin_dir = bundle.join("Contents").join("Linux-x86-64");
    std::fs::create_dir_all(&bin_dir).expect("create bundle folders");
    std::fs::copy(
        target.join(profile).join("libmorphfx_ofx.so"),
        bin_dir.join("MorphFX.ofx"),
    )
    .expect("copy the plugin binary");
    let plist =
        std::fs::read_to_string(root().join("bundle/Info.plist")).expect("bundle/Info.plist");
    std::fs::write(bundle.join("Contents").join("Info.plist"), plist).expect("write Info.plist");
    bundle
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match args.first().map(String::as_str) {
        Some("bundle") => {
            let b = bundle(args.iter().any(|a| a == "--release"));
            println!("bundle: {}", b.display());
        }
        Some("demo") => {
            let b = bundle(true);
            let mut run = vec![
                "run",
                "--release",
                "--quiet",
                "--package",
                "morphfx-harness",
                "--bin",
                "morphfx",
                "--",
                "--bundle",
            ];
            let b = b.to_string_lossy().into_owned();
            run.push(&b);
            run.push("demo");
            run.extend(args[1..].iter().map(String::as_str));
            cargo(&run);
        }
        Some("test") => {
            let b = bundle(false);
            // Tests find the bundle through this variable.
            unsafe_env("MORPHFX_BUNDLE", &b);
            let mut run = vec!["test", "--workspace"];
            run.extend(args[1..].iter().map(String::as_str));
            cargo(&run);
        }
        _ => {
            eprintln!(
                "usage: cargo xtask bundle [--release] | demo [-o DIR] | test [cargo test args]"
            );
            exit(2);
        }
    }
}

fn unsafe_env(key: &str, value: &Path) {
    // Single-threaded here: setting the variable before spawning cargo is sound.
    unsafe { std::env::set_var(key, value) };
}
