//! `pathlight render`: load, render progressively, write the image.

use std::ops::Range;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use anyhow::{Context, bail};
use pathlight_core::state::{Fingerprint, RenderState};
use pathlight_core::{Accumulation, PreparedScene, Renderer};
use pathlight_denoise::{Denoiser, Mode};
use pathlight_gpu::Accel;
use pathlight_gpu::context::{available_adapters, describe};
use pathlight_scene::Scene;
use pathlight_scene::settings::check_spp;

use crate::backend::{Device, load_scene};
use crate::cli::RenderArgs;
use crate::denoise;
use crate::output;
use crate::progress::Progress;
use crate::shard::part_of;

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
    let to_state = output::format_of(&args.output)? == output::Format::State;
    if args.denoise.is_some() && to_state {
        bail!(
            "--denoise writes an image, not a state: render to {} without it and denoise \
             later with `pathlight denoise {}` (give the render --aov albedo,normal to guide it)",
            args.output.display(),
            args.output.display()
        );
    }
    scene.settings.aovs = args.denoise.is_some() || !args.aov.is_empty();
    // Without OIDN, refused before rendering.
    let denoiser = match args.denoise {
        Some(mode) => Some((denoise::load()?, denoise::mode(mode))),
        None => None,
    };
    if let Some(checkpoint) = &args.checkpoint {
        if output::format_of(checkpoint).ok() != Some(output::Format::State) {
            bail!(
                "--checkpoint {}: a checkpoint is a state file; give it the .state extension",
                checkpoint.display()
            );
        }
        output::check_writable(checkpoint)?;
    }
    render_to_file(
        &scene,
        args,
        &interrupted,
        denoiser.as_ref().map(|(d, m)| (d, *m)),
    )
}

/// What a render starts from: the samples it is asked for and the sums it already has.
struct Start {
    target: Range<u32>,
    accumulation: Accumulation,
}

/// The samples `args` ask for (all, `--samples`, `--shard`, or the rest of `--resume`'s
/// state) and the sums to start from.
fn start(scene: &Scene, args: &RenderArgs, fingerprint: &Fingerprint) -> anyhow::Result<Start> {
    let spp = scene.settings.spp;
    let (width, height) = (scene.camera.width, scene.camera.height);
    if let Some(path) = &args.resume {
        let state = output::read_state(path)?;
        let differences = state
            .fingerprint
            .differences(fingerprint, (&path.display().to_string(), "this render"));
        if !differences.is_empty() {
            bail!(
                "cannot resume {}: it is another render: {}",
                path.display(),
                differences.join("; ")
            );
        }
        let accumulation = state
            .accumulation()
            .with_context(|| format!("cannot resume {}", path.display()))?;
        let cursor = accumulation.cursor;
        let rendered = cursor.next_sample();
        let end = match args.spp {
            Some(spp) => spp,
            None => state.target.end,
        };
        if end < rendered + u32::from(cursor.in_pass()) {
            bail!(
                "cannot resume {} to {end} spp: it holds samples {}..{rendered} already",
                path.display(),
                cursor.first_sample
            );
        }
        return Ok(Start {
            target: state.target.start..end,
            accumulation,
        });
    }
    let target = match (&args.samples, args.shard) {
        (Some(samples), _) => {
            if samples.end > spp {
                bail!(
                    "--samples {}..{} reaches past the spp ({spp}): sample indices run \
                     from 0 to {}",
                    samples.start,
                    samples.end,
                    spp - 1
                );
            }
            samples.clone()
        }
        (None, Some(shard)) => {
            let (index, count) =
                shard.resolve(args.shard_count, |name| std::env::var(name).ok())?;
            let part = part_of(index, count, spp);
            note!(
                "shard {index} of {count}: samples {}..{}",
                part.start,
                part.end
            );
            part
        }
        (None, None) => 0..spp,
    };
    Ok(Start {
        accumulation: Accumulation::empty(width, height, target.start, scene.settings.aovs),
        target,
    })
}

/// Why a render stopped before its target.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Stop {
    Signal,
    TimeLimit,
}

fn render_to_file(
    scene: &Scene,
    args: &RenderArgs,
    interrupted: &AtomicBool,
    denoiser: Option<(&Denoiser, Mode)>,
) -> anyhow::Result<()> {
    let started = Instant::now();
    let prepared = PreparedScene::new(scene)?;
    // The scene's hash only where a state is read or written.
    let writes_state = output::format_of(&args.output)? == output::Format::State;
    let fingerprint = if args.resume.is_some() || args.checkpoint.is_some() || writes_state {
        Fingerprint::new(&prepared, &scene.camera, &scene.settings)
    } else {
        Fingerprint::unhashed(&scene.camera, &scene.settings)
    };
    let Start {
        target,
        accumulation,
    } = start(scene, args, &fingerprint)?;
    let device = Device::open(&args.device)?;
    let mut renderer = device.renderer(scene, &prepared, Accel::Bvh, args.gpu_kernel.into())?;
    let kind = match device {
        Device::Gpu(_) => "adapter",
        Device::Cpu => "backend",
    };
    note!("{kind}: {}", renderer.device());
    let first_sample = accumulation.cursor.first_sample;
    renderer.resume(&accumulation)?;
    let total = target.end - first_sample;
    if accumulation.cursor.samples > 0 {
        note!(
            "resuming at sample {} of {}..{}",
            accumulation.cursor.next_sample(),
            target.start,
            target.end
        );
    }
    let state_of = |renderer: &dyn Renderer| -> anyhow::Result<RenderState> {
        Ok(RenderState::new(
            fingerprint.clone(),
            target.clone(),
            renderer.device(),
            renderer.accumulation()?,
        ))
    };

    let (width, height) = (scene.camera.width, scene.camera.height);
    let mut progress = Progress::new(total, u64::from(width) * u64::from(height));
    let render_started = Instant::now();
    let mut last_checkpoint = Instant::now();
    let mut stop = None;
    while renderer.samples_done() < total {
        if interrupted.load(Ordering::SeqCst) {
            stop = Some(Stop::Signal);
            break;
        }
        if args
            .time_limit
            .is_some_and(|limit| render_started.elapsed() >= limit)
        {
            stop = Some(Stop::TimeLimit);
            break;
        }
        renderer.advance(total - renderer.samples_done())?;
        progress.update(renderer.samples_done());
        if let Some(checkpoint) = &args.checkpoint
            && last_checkpoint.elapsed() >= args.checkpoint_every
        {
            output::write_render(&state_of(renderer.as_ref())?, checkpoint)?;
            last_checkpoint = Instant::now();
        }
    }
    progress.finish();
    let render_time = render_started.elapsed();
    if let Some(kernel) = renderer.kernel() {
        note!("kernel: {kernel}");
    }
    let spp = renderer.samples_done();
    let samples_per_second = progress.samples_per_second(spp);
    let state = state_of(renderer.as_ref())?;
    let dropped = renderer.samples_dropped()?;
    if dropped > 0 {
        note!(
            "warning: {dropped} samples were not finite (NaN or infinite) and count as black; \
             this is a bug in pathlight, please report it with the scene"
        );
    }
    if let Some(checkpoint) = &args.checkpoint {
        output::write_render(&state, checkpoint)?;
        note!("checkpoint {} written", checkpoint.display());
    }
    let has_samples = spp > 0 || state.rows.iter().any(|r| !r.is_empty());
    if !has_samples && stop.is_some() {
        note!("stopped before the first sample; no image written");
        return match stop {
            Some(Stop::Signal) => Err(Interrupted.into()),
            _ => Ok(()),
        };
    }
    if output::format_of(&args.output)? == output::Format::State {
        output::write_render(&state, &args.output)?;
    } else {
        let images = denoise::images(state.film(), state.aov_films(), denoiser, &args.aov)?;
        output::write_images(&images, &args.output)?;
    }
    match stop {
        Some(Stop::Signal) => note!(
            "interrupted: kept {spp} of {total} spp (rows already sampled in the pass under way \
             hold one more)"
        ),
        Some(Stop::TimeLimit) => note!(
            "time limit reached: kept {spp} of {total} spp (rows already sampled in the pass \
             under way hold one more)"
        ),
        None => {}
    }
    note!(
        "wrote {}: {width}x{height}, {spp} spp (samples {}..{}), render {:.3} s ({:.2} M \
         samples/s), total {:.2} s",
        args.output.display(),
        first_sample,
        first_sample + spp,
        render_time.as_secs_f64(),
        samples_per_second / 1e6,
        started.elapsed().as_secs_f64()
    );
    if stop == Some(Stop::Signal) {
        return Err(Interrupted.into());
    }
    Ok(())
}
