//! `pathlight.Renderer`: a progressive render on either backend, stepped from Python with
//! the GIL released, stopped by Ctrl-C between steps, saved to and resumed from state files.

use std::path::PathBuf;
use std::sync::Mutex;

use numpy::PyArray3;
use pathlight_core::state::{Fingerprint, RenderState};
use pathlight_core::{Accumulation, Film, PreparedScene, Renderer as Backend};
use pathlight_cpu::{CpuRenderer, InstructionSet};
use pathlight_gpu::context::{AutoChoice, auto_choice, available_adapters};
use pathlight_gpu::{Accel, GpuContext, GpuRenderer, Kernel};
use pathlight_scene::settings::{check_max_depth, check_resolution};
use pathlight_scene::{Camera, RenderSettings};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::arrays::to_numpy;
use crate::errors::{RenderError, render_error};
use crate::files::{read_state, write_state};
use crate::scene::{Scene, camera_dict, changed_camera};

/// A progressive render of a scene (a copy of it, taken when the renderer is made: changes
/// to the renderer's camera and materials do not touch the scene's). Arguments left out take
/// the scene's values; `backend` is "auto" (a hardware GPU when there is one, else the CPU
/// backend), "gpu" or "cpu"; `aovs` accumulates the albedo and normal images too;
/// `first_sample` starts the render at that sample index (one shard of a render made of
/// several, summed by `merge`).
#[pyclass(module = "pathlight", name = "Renderer")]
pub struct Renderer {
    scene: Scene,
    /// The backend: behind a lock only so that the class may be shared between threads;
    /// methods that render hold `&mut self` and reach it without locking.
    backend: Mutex<Box<dyn Backend + Send>>,
    /// "cpu" or "gpu".
    kind: &'static str,
}

impl Renderer {
    fn backend(&mut self) -> &mut Box<dyn Backend + Send> {
        self.backend
            .get_mut()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
    }

    /// Renders until every pixel holds `spp` samples (see [`render_to`]).
    pub fn render_to(&mut self, py: Python, spp: u32) -> PyResult<()> {
        render_to(py, self.backend(), spp)
    }

    /// The image so far.
    pub fn image<'py>(&mut self, py: Python<'py>) -> PyResult<Bound<'py, PyArray3<f32>>> {
        let film = self.backend().film().map_err(render_error)?;
        Ok(to_numpy(py, &film))
    }

    /// The auxiliary images so far (albedo, normal), refused for a render without them.
    fn aov_films(&mut self) -> PyResult<(Film, Film)> {
        let (width, height) = (
            self.scene.scene.camera.width,
            self.scene.scene.camera.height,
        );
        let accumulation = self.backend().accumulation().map_err(render_error)?;
        Film::aovs_from_accumulation(width, height, &accumulation).ok_or_else(|| {
            RenderError::new_err("this render has no albedo and normal: make it with aovs=True")
        })
    }

    /// The fingerprint of what this renderer renders (the scene hashed).
    fn fingerprint(&self, py: Python) -> PyResult<Fingerprint> {
        let prepared = self.scene.prepared(py)?;
        let (camera, settings) = (&self.scene.scene.camera, &self.scene.scene.settings);
        Ok(py.detach(|| Fingerprint::new(&prepared, camera, settings)))
    }
}

#[pymethods]
impl Renderer {
    /// A progressive render of `scene` (see the class).
    #[new]
    #[pyo3(signature = (scene, *, backend = "auto", seed = None, width = None, height = None, max_depth = None, aovs = false, first_sample = 0))]
    #[expect(clippy::too_many_arguments, reason = "Python keyword arguments")]
    pub fn new(
        py: Python,
        scene: &Scene,
        backend: &str,
        seed: Option<u32>,
        width: Option<u32>,
        height: Option<u32>,
        max_depth: Option<u32>,
        aovs: bool,
        first_sample: u32,
    ) -> PyResult<Self> {
        let (camera, settings) =
            render_settings(scene, backend, seed, width, height, max_depth, aovs)?;
        let prepared = scene.prepared(py)?;
        let (renderer, kind) = open(py, &prepared, &camera, &settings, backend, first_sample)?;
        let mut scene = scene.clone();
        scene.scene.camera = camera;
        scene.scene.settings = settings;
        Ok(Self {
            scene,
            backend: Mutex::new(renderer),
            kind,
        })
    }

    /// Adds `spp` samples to every pixel; returns the samples per pixel now held.
    #[pyo3(signature = (spp = 1))]
    fn step(&mut self, py: Python, spp: u32) -> PyResult<u32> {
        let target = self.backend().samples_done().saturating_add(spp);
        self.render_to(py, target)?;
        Ok(self.backend().samples_done())
    }

    /// The image so far: float32, shape (height, width, 3), linear RGB.
    #[pyo3(name = "image")]
    fn py_image<'py>(&mut self, py: Python<'py>) -> PyResult<Bound<'py, PyArray3<f32>>> {
        self.image(py)
    }

    /// The albedo image so far (a render made with aovs=True).
    fn albedo<'py>(&mut self, py: Python<'py>) -> PyResult<Bound<'py, PyArray3<f32>>> {
        Ok(to_numpy(py, &self.aov_films()?.0))
    }

    /// The shading normal image so far (a render made with aovs=True), components in [-1, 1].
    fn normal<'py>(&mut self, py: Python<'py>) -> PyResult<Bound<'py, PyArray3<f32>>> {
        Ok(to_numpy(py, &self.aov_films()?.1))
    }

    /// Samples per pixel held (every pixel; rows of a pass cut short hold one more).
    #[getter]
    fn samples(&mut self) -> u32 {
        self.backend().samples_done()
    }

    /// The backend rendering: "cpu" or "gpu".
    #[getter]
    fn backend_name(&self) -> &'static str {
        self.kind
    }

    /// Where it renders, in words (the adapter, or the CPU's threads and level).
    #[getter]
    fn device(&mut self) -> String {
        self.backend().device()
    }

    /// The camera, as `Scene.camera`.
    #[getter]
    fn camera<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        camera_dict(py, &self.scene.scene.camera)
    }

    /// Moves, turns or resizes the camera (as `Scene.set_camera`) and starts the image again.
    #[pyo3(signature = (**keys))]
    fn set_camera(&mut self, keys: Option<&Bound<PyDict>>) -> PyResult<()> {
        let camera = changed_camera(&self.scene.scene.camera, keys)?;
        self.backend().set_camera(&camera).map_err(render_error)?;
        self.scene.scene.camera = camera;
        Ok(())
    }

    /// Changes material `name`'s keys (as `Scene.set_material`) and starts the image again.
    #[pyo3(signature = (name, **keys))]
    fn set_material(
        &mut self,
        py: Python,
        name: &str,
        keys: Option<&Bound<PyDict>>,
    ) -> PyResult<()> {
        self.scene.change_material(name, keys)?;
        let shading = self.scene.prepared(py)?.shading;
        self.backend().set_materials(&shading).map_err(render_error)
    }

    /// Empties the image: the next sample is the first again.
    fn restart(&mut self) {
        self.backend().restart();
    }

    /// Writes the render's state (its exact sums) to `path`, for `resume` and `merge` here
    /// or on the command line (`pathlight render --resume`, `pathlight merge`).
    fn save_state(&mut self, py: Python, path: PathBuf) -> PyResult<()> {
        let fingerprint = self.fingerprint(py)?;
        let backend = self.backend();
        let accumulation = backend.accumulation().map_err(render_error)?;
        let cursor = accumulation.cursor;
        let target = cursor.first_sample..cursor.next_sample() + u32::from(cursor.in_pass());
        let state = RenderState::new(fingerprint, target, backend.device(), accumulation);
        write_state(&state, &path)
    }

    /// Replaces the image with the state in `path` (a render of the same scene, camera and
    /// settings, from here or the command line), to go on from it.
    fn resume(&mut self, py: Python, path: PathBuf) -> PyResult<()> {
        let state = read_state(&path)?;
        let differences = state.fingerprint.differences(
            &self.fingerprint(py)?,
            (&path.display().to_string(), "this render"),
        );
        if !differences.is_empty() {
            return Err(RenderError::new_err(format!(
                "cannot resume {}: it is another render: {}",
                path.display(),
                differences.join("; ")
            )));
        }
        let accumulation = state
            .accumulation()
            .map_err(|e| RenderError::new_err(format!("cannot resume {}: {e}", path.display())))?;
        self.backend().resume(&accumulation).map_err(render_error)
    }

    fn __repr__(&mut self) -> String {
        let c = &self.scene.scene.camera;
        let (width, height) = (c.width, c.height);
        format!(
            "<pathlight.Renderer {width}x{height}, {} spp, {}>",
            self.backend().samples_done(),
            self.backend().device()
        )
    }
}

/// The backends `open` opens.
const BACKENDS: [&str; 3] = ["auto", "gpu", "cpu"];

/// The error of a backend name not among [`BACKENDS`].
fn unknown_backend(name: &str) -> PyErr {
    PyValueError::new_err(format!(
        "backend {name:?}: use \"auto\", \"gpu\" or \"cpu\""
    ))
}

/// The camera and settings a render of `scene` runs with: the scene's, with the arguments
/// given; refused, before anything is prepared, with a bad value or an unknown `backend`.
pub fn render_settings(
    scene: &Scene,
    backend: &str,
    seed: Option<u32>,
    width: Option<u32>,
    height: Option<u32>,
    max_depth: Option<u32>,
    aovs: bool,
) -> PyResult<(Camera, RenderSettings)> {
    if !BACKENDS.contains(&backend) {
        return Err(unknown_backend(backend));
    }
    let value = |e: pathlight_scene::RangeError| PyValueError::new_err(e.to_string());
    let mut settings = scene.scene.settings;
    settings.seed = seed.unwrap_or(settings.seed);
    settings.max_depth = max_depth.unwrap_or(settings.max_depth);
    settings.aovs = aovs;
    check_max_depth(settings.max_depth).map_err(value)?;
    let mut camera = scene.scene.camera.clone();
    camera.width = width.unwrap_or(camera.width);
    camera.height = height.unwrap_or(camera.height);
    check_resolution(camera.width, camera.height).map_err(value)?;
    Ok((camera, settings))
}

/// The backend `name` asks for ("auto", "gpu" or "cpu"), rendering `prepared` as `camera`
/// and `settings` ask from sample `first_sample` on, and its kind.
pub fn open(
    py: Python,
    prepared: &PreparedScene,
    camera: &Camera,
    settings: &RenderSettings,
    name: &str,
    first_sample: u32,
) -> PyResult<(Box<dyn Backend + Send>, &'static str)> {
    let gpu = |context: GpuContext| -> PyResult<(Box<dyn Backend + Send>, &'static str)> {
        // The kernel that renders faster here, timed on the first passes (`auto`).
        let renderer = py
            .detach(|| {
                let mut renderer =
                    GpuRenderer::new(&context, prepared, camera, settings, Accel::Bvh)?;
                renderer.set_kernel(Kernel::Auto)?;
                Ok::<_, pathlight_core::RenderError>(renderer)
            })
            .map_err(render_error)?;
        Ok((Box::new(renderer), "gpu"))
    };
    let (mut renderer, kind) = match name {
        "cpu" => {
            let mut renderer = CpuRenderer::new(prepared, camera, settings);
            let level = InstructionSet::from_environment().map_err(render_error)?;
            renderer.set_instruction_set(level).map_err(render_error)?;
            (Box::new(renderer) as Box<dyn Backend + Send>, "cpu")
        }
        "gpu" => gpu(py.detach(|| GpuContext::new(None)).map_err(render_error)?)?,
        "auto" => {
            let adapters = py.detach(available_adapters);
            let infos: Vec<_> = adapters.iter().map(|a| a.get_info()).collect();
            match auto_choice(&infos) {
                AutoChoice::Gpu(i) => {
                    gpu(GpuContext::from_adapter(&adapters[i]).map_err(render_error)?)?
                }
                AutoChoice::Cpu(_) => {
                    return open(py, prepared, camera, settings, "cpu", first_sample);
                }
            }
        }
        other => return Err(unknown_backend(other)),
    };
    if first_sample > 0 {
        let empty = Accumulation::empty(camera.width, camera.height, first_sample, settings.aovs);
        renderer.resume(&empty).map_err(render_error)?;
    }
    Ok((renderer, kind))
}

/// Renders on `backend` until every pixel holds `spp` samples (from the first), the GIL
/// released while it works; a signal (Ctrl-C) raises its exception between steps of a
/// fraction of a second, the samples so far kept.
pub fn render_to(py: Python, backend: &mut Box<dyn Backend + Send>, spp: u32) -> PyResult<()> {
    while backend.samples_done() < spp {
        let wanted = spp - backend.samples_done();
        py.detach(|| backend.advance(wanted))
            .map_err(render_error)?;
        py.check_signals()?;
    }
    Ok(())
}
