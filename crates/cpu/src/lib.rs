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

use std::ops::Range;
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
    /// Rows per `advance` while one pass takes longer than [`TARGET_BATCH`] (else the height).
    band_rows: u32,
    /// Rows of the pass in progress that already hold its sample.
    rows_ahead: u32,
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
            band_rows: params.height,
            rows_ahead: 0,
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

    /// Adds `samples` samples per pixel (from sample `samples_done`) to the pixels of `rows`.
    fn render(&mut self, rows: Range<u32>, samples: u32) {
        let scene = CpuScene::new(&self.scene);
        let (params, isa, offset) = (&self.params, self.isa, self.samples_done);
        let width = params.width as usize;
        let pixels = rows.start as usize * width..rows.end as usize * width;
        let tally = self.sums[pixels]
            .par_chunks_mut(width)
            .enumerate()
            .map_init(
                || Tracer::new(&scene),
                |tracer, (y, row)| {
                    let job = RowJob {
                        scene: &scene,
                        params,
                        y: rows.start + y as u32,
                        samples: offset..offset + samples,
                    };
                    render_row_with(isa, tracer, &job, row)
                },
            )
            .sum::<Tally>();
        self.tally = self.tally + tally;
    }

    /// Renders the next band of rows of the pass in progress; returns whether it completed
    /// the pass. Bands are sized to take about [`TARGET_BATCH`].
    fn render_band(&mut self) -> bool {
        let height = self.params.height;
        let rows = self.band_rows.min(height - self.rows_ahead);
        let started = Instant::now();
        self.render(self.rows_ahead..self.rows_ahead + rows, 1);
        let per_row = started.elapsed().as_secs_f64() / f64::from(rows);
        self.band_rows = ((TARGET_BATCH.as_secs_f64() / per_row.max(1e-9)) as u32).clamp(1, height);
        self.rows_ahead += rows;
        if self.rows_ahead < height {
            return false;
        }
        self.rows_ahead = 0;
        self.samples_done += 1;
        true
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
        self.rows_ahead = 0;
        self.tally = Tally::default();
    }

    /// Twin of the GPU renderer's `advance`: the same samples of the same pixels give the
    /// same estimator. A batch is sized to take about `TARGET_BATCH`.
    fn advance(&mut self, max_samples: u32) -> Result<u32, RenderError> {
        let samples = self.batch_samples.min(max_samples);
        if samples == 0 {
            return Ok(0);
        }
        if self.rows_ahead > 0 || self.band_rows < self.params.height {
            return Ok(u32::from(self.render_band()));
        }
        let started = Instant::now();
        self.render(0..self.params.height, samples);
        self.samples_done += samples;
        let per_sample = started.elapsed().as_secs_f64() / f64::from(samples);
        let per_target = TARGET_BATCH.as_secs_f64() / per_sample.max(1e-9);
        self.batch_samples = (per_target as u32).clamp(1, 1024);
        // A pass longer than the target: bands of rows from now on, so that an interrupt
        // waits for a fraction of a second.
        self.band_rows =
            ((f64::from(self.params.height) * per_target) as u32).clamp(1, self.params.height);
        Ok(samples)
    }

    /// A whole frame at once: rows are spread over every core.
    fn step_frame(&mut self, _target: Duration) -> Result<bool, RenderError> {
        self.queue_frame()?;
        Ok(true)
    }

    fn queue_frame(&mut self) -> Result<(), RenderError> {
        self.render(0..self.params.height, 1);
        self.samples_done += 1;
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
            self.rows_ahead,
            &self.sums,
        ))
    }
}

#[cfg(test)]
mod tests {
    use pathlight_core::{PreparedScene, Renderer};
    use pathlight_scene::default_scene;

    use super::CpuRenderer;

    /// A pass cut in bands of rows (as when one pass takes longer than a batch) gives the
    /// pixels of whole passes, and mid-pass the rows already sampled hold their own mean.
    #[test]
    fn passes_in_bands_keep_the_image_exact() {
        let mut scene = default_scene::load().unwrap();
        scene.camera.width = 12;
        scene.camera.height = 10;
        let prepared = PreparedScene::new(&scene).unwrap();
        let whole = |spp: u32| {
            let mut r = CpuRenderer::new(&prepared, &scene.camera, &scene.settings);
            while r.samples_done() < spp {
                r.advance(spp - r.samples_done()).unwrap();
            }
            r.film().unwrap()
        };
        let (one, two) = (whole(1), whole(2));
        let mut banded = CpuRenderer::new(&prepared, &scene.camera, &scene.settings);
        banded.advance(1).unwrap();
        banded.band_rows = 4;
        // Bands of 4, 4 and 2 rows complete the second pass.
        assert_eq!(banded.advance(1).unwrap(), 0);
        assert_eq!(banded.rows_ahead, 4);
        let mid = banded.film().unwrap();
        let split = 4 * 12;
        assert_eq!(mid.pixels[..split], two.pixels[..split], "rows ahead");
        assert_eq!(mid.pixels[split..], one.pixels[split..], "rows behind");
        banded.band_rows = 4;
        assert_eq!(banded.advance(1).unwrap(), 0);
        banded.band_rows = 4;
        assert_eq!(banded.advance(1).unwrap(), 1);
        assert_eq!(banded.film().unwrap(), two);
    }
}
