//! The progressive renderer: owns the accumulation buffer and schedules the integrator.
//!
//! Work is submitted in pieces of about [`TARGET_SUBMISSION`] (a band of rows times some
//! samples per pixel), sized from the measured speed, so no single submission trips a
//! desktop GPU's watchdog and progress can be reported between them.

use std::time::{Duration, Instant};

use pathlight_core::gpu_types::{
    FLAG_ALPHA, GpuAccumPixel, GpuAovPixel, GpuRenderParams, TEXTURE_COAT_NORMAL, TEXTURE_NORMAL,
};
use pathlight_core::materials::MODEL_METAL_ROUGH;
use pathlight_core::{
    Accumulation, Film, PreparedScene, RenderError, Renderer, SampleCursor, Shading,
};
use pathlight_scene::{Camera, RenderSettings};

use crate::context::{GpuContext, describe};
use crate::dispatch_times::{self, DispatchTimes};
use crate::kernel_trial::{KernelChoice, KernelTrial};
use crate::pipeline::{bind_buffers, create_compute_pipeline, storage_entry};
use crate::scene_buffers::SceneBuffers;
use crate::wavefront::{WAVEFRONT_ENTRY_POINTS, Wavefront};
use crate::wgsl;

/// Aimed-for GPU time of one submission.
pub const TARGET_SUBMISSION: Duration = Duration::from_millis(100);
/// Most samples per pixel one dispatch adds.
const MAX_BATCH_SAMPLES: u32 = 256;
/// Most entries of the compiled traversal stack. Deeper trees' walks that would overflow it
/// start again without a stack (`trace_stackless` in `bvh.wgsl`): a stack of hundreds of
/// entries made lavapipe's first batch take minutes.
pub const MAX_STACK: u32 = 64;
/// Workgroup edge of the integrator (`@workgroup_size(8, 8)`).
const WORKGROUP: u32 = 8;
/// The `auto` kernel's trial renders whole passes once a pass takes at most about this many
/// submissions' time ([`TARGET_SUBMISSION`]); until then the megakernel renders bands of rows.
const TRIAL_PASS_SUBMISSIONS: u32 = 4;

/// How the integrator finds the nearest hit. Every scheme finds the same hit (a test checks
/// it); the slower two reproduce the seed's frame-rate table (`pathlight bench --accel`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Accel {
    /// The BVH over every shape and triangle.
    #[default]
    Bvh,
    /// Every object in turn; a mesh's triangles only when the ray hits its bounding box.
    BoundingVolume,
    /// Every object and every triangle in turn.
    BruteForce,
}

impl Accel {
    /// All schemes, fastest first.
    pub const ALL: [Accel; 3] = [Accel::Bvh, Accel::BoundingVolume, Accel::BruteForce];

    /// Its name on the command line and in reports.
    pub fn name(self) -> &'static str {
        match self {
            Accel::Bvh => "bvh",
            Accel::BoundingVolume => "bounding-volume",
            Accel::BruteForce => "brute-force",
        }
    }

    /// The shader's `ACCEL` pipeline constant selecting this scheme (`bvh.wgsl`).
    pub fn pipeline_constants(self) -> [(&'static str, f64); 1] {
        let value = match self {
            Accel::Bvh => 0.0,
            Accel::BoundingVolume => 1.0,
            Accel::BruteForce => 2.0,
        };
        [("ACCEL", value)]
    }
}

/// How the integrator is split into kernels. Both give the same image bit for bit (a test
/// checks it); which is faster depends on the device and the image (BENCHMARKS.md, "The
/// wavefront split").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Kernel {
    /// One kernel follows each path from the camera to its end (`integrator.wgsl`).
    #[default]
    Megakernel,
    /// Kernels over queues of paths, one segment of every path at a time (`wavefront.wgsl`).
    Wavefront,
    /// Both, timed in turn on the first whole passes of the image, the faster kept
    /// ([`crate::kernel_trial`]).
    Auto,
}

impl Kernel {
    /// Its name on the command line and in reports.
    pub fn name(self) -> &'static str {
        match self {
            Kernel::Megakernel => "megakernel",
            Kernel::Wavefront => "wavefront",
            Kernel::Auto => "auto",
        }
    }
}

/// What a scene's integrator kernel compiles in: the pipeline constants of `scene.wgsl` that
/// compile unused features out, so that a scene pays in registers only for what it uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct KernelFeatures {
    /// Instances (`INSTANCES`).
    instances: bool,
    /// Metal-rough (glTF) materials (`METAL_ROUGH`).
    metal_rough: bool,
    /// Texture slots (`TEXTURES`).
    textures: bool,
    /// Normal maps (`NORMAL_MAPS`).
    normal_maps: bool,
    /// Objects with alpha cut-outs (`ALPHA`).
    alpha: bool,
    /// Auxiliary images (`AOVS` of `integrator.wgsl`).
    aovs: bool,
}

impl KernelFeatures {
    /// The features `scene` uses, rendered with auxiliary images or not (`aovs`).
    fn of(scene: &PreparedScene, aovs: bool) -> Self {
        Self {
            instances: scene.geometry.has_instances(),
            aovs,
            ..Self::of_shading(&scene.shading)
        }
    }

    /// The features materials and objects `shading` use (no instances, no auxiliary images).
    fn of_shading(shading: &Shading) -> Self {
        let objects = &shading.objects[..shading.object_count as usize];
        Self {
            instances: false,
            metal_rough: shading
                .materials
                .iter()
                .any(|m| m.model == MODEL_METAL_ROUGH),
            textures: shading.materials.iter().any(|m| m.texture_mask != 0),
            normal_maps: shading
                .materials
                .iter()
                .any(|m| m.texture_mask & (1 << TEXTURE_NORMAL | 1 << TEXTURE_COAT_NORMAL) != 0),
            alpha: objects.iter().any(|o| o.flags & FLAG_ALPHA != 0),
            aovs: false,
        }
    }

    /// The pipeline constants.
    fn constants(self) -> [(&'static str, f64); 6] {
        let value = |on: bool| f64::from(u8::from(on));
        [
            ("INSTANCES", value(self.instances)),
            ("METAL_ROUGH", value(self.metal_rough)),
            ("TEXTURES", value(self.textures)),
            ("NORMAL_MAPS", value(self.normal_maps)),
            ("ALPHA", value(self.alpha)),
            ("AOVS", value(self.aovs)),
        ]
    }
}

/// A progressive render on a wgpu adapter: the scene on the device, the integrator
/// pipeline and the accumulation buffer.
#[derive(Debug)]
pub struct GpuRenderer {
    /// The device (a cheap clone of the caller's context).
    ctx: GpuContext,
    scene: SceneBuffers,
    pipeline: wgpu::ComputePipeline,
    /// How the pipeline finds hits, and what it compiles in (rebuilt when new materials
    /// change that).
    accel: Accel,
    features: KernelFeatures,
    params_buffer: wgpu::Buffer,
    accum_buffer: wgpu::Buffer,
    /// The auxiliary images' sums ([`GpuAovPixel`] per pixel), or a placeholder for a render
    /// without them.
    aov_buffer: wgpu::Buffer,
    /// Since the last restart: rays traced (64-bit: low word, high word) and samples
    /// dropped as not finite (`counters` in `integrator.wgsl`).
    counters: wgpu::Buffer,
    frame_layout: wgpu::BindGroupLayout,
    frame_bind_group: wgpu::BindGroup,
    params: GpuRenderParams,
    /// Entries of the pipeline's traversal stack.
    stack_size: u32,
    /// The samples the accumulation buffer holds.
    cursor: SampleCursor,
    /// Current piece size: rows per dispatch and samples per pixel per dispatch.
    rows_per_dispatch: u32,
    batch_samples: u32,
    /// Whether the piece size follows the measured speed (see [`Self::set_piece`]).
    adaptive: bool,
    /// The kernel asked for.
    kernel: Kernel,
    /// The wavefront kernels, when the kernel asked for may use them.
    wavefront: Option<Wavefront>,
    /// Whether the wavefront renders instead of `pipeline` now.
    use_wavefront: bool,
    /// The `auto` kernel's trial while it is under way, then its outcome.
    trial: Option<KernelTrial>,
    choice: Option<KernelChoice>,
}

impl GpuRenderer {
    /// Uploads `scene` and creates the pipeline for `camera` and `settings`, finding hits
    /// with `accel`; the image starts empty.
    pub fn new(
        ctx: &GpuContext,
        scene: &PreparedScene,
        camera: &Camera,
        settings: &RenderSettings,
        accel: Accel,
    ) -> Result<Self, RenderError> {
        let device = &ctx.device;
        let params = GpuRenderParams::new(camera, settings, &scene.shading);
        let accum_size = accumulation_size(device, &params)?;
        let aov_size = aov_size(device, &params)?;
        let scene_buffers = SceneBuffers::upload(device, scene)?;
        let frame_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("frame layout"),
            entries: &[
                storage_entry(0, true),
                storage_entry(1, false),
                storage_entry(2, false),
                storage_entry(3, false),
            ],
        });
        let stack_size = stack_size(scene);
        let features = KernelFeatures::of(scene, settings.aovs);
        let pipeline = IntegratorKernel::new(Kernel::Megakernel, accel, stack_size, features)?
            .pipeline(device, &scene_buffers.layout, &frame_layout)?;
        let params_buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("render params"),
            size: size_of::<GpuRenderParams>() as u64,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let accum_buffer = create_accumulation(device, "accumulation", accum_size);
        let aov_buffer = create_accumulation(device, "auxiliary images", aov_size);
        let counters = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("counters"),
            size: 3 * size_of::<u32>() as u64,
            usage: wgpu::BufferUsages::STORAGE
                | wgpu::BufferUsages::COPY_SRC
                | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let frame_bind_group = frame_bind_group(
            device,
            &frame_layout,
            &params_buffer,
            &accum_buffer,
            &counters,
            &aov_buffer,
        );
        Ok(Self {
            ctx: ctx.clone(),
            scene: scene_buffers,
            pipeline,
            accel,
            features,
            params_buffer,
            accum_buffer,
            aov_buffer,
            counters,
            frame_layout,
            frame_bind_group,
            stack_size,
            rows_per_dispatch: params.height.min(WORKGROUP * 4),
            batch_samples: 1,
            adaptive: true,
            params,
            cursor: SampleCursor::default(),
            kernel: Kernel::Megakernel,
            wavefront: None,
            use_wavefront: false,
            trial: None,
            choice: None,
        })
    }

    /// Fixes the piece size (rows per dispatch; samples per pixel per dispatch when it covers
    /// every row, else one) instead of sizing pieces from the measured speed. The image does not depend on it: samples are
    /// seeded per (pixel, index) and summed exactly.
    pub fn set_piece(&mut self, rows: u32, samples: u32) {
        self.rows_per_dispatch = rows.clamp(1, self.params.height);
        self.batch_samples = samples.clamp(1, MAX_BATCH_SAMPLES);
        self.adaptive = false;
    }

    /// Renders with `kernel` from now on (the image does not depend on it).
    pub fn set_kernel(&mut self, kernel: Kernel) -> Result<(), RenderError> {
        self.wavefront = match kernel {
            Kernel::Megakernel => None,
            Kernel::Wavefront | Kernel::Auto => Some(self.wavefront_kernels()?),
        };
        self.kernel = kernel;
        self.start_trial();
        Ok(())
    }

    /// Renders with the kernel asked for, or, for `auto`, starts its trial over.
    fn start_trial(&mut self) {
        self.use_wavefront = self.kernel == Kernel::Wavefront;
        self.trial = (self.kernel == Kernel::Auto).then(KernelTrial::default);
        self.choice = None;
    }

    /// The wavefront kernels when they render now.
    fn active_wavefront(&self) -> Option<&Wavefront> {
        self.wavefront.as_ref().filter(|_| self.use_wavefront)
    }

    /// Renders the next whole pass of the image (after finishing the pass under way) with a
    /// timestamp after every dispatch, and returns each dispatch's GPU time in order, named:
    /// `megakernel`, or the wavefront's `start`, `trace N` and `shade N` of segment N and
    /// `finish`, a wave of rows after another. Refused where the device has no timestamp
    /// queries inside compute passes, or a pass needs more than a query set holds.
    pub fn profile_pass(&mut self) -> Result<Vec<(String, Duration)>, RenderError> {
        let adapter = &self.ctx.adapter_info.name;
        if !self
            .ctx
            .device
            .features()
            .contains(dispatch_times::FEATURES)
        {
            return Err(RenderError::Gpu(format!(
                "{adapter} has no timestamp queries inside compute passes"
            )));
        }
        if self.cursor.in_pass() {
            self.queue_frame()?;
        }
        let height = self.params.height;
        let (waves, per_wave) = match self.active_wavefront() {
            Some(wavefront) => (
                height.div_ceil(wavefront.rows()),
                4 + 2 * self.params.max_depth,
            ),
            None => (1, 2),
        };
        let capacity = u64::from(waves) * u64::from(per_wave);
        if capacity > u64::from(wgpu::QUERY_SET_MAX_QUERIES) {
            return Err(RenderError::Gpu(format!(
                "a pass takes {capacity} timestamps, more than a query set's {}",
                wgpu::QUERY_SET_MAX_QUERIES
            )));
        }
        let mut times = DispatchTimes::new(&self.ctx.device, capacity as u32);
        self.submit_timed(0, height, 1, Some(&mut times));
        self.cursor.add_passes(1);
        let resolved = self.ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("timestamps"),
            size: times.size().max(8),
            usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let mut encoder = self.ctx.device.create_command_encoder(&Default::default());
        times.resolve(&mut encoder, &resolved);
        self.ctx.queue.submit([encoder.finish()]);
        let ticks: Vec<u64> = self.read_buffer(&resolved)?;
        Ok(times.durations(&ticks, self.ctx.queue.get_timestamp_period()))
    }

    /// For the `auto` kernel's trial, while it is under way: its next step, timed, when a
    /// pass is starting and the caller renders whole passes (`whole_passes`) or a pass takes
    /// at most about [`TRIAL_PASS_SUBMISSIONS`] submissions' time. A step is whole passes
    /// (at most `max_passes`): as frames, a pass a submission (`frames`), or as one batch of
    /// samples, the way the caller renders them. Returns the passes rendered.
    fn trial_step(
        &mut self,
        whole_passes: bool,
        frames: bool,
        max_passes: u32,
    ) -> Result<u32, RenderError> {
        let Some((kernel, passes)) = self.trial.as_ref().map(|t| (t.next(), t.passes())) else {
            return Ok(0);
        };
        let height = self.params.height;
        let short_pass = self.rows_per_dispatch * TRIAL_PASS_SUBMISSIONS >= height;
        if self.cursor.in_pass() || !(whole_passes || short_pass) {
            return Ok(0);
        }
        let passes = passes.min(max_passes);
        self.use_wavefront = kernel == Kernel::Wavefront;
        let started = Instant::now();
        if frames {
            self.submit_frames(passes);
        } else {
            self.submit(0, height, passes);
            self.cursor.add_passes(passes);
        }
        self.wait()?;
        let elapsed = started.elapsed();
        log::debug!(
            "kernel trial: {passes} passes with the {} took {elapsed:?}",
            kernel.name()
        );
        if let Some(choice) = self.trial.as_mut().and_then(|t| t.record(elapsed, passes)) {
            log::info!("kernel: {}", choice.describe());
            self.use_wavefront = choice.kernel == Kernel::Wavefront;
            self.trial = None;
            self.choice = Some(choice);
            if self.adaptive {
                let best = choice.megakernel.min(choice.wavefront);
                self.reschedule(best, 1);
            }
        }
        Ok(passes)
    }

    /// The wavefront kernels for the scene, the features and the image size.
    fn wavefront_kernels(&self) -> Result<Wavefront, RenderError> {
        let kernel = IntegratorKernel::new(
            Kernel::Wavefront,
            self.accel,
            self.stack_size,
            self.features,
        )?;
        Wavefront::new(
            &self.ctx.device,
            &kernel,
            &self.scene.layout,
            &self.frame_layout,
            (self.params.width, self.params.height),
            self.features.aovs,
        )
    }

    /// The samples the accumulation buffer holds (see [`Renderer::step_frame`]).
    pub fn cursor(&self) -> SampleCursor {
        self.cursor
    }

    /// The accumulation buffer (per pixel [`GpuAccumPixel`]: a fixed-point sum of samples),
    /// for a display pass to read.
    pub fn accumulation_buffer(&self) -> &wgpu::Buffer {
        &self.accum_buffer
    }

    /// The device it renders on.
    pub fn context(&self) -> &GpuContext {
        &self.ctx
    }

    fn wait(&self) -> Result<(), RenderError> {
        self.ctx
            .device
            .poll(wgpu::PollType::wait_indefinitely())
            .map(|_| ())
            .map_err(|err| RenderError::Gpu(err.to_string()))
    }

    /// Queues `samples` samples per pixel for rows `row .. row + rows`.
    fn submit(&self, row: u32, rows: u32, samples: u32) {
        self.submit_timed(row, rows, samples, None);
    }

    /// [`Self::submit`], with the dispatches' timestamps written to `times`.
    fn submit_timed(
        &self,
        row: u32,
        rows: u32,
        samples: u32,
        mut times: Option<&mut DispatchTimes>,
    ) {
        // The wavefront takes the band in waves of paths its dispatches can hold.
        let wave = self.active_wavefront().map_or(rows, Wavefront::rows);
        for start in (row..row + rows).step_by(wave as usize) {
            let wave_rows = wave.min(row + rows - start);
            self.submit_wave(start, wave_rows, samples, times.as_deref_mut());
        }
    }

    /// Queues `samples` samples per pixel for rows `row .. row + rows` as one submission,
    /// writing the dispatches' timestamps to `times`.
    fn submit_wave(
        &self,
        row: u32,
        rows: u32,
        samples: u32,
        mut times: Option<&mut DispatchTimes>,
    ) {
        self.write_params(row, rows, samples);
        let mut encoder = self.ctx.device.create_command_encoder(&Default::default());
        if let Some(wavefront) = self.active_wavefront() {
            wavefront.record(
                &self.ctx.queue,
                &mut encoder,
                &self.scene.bind_group,
                &self.frame_bind_group,
                self.params.width,
                rows,
                samples,
                self.params.max_depth,
                times,
            );
        } else {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("integrator"),
                timestamp_writes: None,
            });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &self.scene.bind_group, &[]);
            pass.set_bind_group(1, &self.frame_bind_group, &[]);
            if let Some(times) = times.as_deref_mut() {
                times.begin(&mut pass);
            }
            pass.dispatch_workgroups(
                self.params.width.div_ceil(WORKGROUP),
                rows.div_ceil(WORKGROUP),
                1,
            );
            if let Some(times) = times {
                times.end(&mut pass, "megakernel".into());
            }
        }
        self.ctx.queue.submit([encoder.finish()]);
    }

    /// Sets the parameters of the next submission: `samples` samples per pixel of rows
    /// `row .. row + rows`, from the cursor's next sample.
    fn write_params(&self, row: u32, rows: u32, samples: u32) {
        let params = GpuRenderParams {
            sample_offset: self.cursor.next_sample(),
            batch_samples: samples,
            row_offset: row,
            row_end: row + rows,
            ..self.params
        };
        self.ctx
            .queue
            .write_buffer(&self.params_buffer, 0, bytemuck::bytes_of(&params));
    }

    /// Queues `frames` whole passes of one sample each (a pass must not be under way) and
    /// counts them: with the wavefront, where its path state holds two frames or more, as one
    /// run of overlapped frames ([`Wavefront::submit_frames`]); else a pass a
    /// submission.
    fn submit_frames(&mut self, frames: u32) {
        let (height, max_depth) = (self.params.height, self.params.max_depth);
        let overlapped = self
            .active_wavefront()
            .filter(|w| frames > 1 && w.frame_layers(height, max_depth, frames).0 > 1);
        let Some(wavefront) = overlapped else {
            for _ in 0..frames {
                self.submit(0, height, 1);
                self.cursor.add_passes(1);
            }
            return;
        };
        self.write_params(0, height, 1);
        wavefront.submit_frames(
            &self.ctx.device,
            &self.ctx.queue,
            &self.scene.bind_group,
            &self.frame_bind_group,
            self.params.width,
            height,
            frames,
            max_depth,
        );
        self.cursor.add_passes(frames);
    }

    /// Sizes the next pieces from the speed of the last `advance`.
    fn reschedule(&mut self, elapsed: Duration, samples: u32) {
        let width = u64::from(self.params.width);
        let height = u64::from(self.params.height);
        let done = width * height * u64::from(samples);
        let rate = done as f64 / elapsed.as_secs_f64().max(1e-6);
        let per_submission = (rate * TARGET_SUBMISSION.as_secs_f64()).max(1.0) as u64;
        if per_submission >= width * height {
            self.rows_per_dispatch = self.params.height;
            self.batch_samples =
                (per_submission / (width * height)).clamp(1, u64::from(MAX_BATCH_SAMPLES)) as u32;
        } else {
            // Whole workgroups of rows, so no invocation idles at a band's edge.
            let rows =
                (per_submission / width / u64::from(WORKGROUP)).max(1) * u64::from(WORKGROUP);
            self.rows_per_dispatch = rows.min(height) as u32;
            self.batch_samples = 1;
        }
    }

    /// Copies a buffer back to the host.
    fn read_buffer<T: bytemuck::Pod>(&self, buffer: &wgpu::Buffer) -> Result<Vec<T>, RenderError> {
        let device = &self.ctx.device;
        let size = buffer.size();
        let staging = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("readback"),
            size,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut encoder = device.create_command_encoder(&Default::default());
        encoder.copy_buffer_to_buffer(buffer, 0, &staging, 0, size);
        self.ctx.queue.submit([encoder.finish()]);
        let slice = staging.slice(..);
        let (sender, receiver) = std::sync::mpsc::channel();
        slice.map_async(wgpu::MapMode::Read, move |result| {
            let _ = sender.send(result);
        });
        self.wait()?;
        receiver
            .recv()
            .map_err(|err| RenderError::Gpu(err.to_string()))?
            .map_err(|err| RenderError::Gpu(err.to_string()))?;
        let view = slice
            .get_mapped_range()
            .map_err(|err| RenderError::Gpu(err.to_string()))?;
        Ok(bytemuck::cast_slice(&view).to_vec())
    }
}

impl Renderer for GpuRenderer {
    fn device(&self) -> String {
        describe(&self.ctx.adapter_info)
    }

    fn kernel(&self) -> Option<String> {
        Some(match (&self.choice, self.kernel) {
            (Some(choice), _) => choice.describe(),
            (None, Kernel::Auto) => "auto (not chosen yet: the first passes time both)".into(),
            (None, kernel) => kernel.name().into(),
        })
    }

    fn size(&self) -> (u32, u32) {
        (self.params.width, self.params.height)
    }

    /// Writes only the per-render constants; a new image size also gets a new accumulation
    /// buffer.
    fn set_camera(&mut self, camera: &Camera) -> Result<(), RenderError> {
        let old = (self.params.width, self.params.height);
        self.params.set_camera(camera);
        if (camera.width, camera.height) != old {
            let device = &self.ctx.device;
            let size = accumulation_size(device, &self.params)?;
            self.accum_buffer = create_accumulation(device, "accumulation", size);
            let size = aov_size(device, &self.params)?;
            self.aov_buffer = create_accumulation(device, "auxiliary images", size);
            self.frame_bind_group = frame_bind_group(
                device,
                &self.frame_layout,
                &self.params_buffer,
                &self.accum_buffer,
                &self.counters,
                &self.aov_buffer,
            );
            self.rows_per_dispatch = camera.height.min(WORKGROUP * 4);
            self.batch_samples = 1;
            if self.wavefront.is_some() {
                self.wavefront = Some(self.wavefront_kernels()?);
            }
            // Which kernel is faster depends on the image size.
            self.start_trial();
        }
        self.restart();
        Ok(())
    }

    /// Uploads the objects, materials and light table again; the BVH stays, and so does the
    /// pipeline unless the new materials use a feature it compiled out, or no longer use one
    /// it compiled in.
    fn set_materials(&mut self, shading: &Shading) -> Result<(), RenderError> {
        let features = KernelFeatures {
            instances: self.features.instances,
            aovs: self.features.aovs,
            ..KernelFeatures::of_shading(shading)
        };
        if features != self.features {
            self.pipeline =
                IntegratorKernel::new(Kernel::Megakernel, self.accel, self.stack_size, features)?
                    .pipeline(&self.ctx.device, &self.scene.layout, &self.frame_layout)?;
            self.features = features;
            if self.wavefront.is_some() {
                self.wavefront = Some(self.wavefront_kernels()?);
            }
        }
        self.scene.set_shading(&self.ctx.device, shading)?;
        self.params.set_shading(shading);
        self.restart();
        Ok(())
    }

    fn restart(&mut self) {
        let mut encoder = self.ctx.device.create_command_encoder(&Default::default());
        encoder.clear_buffer(&self.accum_buffer, 0, None);
        encoder.clear_buffer(&self.aov_buffer, 0, None);
        encoder.clear_buffer(&self.counters, 0, None);
        self.ctx.queue.submit([encoder.finish()]);
        self.cursor = SampleCursor::default();
    }

    /// One submission of about [`TARGET_SUBMISSION`]: samples over the whole image, or, when
    /// one sample of the image takes longer, the next band of rows of the pass in progress.
    fn advance(&mut self, max_samples: u32) -> Result<u32, RenderError> {
        let samples = self.batch_samples.min(max_samples);
        if samples == 0 {
            return Ok(0);
        }
        let trial = self.trial_step(false, false, max_samples)?;
        if trial > 0 {
            return Ok(trial);
        }
        if self.cursor.in_pass() || self.rows_per_dispatch < self.params.height {
            let done = self.step_frame(TARGET_SUBMISSION)?;
            return Ok(u32::from(done));
        }
        let started = Instant::now();
        self.submit(0, self.params.height, samples);
        self.wait()?;
        let elapsed = started.elapsed();
        log::debug!("{samples} samples of every pixel: {elapsed:?}");
        self.cursor.add_passes(samples);
        if self.adaptive {
            self.reschedule(elapsed, samples);
        }
        Ok(samples)
    }

    /// Renders the next band of rows, sized so that a submission takes about `target`.
    /// Rows `0 .. cursor().rows_ahead` of an incomplete frame hold one sample more than the
    /// others.
    fn step_frame(&mut self, target: Duration) -> Result<bool, RenderError> {
        if self.trial_step(false, true, u32::MAX)? > 0 {
            return Ok(true);
        }
        let height = self.params.height;
        let band = self.cursor.next_band(self.rows_per_dispatch, height);
        let rows = band.len() as u32;
        let started = Instant::now();
        self.submit(band.start, rows, 1);
        self.wait()?;
        let elapsed = started.elapsed();
        log::debug!("rows {}..{}, one sample: {elapsed:?}", band.start, band.end);
        if self.adaptive {
            self.rows_per_dispatch =
                next_band_rows(self.rows_per_dispatch, rows, elapsed, target, height);
        }
        Ok(self.cursor.add_band(band.end, height))
    }

    /// The rest of the pass in progress, or a whole one, as one dispatch not waited for.
    fn queue_frame(&mut self) -> Result<(), RenderError> {
        if self.trial_step(true, true, u32::MAX)? > 0 {
            return Ok(());
        }
        let height = self.params.height;
        let band = self.cursor.next_band(height, height);
        self.submit(band.start, band.len() as u32, 1);
        self.cursor.add_band(band.end, height);
        Ok(())
    }

    /// Whole passes, overlapped where the wavefront renders (`submit_frames`), after
    /// the `auto` kernel's trial steps and the rest of a pass under way.
    fn queue_frames(&mut self, frames: u32) -> Result<(), RenderError> {
        let mut left = frames;
        while left > 0 {
            let trial = self.trial_step(true, true, left)?;
            if trial > 0 {
                left -= trial;
            } else if self.cursor.in_pass() {
                self.queue_frame()?;
                left -= 1;
            } else {
                self.submit_frames(left);
                left = 0;
            }
        }
        Ok(())
    }

    fn finish(&self) -> Result<(), RenderError> {
        self.wait()
    }

    fn samples_done(&self) -> u32 {
        self.cursor.samples
    }

    fn accumulation(&self) -> Result<Accumulation, RenderError> {
        let aovs = if self.params.aovs != 0 {
            self.read_buffer(&self.aov_buffer)?
        } else {
            Vec::new()
        };
        Ok(Accumulation {
            cursor: self.cursor,
            sums: self.read_buffer(&self.accum_buffer)?,
            aovs,
        })
    }

    fn resume(&mut self, from: &Accumulation) -> Result<(), RenderError> {
        from.check_fits(self.params.width, self.params.height, self.params.aovs != 0)?;
        self.restart();
        self.ctx
            .queue
            .write_buffer(&self.accum_buffer, 0, bytemuck::cast_slice(&from.sums));
        if from.has_aovs() {
            self.ctx
                .queue
                .write_buffer(&self.aov_buffer, 0, bytemuck::cast_slice(&from.aovs));
        }
        self.cursor = from.cursor;
        Ok(())
    }

    fn rays_traced(&self) -> Result<u64, RenderError> {
        let words: Vec<u32> = self.read_buffer(&self.counters)?;
        Ok(u64::from(words[0]) | (u64::from(words[1]) << 32))
    }

    fn samples_dropped(&self) -> Result<u64, RenderError> {
        let words: Vec<u32> = self.read_buffer(&self.counters)?;
        Ok(u64::from(words[2]))
    }

    /// Copies the accumulation back and divides by each pixel's sample count. `spp` of the
    /// film counts whole frames only.
    fn film(&self) -> Result<Film, RenderError> {
        let (width, height) = self.size();
        Ok(Film::from_accumulation(
            width,
            height,
            &Renderer::accumulation(self)?,
        ))
    }

    fn traversal_stack(&self) -> Option<u32> {
        Some(self.stack_size)
    }
}

/// Bytes of the accumulation buffer for `params`' image, or why the device cannot bind it.
/// Rows of the next band: as many as `target` renders at the speed of the last band
/// (`rows` rows in `elapsed`), between half and twice the rows `asked` for it (a pass's last
/// band is cut short, so the size asked for is the base, not the band's), in whole
/// workgroups of rows, at most `height`.
fn next_band_rows(asked: u32, rows: u32, elapsed: Duration, target: Duration, height: u32) -> u32 {
    let in_target = f64::from(rows) * target.as_secs_f64() / elapsed.as_secs_f64().max(1e-6);
    let asked = f64::from(asked);
    let workgroups = (in_target.clamp(0.5 * asked, 2.0 * asked) / f64::from(WORKGROUP)).round();
    (workgroups as u32 * WORKGROUP).clamp(WORKGROUP.min(height), height)
}

fn accumulation_size(device: &wgpu::Device, params: &GpuRenderParams) -> Result<u64, RenderError> {
    per_pixel_size(
        device,
        params,
        size_of::<GpuAccumPixel>(),
        "accumulation buffer",
    )
}

/// Bytes of the auxiliary images' buffer for `params`' image (a placeholder's without
/// them), or why the device cannot bind it.
fn aov_size(device: &wgpu::Device, params: &GpuRenderParams) -> Result<u64, RenderError> {
    if params.aovs == 0 {
        return Ok(size_of::<GpuAovPixel>() as u64);
    }
    per_pixel_size(
        device,
        params,
        size_of::<GpuAovPixel>(),
        "buffer of auxiliary images",
    )
}

/// Bytes of a buffer of `bytes` per pixel of `params`' image, or why the device cannot bind
/// it (`what` names it).
fn per_pixel_size(
    device: &wgpu::Device,
    params: &GpuRenderParams,
    bytes: usize,
    what: &str,
) -> Result<u64, RenderError> {
    let pixels = u64::from(params.width) * u64::from(params.height);
    let size = pixels * bytes as u64;
    let limit = device.limits().max_storage_buffer_binding_size;
    if size > limit {
        return Err(RenderError::Limits(format!(
            "a {}x{} image needs a {} MiB {what}; this device binds at most {} MiB",
            params.width,
            params.height,
            size >> 20,
            limit >> 20
        )));
    }
    Ok(size)
}

/// An empty buffer of sums of `size` bytes, labelled `label`.
fn create_accumulation(device: &wgpu::Device, label: &str, size: u64) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size,
        usage: wgpu::BufferUsages::STORAGE
            | wgpu::BufferUsages::COPY_SRC
            | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

/// Bind group 1 of the integrator: parameters, accumulation, ray counter, auxiliary images.
fn frame_bind_group(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    params: &wgpu::Buffer,
    accum: &wgpu::Buffer,
    counters: &wgpu::Buffer,
    aovs: &wgpu::Buffer,
) -> wgpu::BindGroup {
    bind_buffers(device, "frame", layout, &[params, accum, counters, aovs])
}

/// The integrator kernels of a scene: their WGSL module, with the traversal stack sized to the
/// scene's tree, its pipeline constants (the hit-finding scheme, the features compiled in)
/// and its entry points.
/// `examples/kernel_stats.rs` compiles it as the renderer does.
#[derive(Debug, Clone)]
pub struct IntegratorKernel {
    /// The assembled WGSL module.
    pub source: String,
    /// Its pipeline-overridable constants by name.
    pub constants: Vec<(&'static str, f64)>,
    /// Its entry points: `render` (the megakernel), or the wavefront's kernels.
    pub entry_points: &'static [&'static str],
}

impl IntegratorKernel {
    /// The kernels the renderer compiles as `kernel` for `scene`, `settings` and `accel`
    /// (`auto` is the two kernels: it asks for one of them).
    pub fn of(
        scene: &PreparedScene,
        settings: &RenderSettings,
        accel: Accel,
        kernel: Kernel,
    ) -> Result<Self, RenderError> {
        Self::new(
            kernel,
            accel,
            stack_size(scene),
            KernelFeatures::of(scene, settings.aovs),
        )
    }

    fn new(
        kernel: Kernel,
        accel: Accel,
        stack_size: u32,
        features: KernelFeatures,
    ) -> Result<Self, RenderError> {
        let (module, entry_points) = match kernel {
            Kernel::Megakernel => ("integrator", &["render"][..]),
            Kernel::Wavefront => ("wavefront", &WAVEFRONT_ENTRY_POINTS[..]),
            Kernel::Auto => {
                return Err(RenderError::Pipeline {
                    label: "auto".into(),
                    message: "`auto` compiles both kernels: ask for `megakernel` or `wavefront`"
                        .into(),
                });
            }
        };
        let source = wgsl::assemble(module, &[("STACK_SIZE", stack_size)]).map_err(|err| {
            RenderError::Pipeline {
                label: module.into(),
                message: err.to_string(),
            }
        })?;
        let mut constants = accel.pipeline_constants().to_vec();
        constants.extend(features.constants());
        Ok(Self {
            source,
            constants,
            entry_points,
        })
    }

    fn pipeline(
        &self,
        device: &wgpu::Device,
        scene_layout: &wgpu::BindGroupLayout,
        frame_layout: &wgpu::BindGroupLayout,
    ) -> Result<wgpu::ComputePipeline, RenderError> {
        create_compute_pipeline(
            device,
            "integrator",
            &self.source,
            "render",
            &[scene_layout, frame_layout],
            &self.constants,
        )
    }
}

/// Entries of the traversal stack compiled for `scene`: its tree's bound, rounded up to 8, at
/// most [`MAX_STACK`].
fn stack_size(scene: &PreparedScene) -> u32 {
    scene
        .geometry
        .stack_bound
        .next_multiple_of(8)
        .min(MAX_STACK)
}

#[cfg(test)]
mod tests {
    use super::*;

    const TARGET: Duration = TARGET_SUBMISSION;

    fn ms(n: f64) -> Duration {
        Duration::from_secs_f64(n / 1e3)
    }

    #[test]
    fn bands_grow_at_most_twofold_to_a_whole_pass() {
        // 32 rows in 1 ms: 3200 rows would fit the target; twice the band is the limit.
        assert_eq!(next_band_rows(32, 32, ms(1.0), TARGET, 500), 64);
        assert_eq!(next_band_rows(256, 256, ms(1.0), TARGET, 500), 500);
        // At the target's speed the size holds; slower bands shrink, at most by half.
        assert_eq!(next_band_rows(96, 96, TARGET, TARGET, 500), 96);
        assert_eq!(next_band_rows(96, 96, TARGET * 10, TARGET, 500), 48);
        // Never below a workgroup of rows, or the image's height when it is smaller.
        assert_eq!(next_band_rows(8, 8, TARGET * 10, TARGET, 500), 8);
        assert_eq!(next_band_rows(8, 5, TARGET * 10, TARGET, 5), 5);
    }

    #[test]
    fn a_passs_last_band_cut_short_does_not_shrink_the_next() {
        // 256 rows asked for, 20 left in the pass (rows 480..500): the next band is twice
        // the 256, the whole image, not twice the 20 (which kept a 500-row image in bands
        // for good: 40, 80, 160, 220, 440, 60, ...).
        assert_eq!(next_band_rows(256, 20, ms(0.4), TARGET, 500), 500);
    }
}
