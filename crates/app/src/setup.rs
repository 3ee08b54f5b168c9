//! What every command does first: load the scene, apply the command line's overrides, and
//! open the backend that will render it.

use anyhow::{Context, anyhow};
use pathlight_core::gpu::{SAMPLER_INDEPENDENT, SAMPLER_SOBOL};
use pathlight_core::load::{check_max_depth, check_resolution};
use pathlight_core::{Film, GpuScene, Scene, default_scene, load_scene_file};
use pathlight_cpu::CpuRenderer;
use pathlight_render::context::describe;
use pathlight_render::{Accel, GpuContext, ProgressiveRenderer};

use crate::cli::{Backend, DeviceArgs, SamplerChoice, SceneArgs};

/// Loads the scene named on the command line (or the default scene) with its overrides
/// applied, refusing bad values.
pub fn load_scene(args: &SceneArgs) -> anyhow::Result<Scene> {
    let mut scene = match &args.scene {
        Some(path) => load_scene_file(path)?,
        None => default_scene::load().context("the built-in default scene")?,
    };
    if let Some(width) = args.width {
        scene.camera.width = width;
    }
    if let Some(height) = args.height {
        scene.camera.height = height;
    }
    check_resolution(scene.camera.width, scene.camera.height).map_err(|m| anyhow!(m))?;
    if let Some(max_depth) = args.max_depth {
        scene.settings.max_depth = max_depth;
    }
    check_max_depth(scene.settings.max_depth).map_err(|m| anyhow!(m))?;
    if let Some(seed) = args.seed {
        scene.settings.seed = seed;
    }
    if let Some(sampler) = args.sampler {
        scene.settings.sampler = match sampler {
            SamplerChoice::Sobol => SAMPLER_SOBOL,
            SamplerChoice::Independent => SAMPLER_INDEPENDENT,
        };
    }
    Ok(scene)
}

/// Opens the GPU context the device arguments ask for, or `None` for the CPU backend.
pub fn open_context(args: &DeviceArgs) -> anyhow::Result<Option<GpuContext>> {
    Ok(match args.backend {
        Backend::Gpu => Some(GpuContext::new(args.adapter.as_deref())?),
        Backend::Cpu => None,
    })
}

/// Where rendering runs, for messages and reports: the adapter, or the CPU backend.
pub fn device_name(ctx: Option<&GpuContext>) -> String {
    match ctx {
        Some(ctx) => describe(&ctx.adapter_info),
        None => format!(
            "cpu backend, {} threads, {}",
            rayon::current_num_threads(),
            pathlight_cpu::InstructionSet::best().name()
        ),
    }
}

/// A progressive renderer on either backend. (One per command: the variants' sizes do not
/// matter.)
#[allow(clippy::large_enum_variant)]
pub enum Renderer {
    /// WGSL on a wgpu adapter.
    Gpu(ProgressiveRenderer),
    /// The native CPU twin.
    Cpu(CpuRenderer),
}

impl Renderer {
    /// Prepares `scene` on the context's adapter, or on the CPU when there is none.
    pub fn new(
        ctx: Option<&GpuContext>,
        scene: &Scene,
        gpu_scene: GpuScene,
        accel: Accel,
    ) -> anyhow::Result<Self> {
        Ok(match ctx {
            Some(ctx) => Renderer::Gpu(ProgressiveRenderer::with_accel(
                ctx, scene, &gpu_scene, accel,
            )?),
            None if accel != Accel::Bvh => {
                anyhow::bail!(
                    "--accel {} needs the GPU backend; the CPU backend has only the BVH",
                    accel.name()
                )
            }
            None => Renderer::Cpu(CpuRenderer::new(scene, gpu_scene)),
        })
    }

    /// Samples per pixel accumulated so far.
    pub fn samples_done(&self) -> u32 {
        match self {
            Self::Gpu(r) => r.samples_done(),
            Self::Cpu(r) => r.samples_done(),
        }
    }

    /// Adds up to `max_samples` samples per pixel; returns how many.
    pub fn advance(&mut self, max_samples: u32) -> anyhow::Result<u32> {
        Ok(match self {
            Self::Gpu(r) => r.advance(max_samples)?,
            Self::Cpu(r) => r.advance(max_samples),
        })
    }

    /// Adds one sample per pixel as one unit of work (one dispatch on the GPU, not waited
    /// for: see [`Self::finish`]).
    pub fn frame(&mut self) {
        match self {
            Self::Gpu(r) => r.submit_frame(),
            Self::Cpu(r) => {
                r.advance(1);
            }
        }
    }

    /// Waits for the frames queued so far.
    pub fn finish(&self) -> anyhow::Result<()> {
        if let Self::Gpu(r) = self {
            r.finish()?;
        }
        Ok(())
    }

    /// Entries of the GPU's traversal stack (the integrator is compiled with it); `None` on
    /// the CPU backend, whose stacks grow as needed.
    pub fn traversal_stack(&self) -> Option<u32> {
        match self {
            Self::Gpu(r) => Some(r.stack_size()),
            Self::Cpu(_) => None,
        }
    }

    /// Rays traced so far.
    pub fn rays_traced(&self) -> anyhow::Result<u64> {
        Ok(match self {
            Self::Gpu(r) => r.rays_traced()?,
            Self::Cpu(r) => r.rays_traced(),
        })
    }

    /// The mean of the samples so far.
    pub fn film(&self) -> anyhow::Result<Film> {
        Ok(match self {
            Self::Gpu(r) => r.read_film()?,
            Self::Cpu(r) => r.film(),
        })
    }
}
