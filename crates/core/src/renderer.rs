//! The one interface of both backends: a progressive render of a prepared scene that the
//! commands (`render`, `bench`, the viewer) drive the same way on either.

use std::time::Duration;

use pathlight_scene::Camera;

use crate::error::RenderError;
use crate::film::Film;
use crate::gpu_types::GpuAccumPixel;
use crate::shading::Shading;

/// A render's running sums with the samples they hold: what a checkpoint keeps, what a
/// shard hands over, and what a render resumes from.
#[derive(Debug, Clone, PartialEq)]
pub struct Accumulation {
    /// Index of every pixel's first sample.
    pub first_sample: u32,
    /// Whole passes (samples of every pixel) since the first sample.
    pub samples: u32,
    /// Rows `0 .. rows_ahead` hold one sample more (a pass in progress).
    pub rows_ahead: u32,
    /// The fixed-point sums, row by row.
    pub sums: Vec<GpuAccumPixel>,
}

impl Accumulation {
    /// No sample yet: the image empty, its first sample `first_sample`.
    pub fn empty(width: u32, height: u32, first_sample: u32) -> Self {
        Self {
            first_sample,
            samples: 0,
            rows_ahead: 0,
            sums: vec![GpuAccumPixel::default(); (width * height) as usize],
        }
    }

    /// Refuses sums that do not fit a `width` x `height` image.
    pub fn check_fits(&self, width: u32, height: u32) -> Result<(), RenderError> {
        let pixels = width as usize * height as usize;
        if self.sums.len() != pixels || (self.rows_ahead > 0 && self.rows_ahead >= height) {
            return Err(RenderError::Resume(format!(
                "{} sums with {} rows ahead do not fit a {width}x{height} image",
                self.sums.len(),
                self.rows_ahead
            )));
        }
        if u64::from(self.first_sample) + u64::from(self.samples) + 1 > u64::from(u32::MAX) {
            return Err(RenderError::Resume(format!(
                "samples {}..{} run past the last sample index",
                self.first_sample,
                u64::from(self.first_sample) + u64::from(self.samples)
            )));
        }
        Ok(())
    }
}

/// A progressive render: samples are added to every pixel in turn, and the image at any
/// moment is the mean of the samples so far. Sample `i` of a pixel is the same whatever
/// batches the work was split into, so the image depends only on the sample count.
pub trait Renderer {
    /// Where it renders, for messages and reports (the adapter, or the CPU and its threads).
    fn device(&self) -> String;

    /// Image width and height in pixels.
    fn size(&self) -> (u32, u32);

    /// Moves the camera (and resizes the image to the camera's) and restarts. Only the
    /// per-render constants change: the scene stays where it is.
    fn set_camera(&mut self, camera: &Camera) -> Result<(), RenderError>;

    /// Replaces the materials, lights and environment (a light toggle) and restarts. The
    /// geometry and the BVH stay.
    fn set_materials(&mut self, shading: &Shading) -> Result<(), RenderError>;

    /// Empties the image and the ray count: the next sample is sample 0 again.
    fn restart(&mut self);

    /// Works for a fraction of a second towards up to `max_samples` more samples per pixel;
    /// returns how many samples every pixel gained. Where one sample of the image takes
    /// longer, it renders the next band of rows of a pass (see [`Self::step_frame`]) and
    /// returns 1 when the band completes the pass, else 0.
    fn advance(&mut self, max_samples: u32) -> Result<u32, RenderError>;

    /// Renders the next part of the current frame (one sample per pixel), taking about
    /// `target`; returns whether the frame is complete. A frame in progress shows in
    /// [`Self::film`] exactly (its finished pixels hold one sample more).
    fn step_frame(&mut self, target: Duration) -> Result<bool, RenderError>;

    /// Queues one frame (one sample per pixel) as one unit of work, without waiting for it
    /// where the device works asynchronously; [`Self::finish`] waits.
    fn queue_frame(&mut self) -> Result<(), RenderError>;

    /// Waits until every queued frame has finished.
    fn finish(&self) -> Result<(), RenderError>;

    /// Whole samples per pixel accumulated so far.
    fn samples_done(&self) -> u32;

    /// Rays traced (camera, extension and shadow rays) since the start or the last restart.
    fn rays_traced(&self) -> Result<u64, RenderError>;

    /// Samples since the start or the last restart whose radiance was not finite (NaN or
    /// infinite): they count as black, so that no NaN reaches the image, and a correct render
    /// has none. Tests require zero; `pathlight render` warns otherwise.
    fn samples_dropped(&self) -> Result<u64, RenderError>;

    /// The mean of the samples so far.
    fn film(&self) -> Result<Film, RenderError>;

    /// The running sums and the samples they hold (on the GPU, read back).
    fn accumulation(&self) -> Result<Accumulation, RenderError>;

    /// Replaces the image with `from`: the next pass renders sample
    /// `from.first_sample + from.samples` of every pixel (rows `0 .. from.rows_ahead`
    /// already hold it), so that a render resumed from its own accumulation goes on exactly
    /// as if it had never stopped. The ray and dropped-sample counts start over.
    fn resume(&mut self, from: &Accumulation) -> Result<(), RenderError>;

    /// Entries of the traversal stack the GPU integrator is compiled with; `None` where the
    /// stack grows as needed (the CPU backend).
    fn traversal_stack(&self) -> Option<u32> {
        None
    }
}
