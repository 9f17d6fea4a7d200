//! Feature tools with the command line's meanings: `track`, `snap` and
//! `suggest` run the very commands, on files. Plates may be paths (a file,
//! or a #-numbered sequence) or arrays, which are written out first as
//! float EXRs (exact) into a scratch folder that goes when the call ends.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

use morphfx::choice::Choice;
use morphfx::make_warp::Method;
use morphfx::snake::SnakeSettings;
use morphfx::suggest::SuggestSettings;
use morphfx_harness::commands::snap::Snap;
use morphfx_harness::commands::suggest::Suggest;
use morphfx_harness::commands::track::track_job;
use morphfx_harness::host::{ErrorKind, HostError};
use morphfx_harness::io::{self, ExrPrecision};
use morphfx_harness::rows::Rows;
use morphfx_harness::sequence::{frame_path, parse_frames};
use pyo3::prelude::*;
use pyo3::types::{PyList, PyTuple};

use crate::arrays::rows_of;
use crate::errors::{ImageError, ParamError, RenderError, SceneError};
use crate::scene::Scene;

/// A folder for one call's files, removed with everything in it when the
/// call ends.
struct Scratch(PathBuf);

impl Scratch {
    fn new() -> PyResult<Scratch> {
        static CALLS: AtomicUsize = AtomicUsize::new(0);
        let call = CALLS.fetch_add(1, Ordering::Relaxed);
        let dir = std::env::temp_dir().join(format!("morphfx-{}-{call}", std::process::id()));
        std::fs::create_dir_all(&dir).map_err(|e| {
            RenderError::new_err(format!(
                "{}: cannot make a scratch folder: {e}",
                dir.display()
            ))
        })?;
        Ok(Scratch(dir))
    }

    fn path(&self, name: &str) -> PathBuf {
        self.0.join(name)
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// Plates to write before a tool runs: (file, picture).
type Pending = Vec<(PathBuf, Rows)>;

/// A plate argument as the path pattern the command reads: a path as it
/// is; an array as `NAME.exr`; a list of arrays, one per frame of
/// `frames`, as `NAME.####.exr`.
fn pattern(
    value: &Bound<'_, PyAny>,
    name: &str,
    frames: Option<&[i64]>,
    scratch: &Scratch,
    pending: &mut Pending,
) -> PyResult<String> {
    if let Ok(path) = value.extract::<PathBuf>() {
        return Ok(path.to_string_lossy().into_owned());
    }
    let is_list = value.is_instance_of::<PyList>() || value.is_instance_of::<PyTuple>();
    match frames {
        Some(frames) if is_list => {
            let pictures: Vec<Bound<'_, PyAny>> = value.try_iter()?.collect::<PyResult<_>>()?;
            if pictures.len() != frames.len() {
                return Err(ImageError::new_err(format!(
                    "{name}: {} pictures for {} frames: give one per frame",
                    pictures.len(),
                    frames.len()
                )));
            }
            let pattern = scratch.path(&format!("{name}.####.exr"));
            let pattern = pattern.to_string_lossy().into_owned();
            for (picture, &f) in pictures.iter().zip(frames) {
                let rows = rows_of(picture, &format!("{name} at frame {f}"), &[3, 4])?;
                pending.push((frame_path(&pattern, f), rows));
            }
            Ok(pattern)
        }
        _ => {
            let path = scratch.path(&format!("{name}.exr"));
            pending.push((path.clone(), rows_of(value, name, &[3, 4])?));
            Ok(path.to_string_lossy().into_owned())
        }
    }
}

fn write_pending(pending: Pending) -> Result<(), HostError> {
    for (path, rows) in pending {
        io::write(&path, &rows.to_plate(), ExrPrecision::Float)?;
    }
    Ok(())
}

/// The scene argument as a file the command reads.
fn scene_file(scene: &Bound<'_, PyAny>, scratch: &Scratch) -> PyResult<PathBuf> {
    if let Ok(s) = scene.cast::<Scene>() {
        let path = scratch.path("scene.morph.json");
        io::write_text(&path, &s.get().text()).map_err(crate::errors::render)?;
        return Ok(path);
    }
    scene
        .extract()
        .map_err(|_| SceneError::new_err("scene: expected a morphfx.Scene or a scene file's path"))
}

/// A tool's failure as its kind's exception: the scene's, an option's
/// (the command line's `--` options), a plate's, or the tool's own.
fn failure(e: HostError) -> PyErr {
    if e.kind != ErrorKind::BadInput {
        return RenderError::new_err(e.message);
    }
    if e.message.starts_with("scene ") {
        SceneError::new_err(e.message)
    } else if e.message.starts_with("--") {
        ParamError::new_err(e.message)
    } else {
        ImageError::new_err(e.message)
    }
}

/// The tool's output scene.
fn written(path: &Path) -> PyResult<Scene> {
    Scene::read_file(path)
}

/// `frames` as the command line's `--frames` text.
fn frames_text(frames: &Bound<'_, PyAny>) -> PyResult<String> {
    if let Ok(text) = frames.extract::<String>() {
        return Ok(text);
    }
    if let Ok((first, last)) = frames.extract::<(i64, i64)>() {
        return Ok(format!("{first}-{last}"));
    }
    Err(ParamError::new_err(
        "frames: expected \"FIRST-LAST\" or (first, last)",
    ))
}

/// The scene with its keyed features followed through sequence `a` (and
/// `b`) over `frames`, keyed at every frame (`morphfx track`). The
/// defaults are the command line's (the tests hold them to its help).
#[pyfunction]
#[pyo3(signature = (scene, a, b = None, *, frames, radius = 12, min_correlation = 0.75))]
pub fn track(
    py: Python<'_>,
    scene: &Bound<'_, PyAny>,
    a: &Bound<'_, PyAny>,
    b: Option<&Bound<'_, PyAny>>,
    frames: &Bound<'_, PyAny>,
    radius: usize,
    min_correlation: f64,
) -> PyResult<Scene> {
    let scratch = Scratch::new()?;
    let frames = frames_text(frames)?;
    let list = parse_frames(&frames).map_err(failure)?;
    let mut pending = Vec::new();
    let scene = scene_file(scene, &scratch)?;
    let a = pattern(a, "a", Some(&list), &scratch, &mut pending)?;
    let b = b
        .filter(|b| !b.is_none())
        .map(|b| pattern(b, "b", Some(&list), &scratch, &mut pending))
        .transpose()?;
    let out = scratch.path("tracked.morph.json");
    py.detach(|| {
        write_pending(pending)?;
        track_job(
            &scene,
            &a,
            b.as_deref(),
            &frames,
            Some(&out),
            radius,
            min_correlation,
        )
    })
    .map_err(failure)?;
    written(&out)
}

/// The scene with its polylines and curves snapped onto nearby edges of A
/// and B by snakes (`morphfx snap`).
#[pyfunction]
#[pyo3(signature = (scene, a, b, *, frame = None, sigma = 3.0, iterations = 200, clamp_controls = false))]
#[allow(clippy::too_many_arguments)]
pub fn snap(
    py: Python<'_>,
    scene: &Bound<'_, PyAny>,
    a: &Bound<'_, PyAny>,
    b: &Bound<'_, PyAny>,
    frame: Option<f64>,
    sigma: f64,
    iterations: usize,
    clamp_controls: bool,
) -> PyResult<Scene> {
    let scratch = Scratch::new()?;
    let mut pending = Vec::new();
    let scene = scene_file(scene, &scratch)?;
    let a = pattern(a, "a", None, &scratch, &mut pending)?;
    let b = pattern(b, "b", None, &scratch, &mut pending)?;
    let out = scratch.path("snapped.morph.json");
    py.detach(|| {
        write_pending(pending)?;
        Snap {
            scene: &scene,
            a: &a,
            b: &b,
            output: &out,
            frame,
            sigma,
            settings: SnakeSettings {
                iterations,
                clamp_controls,
                ..SnakeSettings::default()
            },
        }
        .run()
    })
    .map_err(failure)?;
    written(&out)
}

/// Feature pairs proposed between A and B, as a scene (`morphfx
/// suggest`): the base `scene`'s features kept, suggestions after them.
#[pyfunction]
#[pyo3(signature = (a, b, *, frames = None, at = None, scene = None, count = 40, min_confidence = 0.5, method = None))]
#[allow(clippy::too_many_arguments)]
pub fn suggest(
    py: Python<'_>,
    a: &Bound<'_, PyAny>,
    b: &Bound<'_, PyAny>,
    frames: Option<&Bound<'_, PyAny>>,
    at: Option<i64>,
    scene: Option<&Bound<'_, PyAny>>,
    count: usize,
    min_confidence: f64,
    method: Option<&str>,
) -> PyResult<Scene> {
    let scratch = Scratch::new()?;
    let frames = frames.map(frames_text).transpose()?;
    let list = frames
        .as_deref()
        .map(parse_frames)
        .transpose()
        .map_err(failure)?;
    let method = method
        .map(|name| {
            Method::ALL
                .iter()
                .copied()
                .find(|m| m.name() == name)
                .ok_or_else(|| {
                    let names: Vec<_> = Method::ALL.iter().map(|m| m.name()).collect();
                    ParamError::new_err(format!("method {name}: one of {}", names.join(", ")))
                })
        })
        .transpose()?;
    let mut pending = Vec::new();
    let scene = scene
        .filter(|s| !s.is_none())
        .map(|s| scene_file(s, &scratch))
        .transpose()?;
    let a = pattern(a, "a", list.as_deref(), &scratch, &mut pending)?;
    let b = pattern(b, "b", list.as_deref(), &scratch, &mut pending)?;
    let out = scratch.path("suggested.morph.json");
    py.detach(|| {
        write_pending(pending)?;
        Suggest {
            a: &a,
            b: &b,
            output: &out,
            frames: frames.as_deref(),
            at,
            scene: scene.as_deref(),
            method,
            settings: SuggestSettings {
                count,
                min_confidence,
                ..SuggestSettings::default()
            },
        }
        .run()
    })
    .map_err(failure)?;
    written(&out)
}
