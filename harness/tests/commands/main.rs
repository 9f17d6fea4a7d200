//! Every test that drives the `morphfx` binary as a user does, as one test
//! binary, a module per file: one link of the harness and its
//! dependencies instead of nine.

#[path = "../common/mod.rs"]
mod common;

mod cli;
mod corrupt_exr;
mod doc_examples;
mod farm;
mod faults;
mod layers_cli;
mod long_run;
mod mattes_cli;
mod methods;
mod sequences;
mod suggest;
