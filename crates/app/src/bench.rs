//! `pathlight bench`: frames per second, samples/s and rays/s at one sample per pixel per
//! frame, as the seed's viewer rendered, and the seed's frame-rate table.

use std::time::{Duration, Instant};

use anyhow::bail;
use pathlight_core::PreparedScene;
use pathlight_gpu::Accel;
use pathlight_scene::Scene;
use serde::Serialize;

use crate::backend::{Device, load_scene};
use crate::cli::BenchArgs;

/// A timed chunk of GPU frames grows until it takes about this long, so a fast GPU is not
/// timed one synchronisation at a time and a slow one still stops near the time limit.
const CHUNK_TARGET: Duration = Duration::from_millis(50);

/// The seed's table: column label, scheme, objects left out, the seed's fps.
const SEED_TABLE: [(&str, Accel, &[&str], f64); 4] = [
    ("brute force", Accel::BruteForce, &[], 4.8),
    ("bounding volume", Accel::BoundingVolume, &[], 8.3),
    ("BVH", Accel::Bvh, &[], 92.0),
    ("BVH, no vase", Accel::Bvh, &["vase"], 146.0),
];

/// One configuration's figures.
#[derive(Debug, Serialize)]
struct Measurement {
    /// Column label in the seed table, or the scheme's name.
    label: String,
    accel: String,
    /// How the GPU integrator is split into kernels, and how that was chosen (`-` on the CPU
    /// backend).
    gpu_kernel: String,
    without: Vec<String>,
    width: u32,
    height: u32,
    max_depth: u32,
    triangles: usize,
    /// Entries of the GPU's traversal stack (the integrator is compiled with it: the scene's
    /// bound rounded up to 8); none on the CPU backend.
    traversal_stack: Option<u32>,
    /// Seconds to prepare the scene (the BVH build and the buffers).
    bvh_build_s: f64,
    /// Seconds from the start of this configuration (the command's start for the first:
    /// scene loading, BVH build, adapter, pipeline compilation) to the end of the first frame.
    first_frame_s: f64,
    warmup_frames: u32,
    frames: u32,
    seconds: f64,
    fps: f64,
    samples_per_s: f64,
    rays_per_s: f64,
    rays_per_sample: f64,
    /// The seed's figure for this column (seed table only).
    #[serde(skip_serializing_if = "Option::is_none")]
    seed_fps: Option<f64>,
}

/// The whole report.
#[derive(Debug, Serialize)]
struct Report {
    pathlight: &'static str,
    scene: String,
    device: String,
    /// The backend that ran (`gpu` or `cpu`).
    backend: String,
    /// The backend asked for (`auto`, `gpu` or `cpu`).
    backend_asked: String,
    runs: Vec<Measurement>,
}

/// Runs the command.
pub fn run(args: &BenchArgs) -> anyhow::Result<()> {
    let started = Instant::now();
    let scene = load_scene(&args.scene)?;
    let device = Device::open(&args.device)?;
    let configs: Vec<(String, Accel, Vec<String>, Option<f64>)> = if args.seed_table {
        SEED_TABLE
            .iter()
            .map(|&(label, accel, without, seed)| {
                let without = without.iter().map(|s| s.to_string()).collect();
                (label.to_string(), accel, without, Some(seed))
            })
            .collect()
    } else {
        let accel = Accel::from(args.accel);
        vec![(accel.name().into(), accel, args.without.clone(), None)]
    };
    let mut report = Report {
        pathlight: env!("CARGO_PKG_VERSION"),
        scene: match &args.scene.scene {
            Some(path) => path.display().to_string(),
            None => "default".into(),
        },
        device: device.describe(),
        backend: device.backend_name().to_string(),
        backend_asked: format!("{:?}", args.device.backend).to_lowercase(),
        runs: Vec::new(),
    };
    for (i, (label, accel, without, seed_fps)) in configs.into_iter().enumerate() {
        let config_start = if i == 0 { started } else { Instant::now() };
        let scene = without_objects(&scene, &without)?;
        if args.seed_table && !args.json {
            note!("measuring {label} ...");
        }
        let mut m = measure(&scene, &device, accel, args, config_start)?;
        m.label = label;
        m.without = without;
        m.seed_fps = seed_fps;
        report.runs.push(m);
    }
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else if args.seed_table {
        print_seed_table(&report);
    } else {
        print_single(&report);
    }
    Ok(())
}

/// The scene without the objects named in `names`; every name must exist.
fn without_objects(scene: &Scene, names: &[String]) -> anyhow::Result<Scene> {
    let mut out = scene.clone();
    for name in names {
        let before = out.objects.len();
        out.objects.retain(|o| &o.name != name);
        if out.objects.len() == before {
            let known: Vec<&str> = scene.objects.iter().map(|o| o.name.as_str()).collect();
            bail!(
                "--without {name:?}: the scene has no object of that name (it has: {})",
                known.join(", ")
            );
        }
    }
    Ok(out)
}

/// Renders warm-up frames, then times frames.
fn measure(
    scene: &Scene,
    device: &Device,
    accel: Accel,
    args: &BenchArgs,
    started: Instant,
) -> anyhow::Result<Measurement> {
    let build_start = Instant::now();
    let prepared = PreparedScene::new(scene)?;
    let bvh_build_s = build_start.elapsed().as_secs_f64();
    let triangles = prepared.geometry.triangle_count();
    let mut renderer = device.renderer(scene, &prepared, accel, args.gpu_kernel.into())?;
    let traversal_stack = renderer.traversal_stack();
    let time_limit = args.time_limit;

    // The first frame is never timed: it includes the pipeline's first use.
    renderer.queue_frame()?;
    renderer.finish()?;
    let first_frame_s = started.elapsed().as_secs_f64();
    let warmup_start = Instant::now();
    let mut warmup_frames = 1;
    while warmup_frames < args.warmup.max(1) && warmup_start.elapsed() < time_limit {
        renderer.queue_frame()?;
        renderer.finish()?;
        warmup_frames += 1;
    }

    let rays_before = renderer.rays_traced()?;
    let timed_start = Instant::now();
    let (mut frames, mut chunk) = (0, 1);
    while frames < args.frames.max(1) {
        let chunk_start = Instant::now();
        let n = chunk.min(args.frames.max(1) - frames);
        renderer.queue_frames(n)?;
        renderer.finish()?;
        frames += n;
        if timed_start.elapsed() >= time_limit {
            break;
        }
        if chunk_start.elapsed() < CHUNK_TARGET {
            chunk *= 2;
        }
    }
    let seconds = timed_start.elapsed().as_secs_f64();
    let rays = renderer.rays_traced()? - rays_before;
    let (width, height) = (scene.camera.width, scene.camera.height);
    let samples = f64::from(frames) * f64::from(width) * f64::from(height);
    Ok(Measurement {
        label: String::new(),
        accel: accel.name().into(),
        gpu_kernel: renderer.kernel().unwrap_or_else(|| "-".into()),
        without: Vec::new(),
        width,
        height,
        max_depth: scene.settings.max_depth,
        triangles,
        traversal_stack,
        bvh_build_s,
        first_frame_s,
        warmup_frames,
        frames,
        seconds,
        fps: f64::from(frames) / seconds,
        samples_per_s: samples / seconds,
        rays_per_s: rays as f64 / seconds,
        rays_per_sample: rays as f64 / samples,
        seed_fps: None,
    })
}

fn print_single(report: &Report) {
    let m = &report.runs[0];
    let without = if m.without.is_empty() {
        String::new()
    } else {
        format!(", without {}", m.without.join(", "))
    };
    println!("scene        {}{without}", report.scene);
    println!("device       {}", report.device_line());
    println!(
        "settings     {}x{}, max_depth {}, 1 spp per frame, accel {}, kernel {}",
        m.width, m.height, m.max_depth, m.accel, m.gpu_kernel
    );
    println!(
        "frames       {} timed in {:.3} s after {} warm-up",
        m.frames, m.seconds, m.warmup_frames
    );
    println!("fps          {:.2}", m.fps);
    println!("samples/s    {:.3} M", m.samples_per_s / 1e6);
    println!(
        "rays/s       {:.3} M ({:.2} rays per sample)",
        m.rays_per_s / 1e6,
        m.rays_per_sample
    );
    let stack = m
        .traversal_stack
        .map_or(String::new(), |entries| format!(", stack {entries}"));
    println!(
        "first frame  {:.3} s after start (BVH build {:.3} s, {} triangles{stack})",
        m.first_frame_s, m.bvh_build_s, m.triangles
    );
}

impl Report {
    /// Where it ran and which backend, noting an automatic choice.
    fn device_line(&self) -> String {
        let chosen = if self.backend_asked == "auto" {
            ", chosen by --backend auto"
        } else {
            ""
        };
        format!("{} ({} backend{chosen})", self.device, self.backend)
    }
}

/// One cell of the seed table from a measurement.
type Cell = fn(&Measurement) -> String;

fn print_seed_table(report: &Report) {
    let first = &report.runs[0];
    println!(
        "{} scene, {}x{}, max_depth {}, 1 spp per frame",
        report.scene, first.width, first.height, first.max_depth
    );
    println!("device: {}", report.device_line());
    print!("{:<18}", "");
    for m in &report.runs {
        print!("{:>17}", m.label);
    }
    println!();
    let rows: [(&str, Cell); 4] = [
        ("seed (fps)", |m| {
            format!("{:.1}", m.seed_fps.unwrap_or(f64::NAN))
        }),
        ("here (fps)", |m| format!("{:.2}", m.fps)),
        ("here (M rays/s)", |m| format!("{:.2}", m.rays_per_s / 1e6)),
        ("frames timed", |m| m.frames.to_string()),
    ];
    for (name, value) in rows {
        print!("{name:<18}");
        for m in &report.runs {
            print!("{:>17}", value(m));
        }
        println!();
    }
    let bvh = report.runs.iter().find(|m| m.label == "BVH");
    let brute = report.runs.iter().find(|m| m.label == "brute force");
    if let (Some(bvh), Some(brute)) = (bvh, brute) {
        println!(
            "BVH over brute force: {:.1}x here, {:.1}x in the seed",
            bvh.fps / brute.fps,
            92.0 / 4.8
        );
    }
}
