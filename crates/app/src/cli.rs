//! Command-line interface (clap derive; doc comments are the help text).

use std::path::PathBuf;

use clap::{Parser, Subcommand, ValueEnum};

/// pathlight: a physically based, progressive path tracer running in WGSL compute shaders on
/// any GPU, and on the CPU through Mesa's software adapters.
#[derive(Debug, Parser)]
#[command(version, about)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Render a scene headless to a PNG or EXR file.
    Render(RenderArgs),
}

/// Where the light transport runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Backend {
    /// WGSL compute shaders on a wgpu adapter (a GPU, or lavapipe/llvmpipe without one).
    Gpu,
    /// The same transport in native Rust on all CPU cores (rayon).
    Cpu,
}

/// Options of `pathlight render`.
#[derive(Debug, clap::Args)]
pub struct RenderArgs {
    /// Scene file (TOML, see docs/scene-format.md); the built-in default scene when absent.
    pub scene: Option<PathBuf>,
    /// Output image: `.png` (sRGB, clamped, 8-bit) or `.exr` (linear float RGB).
    #[arg(short, long, default_value = "pathlight.png")]
    pub output: PathBuf,
    /// Samples per pixel (overrides the scene's `render.spp`).
    #[arg(long)]
    pub spp: Option<u32>,
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
    /// Where the light transport runs.
    #[arg(long, value_enum, default_value_t = Backend::Gpu)]
    pub backend: Backend,
    /// Use the adapter whose name contains this text (any case), or a backend name
    /// (`vulkan`, `gl`, ...). `WGPU_BACKEND=vulkan,gl` restricts the backends searched.
    #[arg(long, value_name = "NAME")]
    pub adapter: Option<String>,
    /// List the adapters found and exit.
    #[arg(long)]
    pub list_adapters: bool,
}
