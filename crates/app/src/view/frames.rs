//! The viewer's renderer on either backend, behind one interface: the GPU backend renders
//! in the event loop in short submissions; the CPU backend renders on a thread of its own
//! ([`crate::view::cpu_frames`]), so the event loop never waits on it.

use std::time::{Duration, Instant};

use pathlight_core::{Accumulation, Film, Renderer, Shading, ToneMap};
use pathlight_cpu::display::ChannelOrder;
use pathlight_gpu::display::{DisplayPass, DisplaySource};
use pathlight_gpu::{GpuContext, GpuRenderer};
use pathlight_scene::Camera;

/// Frames finished by one [`Frames::render`] call.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Rendered {
    /// Whole frames (one sample per pixel each) finished.
    pub frames: u32,
    /// Rendering time they took (time spent waiting for work excluded).
    pub time: Duration,
}

/// Where an image is drawn: the window's surface texture, and the means to fill it.
pub struct Target<'a> {
    /// The device that presents.
    pub ctx: &'a GpuContext,
    /// The display pass for the surface's format.
    pub display: &'a DisplayPass,
    /// The surface texture.
    pub texture: &'a wgpu::Texture,
    /// Its size in pixels.
    pub size: (u32, u32),
    /// The byte order of its 8-bit sRGB pixels, when the CPU may copy them into it.
    pub direct: Option<ChannelOrder>,
    /// The tone mapper.
    pub tonemap: ToneMap,
}

impl Target<'_> {
    /// Draws `source` through the display pass.
    pub fn draw_sums(&self, source: DisplaySource) {
        let view = self.texture.create_view(&Default::default());
        self.display
            .draw(self.ctx, source, &view, self.size, self.tonemap);
    }

    /// Copies `bytes`, 8-bit pixels of the target's size in its byte order (`direct`), into
    /// the surface texture.
    pub fn copy_pixels(&self, bytes: &[u8]) {
        let (width, height) = self.size;
        self.ctx.queue.write_texture(
            self.texture.as_image_copy(),
            bytes,
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(4 * width),
                rows_per_image: None,
            },
            wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: 1,
            },
        );
    }
}

/// A progressive render the viewer drives and shows.
pub trait Frames {
    /// Where it renders, for the title bar.
    fn device(&self) -> String;

    /// Moves the camera (and resizes the image to the camera's) and restarts. A `preview`
    /// camera's frames are rendered whole, each before the next camera is taken, so that
    /// a stream of moves shows frames instead of restarting one.
    fn set_camera(&mut self, camera: &Camera, preview: bool) -> anyhow::Result<()>;

    /// Replaces the materials and lights and restarts.
    fn set_materials(&mut self, shading: &Shading) -> anyhow::Result<()>;

    /// Empties the image.
    fn restart(&mut self);

    /// Works towards `wanted` more whole frames for up to about `budget`, and returns the
    /// frames finished since the last call. The CPU backend never waits here: it tells its
    /// thread how many frames are wanted and collects what it finished.
    fn render(&mut self, wanted: u32, budget: Duration) -> anyhow::Result<Rendered>;

    /// Draws the newest image into `target`.
    fn draw(&mut self, target: &Target);

    /// The image as shown.
    fn film(&self) -> anyhow::Result<Film>;

    /// The sums of the image as shown, its auxiliary images' included.
    fn accumulation(&self) -> anyhow::Result<Accumulation>;

    /// Whole samples per pixel of the image as shown.
    fn samples_done(&self) -> u32;

    /// Rays traced since the last restart.
    fn rays_traced(&self) -> anyhow::Result<u64>;

    /// Whether the event loop must keep calling [`Self::render`] while frames are wanted
    /// (the GPU backend renders in it); otherwise the backend wakes the loop itself.
    fn polled(&self) -> bool {
        true
    }
}

/// Aimed-for time of a preview frame's submission or band (either backend): long enough
/// for a whole frame.
pub const WHOLE_FRAME: Duration = Duration::from_secs(10);

/// The GPU backend, on the device that presents to the window.
pub struct GpuFrames {
    renderer: GpuRenderer,
    /// Aimed-for time of one submission.
    submission_target: Duration,
    /// Whether frames are previews, submitted whole.
    preview: bool,
}

impl GpuFrames {
    /// Frames of `renderer`, submitted in pieces of about `submission_target`.
    pub fn new(renderer: GpuRenderer, submission_target: Duration) -> Self {
        Self {
            renderer,
            submission_target,
            preview: false,
        }
    }
}

impl Frames for GpuFrames {
    fn device(&self) -> String {
        self.renderer.context().adapter_info.name.clone()
    }

    fn set_camera(&mut self, camera: &Camera, preview: bool) -> anyhow::Result<()> {
        self.preview = preview;
        Ok(self.renderer.set_camera(camera)?)
    }

    fn set_materials(&mut self, shading: &Shading) -> anyhow::Result<()> {
        Ok(self.renderer.set_materials(shading)?)
    }

    fn restart(&mut self) {
        self.renderer.restart();
    }

    fn render(&mut self, wanted: u32, budget: Duration) -> anyhow::Result<Rendered> {
        let started = Instant::now();
        let mut rendered = Rendered::default();
        while rendered.frames < wanted && started.elapsed() < budget {
            let piece = Instant::now();
            let target = if self.preview {
                WHOLE_FRAME
            } else {
                self.submission_target
            };
            let frame_done = self.renderer.step_frame(target)?;
            rendered.time += piece.elapsed();
            rendered.frames += u32::from(frame_done);
        }
        Ok(rendered)
    }

    fn draw(&mut self, target: &Target) {
        target.draw_sums(DisplaySource::of(&self.renderer));
    }

    fn film(&self) -> anyhow::Result<Film> {
        Ok(self.renderer.film()?)
    }

    fn accumulation(&self) -> anyhow::Result<Accumulation> {
        Ok(self.renderer.accumulation()?)
    }

    fn samples_done(&self) -> u32 {
        self.renderer.samples_done()
    }

    fn rays_traced(&self) -> anyhow::Result<u64> {
        Ok(self.renderer.rays_traced()?)
    }
}
