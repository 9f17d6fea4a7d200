//! Where the MorphFX bundle is: `--bundle`, `--plugin-path`, `OFX_PLUGIN_PATH`,
//! beside the `morphfx` binary (a cargo build), then the OFX standard folder.

use std::path::{Path, PathBuf};

use crate::error::HostError;

/// The bundle to load: the one given, else the first that exists of the
/// places a host searches.
pub fn find_bundle(given: Option<&Path>, plugin_path: &str) -> Result<PathBuf, HostError> {
    const NAME: &str = "MorphFX.ofx.bundle";
    if let Some(p) = given {
        return Ok(p.to_path_buf());
    }
    let mut candidates = Vec::new();
    if !plugin_path.is_empty() {
        candidates.extend(std::env::split_paths(plugin_path).map(|d| d.join(NAME)));
    }
    if let Ok(paths) = std::env::var("OFX_PLUGIN_PATH") {
        candidates.extend(std::env::split_paths(&paths).map(|d| d.join(NAME)));
    }
    if let Some(dir) = std::env::current_exe()
        .ok()
        .and_then(|e| e.parent().map(Path::to_path_buf))
    {
        // target/<profile>/morphfx → target/bundle/MorphFX.ofx.bundle (cargo xtask bundle),
        // or the cdylib cargo left beside the binary.
        candidates.push(dir.join("..").join("bundle").join(NAME));
        candidates.push(dir.join("libmorphfx_ofx.so"));
    }
    candidates.push(PathBuf::from("/usr/OFX/Plugins").join(NAME));
    candidates
        .into_iter()
        .find(|c| crate::host::bundle_binary(c).is_file())
        .ok_or_else(|| {
            HostError::bad(
                "no MorphFX bundle found: pass --bundle, set OFX_PLUGIN_PATH, \
            or build one with `cargo xtask bundle`",
            )
        })
}
