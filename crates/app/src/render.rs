//! `pathlight render`: load, render progressively, write the image.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use pathlight_core::PreparedScene;
use pathlight_render::Accel;
use pathlight_render::context::{available_adapters, describe};
use pathlight_scene::Scene;
use pathlight_scene::settings::check_spp;

use crate::backend::{Device, load_scene};
use crate::cli::RenderArgs;
use crate::output;
use crate::progress::Progress;

/// Runs the command.
pub fn run(args: &RenderArgs) -> anyhow::Result<()> {
    if args.list_adapters {
        for adapter in available_adapters() {
            println!("{}", describe(&adapter.get_info()));
        }
        return Ok(());
    }
    let mut scene = load_scene(&args.scene)?;
    if let Some(spp) = args.spp {
        scene.settings.spp = spp;
    }
    check_spp(scene.settings.spp)?;
    let created = output::check_writable(&args.output)?;
    let result = render_to_file(&scene, args);
    if result.is_err() && created {
        let _ = std::fs::remove_file(&args.output);
    }
    result
}

fn render_to_file(scene: &Scene, args: &RenderArgs) -> anyhow::Result<()> {
    let started = Instant::now();
    let prepared = PreparedScene::new(scene)?;
    let device = Device::open(&args.device)?;
    let mut renderer = device.renderer(scene, &prepared, Accel::Bvh)?;
    let kind = match device {
        Device::Gpu(_) => "adapter",
        Device::Cpu => "backend",
    };
    note!("{kind}: {}", renderer.device());

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
    let dropped = renderer.samples_dropped()?;
    if dropped > 0 {
        note!(
            "warning: {dropped} samples were not finite (NaN or infinite) and count as black; \
             this is a bug in pathlight, please report it with the scene"
        );
    }
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
