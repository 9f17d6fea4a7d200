//! `morphfx` for Python: scenes, images as numpy arrays, and renders.
//!
//! The module is its own OpenFX binary: it links the plugin, and renders
//! load it through the C ABI into the host `morphfx` uses
//! (`morphfx_harness`), so a render here is the command line's render,
//! pixel for pixel. Source arrays are lent to the host, which hands their
//! memory to the plugin in place. Tools (track, snap, suggest) run the
//! command line's code on files, writing arrays out first where given.
//!
//! Every error becomes a `morphfx.Error` subclass carrying the command
//! line's message; the GIL is released while pixels are worked on.
#![forbid(unsafe_code)]

use pyo3::prelude::*;

// Linked for its exported entry points (`OfxGetPlugin`, ...), which make
// this module an OpenFX binary; nothing here calls it by name.
extern crate morphfx_ofx;

mod arrays;
mod errors;
mod render;
mod scene;
mod tools;

#[pymodule(name = "morphfx")]
fn morphfx_module(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    errors::add(m)?;
    m.add_class::<scene::Scene>()?;
    m.add_function(wrap_pyfunction!(arrays::read_image, m)?)?;
    m.add_function(wrap_pyfunction!(arrays::write_image, m)?)?;
    m.add_function(wrap_pyfunction!(render::morph, m)?)?;
    m.add_function(wrap_pyfunction!(render::warp, m)?)?;
    m.add_function(wrap_pyfunction!(render::stmap, m)?)?;
    m.add_function(wrap_pyfunction!(render::params, m)?)?;
    m.add_function(wrap_pyfunction!(render::last_render_seconds, m)?)?;
    m.add_function(wrap_pyfunction!(render::build, m)?)?;
    m.add_function(wrap_pyfunction!(tools::track, m)?)?;
    m.add_function(wrap_pyfunction!(tools::snap, m)?)?;
    m.add_function(wrap_pyfunction!(tools::suggest, m)?)?;
    // What `from morphfx import *` (and a package wrapping the module) takes.
    let names: Vec<String> = m
        .dict()
        .keys()
        .iter()
        .map(|k| k.to_string())
        .filter(|k| !k.starts_with('_') || k == "__version__")
        .collect();
    m.add("__all__", names)?;
    Ok(())
}
