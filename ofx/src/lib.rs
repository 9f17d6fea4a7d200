//! The MorphFX OpenFX plugin: Morph and Warp nodes over the `morphfx` core.
//!
//! `wrapper/` holds every line of FFI (exports, suites, property sets, params,
//! clips and images, status mapping); `nodes/` is safe Rust: one file per
//! node, params declared as data, render glue calling the core.

mod cache;
mod nodes;
mod wrapper;

pub use nodes::{PLUGIN_IDS, PLUGIN_VERSION};
