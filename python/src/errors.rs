//! The module's exceptions: one base class, one subclass per kind of
//! failure, each carrying the command line's message.

use morphfx_harness::host::HostError;
use pyo3::create_exception;
use pyo3::exceptions::PyException;
use pyo3::prelude::*;

create_exception!(
    morphfx,
    Error,
    PyException,
    "A MorphFX failure; the message is the command line's."
);
create_exception!(
    morphfx,
    SceneError,
    Error,
    "A scene that cannot be read, or is not a valid scene."
);
create_exception!(
    morphfx,
    ImageError,
    Error,
    "An image that cannot be read, written or used (file, shape, size)."
);
create_exception!(
    morphfx,
    ParamError,
    Error,
    "A node param or option: unknown, of the wrong type, out of range, or set by the scene."
);
create_exception!(
    morphfx,
    RenderError,
    Error,
    "A render or tool that failed on valid input (the plugin's or tool's message)."
);

pub fn add(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("Error", py.get_type::<Error>())?;
    m.add("SceneError", py.get_type::<SceneError>())?;
    m.add("ImageError", py.get_type::<ImageError>())?;
    m.add("ParamError", py.get_type::<ParamError>())?;
    m.add("RenderError", py.get_type::<RenderError>())?;
    Ok(())
}

pub fn scene(e: HostError) -> PyErr {
    SceneError::new_err(e.message)
}

pub fn image(e: HostError) -> PyErr {
    ImageError::new_err(e.message)
}

pub fn param(e: HostError) -> PyErr {
    ParamError::new_err(e.message)
}

/// A tool's or render's failure: bad input is the user's to fix (an image
/// or option), anything else the render's.
pub fn render(e: HostError) -> PyErr {
    RenderError::new_err(e.message)
}
