//! pathlight's native CPU backend: the WGSL integrator's twin in Rust over the same scene
//! buffers ([`pathlight_core::GpuScene`]), its rays traced in a [`WideBvh`], parallel over
//! rows with rayon, compiled per instruction-set level ([`InstructionSet`]). Every function
//! names its WGSL twin; the tests render scenes on both backends and compare.

pub mod bsdf;
pub mod integrator;
pub mod lights;
mod row;
pub mod sampler;
pub mod sampling;
pub mod scene;
pub mod surface;

use std::time::{Duration, Instant};

use pathlight_core::frame::frame_params;
use pathlight_core::gpu::GpuFrameParams;
use pathlight_core::{Film, GpuScene, Scene, Tracer, WideBvh};

use crate::scene::CpuScene;
use rayon::prelude::*;

pub use crate::row::InstructionSet;
use crate::row::{RowJob, render_row_with};

/// Aimed-for duration of one `advance` (for progress reports and interruption).
const TARGET_BATCH: Duration = Duration::from_millis(250);

/// A progressive render on the CPU.
#[derive(Debug)]
pub struct CpuRenderer {
    scene: CpuScene,
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

impl CpuRenderer {
    /// Prepares `scene`; the image starts empty.
    pub fn new(scene: &Scene, gpu_scene: GpuScene) -> Self {
        let params = frame_params(scene, &gpu_scene);
        let pixels = (params.width * params.height) as usize;
        Self {
            bvh: WideBvh::build(&gpu_scene),
            scene: CpuScene::new(gpu_scene),
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

    /// Samples per pixel accumulated so far.
    pub fn samples_done(&self) -> u32 {
        self.samples_done
    }

    /// Rays traced so far (camera, extension and shadow rays).
    pub fn rays_traced(&self) -> u64 {
        self.rays_traced
    }

    /// Adds up to `max_samples` samples per pixel (at least one when `max_samples` > 0) in
    /// about `TARGET_BATCH`; returns how many were added. Twin of the GPU renderer's
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
            .map_init(
                || Tracer::new(&scene.gpu, bvh),
                |tracer, (y, row)| {
                    let job = RowJob {
                        scene,
                        params,
                        y: y as u32,
                        samples: offset..offset + samples,
                    };
                    render_row_with(isa, tracer, &job, row)
                },
            )
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
