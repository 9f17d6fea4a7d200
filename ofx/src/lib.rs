//! The MorphFX OpenFX plugin: Morph and Warp nodes over the `morphfx` core.
//!
//! The generic OpenFX layer (the `ofx-layer` crate) holds all of the FFI
//! and names no node; `nodes/` is safe Rust (`forbid(unsafe_code)`): the
//! nodes as implementors of the layer's traits, params declared as data,
//! render glue calling the core. This file is the composition root: the
//! one place that names the bundle's nodes.
#![forbid(unsafe_code)]

mod cache;
mod nodes;

use nodes::{Effect, Morph, Warp};

ofx_layer::export!(Effect<Morph>, Effect<Warp>);
