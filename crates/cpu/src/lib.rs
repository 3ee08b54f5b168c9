//! pathlight's native CPU backend: the twin of every WGSL file of the integrator, file for
//! file (`shaders/X.wgsl` is `src/X.rs`, each function naming its WGSL twin), over the
//! same prepared scene, parallel over rows with rayon and compiled per instruction-set
//! level ([`InstructionSet`]). Its rays are traced in packets ([`packet`]) through the
//! 4-wide BVH both backends walk. The tests render scenes on both backends and compare.

pub mod bsdf;
pub mod bvh;
pub mod camera;
pub mod cpu_scene;
pub mod integrator;
pub mod intersect;
pub mod lights;
pub mod packet;
mod row;
pub mod sampler;
pub mod sampling;
pub mod surface;

use std::time::{Duration, Instant};

use pathlight_core::gpu_types::GpuRenderParams;
use pathlight_core::{Film, PreparedScene, RenderError, Renderer, Shading};
use pathlight_scene::{Camera, RenderSettings};
use rayon::prelude::*;

pub use crate::bvh::Tracer;
pub use crate::cpu_scene::CpuScene;
pub use crate::row::InstructionSet;
use crate::row::{RowJob, Tally, render_row_with};

/// Aimed-for duration of one `advance` (for progress reports and interruption).
const TARGET_BATCH: Duration = Duration::from_millis(250);

/// A progressive render on the CPU.
#[derive(Debug)]
pub struct CpuRenderer {
    scene: PreparedScene,
    params: GpuRenderParams,
    /// Per pixel, the sum of accumulated samples (f64: exact enough for any sample count).
    sums: Vec<[f64; 3]>,
    samples_done: u32,
    batch_samples: u32,
    /// Rays traced and samples dropped as not finite, since the last restart.
    tally: Tally,
    /// The compiled form of the path tracer that runs.
    isa: InstructionSet,
}

/// The CPU backend running `isa`, as reports name it (`cpu backend, 2 threads, x86-64-v3`).
pub fn describe(isa: InstructionSet) -> String {
    format!(
        "cpu backend, {} threads, {}",
        rayon::current_num_threads(),
        isa.name()
    )
}

/// A level of the path tracer this CPU cannot run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("this CPU cannot run the {} build", .0.name())]
pub struct UnsupportedInstructionSet(pub InstructionSet);

impl CpuRenderer {
    /// Renders `scene` as `camera` sees it with `settings`; the image starts empty.
    pub fn new(scene: &PreparedScene, camera: &Camera, settings: &RenderSettings) -> Self {
        let params = GpuRenderParams::new(camera, settings, &scene.shading);
        let pixels = (params.width * params.height) as usize;
        Self {
            scene: scene.clone(),
            params,
            sums: vec![[0.0; 3]; pixels],
            samples_done: 0,
            batch_samples: 1,
            tally: Tally::default(),
            isa: InstructionSet::best(),
        }
    }

    /// Runs the path tracer as compiled for `isa` from now on; refused (nothing changes)
    /// when this CPU lacks its features.
    pub fn set_instruction_set(
        &mut self,
        isa: InstructionSet,
    ) -> Result<(), UnsupportedInstructionSet> {
        if !InstructionSet::supported().contains(&isa) {
            return Err(UnsupportedInstructionSet(isa));
        }
        self.isa = isa;
        Ok(())
    }

    /// Adds `samples` samples per pixel (from sample `samples_done`) to every pixel.
    fn render(&mut self, samples: u32) {
        let scene = CpuScene::new(&self.scene);
        let (params, isa, offset) = (&self.params, self.isa, self.samples_done);
        let width = params.width as usize;
        let tally = self
            .sums
            .par_chunks_mut(width)
            .enumerate()
            .map_init(
                || Tracer::new(&scene),
                |tracer, (y, row)| {
                    let job = RowJob {
                        scene: &scene,
                        params,
                        y: y as u32,
                        samples: offset..offset + samples,
                    };
                    render_row_with(isa, tracer, &job, row)
                },
            )
            .sum::<Tally>();
        self.tally = self.tally + tally;
        self.samples_done += samples;
    }
}

impl Renderer for CpuRenderer {
    fn device(&self) -> String {
        describe(self.isa)
    }

    fn size(&self) -> (u32, u32) {
        (self.params.width, self.params.height)
    }

    fn set_camera(&mut self, camera: &Camera) -> Result<(), RenderError> {
        self.params.set_camera(camera);
        self.sums = vec![[0.0; 3]; (camera.width * camera.height) as usize];
        self.restart();
        Ok(())
    }

    fn set_materials(&mut self, shading: &Shading) -> Result<(), RenderError> {
        self.scene.shading = shading.clone();
        self.params.set_shading(shading);
        self.restart();
        Ok(())
    }

    fn restart(&mut self) {
        self.sums.fill([0.0; 3]);
        self.samples_done = 0;
        self.tally = Tally::default();
    }

    /// Twin of the GPU renderer's `advance`: the same samples of the same pixels give the
    /// same estimator. A batch is sized to take about `TARGET_BATCH`.
    fn advance(&mut self, max_samples: u32) -> Result<u32, RenderError> {
        let samples = self.batch_samples.min(max_samples);
        if samples == 0 {
            return Ok(0);
        }
        let started = Instant::now();
        self.render(samples);
        let per_sample = started.elapsed().as_secs_f64() / f64::from(samples);
        self.batch_samples =
            ((TARGET_BATCH.as_secs_f64() / per_sample.max(1e-9)) as u32).clamp(1, 1024);
        Ok(samples)
    }

    /// A whole frame at once: rows are spread over every core.
    fn step_frame(&mut self, _target: Duration) -> Result<bool, RenderError> {
        self.queue_frame()?;
        Ok(true)
    }

    fn queue_frame(&mut self) -> Result<(), RenderError> {
        self.render(1);
        Ok(())
    }

    fn finish(&self) -> Result<(), RenderError> {
        Ok(())
    }

    fn samples_done(&self) -> u32 {
        self.samples_done
    }

    fn rays_traced(&self) -> Result<u64, RenderError> {
        Ok(self.tally.rays)
    }

    fn samples_dropped(&self) -> Result<u64, RenderError> {
        Ok(self.tally.dropped)
    }

    fn film(&self) -> Result<Film, RenderError> {
        let (width, height) = self.size();
        Ok(Film::from_sums(
            width,
            height,
            self.samples_done,
            &self.sums,
        ))
    }
}
