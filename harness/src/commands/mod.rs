//! One module per `morphfx` command, in the library so tests can run them
//! in process; `main.rs` parses the command line and dispatches here.

pub mod bench;
pub mod demo;
pub mod job;
pub mod layers;
pub mod openjd;
pub mod overlay;
pub mod params;
pub mod plugins;
pub mod snap;
pub mod suggest;
pub mod track;
