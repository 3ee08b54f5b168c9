//! `pathlight.Scene`: a loaded scene, its camera and its materials changeable between renders,
//! and the geometry prepared once for all of them.

use std::path::{Path, PathBuf};
use std::sync::{Arc, OnceLock};

use glam::Vec3;
use pathlight_core::{EnvironmentData, PreparedScene};
use pathlight_scene::settings::{
    check_aperture, check_env_rotation, check_env_strength, check_length, check_resolution,
    check_view,
};
use pathlight_scene::{
    Camera, Environment, HdrImage, SceneSource, default_scene, gltf_scene, load_materials,
    load_scene,
};
use pyo3::exceptions::{PyKeyError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};

use crate::errors::{SceneError, render_error, scene_error};

/// What `pathlight.load` takes: scene data (a dict with the scene file's keys) or a path.
#[derive(FromPyObject)]
pub enum SceneInput<'py> {
    /// The scene file's keys, as Python values.
    Data(Bound<'py, PyDict>),
    /// A scene file or glTF file.
    Path(PathBuf),
}

/// The scene-file text a scene was built from, kept to build its materials again when one
/// changes (a glTF file's scene has none: its materials do not change).
#[derive(Clone)]
struct Source {
    /// The name errors give it.
    name: String,
    /// Its keys, as changed so far.
    table: toml::Table,
    /// The folder relative asset paths start from.
    base_dir: PathBuf,
    /// Assets compiled in (the default scene's).
    embedded: &'static [(&'static str, &'static [u8])],
}

impl Source {
    /// Builds a scene from `text` (which parses to `table`), named `name` in errors.
    fn load(&self, text: &str) -> PyResult<pathlight_scene::Scene> {
        load_scene(&SceneSource {
            name: self.name.clone(),
            text,
            base_dir: self.base_dir.clone(),
            embedded: self.embedded,
        })
        .map_err(scene_error)
    }
}

/// A scene: loaded from a scene file, a glTF file or Python data. Its camera and (for a scene
/// file's or data's scene) its materials can change between renders; the geometry is
/// prepared (its BVH built) once, on the first render.
#[pyclass(module = "pathlight", name = "Scene")]
#[derive(Clone)]
pub struct Scene {
    pub(crate) scene: pathlight_scene::Scene,
    source: Option<Source>,
    prepared: OnceLock<PreparedScene>,
}

impl Scene {
    fn new(scene: pathlight_scene::Scene, source: Option<Source>) -> Self {
        Self {
            scene,
            source,
            prepared: OnceLock::new(),
        }
    }

    /// The scene `source` names (with `base_dir` for a dict's asset paths; `camera`, a glTF
    /// file's camera to look through).
    pub fn load(
        source: SceneInput,
        base_dir: Option<PathBuf>,
        camera: Option<usize>,
    ) -> PyResult<Self> {
        if camera.is_some() && !matches!(&source, SceneInput::Path(path) if is_gltf(path)) {
            return Err(PyValueError::new_err(
                "camera chooses a camera of a glTF file (.gltf, .glb)",
            ));
        }
        match source {
            SceneInput::Data(data) => {
                let table = to_table(&data, "")?;
                let base_dir = match base_dir {
                    Some(dir) => dir,
                    None => std::env::current_dir().map_err(scene_error)?,
                };
                let source = Source {
                    name: "<scene data>".into(),
                    table,
                    base_dir,
                    embedded: &[],
                };
                let text = toml::to_string(&source.table).map_err(scene_error)?;
                Ok(Self::new(source.load(&text)?, Some(source)))
            }
            SceneInput::Path(path) => {
                if base_dir.is_some() {
                    return Err(PyValueError::new_err(
                        "base_dir is for scene data: a file's asset paths start from its folder",
                    ));
                }
                if is_gltf(&path) {
                    return Ok(Self::new(
                        gltf_scene(&path, camera).map_err(scene_error)?,
                        None,
                    ));
                }
                let text = std::fs::read_to_string(&path).map_err(|source| {
                    scene_error(pathlight_scene::SceneError::Io {
                        path: path.clone(),
                        source,
                    })
                })?;
                let source = Source {
                    name: path.display().to_string(),
                    table: toml::Table::new(),
                    base_dir: path.parent().map(Path::to_owned).unwrap_or_default(),
                    embedded: &[],
                };
                let scene = source.load(&text)?;
                // The text loaded, so it parses.
                let table = text.parse().map_err(scene_error)?;
                Ok(Self::new(scene, Some(Source { table, ..source })))
            }
        }
    }

    /// The built-in default scene.
    pub fn default_scene() -> PyResult<Self> {
        let source = Source {
            name: "<default scene>".into(),
            table: default_scene::TEXT.parse().map_err(scene_error)?,
            base_dir: PathBuf::new(),
            embedded: default_scene::ASSETS,
        };
        Ok(Self::new(source.load(default_scene::TEXT)?, Some(source)))
    }

    /// The scene prepared for rendering: built on the first call (without the GIL), then
    /// kept.
    pub fn prepared(&self, py: Python) -> PyResult<PreparedScene> {
        if let Some(prepared) = self.prepared.get() {
            return Ok(prepared.clone());
        }
        let prepared = py
            .detach(|| PreparedScene::new(&self.scene))
            .map_err(render_error)?;
        Ok(self.prepared.get_or_init(|| prepared).clone())
    }

    /// Material `name` built again with `keys` changed (`None` removes a key), the other
    /// materials as they were; returns the new materials, which replace the scene's.
    pub fn change_material(
        &mut self,
        name: &str,
        keys: Option<&Bound<PyDict>>,
    ) -> PyResult<Vec<pathlight_scene::Material>> {
        let Some(source) = &mut self.source else {
            return Err(SceneError::new_err(
                "the materials of a glTF file's scene do not change from Python (those of \
                 scene files and scene data do)",
            ));
        };
        let mut table = source.table.clone();
        let materials = table
            .entry("materials")
            .or_insert_with(|| toml::Value::Table(toml::Table::new()));
        let Some(material) = materials
            .as_table_mut()
            .and_then(|materials| materials.get_mut(name))
            .and_then(toml::Value::as_table_mut)
        else {
            let names: Vec<&str> = self
                .scene
                .materials
                .iter()
                .map(|m| m.name.as_str())
                .collect();
            return Err(PyKeyError::new_err(format!(
                "no material {name:?} in {}: its materials are {}",
                source.name,
                names.join(", ")
            )));
        };
        for (key, value) in keys.into_iter().flatten() {
            let key: String = key.extract()?;
            if key == "texture" {
                return Err(PyValueError::new_err(format!(
                    "materials.{name}.texture: textures are read with the scene; load it again \
                     to change one"
                )));
            }
            if value.is_none() {
                material.remove(&key);
            } else {
                material.insert(
                    key.clone(),
                    to_value(&value, &format!("materials.{name}.{key}"))?,
                );
            }
        }
        let text = toml::to_string(&table).map_err(scene_error)?;
        let built = load_materials(&SceneSource {
            name: format!("{} (material {name} changed)", source.name),
            text: &text,
            base_dir: source.base_dir.clone(),
            embedded: source.embedded,
        })
        .map_err(scene_error)?;
        source.table = table;
        let mut materials = self.scene.materials.clone();
        materials[..built.len()].clone_from_slice(&built);
        self.apply_materials(materials.clone());
        Ok(materials)
    }

    /// Replaces the materials (and the prepared scene's shading, when it is prepared).
    fn apply_materials(&mut self, materials: Vec<pathlight_scene::Material>) {
        self.scene.materials = materials;
        if let Some(prepared) = self.prepared.get_mut() {
            prepared.shading = prepared.shading_of(&self.scene);
        }
    }
}

#[pymethods]
impl Scene {
    /// The camera: position, look_at, up, fov_y (degrees), width, height, aperture_radius,
    /// focus_distance.
    #[getter]
    fn camera<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        camera_dict(py, &self.scene.camera)
    }

    /// Moves, turns or resizes the camera: keys `position`, `look_at`, `up`, `fov_y`,
    /// `width`, `height`, `aperture_radius`, `focus_distance`; those left out keep their
    /// values.
    #[pyo3(signature = (**keys))]
    fn set_camera(&mut self, keys: Option<&Bound<PyDict>>) -> PyResult<()> {
        self.scene.camera = changed_camera(&self.scene.camera, keys)?;
        Ok(())
    }

    /// Changes the light from far away: an HDR `map` (a path: `.hdr` or `.exr`, strength 1,
    /// no turn unless given), or a constant `radiance` (linear RGB; `[0, 0, 0]`: none), or the
    /// current map's `strength` and `rotation` (degrees about +y) alone, as the scene file's
    /// `[environment]` and `pathlight render --env` give them.
    #[pyo3(signature = (*, map = None, radiance = None, strength = None, rotation = None))]
    fn set_environment(
        &mut self,
        map: Option<PathBuf>,
        radiance: Option<[f32; 3]>,
        strength: Option<f32>,
        rotation: Option<f32>,
    ) -> PyResult<()> {
        let value = |e: pathlight_scene::RangeError| PyValueError::new_err(e.to_string());
        let environment = match radiance {
            Some(radiance) => {
                if map.is_some() || strength.is_some() || rotation.is_some() {
                    return Err(PyValueError::new_err(
                        "radiance is a constant environment: give it without map, strength and \
                         rotation",
                    ));
                }
                if !radiance.iter().all(|c| c.is_finite() && *c >= 0.0) {
                    return Err(PyValueError::new_err(format!(
                        "radiance = {radiance:?} must be finite and not negative"
                    )));
                }
                Environment::Constant(Vec3::from(radiance))
            }
            None => {
                if let Some(strength) = strength {
                    check_env_strength("strength", strength).map_err(value)?;
                }
                if let Some(rotation) = rotation {
                    check_env_rotation("rotation", rotation).map_err(value)?;
                }
                let image = match &map {
                    Some(path) => Some(Arc::new(HdrImage::open(path).map_err(scene_error)?)),
                    None => None,
                };
                self.scene
                    .environment
                    .with_map(image, strength, rotation)
                    .ok_or_else(|| {
                        PyValueError::new_err(
                            "strength and rotation need an environment map: give map=PATH",
                        )
                    })?
            }
        };
        self.scene.environment = environment;
        if let Some(prepared) = self.prepared.get_mut() {
            prepared.environment = Arc::new(match &self.scene.environment {
                Environment::Map(map) => EnvironmentData::build(&map.image),
                Environment::Constant(_) => EnvironmentData::none(),
            });
            prepared.shading = prepared.shading_of(&self.scene);
        }
        Ok(())
    }

    /// The materials' names, in the scene's order.
    #[getter]
    fn materials(&self) -> Vec<String> {
        self.scene
            .materials
            .iter()
            .map(|m| m.name.clone())
            .collect()
    }

    /// Changes material `name`'s keys (those of the scene file's `[materials.NAME]`; `None`
    /// removes a key), checked as the scene file's are.
    #[pyo3(signature = (name, **keys))]
    fn set_material(&mut self, name: &str, keys: Option<&Bound<PyDict>>) -> PyResult<()> {
        self.change_material(name, keys)?;
        Ok(())
    }

    /// Samples per pixel the scene asks for (`[render] spp`).
    #[getter]
    fn spp(&self) -> u32 {
        self.scene.settings.spp
    }

    fn __repr__(&self) -> String {
        let c = &self.scene.camera;
        format!(
            "<pathlight.Scene {}x{}, {} objects, {} materials, {} lights>",
            c.width,
            c.height,
            self.scene.objects.len(),
            self.scene.materials.len(),
            self.scene.lights.len()
        )
    }
}

/// Whether `path` names a glTF file (`.gltf`, `.glb`, any case).
fn is_gltf(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("gltf") || e.eq_ignore_ascii_case("glb"))
}

/// A camera as a dict.
pub fn camera_dict<'py>(py: Python<'py>, camera: &Camera) -> PyResult<Bound<'py, PyDict>> {
    let dict = PyDict::new(py);
    dict.set_item("position", camera.position.to_array())?;
    dict.set_item("look_at", camera.look_at.to_array())?;
    dict.set_item("up", camera.up.to_array())?;
    dict.set_item("fov_y", camera.fov_y_deg)?;
    dict.set_item("width", camera.width)?;
    dict.set_item("height", camera.height)?;
    dict.set_item("aperture_radius", camera.aperture_radius)?;
    dict.set_item("focus_distance", camera.focus_distance)?;
    Ok(dict)
}

/// The camera keys `set_camera` takes.
const CAMERA_KEYS: [&str; 8] = [
    "position",
    "look_at",
    "up",
    "fov_y",
    "width",
    "height",
    "aperture_radius",
    "focus_distance",
];

/// `camera` with the `keys` given changed, refused as the scene file refuses such a camera
/// (an unknown key too). A focus distance that was the distance to `look_at` follows a
/// moved camera or target.
pub fn changed_camera(camera: &Camera, keys: Option<&Bound<PyDict>>) -> PyResult<Camera> {
    let get = |key: &str| -> PyResult<Option<Bound<PyAny>>> {
        Ok(match keys {
            Some(keys) => keys.get_item(key)?.filter(|v| !v.is_none()),
            None => None,
        })
    };
    for key in keys.into_iter().flat_map(|k| k.keys()) {
        let key: String = key.extract()?;
        if !CAMERA_KEYS.contains(&key.as_str()) {
            return Err(PyTypeError::new_err(format!(
                "set_camera has no key {key:?}: it takes {}",
                CAMERA_KEYS.join(", ")
            )));
        }
    }
    let point = |key: &str, old: Vec3| -> PyResult<Vec3> {
        match get(key)? {
            Some(v) => {
                let v: [f32; 3] = v.extract()?;
                if v.iter().all(|c| c.is_finite()) {
                    Ok(Vec3::from(v))
                } else {
                    Err(PyValueError::new_err(format!(
                        "{key} = {v:?} is not finite"
                    )))
                }
            }
            None => Ok(old),
        }
    };
    let number =
        |key: &str| -> PyResult<Option<f32>> { get(key)?.map(|v| v.extract()).transpose() };
    let size = |key: &str| -> PyResult<Option<u32>> { get(key)?.map(|v| v.extract()).transpose() };
    let value = |e: pathlight_scene::RangeError| PyValueError::new_err(e.to_string());
    let position = point("position", camera.position)?;
    let look_at = point("look_at", camera.look_at)?;
    let up = point("up", camera.up)?;
    let fov_y_deg = number("fov_y")?.unwrap_or(camera.fov_y_deg);
    check_view("", position, look_at, up, fov_y_deg).map_err(value)?;
    let width = size("width")?.unwrap_or(camera.width);
    let height = size("height")?.unwrap_or(camera.height);
    check_resolution(width, height).map_err(value)?;
    let aperture_radius = match number("aperture_radius")? {
        Some(radius) => check_aperture("aperture_radius", radius).map_err(value)?,
        None => camera.aperture_radius,
    };
    let focus_distance = match number("focus_distance")? {
        Some(distance) => check_length("focus_distance", distance).map_err(value)?,
        None if camera.focus_distance == camera.look_distance() => position.distance(look_at),
        None => camera.focus_distance,
    };
    Ok(Camera {
        position,
        look_at,
        up,
        fov_y_deg,
        width,
        height,
        aperture_radius,
        focus_distance,
    })
}

/// A dict of scene keys as a TOML table (`at`: the keys above it, for errors).
fn to_table(dict: &Bound<PyDict>, at: &str) -> PyResult<toml::Table> {
    let mut table = toml::Table::new();
    for (key, value) in dict {
        let Ok(key) = key.cast::<PyString>() else {
            return Err(PyTypeError::new_err(format!(
                "scene data{}: the key {} is not a string",
                if at.is_empty() {
                    String::new()
                } else {
                    format!(" at {at}")
                },
                key.repr()?
            )));
        };
        let key: String = key.extract()?;
        let path = if at.is_empty() {
            key.clone()
        } else {
            format!("{at}.{key}")
        };
        if !value.is_none() {
            table.insert(key, to_value(&value, &path)?);
        }
    }
    Ok(table)
}

/// A Python value as a TOML value: dicts, lists and tuples, strings and paths, numbers
/// (NumPy's too) and booleans (`at`: its key, for errors).
fn to_value(value: &Bound<PyAny>, at: &str) -> PyResult<toml::Value> {
    if value.is_instance_of::<PyBool>() {
        return Ok(toml::Value::Boolean(value.extract()?));
    }
    if value.is_instance_of::<PyInt>() {
        return Ok(toml::Value::Integer(value.extract().map_err(|_| {
            PyValueError::new_err(format!("{at}: {} is out of range", value))
        })?));
    }
    if value.is_instance_of::<PyFloat>() {
        return Ok(toml::Value::Float(value.extract()?));
    }
    if let Ok(text) = value.cast::<PyString>() {
        return Ok(toml::Value::String(text.extract()?));
    }
    if let Ok(dict) = value.cast::<PyDict>() {
        return Ok(toml::Value::Table(to_table(dict, at)?));
    }
    if value.is_instance_of::<PyList>() || value.is_instance_of::<PyTuple>() {
        let items = value
            .try_iter()?
            .enumerate()
            .map(|(i, item)| to_value(&item?, &format!("{at}[{i}]")))
            .collect::<PyResult<_>>()?;
        return Ok(toml::Value::Array(items));
    }
    if value.hasattr("__fspath__")? {
        let path: PathBuf = value.extract()?;
        return Ok(toml::Value::String(path.to_string_lossy().into_owned()));
    }
    // NumPy arrays and scalars.
    if value.hasattr("tolist")? {
        return to_value(&value.call_method0("tolist")?, at);
    }
    Err(PyTypeError::new_err(format!(
        "{at}: a {} is not a scene value (a dict, list, string, number or bool)",
        value.get_type().name()?
    )))
}
