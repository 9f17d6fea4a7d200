//! The nodes, in safe Rust, by floors: `kind` (what a node type states
//! about itself) and `params` at the bottom; the per-instance `state` and
//! the warp `inputs` both `render` and `overlay` read; the actions
//! (`render`, `overlay`, `snap`, `track`, `suggest`, `grid`); `node`, which makes every
//! [`Node`] an OpenFX image effect; and the node types (`morph`, `warp`),
//! each a file stating its [`kind::NodeKind`].
#![forbid(unsafe_code)]

mod grid;
mod inputs;
mod kind;
mod lines;
mod morph;
mod node;
pub mod overlay;
pub mod params;
mod render;
mod snap;
mod state;
mod suggest;
mod track;
mod warp;

pub use morph::Morph;
pub use node::Effect;
pub use warp::Warp;
