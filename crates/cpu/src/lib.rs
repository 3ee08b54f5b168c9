//! pathlight's native CPU backend: the WGSL integrator's twin in Rust over the same scene
//! buffers ([`pathlight_core::GpuScene`]), parallel over rows with rayon. Every function
//! names its WGSL twin; the tests render scenes on both backends and compare.

pub mod bsdf;
pub mod integrator;
pub mod lights;
pub mod sampler;
pub mod sampling;
pub mod surface;

use std::time::{Duration, Instant};

use pathlight_core::frame::frame_params;
use pathlight_core::gpu::GpuFrameParams;
use pathlight_core::{Film, GpuScene, Scene, WideBvh};
use rayon::prelude::*;

use crate::integrator::{accumulated_value, camera_ray, trace_path};
use crate::sampler::Sampler;

/// Aimed-for duration of one `advance` (for progress reports and interruption).
const TARGET_BATCH: Duration = Duration::from_millis(250);

/// A progressive render on the CPU.
#[derive(Debug)]
pub struct CpuRenderer {
    scene: GpuScene,
    /// The scene's 4-wide BVH, which the CPU traces rays in.
    bvh: WideBvh,
    params: GpuFrameParams,
    /// Per pixel, the sum of accumulated samples (f64: exact enough for any sample count).
    sums: Vec<[f64; 3]>,
    samples_done: u32,
    batch_samples: u32,
    /// Rays traced so far.
    rays_traced: u64,
    /// The compiled form of the path tracer that runs.
    isa: InstructionSet,
}

/// One row's share of an `advance`.
struct RowJob<'a> {
    scene: &'a GpuScene,
    bvh: &'a WideBvh,
    params: &'a GpuFrameParams,
    y: u32,
    /// Sample indices to add to every pixel.
    samples: std::ops::Range<u32>,
}

/// Adds the samples of `job` to its row's sums; returns the rays traced. The whole path
/// tracer is inlined here, so that [`render_row_avx2`] compiles all of it for AVX2.
#[inline(always)]
fn render_row(job: &RowJob, row: &mut [[f64; 3]]) -> u64 {
    let params = job.params;
    let mut rays = 0;
    for (x, sum) in row.iter_mut().enumerate() {
        let pixel = job.y * params.width + x as u32;
        for i in job.samples.clone() {
            let mut sampler = Sampler::new(params.sampler, pixel, i, params.seed);
            let ray = camera_ray(params, x as u32, job.y, &mut sampler);
            let path = trace_path(job.scene, job.bvh, params, ray, &mut sampler);
            rays += u64::from(path.rays);
            let value = accumulated_value(path.radiance);
            for c in 0..3 {
                sum[c] += f64::from(value[c]);
            }
        }
    }
    rays
}

/// The instruction set a row renderer is compiled for: [`render_row`] is compiled once per
/// level and the best one the CPU has is chosen at run time (AVX2 and FMA give the scalar
/// code three-operand SSE/AVX encodings, BMI2 shifts, GFNI one-instruction bit reversal;
/// +27% on cornell-spheres on an AMD EPYC with AVX-512). Rust never fuses a multiply and an
/// add on its own, so every level computes the same image bit for bit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InstructionSet {
    /// The target's baseline (SSE2 on x86-64).
    Baseline,
    /// x86-64-v3: AVX2, FMA, BMI1/2, LZCNT, MOVBE, F16C.
    #[cfg(target_arch = "x86_64")]
    X86_64V3,
    /// x86-64-v4 (AVX-512 F/VL/BW/DQ/CD) and GFNI.
    #[cfg(target_arch = "x86_64")]
    X86_64V4Gfni,
}

impl InstructionSet {
    /// Every level this CPU can run, baseline first.
    pub fn supported() -> Vec<Self> {
        #[allow(unused_mut)]
        let mut levels = vec![Self::Baseline];
        #[cfg(target_arch = "x86_64")]
        {
            use std::arch::is_x86_feature_detected as has;
            let v3 = has!("avx2") && has!("fma") && has!("bmi1") && has!("bmi2");
            let v3 = v3 && has!("lzcnt") && has!("movbe") && has!("f16c");
            if v3 {
                levels.push(Self::X86_64V3);
                let v4 = has!("avx512f") && has!("avx512vl") && has!("avx512bw");
                if v4 && has!("avx512dq") && has!("avx512cd") && has!("gfni") {
                    levels.push(Self::X86_64V4Gfni);
                }
            }
        }
        levels
    }

    /// The best level this CPU can run.
    pub fn best() -> Self {
        Self::supported().pop().unwrap_or(Self::Baseline)
    }

    /// Its name, as reports show it.
    pub fn name(self) -> &'static str {
        match self {
            Self::Baseline => "baseline",
            #[cfg(target_arch = "x86_64")]
            Self::X86_64V3 => "x86-64-v3",
            #[cfg(target_arch = "x86_64")]
            Self::X86_64V4Gfni => "x86-64-v4+gfni",
        }
    }
}

/// [`render_row`] compiled for `isa`, which the CPU must support.
fn render_row_with(isa: InstructionSet, job: &RowJob, row: &mut [[f64; 3]]) -> u64 {
    match isa {
        InstructionSet::Baseline => render_row(job, row),
        // SAFETY: `InstructionSet::supported` found the features on this CPU.
        #[cfg(target_arch = "x86_64")]
        InstructionSet::X86_64V3 => unsafe { render_row_x86_64_v3(job, row) },
        // SAFETY: as above.
        #[cfg(target_arch = "x86_64")]
        InstructionSet::X86_64V4Gfni => unsafe { render_row_x86_64_v4_gfni(job, row) },
    }
}

/// [`render_row`] for x86-64-v3.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx,avx2,fma,bmi1,bmi2,lzcnt,popcnt,f16c,movbe")]
fn render_row_x86_64_v3(job: &RowJob, row: &mut [[f64; 3]]) -> u64 {
    render_row(job, row)
}

/// [`render_row`] for x86-64-v4 with GFNI.
#[cfg(target_arch = "x86_64")]
#[target_feature(
    enable = "avx,avx2,fma,bmi1,bmi2,lzcnt,popcnt,f16c,movbe,avx512f,avx512vl,avx512bw,avx512dq,avx512cd,gfni"
)]
fn render_row_x86_64_v4_gfni(job: &RowJob, row: &mut [[f64; 3]]) -> u64 {
    render_row(job, row)
}

impl CpuRenderer {
    /// Prepares `scene`; the image starts empty.
    pub fn new(scene: &Scene, gpu_scene: GpuScene) -> Self {
        let params = frame_params(scene, &gpu_scene);
        let pixels = (params.width * params.height) as usize;
        Self {
            bvh: WideBvh::build(&gpu_scene),
            scene: gpu_scene,
            params,
            sums: vec![[0.0; 3]; pixels],
            samples_done: 0,
            batch_samples: 1,
            rays_traced: 0,
            isa: InstructionSet::best(),
        }
    }

    /// Runs the path tracer as compiled for `isa` from now on; refused (nothing changes)
    /// when this CPU lacks its features.
    pub fn set_instruction_set(&mut self, isa: InstructionSet) -> Result<(), String> {
        if !InstructionSet::supported().contains(&isa) {
            return Err(format!("this CPU cannot run the {} build", isa.name()));
        }
        self.isa = isa;
        Ok(())
    }

    /// The compiled form of the path tracer that runs.
    pub fn instruction_set(&self) -> InstructionSet {
        self.isa
    }

    /// Samples per pixel accumulated so far.
    pub fn samples_done(&self) -> u32 {
        self.samples_done
    }

    /// Rays traced so far (camera, extension and shadow rays).
    pub fn rays_traced(&self) -> u64 {
        self.rays_traced
    }

    /// Adds up to `max_samples` samples per pixel (at least one when `max_samples` > 0) in
    /// about [`TARGET_BATCH`]; returns how many were added. Twin of the GPU renderer's
    /// `advance`: the same samples of the same pixels give the same estimator.
    pub fn advance(&mut self, max_samples: u32) -> u32 {
        let samples = self.batch_samples.min(max_samples);
        if samples == 0 {
            return 0;
        }
        let started = Instant::now();
        let (scene, bvh, params, isa) = (&self.scene, &self.bvh, &self.params, self.isa);
        let offset = self.samples_done;
        let width = params.width as usize;
        let rays: u64 = self
            .sums
            .par_chunks_mut(width)
            .enumerate()
            .map(|(y, row)| {
                let job = RowJob {
                    scene,
                    bvh,
                    params,
                    y: y as u32,
                    samples: offset..offset + samples,
                };
                render_row_with(isa, &job, row)
            })
            .sum();
        self.rays_traced += rays;
        self.samples_done += samples;
        let per_sample = started.elapsed().as_secs_f64() / f64::from(samples);
        self.batch_samples =
            ((TARGET_BATCH.as_secs_f64() / per_sample.max(1e-9)) as u32).clamp(1, 1024);
        samples
    }

    /// The mean of the samples so far.
    pub fn film(&self) -> Film {
        let scale = 1.0 / f64::from(self.samples_done.max(1));
        Film {
            width: self.params.width,
            height: self.params.height,
            spp: self.samples_done,
            pixels: self
                .sums
                .iter()
                .map(|s| s.map(|c| (c * scale) as f32))
                .collect(),
        }
    }
}
