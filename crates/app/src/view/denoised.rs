//! The viewer's denoised display (`D`): the image denoised by Open Image Denoise (its fast
//! mode, guided by the albedo and normal images the viewer renders when OIDN is there) on a
//! thread of its own, shown in place of the raw image through the same tone mapping. A
//! denoising starts when the view is turned on, when the samples have doubled since the last
//! one, at each iteration's end and whenever the accumulation stops (paused, waiting for a
//! right click, finished) with samples the last one lacked; never while the camera moves.

use std::sync::mpsc::{Receiver, TryRecvError, channel};
use std::time::{Duration, Instant};

use pathlight_core::gpu_types::GpuAccumPixel;
use pathlight_core::{Accumulation, Film};
use pathlight_cpu::display::{CpuDisplay, DisplayImage};
use pathlight_denoise::{Aux, DenoiseError, Denoiser, Mode};
use pathlight_gpu::display::DisplaySource;

use super::frames::Target;

/// What a finished denoising hands back.
struct Done {
    denoiser: Denoiser,
    result: Result<Film, DenoiseError>,
    epoch: u64,
    samples: u32,
    took: Duration,
}

/// A denoised image, and as the display reads it.
struct Shown {
    /// The image.
    film: Film,
    /// The image as fixed-point sums of one sample.
    sums: Vec<GpuAccumPixel>,
    width: u32,
    height: u32,
    /// The restart of the image it was made from, and its samples per pixel.
    epoch: u64,
    samples: u32,
    /// Tells the CPU display that the pixels changed.
    id: u64,
}

/// Why a denoising starts now (besides the first of an image).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Moment {
    /// Frames are being rendered.
    Rendering,
    /// An iteration has just ended.
    IterationEnded,
    /// No frame is being rendered (paused, waiting, finished).
    Idle,
}

/// The denoised view and its work.
pub struct Denoised {
    /// OIDN, while no denoising holds it.
    denoiser: Option<Denoiser>,
    /// Why there is no denoiser, when there is none.
    unavailable: Option<String>,
    /// Whether the denoised image is shown.
    on: bool,
    /// The denoising under way.
    job: Option<Receiver<Done>>,
    shown: Option<Shown>,
    next_id: u64,
    display: CpuDisplay,
    bytes: Vec<u8>,
    /// The shown image on the presenting device (for the display pass), and its id.
    buffer: Option<(u64, wgpu::Buffer)>,
}

impl Denoised {
    /// The view, off, with `denoiser` or the reason there is none.
    pub fn new(denoiser: Result<Denoiser, DenoiseError>) -> Self {
        let (denoiser, unavailable) = match denoiser {
            Ok(d) => (Some(d), None),
            Err(err) => (None, Some(err.to_string())),
        };
        Self {
            denoiser,
            unavailable,
            on: false,
            job: None,
            shown: None,
            next_id: 1 << 62,
            display: CpuDisplay::new(),
            bytes: Vec::new(),
            buffer: None,
        }
    }

    /// Whether denoising can be done (the viewer then renders the auxiliary images).
    pub fn available(&self) -> bool {
        self.unavailable.is_none()
    }

    /// Turns the view on or off; returns whether it is on, or why it cannot be.
    pub fn toggle(&mut self) -> Result<bool, String> {
        if let Some(why) = &self.unavailable {
            return Err(why.clone());
        }
        self.on = !self.on;
        Ok(self.on)
    }

    /// Whether the view is on.
    pub fn is_on(&self) -> bool {
        self.on
    }

    /// Collects a finished denoising; returns a line to print about it.
    pub fn collect(&mut self) -> Option<String> {
        let job = self.job.as_ref()?;
        let done = match job.try_recv() {
            Ok(done) => done,
            Err(TryRecvError::Empty) => return None,
            Err(TryRecvError::Disconnected) => {
                self.job = None;
                self.unavailable = Some("the denoising thread stopped".into());
                self.on = false;
                return Some("denoising failed: its thread stopped".into());
            }
        };
        self.job = None;
        self.denoiser = Some(done.denoiser);
        match done.result {
            Ok(film) => {
                self.next_id += 1;
                self.shown = Some(Shown {
                    sums: one_sample_sums(&film),
                    width: film.width,
                    height: film.height,
                    film,
                    epoch: done.epoch,
                    samples: done.samples,
                    id: self.next_id,
                });
                Some(format!(
                    "denoising done: {} spp in {:.2} s",
                    done.samples,
                    done.took.as_secs_f64()
                ))
            }
            Err(err) => {
                self.on = false;
                Some(format!("denoising failed: {err}"))
            }
        }
    }

    /// Whether a denoising of the image (restart `epoch`, `samples` per pixel) should start
    /// at `moment`.
    pub fn due(&self, epoch: u64, samples: u32, moment: Moment) -> bool {
        if !self.on || self.job.is_some() || self.denoiser.is_none() || samples == 0 {
            return false;
        }
        match self.shown.as_ref().filter(|s| s.epoch == epoch) {
            None => true,
            Some(shown) => {
                samples >= 2 * shown.samples
                    || (moment != Moment::Rendering && samples > shown.samples)
            }
        }
    }

    /// Denoises `accumulation` (of a `width` x `height` image, restart `epoch`) on a thread
    /// of its own, calling `wake` when it is done.
    pub fn start(
        &mut self,
        accumulation: Accumulation,
        (width, height): (u32, u32),
        epoch: u64,
        wake: impl Fn() + Send + 'static,
    ) {
        let Some(denoiser) = self.denoiser.take() else {
            return;
        };
        let (sender, receiver) = channel();
        self.job = Some(receiver);
        let samples = accumulation.cursor.samples;
        let spawned = std::thread::Builder::new()
            .name("denoiser".into())
            .spawn(move || {
                let started = Instant::now();
                let film = Film::from_accumulation(width, height, &accumulation);
                let aovs = Film::aovs_from_accumulation(width, height, &accumulation);
                let aux = aovs.as_ref().map(|(albedo, normal)| Aux { albedo, normal });
                let result = denoiser.denoise(&film, aux, Mode::Fast);
                let _ = sender.send(Done {
                    denoiser,
                    result,
                    epoch,
                    samples,
                    took: started.elapsed(),
                });
                wake();
            });
        if spawned.is_err() {
            self.job = None;
            self.unavailable = Some("cannot start a thread for the denoiser".into());
            self.on = false;
        }
    }

    /// Whether the view shows a denoised image of restart `epoch`.
    pub fn showing(&self, epoch: u64) -> bool {
        self.shown_film(epoch).is_some()
    }

    /// The denoised image the view shows of restart `epoch`, if it shows one.
    pub fn shown_film(&self, epoch: u64) -> Option<&Film> {
        let shown = self
            .shown
            .as_ref()
            .filter(|s| self.on && s.epoch == epoch)?;
        Some(&shown.film)
    }

    /// Draws the denoised image into `target` (as the raw image is drawn: copied by the
    /// CPU where the surface takes copies, else through the display pass).
    pub fn draw(&mut self, target: &Target) {
        let Some(shown) = &self.shown else {
            return;
        };
        let image = DisplayImage {
            pixels: &shown.sums,
            width: shown.width,
            height: shown.height,
            samples: 1,
            rows_ahead: 0,
        };
        let Some(order) = target.direct else {
            if self.buffer.as_ref().is_none_or(|(id, _)| *id != shown.id) {
                let ctx = target.ctx;
                let bytes: &[u8] = bytemuck::cast_slice(&shown.sums);
                let buffer = ctx.device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("denoised image"),
                    size: bytes.len() as u64,
                    usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                });
                ctx.queue.write_buffer(&buffer, 0, bytes);
                self.buffer = Some((shown.id, buffer));
            }
            let (_, buffer) = self.buffer.as_ref().expect("uploaded above");
            target.draw_sums(DisplaySource {
                pixels: buffer,
                width: shown.width,
                height: shown.height,
                samples: 1,
                rows_ahead: 0,
            });
            return;
        };
        self.display.pixels(
            &image,
            shown.id,
            target.tonemap,
            target.size,
            order,
            &mut self.bytes,
        );
        target.copy_pixels(&self.bytes);
    }
}

/// `film` as the fixed-point sums of one sample per pixel (what the display divides by 1).
fn one_sample_sums(film: &Film) -> Vec<GpuAccumPixel> {
    film.pixels
        .iter()
        .map(|p| {
            let v = p.map(|c| {
                if c.is_finite() {
                    c.clamp(0.0, 16_777_215.0)
                } else {
                    0.0
                }
            });
            let whole = v.map(f32::floor);
            GpuAccumPixel {
                hi: [whole[0] as u32, whole[1] as u32, whole[2] as u32, 0],
                lo: [0, 1, 2, 3].map(|c| {
                    if c < 3 {
                        ((v[c] - whole[c]) * 4_294_967_296.0) as u32
                    } else {
                        0
                    }
                }),
            }
        })
        .collect()
}
