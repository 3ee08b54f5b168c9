//! The viewer on the CPU backend: a [`CpuRenderer`] on a thread of its own, told by the
//! event loop what to render (camera, materials, frames wanted). After every band of rows
//! it copies those rows into the image the two sides share; the event loop maps the rows
//! whose sample count changed to the window's pixels. Neither side holds the lock longer
//! than a copy of a band or a mapping of the changed rows.

use std::ops::Range;
use std::sync::{Arc, Condvar, Mutex, MutexGuard};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use anyhow::anyhow;
use pathlight_core::Accumulation;
use pathlight_core::gpu_types::{GpuAccumPixel, GpuAovPixel};
use pathlight_core::{Film, RenderError, Renderer, SampleCursor, Shading};
use pathlight_cpu::CpuRenderer;
use pathlight_cpu::display::{CpuDisplay, DisplayImage};
use pathlight_gpu::display::DisplaySource;
use pathlight_scene::Camera;

use crate::view::frames::{Frames, Rendered, Target, WHOLE_FRAME};

/// Aimed-for time of one band of rows: how long a camera move may wait for the thread.
const BAND: Duration = Duration::from_millis(40);

/// The image as the thread last left it.
#[derive(Debug, Default)]
struct Image {
    /// The orders it belongs to.
    generation: u64,
    /// Which restart of the renderer it holds (previews restart within a generation).
    epoch: u64,
    width: u32,
    height: u32,
    /// The samples the pixels hold.
    cursor: SampleCursor,
    rays: u64,
    /// Fixed-point sums, row by row.
    pixels: Vec<GpuAccumPixel>,
    /// The auxiliary images' sums, row by row (empty without them).
    aovs: Vec<GpuAovPixel>,
}

impl Image {
    fn display(&self) -> DisplayImage<'_> {
        DisplayImage {
            pixels: &self.pixels,
            width: self.width,
            height: self.height,
            samples: self.cursor.samples,
            rows_ahead: self.cursor.rows_ahead,
        }
    }
}

/// What the two sides share.
#[derive(Default)]
struct State {
    /// Bumped by every restart but a preview's after a preview: frames are counted per
    /// generation. The thread applies the camera and materials given with it.
    generation: u64,
    /// A camera to apply: with a new generation, or between two preview frames.
    camera: Option<Camera>,
    shading: Option<Shading>,
    /// Whether frames are previews, rendered whole.
    preview: bool,
    /// Frames of this generation the thread should finish, then wait.
    frames_wanted: u32,
    quit: bool,
    /// Frames finished in `image.generation` and their rendering time.
    frames_done: u32,
    time: Duration,
    image: Image,
    /// Whether `image` changed since the event loop last uploaded it.
    changed: bool,
    error: Option<RenderError>,
}

/// The state and the signal that it changed for the thread.
#[derive(Default)]
struct Shared {
    state: Mutex<State>,
    orders: Condvar,
}

impl Shared {
    fn lock(&self) -> MutexGuard<'_, State> {
        // A panic on the other side has already been reported; the state stays usable.
        self.state
            .lock()
            .unwrap_or_else(|poisoned| poisoned.into_inner())
    }
}

/// The CPU backend rendering for the viewer.
pub struct CpuFrames {
    shared: Arc<Shared>,
    thread: Option<JoinHandle<()>>,
    device: String,
    generation: u64,
    /// Frames of this generation already returned by `render`, and their time.
    collected: u32,
    collected_time: Duration,
    /// The shown image's 8-bit pixels at the window's size, when copied into the surface,
    /// and what makes them.
    bytes: Vec<u8>,
    display: CpuDisplay,
    /// Its sums on the presenting device, when drawn by the display pass.
    buffer: Option<wgpu::Buffer>,
}

impl CpuFrames {
    /// Starts `renderer` on a thread of its own; `notify` is called (on that thread) after
    /// every band it renders, to wake the event loop.
    pub fn start(
        renderer: CpuRenderer,
        notify: impl Fn() + Send + 'static,
    ) -> anyhow::Result<Self> {
        let shared = Arc::new(Shared::default());
        let device = renderer.device();
        let thread = std::thread::Builder::new()
            .name("cpu renderer".into())
            .spawn({
                let shared = shared.clone();
                move || render_loop(renderer, &shared, notify)
            })
            .map_err(|err| anyhow!("cannot start the CPU renderer's thread: {err}"))?;
        Ok(Self {
            shared,
            thread: Some(thread),
            device,
            generation: 0,
            collected: 0,
            collected_time: Duration::ZERO,
            bytes: Vec::new(),
            display: CpuDisplay::new(),
            buffer: None,
        })
    }

    /// Starts a new generation with `change` applied to the orders.
    fn restart_with(&mut self, change: impl FnOnce(&mut State)) {
        let mut state = self.shared.lock();
        state.generation += 1;
        state.frames_wanted = 0;
        change(&mut state);
        self.generation = state.generation;
        self.collected = 0;
        self.collected_time = Duration::ZERO;
        drop(state);
        self.shared.orders.notify_one();
    }

    /// The image's sums on the presenting device, uploaded when they changed.
    fn upload(&mut self, target: &Target, state: &mut State) -> DisplaySource<'_> {
        let ctx = target.ctx;
        let image = &state.image;
        let bytes: &[u8] = bytemuck::cast_slice(&image.pixels);
        let size = (bytes.len() as u64).max(size_of::<GpuAccumPixel>() as u64);
        if self.buffer.as_ref().is_none_or(|b| b.size() != size) {
            self.buffer = Some(ctx.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("cpu image"),
                size,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }));
            state.changed = true;
        }
        let buffer = self.buffer.as_ref().expect("created above");
        if state.changed {
            ctx.queue.write_buffer(buffer, 0, bytes);
            state.changed = false;
        }
        DisplaySource {
            pixels: buffer,
            width: image.width.max(1),
            height: image.height.max(1),
            samples: image.cursor.samples,
            rows_ahead: image.cursor.rows_ahead,
        }
    }
}

impl Frames for CpuFrames {
    fn device(&self) -> String {
        self.device.clone()
    }

    fn set_camera(&mut self, camera: &Camera, preview: bool) -> anyhow::Result<()> {
        let mut state = self.shared.lock();
        if preview && state.preview {
            // The next preview frame shows it; the frames of the run count on.
            state.camera = Some(camera.clone());
            drop(state);
            self.shared.orders.notify_one();
            return Ok(());
        }
        drop(state);
        self.restart_with(|state| {
            state.camera = Some(camera.clone());
            state.preview = preview;
        });
        Ok(())
    }

    fn set_materials(&mut self, shading: &Shading) -> anyhow::Result<()> {
        self.restart_with(|state| state.shading = Some(shading.clone()));
        Ok(())
    }

    fn restart(&mut self) {
        self.restart_with(|_| {});
    }

    fn render(&mut self, wanted: u32, _budget: Duration) -> anyhow::Result<Rendered> {
        let mut state = self.shared.lock();
        if let Some(err) = state.error.take() {
            return Err(err.into());
        }
        let target = self.collected.saturating_add(wanted);
        if state.frames_wanted != target {
            state.frames_wanted = target;
            self.shared.orders.notify_one();
        }
        let mut rendered = Rendered::default();
        if state.image.generation == self.generation && state.frames_done > self.collected {
            rendered.frames = state.frames_done - self.collected;
            rendered.time = state.time.saturating_sub(self.collected_time);
            self.collected = state.frames_done;
            self.collected_time = state.time;
        }
        Ok(rendered)
    }

    /// Tone maps on the CPU and copies the pixels into the surface where it allows;
    /// elsewhere uploads the sums for the display pass.
    fn draw(&mut self, target: &Target) {
        let shared = self.shared.clone();
        let mut state = shared.lock();
        let Some(order) = target.direct else {
            target.draw_sums(self.upload(target, &mut state));
            return;
        };
        let image = &state.image;
        self.display.pixels(
            &image.display(),
            image.epoch,
            target.tonemap,
            target.size,
            order,
            &mut self.bytes,
        );
        drop(state);
        target.copy_pixels(&self.bytes);
    }

    fn film(&self) -> anyhow::Result<Film> {
        let state = self.shared.lock();
        let image = &state.image;
        Ok(Film::from_fixed_point(
            image.width,
            image.height,
            &image.cursor,
            &image.pixels,
        ))
    }

    fn accumulation(&self) -> anyhow::Result<Accumulation> {
        let state = self.shared.lock();
        let image = &state.image;
        Ok(Accumulation {
            cursor: image.cursor,
            sums: image.pixels.clone(),
            aovs: image.aovs.clone(),
        })
    }

    fn samples_done(&self) -> u32 {
        self.shared.lock().image.cursor.samples
    }

    fn rays_traced(&self) -> anyhow::Result<u64> {
        Ok(self.shared.lock().image.rays)
    }

    fn polled(&self) -> bool {
        false
    }
}

impl Drop for CpuFrames {
    fn drop(&mut self) {
        self.shared.lock().quit = true;
        self.shared.orders.notify_one();
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }
}

/// The thread: waits for orders, renders bands of rows while frames are wanted, and
/// copies each band into the shared image.
fn render_loop(mut renderer: CpuRenderer, shared: &Shared, notify: impl Fn()) {
    let (mut generation, mut frames, mut time) = (0, 0, Duration::ZERO);
    let mut epoch = 0;
    loop {
        let (change, band) = {
            let mut state = shared.lock();
            while !state.quit
                && state.generation == generation
                && state.camera.is_none()
                && frames >= state.frames_wanted
            {
                state = shared
                    .orders
                    .wait(state)
                    .unwrap_or_else(|poisoned| poisoned.into_inner());
            }
            if state.quit {
                return;
            }
            let band = if state.preview { WHOLE_FRAME } else { BAND };
            let restart = state.generation != generation || state.camera.is_some();
            if state.generation != generation {
                generation = state.generation;
                (frames, time) = (0, Duration::ZERO);
            }
            let change = restart.then(|| {
                epoch += 1;
                (state.camera.take(), state.shading.take())
            });
            (change, band)
        };
        let started = Instant::now();
        let first_row = renderer.cursor().rows_ahead;
        let result = match change {
            // Back to the orders: frames are rendered once wanted.
            Some((camera, shading)) => apply(&mut renderer, camera, shading).map(|()| None),
            None => renderer.step_frame(band).map(Some),
        };
        let frame_done = match result {
            Ok(Some(done)) => done,
            Ok(None) => continue,
            Err(err) => {
                shared.lock().error = Some(err);
                notify();
                return;
            }
        };
        time += started.elapsed();
        frames += u32::from(frame_done);
        let (_, height) = renderer.size();
        let end_row = if frame_done {
            height
        } else {
            renderer.cursor().rows_ahead
        };
        let mut state = shared.lock();
        if state.generation == generation {
            state.frames_done = frames;
            state.time = time;
            state.image.generation = generation;
            publish(&renderer, epoch, first_row..end_row, &mut state.image);
            state.changed = true;
        }
        drop(state);
        notify();
    }
}

/// Copies the rows `rows` that `renderer` just rendered into `image`, and its counts; all
/// of it when `image` held another restart than `epoch`.
fn publish(renderer: &CpuRenderer, epoch: u64, rows: Range<u32>, image: &mut Image) {
    let (width, height) = renderer.size();
    let (sums, aovs) = (renderer.sums(), renderer.aov_sums());
    if image.epoch != epoch || (image.width, image.height) != (width, height) {
        image.pixels.clear();
        image.pixels.extend_from_slice(sums);
        image.aovs.clear();
        image.aovs.extend_from_slice(aovs);
    } else {
        let pixels = (rows.start * width) as usize..(rows.end * width) as usize;
        image.pixels[pixels.clone()].copy_from_slice(&sums[pixels.clone()]);
        if !aovs.is_empty() {
            image.aovs[pixels.clone()].copy_from_slice(&aovs[pixels]);
        }
    }
    image.epoch = epoch;
    (image.width, image.height) = (width, height);
    image.cursor = renderer.cursor();
    image.rays = renderer.rays_traced().unwrap_or(0);
}

/// Gives `renderer` the new camera and materials, if any, and empties the image.
fn apply(
    renderer: &mut CpuRenderer,
    camera: Option<Camera>,
    shading: Option<Shading>,
) -> Result<(), RenderError> {
    if let Some(camera) = camera {
        renderer.set_camera(&camera)?;
    }
    if let Some(shading) = shading {
        renderer.set_materials(&shading)?;
    }
    renderer.restart();
    Ok(())
}
