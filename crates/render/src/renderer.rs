//! The progressive renderer: owns the accumulation buffer and schedules the integrator.
//!
//! Work is submitted in pieces of about [`TARGET_SUBMISSION`] (a band of rows times some
//! samples per pixel), sized from the measured speed, so no single submission trips a
//! desktop GPU's watchdog and progress can be reported between them.

use std::time::{Duration, Instant};

use pathlight_core::gpu::{GpuAccumPixel, GpuFrameParams};
use pathlight_core::{GpuScene, Scene};

use crate::context::GpuContext;
use crate::error::RenderError;
use crate::film::Film;
use crate::scene_buffers::{SceneBuffers, create_compute_pipeline, storage_entry};
use crate::shaders;

/// Aimed-for GPU time of one submission.
pub const TARGET_SUBMISSION: Duration = Duration::from_millis(100);
/// Most samples per pixel one dispatch adds.
const MAX_BATCH_SAMPLES: u32 = 256;
/// Workgroup edge of the integrator (`@workgroup_size(8, 8)`).
const WORKGROUP: u32 = 8;

/// A scene on the device with its accumulation buffer.
#[derive(Debug)]
pub struct ProgressiveRenderer<'a> {
    ctx: &'a GpuContext,
    scene: SceneBuffers,
    pipeline: wgpu::ComputePipeline,
    params_buffer: wgpu::Buffer,
    accum_buffer: wgpu::Buffer,
    frame_bind_group: wgpu::BindGroup,
    params: GpuFrameParams,
    /// Samples per pixel accumulated so far.
    samples_done: u32,
    /// Current piece size: rows per dispatch and samples per pixel per dispatch.
    rows_per_dispatch: u32,
    batch_samples: u32,
}

/// Camera vectors of the integrator: eye, forward, right and up scaled to the image plane.
pub fn frame_params(scene: &Scene, object_count: u32) -> GpuFrameParams {
    let c = &scene.camera;
    let forward = (c.look_at - c.position).normalize();
    let right = forward.cross(c.up).normalize();
    let up = right.cross(forward);
    let tan_half = (c.fov_y_deg.to_radians() * 0.5).tan();
    let aspect = c.width as f32 / c.height as f32;
    GpuFrameParams {
        camera_position: c.position.to_array(),
        width: c.width,
        camera_forward: forward.to_array(),
        height: c.height,
        camera_right: (right * tan_half * aspect).to_array(),
        sample_offset: 0,
        camera_up: (up * tan_half).to_array(),
        batch_samples: 1,
        environment: scene.environment.to_array(),
        max_depth: scene.settings.max_depth,
        rr_depth: scene.settings.rr_depth,
        seed: scene.settings.seed,
        object_count,
        row_offset: 0,
    }
}

impl<'a> ProgressiveRenderer<'a> {
    /// Uploads the scene and creates the pipeline; the image starts empty.
    pub fn new(
        ctx: &'a GpuContext,
        scene: &Scene,
        gpu_scene: &GpuScene,
    ) -> Result<Self, RenderError> {
        let device = &ctx.device;
        let params = frame_params(scene, gpu_scene.object_count);
        let pixels = u64::from(params.width) * u64::from(params.height);
        let accum_size = pixels * size_of::<GpuAccumPixel>() as u64;
        let limit = device.limits().max_storage_buffer_binding_size;
        if accum_size > limit {
            return Err(RenderError::Limits(format!(
                "a {}x{} image needs a {} MiB accumulation buffer; this device binds at most {} MiB",
                params.width,
                params.height,
                accum_size >> 20,
                limit >> 20
            )));
        }
        let scene_buffers = SceneBuffers::upload(device, gpu_scene)?;
        let frame_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("frame layout"),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: wgpu::ShaderStages::COMPUTE,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: false,
                        min_binding_size: wgpu::BufferSize::new(size_of::<GpuFrameParams>() as u64),
                    },
                    count: None,
                },
                storage_entry(1, false),
            ],
        });
        let pipeline = create_compute_pipeline(
            device,
            "integrator",
            &shaders::integrator_module(),
            "render",
            &[&scene_buffers.layout, &frame_layout],
        )?;
        let params_buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("frame params"),
            size: size_of::<GpuFrameParams>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let accum_buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("accumulation"),
            size: accum_size,
            usage: wgpu::BufferUsages::STORAGE
                | wgpu::BufferUsages::COPY_SRC
                | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let frame_bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("frame"),
            layout: &frame_layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: params_buffer.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: accum_buffer.as_entire_binding(),
                },
            ],
        });
        Ok(Self {
            ctx,
            scene: scene_buffers,
            pipeline,
            params_buffer,
            accum_buffer,
            frame_bind_group,
            rows_per_dispatch: params.height.min(WORKGROUP * 4),
            batch_samples: 1,
            params,
            samples_done: 0,
        })
    }

    /// Samples per pixel accumulated so far.
    pub fn samples_done(&self) -> u32 {
        self.samples_done
    }

    fn wait(&self) -> Result<(), RenderError> {
        self.ctx
            .device
            .poll(wgpu::PollType::wait_indefinitely())
            .map(|_| ())
            .map_err(|err| RenderError::Gpu(err.to_string()))
    }

    /// Adds up to `max_samples` samples per pixel to every pixel (at least one when
    /// `max_samples` > 0) in submissions of about [`TARGET_SUBMISSION`]; returns how many
    /// were added.
    pub fn advance(&mut self, max_samples: u32) -> Result<u32, RenderError> {
        let samples = self.batch_samples.min(max_samples);
        if samples == 0 {
            return Ok(0);
        }
        let height = self.params.height;
        let started = Instant::now();
        let mut row = 0;
        while row < height {
            let rows = self.rows_per_dispatch.min(height - row);
            let params = GpuFrameParams {
                sample_offset: self.samples_done,
                batch_samples: samples,
                row_offset: row,
                ..self.params
            };
            self.ctx
                .queue
                .write_buffer(&self.params_buffer, 0, bytemuck::bytes_of(&params));
            let mut encoder = self.ctx.device.create_command_encoder(&Default::default());
            {
                let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some("integrator"),
                    timestamp_writes: None,
                });
                pass.set_pipeline(&self.pipeline);
                pass.set_bind_group(0, &self.scene.bind_group, &[]);
                pass.set_bind_group(1, &self.frame_bind_group, &[]);
                pass.dispatch_workgroups(
                    self.params.width.div_ceil(WORKGROUP),
                    rows.div_ceil(WORKGROUP),
                    1,
                );
            }
            self.ctx.queue.submit([encoder.finish()]);
            self.wait()?;
            row += rows;
        }
        self.samples_done += samples;
        self.reschedule(started.elapsed(), samples);
        Ok(samples)
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
            let rows = (per_submission / width).max(u64::from(WORKGROUP));
            self.rows_per_dispatch = rows.min(height) as u32;
            self.batch_samples = 1;
        }
    }

    /// Copies the accumulation back and divides by the sample count.
    pub fn read_film(&self) -> Result<Film, RenderError> {
        let device = &self.ctx.device;
        let size = self.accum_buffer.size();
        let staging = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("accumulation readback"),
            size,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut encoder = device.create_command_encoder(&Default::default());
        encoder.copy_buffer_to_buffer(&self.accum_buffer, 0, &staging, 0, size);
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
        let accum: &[GpuAccumPixel] = bytemuck::cast_slice(&view);
        let scale = 1.0 / f64::from(self.samples_done.max(1));
        let pixels = accum
            .iter()
            .map(|a| {
                [0, 1, 2].map(|c| {
                    let v = (a.channel_sum(c) * scale) as f32;
                    if v.is_finite() { v } else { 0.0 }
                })
            })
            .collect();
        Ok(Film {
            width: self.params.width,
            height: self.params.height,
            spp: self.samples_done,
            pixels,
        })
    }
}
