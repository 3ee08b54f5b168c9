//! Command-line interface (clap derive; doc comments are the help text).

use std::ops::Range;
use std::path::PathBuf;
use std::time::Duration;

use clap::{Parser, Subcommand, ValueEnum};

use crate::shard::{Shard, parse_range, parse_shard};

/// pathlight: a physically based, progressive path tracer running in WGSL compute shaders on
/// any GPU, and on the CPU through Mesa's software adapters.
#[derive(Debug, Parser)]
#[command(version, about)]
pub struct Cli {
    /// What to do; without one, `view` on a machine with a display.
    #[command(subcommand)]
    pub command: Option<Command>,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Render a scene headless to a PNG or EXR file.
    Render(RenderArgs),
    /// Open the interactive viewer (a window that refines the picture while you watch).
    View(ViewArgs),
    /// Measure frames per second, samples/s and rays/s (one sample per pixel per frame).
    Bench(BenchArgs),
    /// Sum render states (shards, checkpoints) exactly into one image or state.
    Merge(MergeArgs),
    /// Denoise an image (an EXR that `render` wrote) or a render's state with Open Image
    /// Denoise, guided by its albedo and normal images when it has them.
    Denoise(DenoiseArgs),
}

/// The auxiliary images (AOVs) a render can write beside its image.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Aov {
    /// The albedo of the first surface that is not a perfect mirror or glass (what a
    /// denoiser reads), in [0, 1].
    Albedo,
    /// That surface's shading normal in world space, in [-1, 1].
    Normal,
}

impl Aov {
    /// Its layer name in an EXR (`albedo.R`, `normal.X`) and the suffix of its PNG
    /// (`out.albedo.png`).
    pub fn name(self) -> &'static str {
        match self {
            Self::Albedo => "albedo",
            Self::Normal => "normal",
        }
    }
}

/// How hard the denoiser works.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum DenoiseMode {
    /// Final images: the albedo and normal denoised first (Open Image Denoise's
    /// prefiltering), then the image with them as clean guides, at high quality.
    Final,
    /// Previews: the image with the albedo and normal as they are, at balanced quality
    /// (about a seventh of `final`'s time; what the viewer uses).
    Fast,
}

/// Where the light transport runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Backend {
    /// A hardware GPU when there is one, else the CPU backend (Mesa's software adapters
    /// run the WGSL several times slower than the CPU backend).
    Auto,
    /// WGSL compute shaders on a wgpu adapter (a GPU, or lavapipe/llvmpipe without one).
    Gpu,
    /// The same transport in native Rust on all CPU cores (rayon).
    Cpu,
}

/// The scene and the settings every command may override.
#[derive(Debug, clap::Args)]
pub struct SceneArgs {
    /// Scene file: TOML (see docs/scene-format.md) or glTF 2.0 (`.gltf`, `.glb`); the
    /// built-in default scene when absent.
    pub scene: Option<PathBuf>,
    /// Use the glTF file's perspective camera N (counted from 0 in node order) instead of
    /// its first (or, with none, one framing the model).
    #[arg(long, value_name = "N")]
    pub camera: Option<usize>,
    /// Image width in pixels (overrides the scene's camera resolution).
    #[arg(long)]
    pub width: Option<u32>,
    /// Image height in pixels (overrides the scene's camera resolution).
    #[arg(long)]
    pub height: Option<u32>,
    /// Seed of the random sequence (overrides the scene's `render.seed`).
    #[arg(long)]
    pub seed: Option<u32>,
    /// Maximum path length in segments, as Mitsuba counts it: 1 = emitters seen directly,
    /// 2 = direct light only (overrides the scene's `render.max_depth`).
    #[arg(long)]
    pub max_depth: Option<u32>,
    /// Sample generator (overrides the scene's `render.sampler`).
    #[arg(long, value_enum)]
    pub sampler: Option<SamplerChoice>,
    /// Light the scene with this equirectangular HDR map (`.exr`, `.hdr`; replaces the
    /// scene's `[environment]`).
    #[arg(long, value_name = "FILE")]
    pub env: Option<PathBuf>,
    /// Light a glTF file opened on its own by its emitters alone, without the uniform grey
    /// sky added to it (for a closed room lit by its own panels; a file with punctual lights
    /// gets no sky anyway).
    #[arg(long)]
    pub no_default_env: bool,
    /// Factor on the environment map's texels (with `--env`, or on the scene's map).
    #[arg(long, value_name = "FACTOR", allow_hyphen_values = true)]
    pub env_strength: Option<f32>,
    /// Turn of the environment map about the up axis, degrees (with `--env`, or the scene's).
    #[arg(long, value_name = "DEGREES", allow_hyphen_values = true)]
    pub env_rotation: Option<f32>,
    /// Radius of the thin lens (overrides `camera.aperture_radius`; 0 is a pinhole).
    #[arg(long, value_name = "RADIUS", allow_hyphen_values = true)]
    pub aperture: Option<f32>,
    /// Distance of the plane in focus along the view direction (overrides
    /// `camera.focus_distance`).
    #[arg(long, value_name = "DISTANCE", allow_hyphen_values = true)]
    pub focus_distance: Option<f32>,
}

/// The sample generators `--sampler` offers.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum SamplerChoice {
    /// Padded Owen-scrambled Sobol (the default): lower noise at the same sample count.
    Sobol,
    /// Independent hashed random numbers (Mitsuba's `independent` sampler).
    Independent,
}

/// Which device renders.
#[derive(Debug, Clone, clap::Args)]
pub struct DeviceArgs {
    /// Where the light transport runs.
    #[arg(long, value_enum, default_value_t = Backend::Auto)]
    pub backend: Backend,
    /// Use the adapter whose name contains this text (any case), or a backend name
    /// (`vulkan`, `gl`, ...); with `--backend auto`, naming one asks for the GPU backend
    /// (the viewer presents on it whatever the backend). `WGPU_BACKEND=vulkan,gl` restricts
    /// the backends searched.
    #[arg(long, value_name = "NAME")]
    pub adapter: Option<String>,
}

/// Options of `pathlight render`.
#[derive(Debug, clap::Args)]
pub struct RenderArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    /// Output: an image, `.png` (sRGB, clamped, 8-bit) or `.exr` (linear float RGB), or
    /// `.state`, the exact sums for `pathlight merge` and `--resume`.
    #[arg(short, long, default_value = "pathlight.png")]
    pub output: PathBuf,
    /// Samples per pixel (overrides the scene's `render.spp`); with `--resume`, the sample
    /// count to continue to.
    #[arg(long)]
    pub spp: Option<u32>,
    #[command(flatten)]
    pub device: DeviceArgs,
    /// How the integrator is split into kernels (GPU backend); the image is the same.
    #[arg(long, value_enum, default_value_t = GpuKernelArg::Auto)]
    pub gpu_kernel: GpuKernelArg,
    /// List the adapters found and exit.
    #[arg(long)]
    pub list_adapters: bool,
    /// Stop after this long (`90s`, `10m`, `1.5h`; above zero) and write what was rendered,
    /// as an interrupted render does, but exiting with status 0.
    #[arg(long, value_name = "DURATION", value_parser = time_limit)]
    pub time_limit: Option<Duration>,
    /// Keep the render's state in this file (written every `--checkpoint-every` and when the
    /// render stops for any reason); `--resume FILE` continues it.
    #[arg(long, value_name = "FILE")]
    pub checkpoint: Option<PathBuf>,
    /// How often `--checkpoint` is written.
    #[arg(long, value_name = "DURATION", default_value = "60s", value_parser = duration)]
    pub checkpoint_every: Duration,
    /// Continue the render a state file holds (a checkpoint or a shard) to its target (or
    /// to `--spp`); the scene and settings must be those it was rendered with.
    #[arg(long, value_name = "FILE", conflicts_with_all = ["samples", "shard"])]
    pub resume: Option<PathBuf>,
    /// Render only the sample indices START..END of every pixel (a part for `pathlight
    /// merge`), within the spp.
    #[arg(long, value_name = "START..END", value_parser = parse_range, conflicts_with = "shard")]
    pub samples: Option<Range<u32>>,
    /// Render part I of N (from 0) of the spp, `I/N`; `auto` takes the part from a job
    /// array's environment: Slurm ($SLURM_ARRAY_TASK_ID), Kubernetes Indexed Jobs
    /// ($JOB_COMPLETION_INDEX), AWS Batch ($AWS_BATCH_JOB_ARRAY_INDEX).
    #[arg(long, value_name = "I/N|auto", value_parser = parse_shard)]
    pub shard: Option<Shard>,
    /// The number of parts for `--shard auto` where the environment does not give it
    /// (Kubernetes, AWS Batch).
    #[arg(long, value_name = "N", requires = "shard", value_parser = clap::value_parser!(u32).range(1..))]
    pub shard_count: Option<u32>,
    /// Also render these auxiliary images (comma-separated) from the same samples, and
    /// write them: as layers of an EXR (`albedo.R`, `normal.X`, ...), beside a PNG
    /// (`out.albedo.png`), and in a state (for `merge` and `pathlight denoise`).
    #[arg(long, value_enum, value_delimiter = ',', value_name = "albedo,normal")]
    pub aov: Vec<Aov>,
    /// Write the image denoised by Open Image Denoise, guided by the albedo and normal
    /// (rendered for it); an EXR keeps the raw image as the layer `noisy`. Needs OIDN 2
    /// (`tools/get-oidn.sh`); refused before rendering without it.
    #[arg(long, value_enum, value_name = "MODE", num_args = 0..=1, default_missing_value = "final")]
    pub denoise: Option<DenoiseMode>,
}

/// Options of `pathlight denoise`.
#[derive(Debug, clap::Args)]
pub struct DenoiseArgs {
    /// An EXR (its `R`, `G`, `B`, with `albedo.*` and `normal.*` layers when it has them,
    /// as `render --aov albedo,normal` writes) or a state file (`render -o X.state`,
    /// `merge -o X.state`).
    pub input: PathBuf,
    /// The denoised image (`.png`, `.exr`; an EXR keeps the raw image as the layer
    /// `noisy`).
    #[arg(short, long)]
    pub output: PathBuf,
    /// How hard the denoiser works.
    #[arg(long, value_enum, default_value_t = DenoiseMode::Final)]
    pub mode: DenoiseMode,
    /// Also write the input's auxiliary images (as `render --aov` does).
    #[arg(long, value_enum, value_delimiter = ',', value_name = "albedo,normal")]
    pub aov: Vec<Aov>,
}

/// Options of `pathlight merge`.
#[derive(Debug, clap::Args)]
pub struct MergeArgs {
    /// State files (`render -o X.state`, `--checkpoint`) of one render.
    #[arg(required = true, value_name = "PARTS")]
    pub parts: Vec<PathBuf>,
    /// The merged image (`.png`, `.exr`) or state (`.state`).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Write the image even when samples are missing (each pixel the mean of the samples
    /// the parts hold).
    #[arg(long)]
    pub allow_gaps: bool,
    /// Also write the parts' auxiliary images (rendered with `--aov`), as `render --aov`
    /// does.
    #[arg(long, value_enum, value_delimiter = ',', value_name = "albedo,normal")]
    pub aov: Vec<Aov>,
}

/// How the nearest hit is found (`pathlight bench --accel`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum AccelArg {
    /// The BVH over every shape and triangle (what `render` uses).
    Bvh,
    /// Every object in turn; a mesh's triangles only inside its bounding box (the seed's
    /// bounding cylinder).
    BoundingVolume,
    /// Every object and every triangle in turn.
    BruteForce,
}

impl From<AccelArg> for pathlight_gpu::Accel {
    fn from(arg: AccelArg) -> Self {
        match arg {
            AccelArg::Bvh => Self::Bvh,
            AccelArg::BoundingVolume => Self::BoundingVolume,
            AccelArg::BruteForce => Self::BruteForce,
        }
    }
}

/// How the GPU backend splits the integrator into kernels (`--gpu-kernel`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum GpuKernelArg {
    /// One kernel follows each path from the camera to its end.
    Megakernel,
    /// Kernels over queues of paths, one segment of every path at a time: faster where a
    /// segment holds many paths (large images, long paths), slower on short paths
    /// (BENCHMARKS.md, "The wavefront split").
    Wavefront,
    /// Both timed in turn on the first whole passes of the image (two each), the faster kept.
    Auto,
}

impl From<GpuKernelArg> for pathlight_gpu::Kernel {
    fn from(arg: GpuKernelArg) -> Self {
        match arg {
            GpuKernelArg::Megakernel => Self::Megakernel,
            GpuKernelArg::Wavefront => Self::Wavefront,
            GpuKernelArg::Auto => Self::Auto,
        }
    }
}

/// Options of `pathlight bench`.
#[derive(Debug, clap::Args)]
pub struct BenchArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    #[command(flatten)]
    pub device: DeviceArgs,
    /// Frames to time (one sample per pixel each), after the warm-up.
    #[arg(long, default_value_t = 1000)]
    pub frames: u32,
    /// Untimed frames first (shader compilation, caches, clocks).
    #[arg(long, default_value_t = 16)]
    pub warmup: u32,
    /// Stop the warm-up, and the timed frames, after this many seconds each (at least one
    /// frame is always timed), so slow adapters finish.
    #[arg(long, default_value = "20s", value_name = "DURATION", value_parser = duration, allow_negative_numbers = true)]
    pub time_limit: Duration,
    /// How the nearest hit is found (GPU backend).
    #[arg(long, value_enum, default_value_t = AccelArg::Bvh)]
    pub accel: AccelArg,
    /// How the integrator is split into kernels (GPU backend); the image is the same.
    #[arg(long, value_enum, default_value_t = GpuKernelArg::Auto)]
    pub gpu_kernel: GpuKernelArg,
    /// Leave out the object of this name (repeatable), e.g. `--without vase`.
    #[arg(long, value_name = "NAME")]
    pub without: Vec<String>,
    /// Reproduce the seed's frame-rate table: brute force, bounding volume, BVH, and BVH
    /// without the vase, next to the seed's figures.
    #[arg(long, conflicts_with_all = ["accel", "without"])]
    pub seed_table: bool,
    /// Print the results as JSON on standard output instead of a table.
    #[arg(long)]
    pub json: bool,
}

/// Options of `pathlight view`.
#[derive(Debug, clap::Args)]
pub struct ViewArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    /// Frames per iteration (one sample per pixel each).
    #[arg(long, default_value_t = 512, value_parser = clap::value_parser!(u32).range(1..))]
    pub frames_per_iter: u32,
    /// Number of iterations; a right click starts each after the first.
    #[arg(long, default_value_t = 8, value_parser = clap::value_parser!(u32).range(1..))]
    pub iters: u32,
    /// Emitted radiance of a clicked object per unit of its base colour (default: the
    /// brightest emission in the scene).
    #[arg(long, value_name = "STRENGTH", value_parser = positive_strength, allow_negative_numbers = true)]
    pub light_strength: Option<f32>,
    /// Where `S` saves images.
    #[arg(long, default_value = ".", value_name = "DIR")]
    pub save_dir: PathBuf,
    #[command(flatten)]
    pub device: DeviceArgs,
}

impl ViewArgs {
    /// The options of a bare `pathlight`: the default scene with default settings.
    pub fn defaults() -> Self {
        Self {
            scene: SceneArgs {
                scene: None,
                camera: None,
                width: None,
                height: None,
                seed: None,
                max_depth: None,
                sampler: None,
                env: None,
                no_default_env: false,
                env_strength: None,
                env_rotation: None,
                aperture: None,
                focus_distance: None,
            },
            frames_per_iter: 512,
            iters: 8,
            light_strength: None,
            save_dir: ".".into(),
            device: DeviceArgs {
                backend: Backend::Auto,
                adapter: None,
            },
        }
    }
}

/// A command-line value that should be a finite number above zero.
#[derive(Debug, thiserror::Error)]
#[error("{0:?} is not a positive finite number")]
pub struct NotPositive(String);

/// Parses `--light-strength`: a finite number above zero.
fn positive_strength(text: &str) -> Result<f32, NotPositive> {
    match text.parse::<f32>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        _ => Err(NotPositive(text.to_owned())),
    }
}

/// A command-line duration that is not a finite, non-negative number of seconds, minutes or
/// hours.
#[derive(Debug, thiserror::Error)]
#[error(
    "{0:?} is not a duration: a number of seconds (`90`, `90s`), minutes (`10m`) or hours \
     (`1.5h`), finite, from 0 to 10^9 seconds"
)]
pub struct BadDuration(String);

/// Parses a duration: a number with an optional unit `s` (the default), `m` or `h`.
pub fn duration(text: &str) -> Result<Duration, BadDuration> {
    let bad = || BadDuration(text.to_owned());
    let trimmed = text.trim();
    let (number, unit) = match trimmed.char_indices().last() {
        Some((i, 's')) => (&trimmed[..i], 1.0),
        Some((i, 'm')) => (&trimmed[..i], 60.0),
        Some((i, 'h')) => (&trimmed[..i], 3600.0),
        _ => (trimmed, 1.0),
    };
    let seconds = number.trim().parse::<f64>().map_err(|_| bad())? * unit;
    if !(0.0..=1e9).contains(&seconds) {
        return Err(bad());
    }
    Ok(Duration::from_secs_f64(seconds))
}

/// A time limit that is not a duration above zero (at zero a render would stop before its
/// first sample, and write nothing).
#[derive(Debug, thiserror::Error)]
pub enum BadTimeLimit {
    /// Not a duration.
    #[error(transparent)]
    Duration(#[from] BadDuration),
    /// Zero.
    #[error("{0:?}: a time limit must be above zero (a render stopped at once writes nothing)")]
    Zero(String),
}

/// Parses a time limit: a [`duration`] above zero.
pub fn time_limit(text: &str) -> Result<Duration, BadTimeLimit> {
    let limit = duration(text)?;
    if limit.is_zero() {
        return Err(BadTimeLimit::Zero(text.to_owned()));
    }
    Ok(limit)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn durations_read_units_and_refuse_nonsense() {
        assert_eq!(duration("20").unwrap(), Duration::from_secs(20));
        assert_eq!(duration("1.5h").unwrap(), Duration::from_secs(5400));
        assert_eq!(duration("10m").unwrap(), Duration::from_secs(600));
        assert_eq!(duration("0.25s").unwrap(), Duration::from_millis(250));
        for bad in ["inf", "1e300", "nan", "-1", "", "m", "10x", "1e10"] {
            assert!(duration(bad).is_err(), "{bad:?} was accepted");
            assert!(time_limit(bad).is_err(), "{bad:?} was accepted");
        }
        assert_eq!(duration("0s").unwrap(), Duration::ZERO);
        for zero in ["0", "0s", "0.0m", "0h"] {
            assert!(
                matches!(time_limit(zero), Err(BadTimeLimit::Zero(_))),
                "{zero:?}"
            );
        }
        assert_eq!(time_limit("0.5s").unwrap(), Duration::from_millis(500));
    }
}
