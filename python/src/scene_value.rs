//! The `blutrace.Scene` value itself (its methods are `scene`'s): every module that hands
//! a scene to Python (a run's, an optimization's) builds one here, so none of them
//! depends on the module whose methods return them.

use crate::convert::scene_error;
use crate::detached::detached;
use blutrace::scene::Scene as RustScene;
use pyo3::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// A validated, traceable scene: a value (``copy()`` gives an independent one).
///
/// ``Scene.load(path)`` reads a scene file, or ``scene.toml`` in a folder, and every file it
/// names; ``Scene.from_toml(text, path)`` builds one from text (geometry relative to
/// ``path``'s folder). ``get(key)`` and ``set(key, value)`` read and change the scene file's
/// values by key path: dotted keys and array indices from 0 (``sources.0.center.2``), ``*``
/// for every element of an array (``sources.*.center.2``: ``get`` gives their one value, or
/// the list of their values when they differ); ``set`` takes numbers, str, lists, dicts and
/// numpy arrays and scalars, and loads the scene again from the edited file, so every
/// check runs. ``check()`` returns what ``blutrace check --json`` prints.
#[pyclass(module = "blutrace", name = "Scene")]
#[derive(Clone)]
pub struct Scene {
    /// The scene.
    pub inner: Arc<RustScene>,
}

/// The scene file a path names: the path, or `scene.toml` in it when it is a folder.
fn scene_file(p: &Path) -> PathBuf {
    if p.is_dir() {
        p.join("scene.toml")
    } else {
        p.to_path_buf()
    }
}

/// Load and validate a scene: a scene file or a folder holding `scene.toml`.
pub fn load_scene(py: Python<'_>, path: &Path) -> PyResult<Scene> {
    let file = scene_file(path);
    let scene = detached(py, || RustScene::load(&file))?.map_err(scene_error)?;
    Ok(Scene {
        inner: Arc::new(scene),
    })
}
