//! The viewer's display pass (`shaders/display.wgsl`): shows the linear accumulation on a
//! surface through the sRGB curve and an optional tone mapper, leaving it unchanged.

use pathlight_core::{RenderError, Renderer, ToneMap};

use crate::GpuContext;
use crate::gpu_renderer::GpuRenderer;
use crate::pipeline::bind_buffers;
use crate::wgsl;

/// Parameters of the display pass (a read-only storage buffer). WGSL: `DisplayParams`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct GpuDisplayParams {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Samples per pixel in rows `rows_ahead ..`.
    pub samples: u32,
    /// Rows holding one sample more (a frame in progress).
    pub rows_ahead: u32,
    /// Surface width in pixels.
    pub target_width: f32,
    /// Surface height in pixels.
    pub target_height: f32,
    /// The tone mapper (`TONEMAP_*` in the shader).
    pub tonemap: u32,
    /// 1 when the shader applies the sRGB curve (the surface format does not).
    pub encode_srgb: u32,
}
const _: () = assert!(size_of::<GpuDisplayParams>() == 32);

/// An image to display: running sums in the accumulation's fixed point (`AccumPixel`,
/// [`pathlight_core::gpu_types::GpuAccumPixel`] on the host), on the presenting device.
#[derive(Debug, Clone, Copy)]
pub struct DisplaySource<'a> {
    /// The sums, row by row.
    pub pixels: &'a wgpu::Buffer,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Samples per pixel in rows `rows_ahead ..`.
    pub samples: u32,
    /// Rows holding one sample more (a pass in progress).
    pub rows_ahead: u32,
}

impl<'a> DisplaySource<'a> {
    /// The image of a GPU renderer, on its device.
    pub fn of(renderer: &'a GpuRenderer) -> Self {
        let (width, height) = renderer.size();
        Self {
            pixels: renderer.accumulation_buffer(),
            width,
            height,
            samples: renderer.samples_done(),
            rows_ahead: renderer.cursor().rows_ahead,
        }
    }
}

/// The display pipeline for one surface format.
#[derive(Debug)]
pub struct DisplayPass {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    params_buffer: wgpu::Buffer,
    encode_srgb: bool,
}

impl DisplayPass {
    /// Creates the pipeline drawing into textures of `format`.
    pub fn new(device: &wgpu::Device, format: wgpu::TextureFormat) -> Result<Self, RenderError> {
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("display"),
            source: wgpu::ShaderSource::Wgsl(
                wgsl::assemble("display", &[])
                    .map_err(|err| RenderError::Pipeline {
                        label: "display".into(),
                        message: err.to_string(),
                    })?
                    .into(),
            ),
        });
        let entry = |binding, ty| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::FRAGMENT,
            ty: wgpu::BindingType::Buffer {
                ty,
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        };
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("display"),
            entries: &[
                entry(0, wgpu::BufferBindingType::Storage { read_only: true }),
                entry(1, wgpu::BufferBindingType::Storage { read_only: true }),
            ],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("display"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("display"),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vertex_main"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fragment_main"),
                compilation_options: Default::default(),
                targets: &[Some(format.into())],
            }),
            primitive: Default::default(),
            depth_stencil: None,
            multisample: Default::default(),
            multiview_mask: None,
            cache: None,
        });
        let params_buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("display params"),
            size: size_of::<GpuDisplayParams>() as u64,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        if let Some(err) = pollster::block_on(scope.pop()) {
            return Err(RenderError::Pipeline {
                label: "display".into(),
                message: err.to_string(),
            });
        }
        Ok(Self {
            pipeline,
            layout,
            params_buffer,
            encode_srgb: !format.is_srgb(),
        })
    }

    /// Draws `source` (on `ctx`'s device), scaled to fill `target` (`target_size` pixels).
    pub fn draw(
        &self,
        ctx: &GpuContext,
        source: DisplaySource,
        target: &wgpu::TextureView,
        target_size: (u32, u32),
        tonemap: ToneMap,
    ) {
        let params = GpuDisplayParams {
            width: source.width,
            height: source.height,
            samples: source.samples,
            rows_ahead: source.rows_ahead,
            target_width: target_size.0.max(1) as f32,
            target_height: target_size.1.max(1) as f32,
            tonemap: tonemap as u32,
            encode_srgb: u32::from(self.encode_srgb),
        };
        ctx.queue
            .write_buffer(&self.params_buffer, 0, bytemuck::bytes_of(&params));
        let bind_group = bind_buffers(
            &ctx.device,
            "display",
            &self.layout,
            &[&self.params_buffer, source.pixels],
        );
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("display"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: target,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                ..Default::default()
            });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &bind_group, &[]);
            pass.draw(0..3, 0..1);
        }
        ctx.queue.submit([encoder.finish()]);
    }
}
