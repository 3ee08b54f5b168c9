//! The one interface of both backends: a progressive render of a prepared scene that the
//! commands (`render`, `bench`, the viewer) drive the same way on either.

use std::time::Duration;

use pathlight_scene::Camera;

use crate::accumulation::Accumulation;
use crate::error::RenderError;
use crate::film::Film;
use crate::shading::Shading;

/// A progressive render: samples are added to every pixel in turn, and the image at any
/// moment is the mean of the samples so far. Sample `i` of a pixel is the same whatever
/// batches the work was split into, so the image depends only on the sample count.
/// A GPU renderer that chooses its kernel by timing (`auto`) renders its first whole passes
/// a few at a time, waiting for each step, in whichever of [`Self::advance`],
/// [`Self::step_frame`] or [`Self::queue_frame`] comes first.
pub trait Renderer {
    /// Where it renders, for messages and reports (the adapter, or the CPU and its threads).
    fn device(&self) -> String;

    /// How the integrator is split into kernels, and how that was chosen, for messages and
    /// reports; `None` where there is one way (the CPU backend).
    fn kernel(&self) -> Option<String> {
        None
    }

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

    /// Queues `frames` frames as [`Self::queue_frame`] does, one after another; a GPU may
    /// overlap them (a frame's last segments traced beside the next frame's first), which
    /// leaves the same image.
    fn queue_frames(&mut self, frames: u32) -> Result<(), RenderError> {
        for _ in 0..frames {
            self.queue_frame()?;
        }
        Ok(())
    }

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
    /// `from.cursor.next_sample()` of every pixel (rows `0 .. from.cursor.rows_ahead`
    /// already hold it), so that a render resumed from its own accumulation goes on exactly
    /// as if it had never stopped. The ray and dropped-sample counts start over.
    fn resume(&mut self, from: &Accumulation) -> Result<(), RenderError>;

    /// Entries of the traversal stack the GPU integrator is compiled with; `None` where the
    /// stack grows as needed (the CPU backend).
    fn traversal_stack(&self) -> Option<u32> {
        None
    }
}
