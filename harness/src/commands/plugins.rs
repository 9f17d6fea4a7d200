//! `morphfx plugins`: the bundle's plugins and the binary serving each.

use std::path::Path;

use crate::host::{Bundle, HostError};

/// `morphfx plugins`: each plugin of the bundle with its version.
pub fn list_plugins(bundle_path: &Path) -> Result<(), HostError> {
    let bundle = Bundle::load(bundle_path)?;
    println!("bundle: {}", bundle.binary.display());
    for p in &bundle.plugins {
        let served_by = p
            .served_by
            .as_ref()
            .and_then(|b| b.file_name())
            .map(|b| b.to_string_lossy().into_owned())
            .unwrap_or_default();
        println!("{}\t{}.{}\t{served_by}", p.id, p.version.0, p.version.1);
    }
    Ok(())
}
