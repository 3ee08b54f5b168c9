//! The scene on the device: the buffers of a [`GpuScene`] as bind group 0.

use bytemuck::Zeroable;
use pathlight_core::gpu::GpuPrimitive;
use pathlight_core::{GpuScene, WideBvh};
use wgpu::util::DeviceExt;

use crate::error::RenderError;

/// Nodes the traversal can address: its leaf entries hold `node << 2 | lane` in 30 bits
/// (`LEAF` in `shaders/bvh.wgsl`).
const MAX_NODES: usize = 1 << 28;

/// Bind group 0 of every ray-casting pass (see `shaders/scene.wgsl`).
#[derive(Debug)]
pub struct SceneBuffers {
    /// Its layout.
    pub layout: wgpu::BindGroupLayout,
    /// The bound buffers.
    pub bind_group: wgpu::BindGroup,
    /// Most entries the traversal stack needs in this scene ([`WideBvh::stack_bound`]).
    pub stack_bound: u32,
}

/// A read-only storage buffer entry at `binding` for compute.
pub fn storage_entry(binding: u32, read_only: bool) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

impl SceneBuffers {
    /// Uploads `scene` with its BVH in 4-wide form, refusing buffers over the device's
    /// binding limit.
    pub fn upload(device: &wgpu::Device, scene: &GpuScene) -> Result<Self, RenderError> {
        let bvh = WideBvh::build(scene);
        let nodes = bvh.gpu_nodes();
        if nodes.len() >= MAX_NODES {
            return Err(RenderError::Limits(format!(
                "the scene's BVH has {} nodes; the traversal addresses at most {MAX_NODES}",
                nodes.len()
            )));
        }
        // A binding is never empty: a placeholder when there are no primitives.
        let placeholder = [GpuPrimitive::zeroed()];
        let primitives = if scene.primitives.is_empty() {
            &placeholder[..]
        } else {
            &scene.primitives
        };
        let contents: [(&str, &[u8]); 8] = [
            ("bvh nodes", bytemuck::cast_slice(&nodes)),
            ("objects", bytemuck::cast_slice(&scene.objects)),
            ("vertices", bytemuck::cast_slice(&scene.vertices)),
            ("materials", bytemuck::cast_slice(&scene.materials)),
            ("texture table", bytemuck::cast_slice(&scene.textures)),
            ("texels", bytemuck::cast_slice(&scene.texels)),
            ("lights", bytemuck::cast_slice(&scene.lights)),
            ("primitives", bytemuck::cast_slice(primitives)),
        ];
        let limit = device.limits().max_storage_buffer_binding_size;
        let mut buffers = Vec::new();
        for (label, bytes) in contents {
            if bytes.len() as u64 > limit {
                return Err(RenderError::Limits(format!(
                    "the scene's {label} take {} MiB; this device binds at most {} MiB",
                    bytes.len() >> 20,
                    limit >> 20
                )));
            }
            buffers.push(
                device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some(label),
                    contents: bytes,
                    usage: wgpu::BufferUsages::STORAGE,
                }),
            );
        }
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("scene layout"),
            entries: &(0..8).map(|i| storage_entry(i, true)).collect::<Vec<_>>(),
        });
        let buffers: Vec<&wgpu::Buffer> = buffers.iter().collect();
        let bind_group = bind_buffers(device, "scene", &layout, &buffers);
        Ok(Self {
            layout,
            bind_group,
            stack_bound: bvh.stack_bound(),
        })
    }
}

/// A bind group of `layout` binding `buffers[i]`, whole, at binding `i`.
pub fn bind_buffers(
    device: &wgpu::Device,
    label: &str,
    layout: &wgpu::BindGroupLayout,
    buffers: &[&wgpu::Buffer],
) -> wgpu::BindGroup {
    let entries: Vec<_> = buffers
        .iter()
        .enumerate()
        .map(|(i, b)| wgpu::BindGroupEntry {
            binding: i as u32,
            resource: b.as_entire_binding(),
        })
        .collect();
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some(label),
        layout,
        entries: &entries,
    })
}

/// Creates a compute pipeline inside an error scope so a shader mismatch is an error;
/// `constants` sets the shader's pipeline-overridable constants by name.
pub fn create_compute_pipeline(
    device: &wgpu::Device,
    label: &str,
    source: &str,
    entry_point: &str,
    layouts: &[&wgpu::BindGroupLayout],
    constants: &[(&str, f64)],
) -> Result<wgpu::ComputePipeline, RenderError> {
    let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(label),
        source: wgpu::ShaderSource::Wgsl(source.into()),
    });
    let layout_refs: Vec<Option<&wgpu::BindGroupLayout>> =
        layouts.iter().map(|l| Some(*l)).collect();
    let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(label),
        bind_group_layouts: &layout_refs,
        immediate_size: 0,
    });
    let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some(label),
        layout: Some(&pipeline_layout),
        module: &module,
        entry_point: Some(entry_point),
        compilation_options: wgpu::PipelineCompilationOptions {
            constants,
            ..Default::default()
        },
        cache: None,
    });
    match pollster::block_on(scope.pop()) {
        None => Ok(pipeline),
        Some(err) => Err(RenderError::Pipeline {
            label: label.into(),
            message: err.to_string(),
        }),
    }
}
