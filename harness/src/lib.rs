//! `morphfx`, the standalone harness: an OpenFX host for the MorphFX bundle
//! (reached only through its C ABI), EXR/PNG/JPEG/TIFF frame IO, sequences.

pub mod args;
pub mod cli;
pub mod commands;
pub mod error;
pub mod exr_zip;
pub mod host;
pub mod interrupt;
pub mod io;
pub mod layered;
pub mod locate;
pub mod one_frame;
pub mod pipeline;
pub mod plate;
pub mod plates;
pub mod progress;
pub mod raster;
pub mod rows;
pub mod sequence;
pub mod sync;
