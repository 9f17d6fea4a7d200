//! Renders: the nodes of the plugin this module links, loaded through the
//! C ABI into the command line's host and driven as `morphfx morph` and
//! `morphfx warp` drive them.

use std::sync::{Mutex, OnceLock};

use morphfx_harness::args::param_value::{param_lines, ParamSetting};
use morphfx_harness::commands::job::{MORPH_ID, WARP_ID};
use morphfx_harness::host::{this_binary, Bundle, Instance};
use morphfx_harness::one_frame::{instance, LentRows, Node, OneFrame, Rows, Stage};
use numpy::PyArray3;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyList, PyTuple};

use crate::arrays::{array_of, borrowed, Borrowed};
use crate::errors::{self, ParamError, RenderError};
use crate::scene::Scene;

/// This module as an OpenFX binary, loaded once: the module's own shared
/// object exports the plugin's entry points, since it links the plugin.
/// Loaded with the GIL released (the plugin's load runs then), so a second
/// thread that comes meanwhile waits here without holding the GIL.
fn bundle(py: Python<'_>) -> PyResult<&'static Bundle> {
    static BUNDLE: OnceLock<Bundle> = OnceLock::new();
    static LOADING: Mutex<()> = Mutex::new(());
    if let Some(b) = BUNDLE.get() {
        return Ok(b);
    }
    let file = this_binary()
        .ok_or_else(|| RenderError::new_err("cannot find the morphfx module's own file"))?;
    py.detach(|| {
        let _one_at_a_time = LOADING.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(b) = BUNDLE.get() {
            return Ok(b);
        }
        let loaded = Bundle::load(&file)?;
        Ok(BUNDLE.get_or_init(|| loaded))
    })
    .map_err(errors::render)
}

/// A scene argument: a `Scene`, a path to a scene file, or `None`.
fn scene_text(scene: Option<&Bound<'_, PyAny>>) -> PyResult<Option<String>> {
    let Some(scene) = scene.filter(|s| !s.is_none()) else {
        return Ok(None);
    };
    if let Ok(s) = scene.cast::<Scene>() {
        return Ok(Some(s.get().text()));
    }
    let path: std::path::PathBuf = scene.extract().map_err(|_| {
        errors::SceneError::new_err("scene: expected a morphfx.Scene or a scene file's path")
    })?;
    Ok(Some(Scene::read_file(&path)?.text()))
}

/// A param value as `--param` writes it: booleans `true`/`false`, numbers
/// as Python prints them, pairs `x,y`, choices by option name.
fn param_text(id: &str, value: &Bound<'_, PyAny>) -> PyResult<String> {
    if let Ok(b) = value.cast::<PyBool>() {
        return Ok(if b.is_true() { "true" } else { "false" }.to_owned());
    }
    if value.is_instance_of::<PyList>() || value.is_instance_of::<PyTuple>() {
        let parts: PyResult<Vec<String>> = value.try_iter()?.map(|v| param_text(id, &v?)).collect();
        return Ok(parts?.join(","));
    }
    if let Ok(text) = value.extract::<String>() {
        return Ok(text);
    }
    if value.extract::<f64>().is_ok() {
        return Ok(value.str()?.to_string());
    }
    Err(ParamError::new_err(format!(
        "params[{id:?}]: {}: expected a number, bool, string, pair or {{frame: value}} keys",
        value.repr()?
    )))
}

/// `params` as `--param`s: `{id: value}` constants, `{id: {frame: value}}` keys.
fn param_settings(params: Option<&Bound<'_, PyDict>>) -> PyResult<Vec<ParamSetting>> {
    let mut out = Vec::new();
    for (id, value) in params.into_iter().flat_map(|p| p.iter()) {
        let id: String = id
            .extract()
            .map_err(|_| ParamError::new_err("params: keys are param ids (strings)"))?;
        match value.cast::<PyDict>() {
            Ok(keys) => {
                for (frame, v) in keys.iter() {
                    let frame: f64 = frame.extract().map_err(|_| {
                        ParamError::new_err(format!("params[{id:?}]: keys are frames (numbers)"))
                    })?;
                    let value = param_text(&id, &v)?;
                    out.push(ParamSetting {
                        id: id.clone(),
                        frame: Some(frame),
                        value,
                    });
                }
            }
            Err(_) => out.push(ParamSetting {
                value: param_text(&id, &value)?,
                id,
                frame: None,
            }),
        }
    }
    Ok(out)
}

thread_local! {
    /// Seconds the last render on this thread spent in the plugin.
    static LAST_RENDER: std::cell::Cell<f64> = const { std::cell::Cell::new(0.0) };
}

/// Seconds the plugin's render took in this thread's last `morph`, `warp`
/// or `stmap` call: the rest of the call's time is the module's own.
#[pyfunction]
pub fn last_render_seconds() -> f64 {
    LAST_RENDER.get()
}

/// Node instances idle between renders: a render takes one of its node
/// (its params are reset and its inputs cut before use) rather than
/// describing and creating a node each call, which costs 5 ms; renders on
/// several threads at once each take their own.
static IDLE: Mutex<Vec<(Node, Instance<'static>)>> = Mutex::new(Vec::new());

/// Renders `req` with the GIL released, on an idle instance of its node;
/// errors as their kind's exception.
fn rendered(py: Python<'_>, req: OneFrame) -> PyResult<Rows> {
    let bundle = bundle(py)?;
    let node = req.node;
    let done = py.detach(|| {
        let idle = {
            let mut idle = IDLE.lock().unwrap_or_else(|e| e.into_inner());
            let k = idle.iter().position(|(n, _)| *n == node);
            k.map(|k| idle.swap_remove(k).1)
        };
        let inst = match idle {
            Some(inst) => inst,
            None => instance(bundle, node).map_err(|e| (Stage::Render, e))?,
        };
        let done = req.render_on(&inst);
        IDLE.lock()
            .unwrap_or_else(|e| e.into_inner())
            .push((node, inst));
        done
    });
    match done {
        Ok(done) => {
            LAST_RENDER.set(done.render.as_secs_f64());
            Ok(done.rows)
        }
        Err((Stage::Scene, e)) => Err(errors::scene(e)),
        Err((Stage::Params, e)) => Err(errors::param(e)),
        Err((Stage::Inputs, e)) => Err(errors::image(e)),
        Err((Stage::Render, e)) => Err(errors::render(e)),
    }
}

fn run<'py>(py: Python<'py>, req: OneFrame) -> PyResult<Bound<'py, PyArray3<f32>>> {
    array_of(py, rendered(py, req)?)
}

/// What every render call is asked besides its pictures.
struct Asked<'a, 'py> {
    scene: Option<&'a Bound<'py, PyAny>>,
    t: Option<f64>,
    frame: Option<f64>,
    view: &'a str,
    params: Option<&'a Bound<'py, PyDict>>,
}

impl Asked<'_, '_> {
    /// The request of `node` on these pictures.
    fn request<'r>(
        &self,
        node: Node,
        sources: Vec<LentRows<'r>>,
        mask: Option<LentRows<'r>>,
        timing: Option<LentRows<'r>>,
    ) -> PyResult<OneFrame<'r>> {
        Ok(OneFrame {
            node,
            sources,
            mask,
            timing,
            scene: scene_text(self.scene)?,
            t: self.t,
            frame: self.frame,
            view: self.view.to_owned(),
            params: param_settings(self.params)?,
        })
    }
}

/// Sources carry colour: RGB or RGBA.
const SOURCE: &[usize] = &[3, 4];
/// Mattes are read by their alpha, or an RGB matte by its mean.
const MATTE: &[usize] = &[1, 3, 4];

fn matte<'py>(value: Option<&Bound<'py, PyAny>>, what: &str) -> PyResult<Option<Borrowed<'py>>> {
    value
        .filter(|v| !v.is_none())
        .map(|v| borrowed(v, what, MATTE))
        .transpose()
}

/// The rows of an optional picture, lent for the call.
fn lent<'b>(picture: &'b Option<Borrowed<'_>>) -> PyResult<Option<LentRows<'b>>> {
    picture.as_ref().map(Borrowed::rows).transpose()
}

/// The in-between image of A and B (the Morph node), float32 `(H, W, 4)`.
#[pyfunction]
#[pyo3(signature = (scene, a, b, t = None, frame = None, view = "morph", params = None, *, mask = None, timing = None))]
#[allow(clippy::too_many_arguments)]
pub fn morph<'py>(
    py: Python<'py>,
    scene: Option<&Bound<'py, PyAny>>,
    a: &Bound<'py, PyAny>,
    b: &Bound<'py, PyAny>,
    t: Option<f64>,
    frame: Option<f64>,
    view: &str,
    params: Option<&Bound<'py, PyDict>>,
    mask: Option<&Bound<'py, PyAny>>,
    timing: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyArray3<f32>>> {
    let (a, b) = (borrowed(a, "a", SOURCE)?, borrowed(b, "b", SOURCE)?);
    let (mask, timing) = (matte(mask, "mask")?, matte(timing, "timing")?);
    let asked = Asked {
        scene,
        t,
        frame,
        view,
        params,
    };
    let sources = vec![a.rows()?, b.rows()?];
    run(
        py,
        asked.request(Node::Morph, sources, lent(&mask)?, lent(&timing)?)?,
    )
}

/// A warped toward the features' positions at t (the Warp node), float32
/// `(H, W, 4)`. `view="morph"` is the node's picture (its `warped` view).
#[pyfunction]
#[pyo3(signature = (scene, a, t = None, frame = None, view = "morph", params = None, *, mask = None))]
#[allow(clippy::too_many_arguments)]
pub fn warp<'py>(
    py: Python<'py>,
    scene: Option<&Bound<'py, PyAny>>,
    a: &Bound<'py, PyAny>,
    t: Option<f64>,
    frame: Option<f64>,
    view: &str,
    params: Option<&Bound<'py, PyDict>>,
    mask: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyArray3<f32>>> {
    let view = if view == "morph" { "warped" } else { view };
    let (a, mask) = (borrowed(a, "a", SOURCE)?, matte(mask, "mask")?);
    let asked = Asked {
        scene,
        t,
        frame,
        view,
        params,
    };
    run(
        py,
        asked.request(Node::Warp, vec![a.rows()?], lent(&mask)?, None)?,
    )
}

/// The ST map side `"a"` or `"b"` is warped with at t, float32 `(H, W, 2)`
/// in Nuke's STMap convention (x'/W, y'/H). Methods that look at the
/// pictures (auto) take them as `a` and `b`; the rest need only the size.
#[pyfunction]
#[pyo3(signature = (scene, side, t, width, height, *, frame = None, params = None, a = None, b = None))]
#[allow(clippy::too_many_arguments)]
pub fn stmap<'py>(
    py: Python<'py>,
    scene: Option<&Bound<'py, PyAny>>,
    side: &str,
    t: f64,
    width: usize,
    height: usize,
    frame: Option<f64>,
    params: Option<&Bound<'py, PyDict>>,
    a: Option<&Bound<'py, PyAny>>,
    b: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyArray3<f32>>> {
    let view = match side {
        "a" | "A" => "stmap-a",
        "b" | "B" => "stmap-b",
        other => {
            return Err(ParamError::new_err(format!(
                "side {other:?}: expected \"a\" or \"b\""
            )))
        }
    };
    if width == 0 || height == 0 {
        return Err(errors::ImageError::new_err(format!(
            "stmap: a {width}x{height} map: width and height must be positive"
        )));
    }
    let blank = vec![0.0f32; width * height * 4];
    let given = |picture: Option<&Bound<'py, PyAny>>, what: &str| {
        let picture = picture.filter(|p| !p.is_none());
        picture.map(|p| borrowed(p, what, SOURCE)).transpose()
    };
    let (a, b) = (given(a, "a")?, given(b, "b")?);
    let asked = Asked {
        scene,
        t: Some(t),
        frame,
        view,
        params,
    };
    let sources = vec![
        map_source(&a, &blank, (width, height), "a")?,
        map_source(&b, &blank, (width, height), "b")?,
    ];
    let req = asked.request(Node::Morph, sources, None, None)?;
    let map = rendered(py, req)?;
    let data = map
        .data
        .chunks_exact(4)
        .flat_map(|p| [p[0], p[1]])
        .collect();
    let st = Rows {
        channels: 2,
        data,
        ..map
    };
    array_of(py, st)
}

/// An ST map's source: the picture given, else `blank`; the map's size.
fn map_source<'b>(
    picture: &'b Option<Borrowed<'_>>,
    blank: &'b [f32],
    (width, height): (usize, usize),
    what: &str,
) -> PyResult<LentRows<'b>> {
    let rows = match picture {
        Some(p) => p.rows()?,
        None => LentRows {
            width,
            height,
            channels: 4,
            data: blank,
        },
    };
    if (rows.width, rows.height) != (width, height) {
        return Err(errors::ImageError::new_err(format!(
            "{what}: {}x{} but the map is {width}x{height}",
            rows.width, rows.height
        )));
    }
    Ok(rows)
}

/// Which build of the plugin renders: `"x86-64-v3 build with AVX2 and
/// FMA"` where the CPU has them (the module carries that build beside its
/// own), else `"baseline x86-64 build"`.
#[pyfunction]
pub fn build(py: Python<'_>) -> PyResult<String> {
    let bundle = bundle(py)?;
    py.detach(|| instance(bundle, Node::Morph).map(|inst| inst.build_that_ran()))
        .map_err(errors::render)
}

/// Every param of node `"morph"` or `"warp"`, one line each as `morphfx
/// params` prints them: id, type, default and range.
#[pyfunction]
#[pyo3(signature = (node = "morph"))]
pub fn params(py: Python<'_>, node: &str) -> PyResult<Vec<String>> {
    let (id, context) = match node {
        "morph" => (MORPH_ID, "OfxImageEffectContextGeneral"),
        "warp" => (WARP_ID, "OfxImageEffectContextFilter"),
        other => {
            return Err(ParamError::new_err(format!(
                "node {other:?}: expected \"morph\" or \"warp\""
            )))
        }
    };
    let bundle = bundle(py)?;
    py.detach(|| {
        let inst = bundle.instance(id, context)?;
        Ok(param_lines(&inst))
    })
    .map_err(|e: morphfx_harness::host::HostError| RenderError::new_err(e.message))
}
