//! `pathlight render`: load, render progressively, write the image.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use anyhow::{Context, anyhow};
use pathlight_core::Film;
use pathlight_core::load::{check_max_depth, check_resolution, check_spp};
use pathlight_core::{GpuScene, Scene, default_scene, load_scene_file};
use pathlight_cpu::CpuRenderer;
use pathlight_render::context::{available_adapters, describe};
use pathlight_render::{GpuContext, ProgressiveRenderer};

use crate::cli::{Backend, RenderArgs};
use crate::output;
use crate::progress::Progress;

/// Applies the command-line overrides to the scene's settings, refusing bad values.
fn apply_overrides(scene: &mut Scene, args: &RenderArgs) -> anyhow::Result<()> {
    if let Some(width) = args.width {
        scene.camera.width = width;
    }
    if let Some(height) = args.height {
        scene.camera.height = height;
    }
    check_resolution(scene.camera.width, scene.camera.height).map_err(|m| anyhow!(m))?;
    if let Some(spp) = args.spp {
        scene.settings.spp = spp;
    }
    check_spp(scene.settings.spp).map_err(|m| anyhow!(m))?;
    if let Some(max_depth) = args.max_depth {
        scene.settings.max_depth = max_depth;
    }
    check_max_depth(scene.settings.max_depth).map_err(|m| anyhow!(m))?;
    if let Some(seed) = args.seed {
        scene.settings.seed = seed;
    }
    Ok(())
}

/// Runs the command.
pub fn run(args: &RenderArgs) -> anyhow::Result<()> {
    if args.list_adapters {
        for adapter in available_adapters() {
            println!("{}", describe(&adapter.get_info()));
        }
        return Ok(());
    }
    let mut scene = match &args.scene {
        Some(path) => load_scene_file(path)?,
        None => default_scene::load().context("the built-in default scene")?,
    };
    apply_overrides(&mut scene, args)?;
    let created = output::check_writable(&args.output)?;
    let result = render_to_file(&scene, args);
    if result.is_err() && created {
        let _ = std::fs::remove_file(&args.output);
    }
    result
}

/// A progressive renderer on either backend.
enum Renderer<'a> {
    Gpu(ProgressiveRenderer<'a>),
    Cpu(CpuRenderer),
}

impl Renderer<'_> {
    fn samples_done(&self) -> u32 {
        match self {
            Self::Gpu(r) => r.samples_done(),
            Self::Cpu(r) => r.samples_done(),
        }
    }

    fn advance(&mut self, max_samples: u32) -> anyhow::Result<u32> {
        Ok(match self {
            Self::Gpu(r) => r.advance(max_samples)?,
            Self::Cpu(r) => r.advance(max_samples),
        })
    }

    fn film(&self) -> anyhow::Result<Film> {
        Ok(match self {
            Self::Gpu(r) => r.read_film()?,
            Self::Cpu(r) => r.film(),
        })
    }
}

fn render_to_file(scene: &Scene, args: &RenderArgs) -> anyhow::Result<()> {
    let started = Instant::now();
    let gpu_scene = GpuScene::build(scene);
    let ctx = match args.backend {
        Backend::Gpu => Some(GpuContext::new(args.adapter.as_deref())?),
        Backend::Cpu => None,
    };
    let mut renderer = match &ctx {
        Some(ctx) => {
            note!("adapter: {}", describe(&ctx.adapter_info));
            Renderer::Gpu(ProgressiveRenderer::new(ctx, scene, &gpu_scene)?)
        }
        None => {
            note!("backend: cpu, {} threads", rayon::current_num_threads());
            Renderer::Cpu(CpuRenderer::new(scene, gpu_scene))
        }
    };

    let interrupted = Arc::new(AtomicBool::new(false));
    let flag = interrupted.clone();
    // A second handler cannot be installed (e.g. in tests); rendering works without one.
    let _ = ctrlc::set_handler(move || flag.store(true, Ordering::SeqCst));

    let total = scene.settings.spp;
    let (width, height) = (scene.camera.width, scene.camera.height);
    let mut progress = Progress::new(total, u64::from(width) * u64::from(height));
    let render_started = Instant::now();
    while renderer.samples_done() < total && !interrupted.load(Ordering::SeqCst) {
        renderer.advance(total - renderer.samples_done())?;
        progress.update(renderer.samples_done());
    }
    progress.finish();
    let render_time = render_started.elapsed();
    let film = renderer.film()?;
    if film.spp == 0 {
        anyhow::bail!("interrupted before the first sample; nothing written");
    }
    output::write(&film, &args.output)?;
    if film.spp < total {
        note!("interrupted: kept {} of {total} spp", film.spp);
    }
    note!(
        "wrote {}: {width}x{height}, {} spp, render {:.2} s ({:.2} M samples/s), total {:.2} s",
        args.output.display(),
        film.spp,
        render_time.as_secs_f64(),
        progress.samples_per_second(film.spp) / 1e6,
        started.elapsed().as_secs_f64()
    );
    Ok(())
}
