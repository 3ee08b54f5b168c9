//! pathlight's native CPU backend: the twin of every WGSL file of the integrator, file for
//! file (`shaders/X.wgsl` is `src/X.rs`, each function naming its WGSL twin), and of the
//! viewer's display pass ([`display`]), over the same prepared scene, parallel over rows
//! with rayon and compiled per instruction-set level ([`InstructionSet`]). Its rays are
//! traced in packets ([`packet`]) through the 4-wide BVH both backends walk. The tests
//! render scenes on both backends and compare.

pub mod area_light;
pub mod bsdf_lanes;
pub mod bvh;
pub mod camera;
pub mod cpu_scene;
pub mod diffuse;
pub mod display;
pub mod environment;
pub mod glass;
pub mod glossy;
pub mod integrator;
pub mod intersect;
pub mod light_lanes;
pub mod light_sample;
pub mod lights;
pub mod lobes;
pub mod map_lanes;
pub mod material;
pub mod metal_rough;
pub mod metal_rough_lanes;
pub mod microfacet;
pub mod packet;
pub mod point_light;
mod prefetch;
mod row;
pub mod sampler;
pub mod sampling;
pub mod sheen;
pub mod slots;
mod soa;
pub mod sun_light;
pub mod surface;
pub mod table;
pub mod textures;
pub mod tracer;

use std::ops::Range;
use std::time::{Duration, Instant};

use pathlight_core::gpu_types::{GpuAccumPixel, GpuAovPixel, GpuRenderParams};
use pathlight_core::{
    Accumulation, Film, PreparedScene, RenderError, Renderer, SampleCursor, Shading,
};
use pathlight_scene::{Camera, RenderSettings};
use rayon::prelude::*;

pub use crate::cpu_scene::CpuScene;
pub use crate::row::{InstructionSet, LEVEL_VARIABLE, UnknownLevel};
use crate::row::{RowJob, RowSums, Tally, render_row_with};
pub use crate::tracer::Tracer;

/// Aimed-for duration of one `advance` (for progress reports and interruption).
const TARGET_BATCH: Duration = Duration::from_millis(250);
/// Most samples per pixel one `advance` renders.
const MAX_BATCH_SAMPLES: u32 = 1024;

/// A progressive render on the CPU.
#[derive(Debug)]
pub struct CpuRenderer {
    scene: PreparedScene,
    params: GpuRenderParams,
    /// Per pixel, the sum of accumulated samples in the GPU's fixed point (exact, and the
    /// same whatever order they were added in).
    sums: Vec<GpuAccumPixel>,
    /// Per pixel, the auxiliary images' sums (empty for a render without them).
    aovs: Vec<GpuAovPixel>,
    /// The samples the sums hold.
    cursor: SampleCursor,
    /// Seconds one sample of one pixel took in the last render (`None` before the first).
    pixel_seconds: Option<f64>,
    /// Rays traced and samples dropped as not finite, since the last restart.
    tally: Tally,
    /// The compiled form of the path tracer that runs.
    isa: InstructionSet,
}

/// The CPU backend running `isa`, as reports name it (`cpu backend, 2 threads, x86-64-v3`).
pub fn describe(isa: InstructionSet) -> String {
    format!("cpu backend, {}", threads_and_level(isa))
}

/// The threads it renders on and the compiled level it runs (`2 threads, x86-64-v3`).
pub fn threads_and_level(isa: InstructionSet) -> String {
    format!("{} threads, {}", rayon::current_num_threads(), isa.name())
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
            sums: vec![GpuAccumPixel::default(); pixels],
            aovs: vec![GpuAovPixel::default(); if settings.aovs { pixels } else { 0 }],
            cursor: SampleCursor::default(),
            pixel_seconds: None,
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

    /// Adds `samples` samples per pixel (from the cursor's next sample) to the pixels of
    /// `rows`.
    fn render(&mut self, rows: Range<u32>, samples: u32) {
        let scene = CpuScene::new(&self.scene);
        let offset = self.cursor.next_sample();
        let (params, isa) = (&self.params, self.isa);
        let width = params.width as usize;
        let pixels = rows.start as usize * width..rows.end as usize * width;
        let started = Instant::now();
        let aov_rows: Vec<&mut [GpuAovPixel]> = if self.aovs.is_empty() {
            rows.clone().map(|_| &mut [][..]).collect()
        } else {
            self.aovs[pixels.clone()].chunks_mut(width).collect()
        };
        let tally = self.sums[pixels.clone()]
            .par_chunks_mut(width)
            .zip(aov_rows)
            .enumerate()
            .map_init(
                || Tracer::new(&scene),
                |tracer, (y, (color, aovs))| {
                    let job = RowJob {
                        scene: &scene,
                        params,
                        y: rows.start + y as u32,
                        samples: offset..offset + samples,
                    };
                    render_row_with(isa, tracer, &job, &mut RowSums { color, aovs })
                },
            )
            .sum::<Tally>();
        self.tally = self.tally + tally;
        let pixel_samples = (pixels.len() as f64 * f64::from(samples)).max(1.0);
        self.pixel_seconds = Some(started.elapsed().as_secs_f64() / pixel_samples);
    }

    /// Renders the next `rows` rows (fewer at the end) of the pass in progress; returns
    /// whether they completed the pass.
    fn render_band(&mut self, rows: u32) -> bool {
        let height = self.params.height;
        let band = self.cursor.next_band(rows, height);
        let end = band.end;
        self.render(band, 1);
        self.cursor.add_band(end, height)
    }

    /// Rows of one sample that take about `target` at the last render's speed (the whole
    /// image before the first).
    fn rows_for(&self, target: Duration) -> u32 {
        let (width, height) = (self.params.width, self.params.height);
        self.pixel_seconds.map_or(height, |seconds| {
            let row_seconds = seconds * f64::from(width);
            ((target.as_secs_f64() / row_seconds.max(1e-12)) as u32).clamp(1, height)
        })
    }

    /// The running sums, one per pixel, row by row, in the GPU's fixed point
    /// (`AccumPixel`), holding the samples [`Self::cursor`] says.
    pub fn sums(&self) -> &[GpuAccumPixel] {
        &self.sums
    }

    /// The auxiliary images' sums, one per pixel, row by row (empty for a render without
    /// them), holding the samples [`Self::cursor`] says.
    pub fn aov_sums(&self) -> &[GpuAovPixel] {
        &self.aovs
    }

    /// The samples the sums hold.
    pub fn cursor(&self) -> SampleCursor {
        self.cursor
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
        let pixels = (camera.width * camera.height) as usize;
        self.sums = vec![GpuAccumPixel::default(); pixels];
        if self.params.aovs != 0 {
            self.aovs = vec![GpuAovPixel::default(); pixels];
        }
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
        self.sums.fill(GpuAccumPixel::default());
        self.aovs.fill(GpuAovPixel::default());
        self.cursor = SampleCursor::default();
        self.tally = Tally::default();
    }

    /// Twin of the GPU renderer's `advance`: the same samples of the same pixels give the
    /// same estimator. A batch is sized to take about `TARGET_BATCH`; a pass that takes
    /// longer is rendered in bands of rows, so that an interrupt waits a fraction of a second.
    fn advance(&mut self, max_samples: u32) -> Result<u32, RenderError> {
        if max_samples == 0 {
            return Ok(0);
        }
        let pixels = f64::from(self.params.width) * f64::from(self.params.height);
        let pass = self.pixel_seconds.map(|s| s * pixels);
        let target = TARGET_BATCH.as_secs_f64();
        if self.cursor.in_pass() || pass.is_some_and(|p| p > target) {
            let rows = self.rows_for(TARGET_BATCH);
            return Ok(u32::from(self.render_band(rows)));
        }
        let samples = pass
            .map_or(1, |p| {
                ((target / p.max(1e-12)) as u32).clamp(1, MAX_BATCH_SAMPLES)
            })
            .min(max_samples);
        self.render(0..self.params.height, samples);
        self.cursor.add_passes(samples);
        Ok(samples)
    }

    /// Renders bands of rows of the current pass, spread over every core, for about `target`.
    fn step_frame(&mut self, target: Duration) -> Result<bool, RenderError> {
        let rows = self.rows_for(target);
        Ok(self.render_band(rows))
    }

    /// The rest of the pass in progress, or a whole one, at once.
    fn queue_frame(&mut self) -> Result<(), RenderError> {
        self.render_band(self.params.height);
        Ok(())
    }

    fn finish(&self) -> Result<(), RenderError> {
        Ok(())
    }

    fn samples_done(&self) -> u32 {
        self.cursor.samples
    }

    fn accumulation(&self) -> Result<Accumulation, RenderError> {
        Ok(Accumulation {
            cursor: self.cursor,
            sums: self.sums.clone(),
            aovs: self.aovs.clone(),
        })
    }

    fn resume(&mut self, from: &Accumulation) -> Result<(), RenderError> {
        let (width, height) = self.size();
        from.check_fits(width, height, self.params.aovs != 0)?;
        self.sums.copy_from_slice(&from.sums);
        self.aovs.copy_from_slice(&from.aovs);
        self.cursor = from.cursor;
        self.tally = Tally::default();
        Ok(())
    }

    fn rays_traced(&self) -> Result<u64, RenderError> {
        Ok(self.tally.rays)
    }

    fn samples_dropped(&self) -> Result<u64, RenderError> {
        Ok(self.tally.dropped)
    }

    fn film(&self) -> Result<Film, RenderError> {
        let (width, height) = self.size();
        Ok(Film::from_accumulation(
            width,
            height,
            &self.accumulation()?,
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
        // Bands of 4, 4 and 2 rows complete the second pass.
        assert!(!banded.render_band(4));
        assert_eq!(banded.cursor.rows_ahead, 4);
        let mid = banded.film().unwrap();
        let split = 4 * 12;
        assert_eq!(mid.pixels[..split], two.pixels[..split], "rows ahead");
        assert_eq!(mid.pixels[split..], one.pixels[split..], "rows behind");
        assert!(!banded.render_band(4));
        assert!(banded.render_band(4));
        assert_eq!(banded.cursor.rows_ahead, 0);
        assert_eq!(banded.film().unwrap(), two);
    }
}
