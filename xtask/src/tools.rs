//! The outside tools the test command uses, and installing them.

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
