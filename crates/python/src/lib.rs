//! `import pathlight`: the Python module. Scenes are loaded from scene files and glTF files
//! or built from Python data with the scene file's keys (module `scene`), rendered progressively
//! on either backend into NumPy arrays (module `renderer`); state files resume and merge exactly
//! as the command line's do. The Python package around it (`python/pathlight`) re-exports
//! these and carries the type stubs.

mod arrays;
mod errors;
mod files;
mod renderer;
mod scene;

use std::path::PathBuf;

use numpy::{PyArray3, PyReadonlyArray3};
use pathlight_core::state::{RenderState, merge as merge_states};
use pathlight_denoise::{Aux, Denoiser, Mode};
use pathlight_scene::settings::check_spp;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use crate::errors::{RenderError, SceneError, render_error};
use crate::renderer::Renderer;
use crate::scene::{Scene, SceneInput};

/// Loads a scene: a scene file (`.toml`), a glTF file (`.gltf`, `.glb`; `camera` chooses
/// one of its cameras, and without lights of its own it gets a grey sky, as `pathlight
/// render` gives it) or, given a dict, the scene the dict's keys describe as a scene file's
/// would (relative asset paths from `base_dir`, the working folder by default).
#[pyfunction]
#[pyo3(signature = (source, base_dir = None, camera = None))]
fn load(source: SceneInput, base_dir: Option<PathBuf>, camera: Option<usize>) -> PyResult<Scene> {
    Scene::load(source, base_dir, camera)
}

/// The built-in default scene.
#[pyfunction]
fn default_scene() -> PyResult<Scene> {
    Scene::default_scene()
}

/// Renders `scene` and returns the image, a float32 array of shape (height, width, 3) in
/// linear RGB. Arguments left out take the scene's values; `backend` is "auto" (a hardware
/// GPU when there is one, else the CPU backend), "gpu" or "cpu".
#[pyfunction]
#[pyo3(signature = (scene, spp = None, seed = None, width = None, height = None, backend = "auto", max_depth = None))]
#[expect(clippy::too_many_arguments, reason = "Python keyword arguments")]
fn render<'py>(
    py: Python<'py>,
    scene: &Scene,
    spp: Option<u32>,
    seed: Option<u32>,
    width: Option<u32>,
    height: Option<u32>,
    backend: &str,
    max_depth: Option<u32>,
) -> PyResult<Bound<'py, PyArray3<f32>>> {
    // No copy of the scene: the backend gets the prepared scene, camera and settings.
    let (camera, settings) =
        renderer::render_settings(scene, backend, seed, width, height, max_depth, false)?;
    let spp = spp.unwrap_or(settings.spp);
    check_spp(spp).map_err(|e| PyValueError::new_err(e.to_string()))?;
    let prepared = scene.prepared(py)?;
    let (mut backend, _) = renderer::open(py, &prepared, &camera, &settings, backend, 0)?;
    renderer::render_to(py, &mut backend, spp)?;
    Ok(arrays::to_numpy(py, &backend.film().map_err(render_error)?))
}

/// Merges state files (shards of one render, or a render and its resumption) exactly and
/// returns their image; with `output`, also writes the merged state there.
#[pyfunction]
#[pyo3(signature = (paths, output = None))]
fn merge<'py>(
    py: Python<'py>,
    paths: Vec<PathBuf>,
    output: Option<PathBuf>,
) -> PyResult<Bound<'py, PyArray3<f32>>> {
    let mut parts = Vec::with_capacity(paths.len());
    for path in &paths {
        parts.push((path.display().to_string(), files::read_state(path)?));
    }
    let merged = merge_states(&parts).map_err(render_error)?;
    let film = merged.film();
    if let Some(output) = output {
        let state: RenderState = merged.into_state().map_err(render_error)?;
        files::write_state(&state, &output)?;
    }
    Ok(arrays::to_numpy(py, &film))
}

/// Reads an OpenEXR image (as `pathlight render -o image.exr` writes) into a float32 array
/// of shape (height, width, 3).
#[pyfunction]
fn read_exr<'py>(py: Python<'py>, path: PathBuf) -> PyResult<Bound<'py, PyArray3<f32>>> {
    let film = pathlight_core::Film::read_exr(&path)
        .map_err(|e| SceneError::new_err(format!("{}: {e}", path.display())))?;
    Ok(arrays::to_numpy(py, &film))
}

/// Writes `image` (float32, shape (height, width, 3), linear RGB) to `path` as its extension
/// says, as `pathlight render` writes images: `.png` (8-bit, the sRGB curve, clamped) or
/// `.exr` (32-bit float).
#[pyfunction]
fn write_image(path: PathBuf, image: PyReadonlyArray3<'_, f32>) -> PyResult<()> {
    files::write_image(&arrays::from_numpy("image", &image)?, &path)
}

/// Denoises `color` (float32, shape (height, width, 3), linear RGB) with Open Image Denoise,
/// guided by `albedo` and `normal` (both or neither) when given; `mode` is "final" or "fast".
#[pyfunction]
#[pyo3(signature = (color, albedo = None, normal = None, mode = "final"))]
fn denoise<'py>(
    py: Python<'py>,
    color: PyReadonlyArray3<'py, f32>,
    albedo: Option<PyReadonlyArray3<'py, f32>>,
    normal: Option<PyReadonlyArray3<'py, f32>>,
    mode: &str,
) -> PyResult<Bound<'py, PyArray3<f32>>> {
    let mode = match mode {
        "final" => Mode::Final,
        "fast" => Mode::Fast,
        other => {
            return Err(PyValueError::new_err(format!(
                "mode {other:?}: use \"final\" or \"fast\""
            )));
        }
    };
    let color = arrays::from_numpy("color", &color)?;
    let guides = match (albedo, normal) {
        (Some(albedo), Some(normal)) => Some((
            arrays::from_numpy("albedo", &albedo)?,
            arrays::from_numpy("normal", &normal)?,
        )),
        (None, None) => None,
        _ => {
            return Err(PyValueError::new_err(
                "give albedo and normal together, or neither",
            ));
        }
    };
    let denoised = py.detach(|| {
        let denoiser = Denoiser::load()?;
        let aux = guides
            .as_ref()
            .map(|(albedo, normal)| Aux { albedo, normal });
        denoiser.denoise(&color, aux, mode)
    });
    Ok(arrays::to_numpy(py, &denoised.map_err(render_error)?))
}

/// The module `pathlight._pathlight`.
#[pymodule]
fn _pathlight(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Scene>()?;
    m.add_class::<Renderer>()?;
    m.add_function(wrap_pyfunction!(load, m)?)?;
    m.add_function(wrap_pyfunction!(default_scene, m)?)?;
    m.add_function(wrap_pyfunction!(render, m)?)?;
    m.add_function(wrap_pyfunction!(merge, m)?)?;
    m.add_function(wrap_pyfunction!(read_exr, m)?)?;
    m.add_function(wrap_pyfunction!(write_image, m)?)?;
    m.add_function(wrap_pyfunction!(denoise, m)?)?;
    m.add("SceneError", m.py().get_type::<SceneError>())?;
    m.add("RenderError", m.py().get_type::<RenderError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
