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

/// The error of a render stopped by SIGINT or SIGTERM: the image with the samples rendered
/// so far has been written (or nothing, before the first sample). The process exits with
/// [`Interrupted::EXIT_CODE`], so that scripts can tell it from a finished render.
#[derive(Debug, thiserror::Error)]
#[error("interrupted")]
pub struct Interrupted;

impl Interrupted {
    /// The exit status of an interrupted render (as a shell reports a command stopped by
    /// SIGINT).
    pub const EXIT_CODE: u8 = 130;
}

/// Runs the command.
pub fn run(args: &RenderArgs) -> anyhow::Result<()> {
    if args.list_adapters {
        for adapter in available_adapters() {
            println!("{}", describe(&adapter.get_info()));
        }
        return Ok(());
    }
    // Ctrl-C (SIGINT) and SIGTERM (kill, timeout, systemd, job schedulers) stop the render
    // between batches, from the start: a signal during set-up must not kill the process.
    let interrupted = Arc::new(AtomicBool::new(false));
    let flag = interrupted.clone();
    // A second handler cannot be installed (e.g. in tests); rendering works without one.
    let _ = ctrlc::set_handler(move || flag.store(true, Ordering::SeqCst));
    let mut scene = load_scene(&args.scene)?;
    if let Some(spp) = args.spp {
        scene.settings.spp = spp;
    }
    check_spp(scene.settings.spp)?;
    output::check_writable(&args.output)?;
    render_to_file(&scene, args, &interrupted)
}

fn render_to_file(
    scene: &Scene,
    args: &RenderArgs,
    interrupted: &AtomicBool,
) -> anyhow::Result<()> {
    let started = Instant::now();
    let prepared = PreparedScene::new(scene)?;
    let device = Device::open(&args.device)?;
    let mut renderer = device.renderer(scene, &prepared, Accel::Bvh)?;
    let kind = match device {
        Device::Gpu(_) => "adapter",
        Device::Cpu => "backend",
    };
    note!("{kind}: {}", renderer.device());

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
        note!("interrupted before the first sample; nothing written");
        return Err(Interrupted.into());
    }
    output::write(&film, &args.output)?;
    let stopped = film.spp < total;
    if stopped {
        note!(
            "interrupted: kept {} of {total} spp (rows already sampled in the pass under way \
             hold one more)",
            film.spp
        );
    }
    note!(
        "wrote {}: {width}x{height}, {} spp, render {:.2} s ({:.2} M samples/s), total {:.2} s",
        args.output.display(),
        film.spp,
        render_time.as_secs_f64(),
        progress.samples_per_second(film.spp) / 1e6,
        started.elapsed().as_secs_f64()
    );
    if stopped {
        return Err(Interrupted.into());
    }
    Ok(())
}
