//! What every command does first: load the scene, apply the command line's overrides,
//! prepare it once, and open the backend that renders it.

use std::sync::Arc;

use anyhow::Context;
use glam::Vec3;
use pathlight_core::{PreparedScene, Renderer};
use pathlight_cpu::{CpuRenderer, InstructionSet};
use pathlight_gpu::context::{AutoChoice, auto_choice, available_adapters, describe};
use pathlight_gpu::{Accel, GpuContext, GpuRenderer, Kernel};
use pathlight_scene::settings::{
    check_aperture, check_env_rotation, check_env_strength, check_length, check_max_depth,
    check_resolution,
};
use pathlight_scene::{
    Environment, GREY_SKY, HdrImage, Sampler, Scene, default_scene, gltf_scene, load_scene_file,
};

use crate::cli::{Backend, DeviceArgs, SamplerChoice, SceneArgs};

/// Loads the scene named on the command line (or the default scene) with its overrides
/// applied, refusing bad values.
pub fn load_scene(args: &SceneArgs) -> anyhow::Result<Scene> {
    let gltf = args.scene.as_deref().is_some_and(is_gltf);
    if args.camera.is_some() && !gltf {
        anyhow::bail!("--camera chooses a camera of a glTF file (.gltf, .glb)");
    }
    if args.no_default_env && !gltf {
        anyhow::bail!("--no-default-env removes the sky added to a glTF file (.gltf, .glb)");
    }
    if args.no_default_env && args.env.is_some() {
        anyhow::bail!("--no-default-env and --env: the map would replace the default sky anyway");
    }
    let mut scene = match &args.scene {
        Some(path) if gltf => {
            let mut scene = gltf_scene(path, args.camera)?;
            choose_gltf_lighting(&mut scene, args);
            scene
        }
        Some(path) => load_scene_file(path)?,
        None => default_scene::load().context("the built-in default scene")?,
    };
    if let Some(width) = args.width {
        scene.camera.width = width;
    }
    if let Some(height) = args.height {
        scene.camera.height = height;
    }
    check_resolution(scene.camera.width, scene.camera.height)?;
    if let Some(max_depth) = args.max_depth {
        scene.settings.max_depth = max_depth;
    }
    check_max_depth(scene.settings.max_depth)?;
    if let Some(seed) = args.seed {
        scene.settings.seed = seed;
    }
    if let Some(sampler) = args.sampler {
        scene.settings.sampler = match sampler {
            SamplerChoice::Sobol => Sampler::Sobol,
            SamplerChoice::Independent => Sampler::Independent,
        };
    }
    apply_environment(&mut scene, args)?;
    apply_lens(&mut scene, args)?;
    Ok(scene)
}

/// The lighting of a glTF file opened on its own, said in one line: its punctual lights
/// (then `gltf_scene` adds no sky), or the grey sky `gltf_scene` adds; `--env` replaces the
/// sky, `--no-default-env` removes it (leaving the file's emissive materials, warned about
/// when there are none).
fn choose_gltf_lighting(scene: &mut Scene, args: &SceneArgs) {
    let emitters = scene
        .materials
        .iter()
        .filter(|m| m.emission.max_element() > 0.0)
        .count();
    let counted = |n: usize, what: &str| match n {
        0 => None,
        1 => Some(what.to_string()),
        n => Some(format!("{n} {what}s")),
    };
    let own = [
        counted(scene.lights.len(), "punctual light"),
        counted(emitters, "emissive material"),
    ]
    .into_iter()
    .flatten()
    .enumerate()
    .map(|(i, what)| format!("{} {what}", if i == 0 { "the file's" } else { "its" }))
    .collect::<Vec<_>>()
    .join(" and ");
    let also = if own.is_empty() {
        String::new()
    } else {
        format!(" and {own}")
    };
    if args.env.is_some() {
        note!("lighting: the --env map{also}");
    } else if !scene.lights.is_empty() {
        note!(
            "lighting: {own}, no sky (the file places lights of its own; --env FILE adds a \
             map)"
        );
    } else if args.no_default_env {
        scene.environment = Environment::Constant(Vec3::ZERO);
        if emitters == 0 {
            note!(
                "lighting: none (--no-default-env, and nothing in the file emits): the image \
                 will be black"
            );
        } else {
            note!("lighting: {own} alone (--no-default-env)");
        }
    } else {
        note!(
            "lighting: a uniform grey sky of radiance {GREY_SKY}{also} (the file places no \
             lights; --env FILE lights it with a map, --no-default-env with its emitters \
             alone)"
        );
    }
}

/// Whether `path` names a glTF file (by its extension, `.gltf` or `.glb`, any case).
fn is_gltf(path: &std::path::Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("gltf") || e.eq_ignore_ascii_case("glb"))
}

/// `--env`, `--env-strength` and `--env-rotation`.
fn apply_environment(scene: &mut Scene, args: &SceneArgs) -> anyhow::Result<()> {
    if let Some(strength) = args.env_strength {
        check_env_strength("--env-strength", strength)?;
    }
    if let Some(rotation) = args.env_rotation {
        check_env_rotation("--env-rotation", rotation)?;
    }
    let image = match &args.env {
        Some(path) => Some(Arc::new(HdrImage::open(path)?)),
        None => None,
    };
    scene.environment = scene
        .environment
        .with_map(image, args.env_strength, args.env_rotation)
        .context(
            "--env-strength and --env-rotation need an environment map (--env FILE, or `map` \
             in the scene's [environment])",
        )?;
    Ok(())
}

/// `--aperture` and `--focus-distance`.
fn apply_lens(scene: &mut Scene, args: &SceneArgs) -> anyhow::Result<()> {
    if let Some(radius) = args.aperture {
        scene.camera.aperture_radius = check_aperture("--aperture", radius)?;
    }
    if let Some(distance) = args.focus_distance {
        scene.camera.focus_distance = check_length("--focus-distance", distance)?;
    }
    Ok(())
}

/// The device a command renders on: a wgpu adapter, or the CPU backend.
#[expect(
    clippy::large_enum_variant,
    reason = "one per command; boxing the context would buy nothing"
)]
pub enum Device {
    /// WGSL on this adapter.
    Gpu(GpuContext),
    /// The native CPU backend.
    Cpu,
}

impl Device {
    /// Opens the device the arguments ask for; `--backend auto` says what it chose and why.
    pub fn open(args: &DeviceArgs) -> anyhow::Result<Self> {
        Ok(match (args.backend, args.adapter.as_deref()) {
            (Backend::Gpu, name) | (Backend::Auto, name @ Some(_)) => {
                Device::Gpu(GpuContext::new(name)?)
            }
            (Backend::Cpu, _) => Device::Cpu,
            (Backend::Auto, None) => {
                let adapters = available_adapters();
                let infos: Vec<_> = adapters.iter().map(|a| a.get_info()).collect();
                let choice = auto_choice(&infos);
                note!("{}", explain(choice, &infos));
                match choice {
                    AutoChoice::Gpu(i) => Device::Gpu(GpuContext::from_adapter(&adapters[i])?),
                    AutoChoice::Cpu(_) => Device::Cpu,
                }
            }
        })
    }

    /// The backend it is, as `--backend` names it.
    pub fn backend_name(&self) -> &'static str {
        match self {
            Device::Gpu(_) => "gpu",
            Device::Cpu => "cpu",
        }
    }

    /// Where rendering runs, for messages and reports: the adapter, or the CPU backend.
    pub fn describe(&self) -> String {
        match self {
            Device::Gpu(ctx) => describe(&ctx.adapter_info),
            Device::Cpu => {
                pathlight_cpu::describe(cpu_level().unwrap_or_else(|_| InstructionSet::best()))
            }
        }
    }

    /// A progressive render of `prepared` (the scene `scene` prepared) on this device,
    /// finding hits with `accel` (the GPU offers the seed's slower schemes too) and, on the
    /// GPU, running the integrator as `kernel`.
    pub fn renderer(
        &self,
        scene: &Scene,
        prepared: &PreparedScene,
        accel: Accel,
        kernel: Kernel,
    ) -> anyhow::Result<Box<dyn Renderer>> {
        let (camera, settings) = (&scene.camera, &scene.settings);
        Ok(match self {
            Device::Gpu(ctx) => {
                let mut renderer = GpuRenderer::new(ctx, prepared, camera, settings, accel)?;
                renderer.set_kernel(kernel)?;
                Box::new(renderer)
            }
            Device::Cpu if accel != Accel::Bvh => anyhow::bail!(
                "--accel {} needs the GPU backend; the CPU backend has only the BVH",
                accel.name()
            ),
            Device::Cpu if kernel == Kernel::Wavefront => {
                anyhow::bail!("--gpu-kernel {} needs the GPU backend", kernel.name())
            }
            Device::Cpu => Box::new(cpu_renderer(scene, prepared)?),
        })
    }
}

/// The level the CPU backend runs: the best this CPU has, or the one
/// [`pathlight_cpu::LEVEL_VARIABLE`] names.
pub fn cpu_level() -> anyhow::Result<InstructionSet> {
    Ok(InstructionSet::from_environment()?)
}

/// The CPU backend renderer of `prepared` as `scene`'s camera and settings ask, running
/// [`cpu_level`].
pub fn cpu_renderer(scene: &Scene, prepared: &PreparedScene) -> anyhow::Result<CpuRenderer> {
    let mut renderer = CpuRenderer::new(prepared, &scene.camera, &scene.settings);
    renderer.set_instruction_set(cpu_level()?)?;
    Ok(renderer)
}

/// Why `--backend auto` chose what it did, in one line.
pub fn explain(choice: AutoChoice, adapters: &[wgpu::AdapterInfo]) -> String {
    match choice {
        AutoChoice::Gpu(i) => format!(
            "hardware GPU found: using the GPU backend on {}",
            adapters[i].name
        ),
        AutoChoice::Cpu(software) => {
            let level = cpu_level().unwrap_or_else(|_| InstructionSet::best());
            let cpu = pathlight_cpu::threads_and_level(level);
            let forced = match software {
                Some(i) => format!("--backend gpu forces {}", adapters[i].name),
                None => "no adapter for --backend gpu".to_string(),
            };
            format!("no hardware GPU found: using the CPU backend ({cpu}); {forced}")
        }
    }
}
