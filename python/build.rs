//! The plugin's x86-64-v3 build beside the module, as the bundle has it
//! beside its baseline build: the plugin this module links hands every
//! render over to it on a CPU with AVX2 and FMA (twice as fast), and runs
//! itself elsewhere. Built when maturin builds the module (a wheel or
//! `pip install`), into its own target folder as `cargo xtask` builds it,
//! and placed where the wheel picks it up (`tool.maturin.include`).

use std::path::{Path, PathBuf};
use std::process::Command;

/// Where the build goes, beside the module in the wheel.
const FAST_BUILD: &str = "morphfx/MorphFX-x86-64-v3.so";

fn main() {
    let here = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").expect("cargo sets it"));
    let placed = here.join(FAST_BUILD);
    for watched in ["../src", "../ofx/src", "../ofx-layer/src", "../Cargo.lock"] {
        println!("cargo:rerun-if-changed={}", here.join(watched).display());
    }
    println!("cargo:rerun-if-env-changed=PYO3_BUILD_EXTENSION_MODULE");
    // Gone (a clean checkout, a deleted file): made again.
    println!("cargo:rerun-if-changed={}", placed.display());
    let x86_64 = std::env::var("CARGO_CFG_TARGET_ARCH").is_ok_and(|a| a == "x86_64");
    // maturin sets this; cargo check, clippy and doc need no plugin.
    let module = std::env::var_os("PYO3_BUILD_EXTENSION_MODULE").is_some();
    if !(x86_64 && module) {
        return;
    }
    let root = here.parent().expect("python/ lies in the workspace");
    let built = build(root);
    std::fs::create_dir_all(placed.parent().expect("a folder")).expect("make python/morphfx");
    std::fs::copy(&built, &placed).expect("place the x86-64-v3 build");
}

/// `cargo build --release -p morphfx-ofx` for x86-64-v3 in the workspace's
/// `target/x86-64-v3` (where `cargo xtask` builds it too); the library.
fn build(root: &Path) -> PathBuf {
    let target = std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| root.join("target"))
        .join("x86-64-v3");
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let status = Command::new(cargo)
        .args(["build", "--release", "--package", "morphfx-ofx"])
        .current_dir(root)
        // This build's own flags and target folder, not the module's.
        .env_remove("CARGO_ENCODED_RUSTFLAGS")
        .env_remove("PYO3_BUILD_EXTENSION_MODULE")
        .env("RUSTFLAGS", "-C target-cpu=x86-64-v3")
        .env("CARGO_TARGET_DIR", &target)
        .status()
        .expect("cargo runs");
    assert!(status.success(), "the plugin's x86-64-v3 build failed");
    target.join("release").join("libmorphfx_ofx.so")
}
