//! `morphfx.Scene`: a scene document, validated as the command line
//! validates it, its JSON kept as written so it round-trips.

use std::path::PathBuf;

use morphfx::choice::Choice;
use morphfx::scene::Scene as Parsed;
use pyo3::prelude::*;
use serde_json::Value;

use crate::errors::SceneError;

/// A scene (`*.morph.json`): features, keyframes, meshes and settings.
#[pyclass(module = "morphfx", frozen)]
pub struct Scene {
    doc: Value,
    parsed: Parsed,
}

impl Scene {
    /// A scene from its text; errors name `source` as the command line
    /// names the scene file.
    fn parse(text: &str, source: &str) -> PyResult<Scene> {
        let bad = |e: &dyn std::fmt::Display| SceneError::new_err(format!("scene {source}: {e}"));
        let parsed = Parsed::parse(text).map_err(|e| bad(&e))?;
        let doc = serde_json::from_str(text).map_err(|e| bad(&e))?;
        Ok(Scene { doc, parsed })
    }

    /// The document as a scene file holds it.
    pub fn text(&self) -> String {
        serde_json::to_string_pretty(&self.doc).expect("a JSON value always serialises")
    }

    /// The scene a file holds: errors as the command line's.
    pub fn read_file(path: &std::path::Path) -> PyResult<Scene> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| SceneError::new_err(format!("scene {}: {e}", path.display())))?;
        Scene::parse(&text, &path.display().to_string())
    }

    /// `key` of the document as Python objects (through `json`, so the
    /// objects are exactly what `json.loads` makes of the file).
    fn get<'py>(&self, py: Python<'py>, key: &str) -> PyResult<Bound<'py, PyAny>> {
        let value = self
            .doc
            .get(key)
            .cloned()
            .unwrap_or(Value::Array(Vec::new()));
        py.import("json")?
            .call_method1("loads", (value.to_string(),))
    }
}

#[pymethods]
impl Scene {
    /// The scene in file `path`.
    #[staticmethod]
    fn load(path: PathBuf) -> PyResult<Scene> {
        Scene::read_file(&path)
    }

    /// The scene in JSON text `text`.
    #[staticmethod]
    fn from_json(text: &str) -> PyResult<Scene> {
        Scene::parse(text, "text")
    }

    /// The scene as JSON text (what `Scene.from_json` and the command line read).
    fn to_json(&self) -> String {
        self.text()
    }

    /// Writes the scene to file `path`, atomically.
    fn save(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        let text = self.text();
        py.detach(|| morphfx_harness::io::write_text(&path, &text))
            .map_err(crate::errors::scene)
    }

    /// The static features, as the scene format writes them (list of dicts).
    #[getter]
    fn features<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.get(py, "features")
    }

    /// The keyframes: `[{"frame": F, "features": [...]}, ...]`.
    #[getter]
    fn keyframes<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.get(py, "keyframes")
    }

    /// The warp method's name (`field`, `mesh`, `auto`, ...).
    #[getter]
    fn method(&self) -> &'static str {
        self.parsed.settings.method.name()
    }

    /// A copy of the scene with `key` set to `value` (any JSON-able
    /// object), validated: `scene.with_("features", [...])`.
    #[pyo3(name = "with_")]
    fn with(&self, py: Python<'_>, key: &str, value: &Bound<'_, PyAny>) -> PyResult<Scene> {
        let text: String = py
            .import("json")?
            .call_method1("dumps", (value,))?
            .extract()?;
        let value: Value = serde_json::from_str(&text)
            .map_err(|e| SceneError::new_err(format!("scene {key}: {e}")))?;
        let mut doc = self.doc.clone();
        doc[key] = value;
        Scene::parse(&doc.to_string(), "text")
    }

    fn __repr__(&self) -> String {
        let keys = self.parsed.keyframes.len();
        format!(
            "<morphfx.Scene method={} features={} keyframes={keys}>",
            self.method(),
            self.parsed.features.len()
        )
    }
}
