//! Pictures between numpy and the host: float32 `(H, W, C)` arrays, row 0
//! the top row as files store them, and image files read and written as
//! the command line reads and writes them.

use std::path::PathBuf;

use morphfx_harness::io::{self, Colour, ExrPrecision, OutputFormat};
use morphfx_harness::one_frame::LentRows;
use morphfx_harness::rows::Rows;
use numpy::{PyArray1, PyArray3, PyArrayMethods, PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::errors::{self, ImageError, ParamError};

/// A picture argument held for a call: any array-like, converted to
/// C-ordered float32 (no copy when it is one already) and borrowed, so
/// that the render reads numpy's own memory.
pub struct Borrowed<'py> {
    array: PyReadonlyArrayDyn<'py, f32>,
    width: usize,
    height: usize,
    channels: usize,
}

impl Borrowed<'_> {
    /// The picture's rows, lent to the host for the call.
    pub fn rows(&self) -> PyResult<LentRows<'_>> {
        Ok(LentRows {
            width: self.width,
            height: self.height,
            channels: self.channels,
            data: self.array.as_slice()?,
        })
    }

    /// The picture's rows, copied (to write a file from).
    pub fn to_rows(&self) -> PyResult<Rows> {
        Ok(Rows {
            width: self.width,
            height: self.height,
            channels: self.channels,
            data: self.array.as_slice()?.to_vec(),
        })
    }
}

/// `value` borrowed as a picture of `channels` allowed counts.
pub fn borrowed<'py>(
    value: &Bound<'py, PyAny>,
    what: &str,
    channels: &[usize],
) -> PyResult<Borrowed<'py>> {
    let py = value.py();
    let kwargs = PyDict::new(py);
    kwargs.set_item("dtype", "float32")?;
    let array = py
        .import("numpy")?
        .call_method("ascontiguousarray", (value,), Some(&kwargs))
        .map_err(|e| ImageError::new_err(format!("{what}: not an image array: {e}")))?;
    let array: PyReadonlyArrayDyn<'py, f32> = array.extract()?;
    let (height, width, c) = match *array.shape() {
        [h, w] => (h, w, 1),
        [h, w, c] => (h, w, c),
        ref other => {
            return Err(ImageError::new_err(format!(
                "{what}: an array of shape {other:?}: expected (H, W, C)"
            )))
        }
    };
    if !channels.contains(&c) || height == 0 || width == 0 {
        let allowed: Vec<String> = channels.iter().map(|c| c.to_string()).collect();
        return Err(ImageError::new_err(format!(
            "{what}: an array of shape ({height}, {width}, {c}): expected (H, W, C) with \
             H, W > 0 and C one of {}",
            allowed.join(", ")
        )));
    }
    Ok(Borrowed {
        array,
        width,
        height,
        channels: c,
    })
}

/// `value` as rows of `channels` allowed counts, copied.
pub fn rows_of(value: &Bound<'_, PyAny>, what: &str, channels: &[usize]) -> PyResult<Rows> {
    borrowed(value, what, channels)?.to_rows()
}

/// Rows as a float32 `(H, W, C)` array, their buffer moved, not copied.
pub fn array_of(py: Python<'_>, rows: Rows) -> PyResult<Bound<'_, PyArray3<f32>>> {
    let shape = [rows.height, rows.width, rows.channels];
    PyArray1::from_vec(py, rows.data).reshape(shape)
}

fn colour(raw: bool) -> Colour {
    if raw {
        Colour::Raw
    } else {
        Colour::Srgb
    }
}

/// An image file as a float32 `(H, W, 4)` array over its display window.
#[pyfunction]
#[pyo3(signature = (path, *, raw = false))]
pub fn read_image(py: Python<'_>, path: PathBuf, raw: bool) -> PyResult<Bound<'_, PyArray3<f32>>> {
    let rows = py
        .detach(|| io::read_as(&path, colour(raw)).map(|p| Rows::of_plate(&p)))
        .map_err(errors::image)?;
    array_of(py, rows)
}

/// Writes an `(H, W, C)` array (C = 1, 3 or 4) to an EXR, PNG, JPEG or
/// TIFF file, atomically.
#[pyfunction]
#[pyo3(signature = (path, image, *, half = false, compression = None, raw = false))]
pub fn write_image(
    py: Python<'_>,
    path: PathBuf,
    image: &Bound<'_, PyAny>,
    half: bool,
    compression: Option<&str>,
    raw: bool,
) -> PyResult<()> {
    let rows = rows_of(image, "image", &[1, 3, 4])?;
    let precision = if half {
        ExrPrecision::Half
    } else {
        ExrPrecision::Float
    };
    let mut format = OutputFormat::new(precision);
    format.colour = colour(raw);
    if let Some(name) = compression {
        format.compression = io::compression_named(name).ok_or_else(|| {
            let names: Vec<&str> = io::COMPRESSIONS.iter().map(|(n, _)| *n).collect();
            ParamError::new_err(format!(
                "compression {name}: expected one of {}",
                names.join(", ")
            ))
        })?;
    }
    py.detach(|| io::write_as(&path, &rows.to_plate(), format))
        .map_err(errors::image)
}
