//! Times each of the integrator's dispatches on the GPU, with timestamp queries between them
//! ([`GpuRenderer::profile_pass`]): where a frame's time goes, kernel by kernel and, for the
//! wavefront, segment by segment.
//!
//!   cargo run --release -p pathlight-gpu --example kernel_times -- [--wavefront] [--frames N]
//!       [--size WxH] [SCENE]
//!
//! SCENE: a scene file (TOML or glTF); the built-in default scene when absent, each at its own
//! size unless `--size` gives one. Renders 16 untimed frames (one sample per pixel each, as `pathlight bench` does), then
//! N profiled ones (20), and prints each dispatch's median time over them (summed over a
//! frame's waves of rows), its share of the frame and the frame's total. Check the total
//! against `pathlight bench`'s frame time first: on an H200 the wavefront's 500x500 frames of
//! the default scene took 4x longer profiled (BENCHMARKS.md, "The frame kernel by kernel").

use std::path::Path;
use std::time::Duration;

use anyhow::{Context, Result, bail};
use pathlight_core::{PreparedScene, Renderer};
use pathlight_gpu::{Accel, GpuContext, GpuRenderer, Kernel};
use pathlight_scene::settings::check_resolution;
use pathlight_scene::{default_scene, load_scene_file};

fn main() -> Result<()> {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let kernel = if args.iter().any(|a| a == "--wavefront") {
        Kernel::Wavefront
    } else {
        Kernel::Megakernel
    };
    let frames: usize = match option(&mut args, "--frames")? {
        Some(value) => value.parse().with_context(|| format!("--frames {value}"))?,
        None => 20,
    };
    if frames == 0 {
        bail!("--frames 0: at least one frame is profiled");
    }
    let size = option(&mut args, "--size")?;
    args.retain(|a| !a.starts_with("--"));
    let mut scene = match args.first() {
        Some(path) => load_scene_file(Path::new(path))?,
        None => default_scene::load()?,
    };
    if let Some(size) = size {
        let parsed = size
            .split_once('x')
            .and_then(|(w, h)| Some((w.parse().ok()?, h.parse().ok()?)));
        (scene.camera.width, scene.camera.height) =
            parsed.with_context(|| format!("--size {size}: not WxH"))?;
        check_resolution(scene.camera.width, scene.camera.height)
            .with_context(|| format!("--size {size}"))?;
    }
    let ctx = GpuContext::new(None)?;
    let prepared = PreparedScene::new(&scene)?;
    let mut renderer =
        GpuRenderer::new(&ctx, &prepared, &scene.camera, &scene.settings, Accel::Bvh)?;
    renderer.set_kernel(kernel)?;
    for _ in 0..16 {
        renderer.queue_frame()?;
    }
    renderer.finish()?;

    // Per dispatch name, in the order of a frame: its time in each profiled frame.
    let mut times: Vec<(String, Vec<Duration>)> = Vec::new();
    for frame in 0..frames {
        for (name, time) in renderer.profile_pass()? {
            match times.iter_mut().find(|(n, _)| *n == name) {
                Some((_, per_frame)) if per_frame.len() > frame => per_frame[frame] += time,
                Some((_, per_frame)) => per_frame.push(time),
                None => times.push((name, vec![time])),
            }
        }
    }
    let medians: Vec<(String, f64)> = times
        .into_iter()
        .map(|(name, mut per_frame)| {
            per_frame.sort();
            (name, per_frame[per_frame.len() / 2].as_secs_f64() * 1e3)
        })
        .collect();
    let total: f64 = medians.iter().map(|(_, ms)| ms).sum();
    println!("device   {}", renderer.device());
    println!(
        "scene    {}x{}, max_depth {}, {}, median of {frames} frames",
        scene.camera.width,
        scene.camera.height,
        scene.settings.max_depth,
        kernel.name()
    );
    println!("{:<12} {:>9} {:>6}", "dispatch", "ms", "share");
    for (name, ms) in &medians {
        println!(
            "{name:<12} {ms:>9.4} {:>5.1}%",
            100.0 * ms / total.max(1e-12)
        );
    }
    println!("{:<12} {total:>9.4}", "sum");
    Ok(())
}

/// Removes option `name` and its value from `args`; the value, if the option is there.
fn option(args: &mut Vec<String>, name: &str) -> Result<Option<String>> {
    let Some(i) = args.iter().position(|a| a == name) else {
        return Ok(None);
    };
    let value = args
        .get(i + 1)
        .with_context(|| format!("{name} needs a value"))?
        .clone();
    args.drain(i..i + 2);
    Ok(Some(value))
}
