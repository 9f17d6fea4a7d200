//! The MorphFX OpenFX plugin: Morph and Warp nodes over the `morphfx` core.
//!
//! `wrapper/` is the generic OpenFX layer, all of the FFI, naming no node;
//! `nodes/` is safe Rust (`forbid(unsafe_code)`): the nodes as implementors
//! of the layer's traits, params declared as data, render glue calling the
//! core. This file is the composition root: the one place that names the
//! bundle's nodes.

mod cache;
mod nodes;
mod sync;
mod wrapper;

wrapper::export!(nodes::Morph, nodes::Warp);
