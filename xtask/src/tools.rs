//! The outside tools the test command uses, and installing them.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

/// Whether `tool args` runs and succeeds.
pub fn runs(tool: &str, args: &[&str]) -> bool {
    Command::new(tool)
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success())
}

/// Whether this machine installs packages with apt-get (root, Debian
/// family).
pub fn can_apt() -> bool {
    let is_root = Command::new("id")
        .arg("-u")
        .output()
        .is_ok_and(|o| o.stdout.starts_with(b"0"));
    is_root && runs("apt-get", &["--version"])
}

/// Installs `packages` with apt-get when this machine can, saying why;
/// false when it cannot or the install failed.
pub fn apt_install(packages: &[&str], why: &str) -> bool {
    if !can_apt() {
        return false;
    }
    println!("installing {} for {why} (apt-get)...", packages.join(" "));
    let apt = |args: &[&str]| {
        Command::new("apt-get")
            .args(args)
            .env("DEBIAN_FRONTEND", "noninteractive")
            .stdout(Stdio::null())
            .status()
            .is_ok_and(|s| s.success())
    };
    let mut install = vec!["install", "-y", "-qq"];
    install.extend_from_slice(packages);
    // A fresh machine may need its package lists first.
    apt(&install) || (apt(&["update", "-qq"]) && apt(&install))
}

/// A Python virtual environment at `venv` with `packages` installed by
/// pip (made afresh when the list changed); its `bin` folder. `Err` says
/// why not: no python3, or pip could not install (PyPI unreachable?).
pub fn venv(venv: &Path, packages: &[&str]) -> Result<PathBuf, String> {
    let bin = venv.join("bin");
    let pinned = venv.join("pinned.txt");
    let wanted = packages.join("\n");
    if bin.join("python").is_file() && std::fs::read_to_string(&pinned).is_ok_and(|p| p == wanted) {
        return Ok(bin);
    }
    if !runs("python3", &["--version"]) {
        return Err("no python3".into());
    }
    let _ = std::fs::remove_dir_all(venv);
    let made = Command::new("python3")
        .args(["-m", "venv"])
        .arg(venv)
        .output()
        .map_err(|e| format!("python3 -m venv: {e}"))?;
    if !made.status.success() {
        return Err(format!(
            "python3 -m venv failed: {}",
            String::from_utf8_lossy(&made.stderr).trim()
        ));
    }
    println!(
        "installing {} into {} (pip)...",
        packages.join(" "),
        venv.display()
    );
    let pip = Command::new(bin.join("pip"))
        .args(["install", "--quiet", "--disable-pip-version-check"])
        .args(packages)
        .output()
        .map_err(|e| format!("pip: {e}"))?;
    if !pip.status.success() {
        return Err(format!(
            "pip could not install {} (PyPI unreachable?): {}",
            packages.join(" "),
            String::from_utf8_lossy(&pip.stderr).trim()
        ));
    }
    std::fs::write(&pinned, wanted).map_err(|e| format!("{}: {e}", pinned.display()))?;
    Ok(bin)
}
