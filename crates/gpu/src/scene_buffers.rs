//! The prepared scene on the device: bind group 0 of every ray-casting pass
//! (`shaders/scene.wgsl`, `shaders/environment.wgsl`). The geometry, the textures and the
//! environment map are uploaded once; the shading (objects with their materials,
//! materials with their parameters and texture slots, light table) is uploaded again when it
//! changes.

use pathlight_core::gpu_types::GpuPrimitive;
use pathlight_core::{EnvironmentData, Geometry, PreparedScene, RenderError, Shading, Textures};
use wgpu::util::DeviceExt;

use crate::pipeline::{bind_buffers, storage_entry};

/// Nodes the traversal can address: its leaf entries hold `node << 2 | lane` in 30 bits
/// (`LEAF` in `shaders/bvh.wgsl`).
const MAX_NODES: usize = 1 << 28;

/// Bindings of `scene.wgsl` and `environment.wgsl`, by number.
const BINDINGS: usize = 14;

/// The scene's buffers on the device and the bind group over them.
#[derive(Debug)]
pub struct SceneBuffers {
    /// Bind group 0's layout.
    pub layout: wgpu::BindGroupLayout,
    /// The bound buffers.
    pub bind_group: wgpu::BindGroup,
    /// Buffers by binding number (`scene.wgsl`).
    buffers: Vec<wgpu::Buffer>,
}

/// A storage buffer holding `bytes`, refused when larger than the device binds.
fn storage_buffer(
    device: &wgpu::Device,
    label: &str,
    bytes: &[u8],
) -> Result<wgpu::Buffer, RenderError> {
    let limit = device.limits().max_storage_buffer_binding_size;
    if bytes.len() as u64 > limit {
        let mib = |n: u64| n as f64 / f64::from(1 << 20);
        return Err(RenderError::Limits(format!(
            "the scene's {label} take {:.1} MiB; this device binds at most {:.1} MiB \
             (the CPU backend, --backend cpu, has no such limit)",
            mib(bytes.len() as u64),
            mib(limit)
        )));
    }
    Ok(
        device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some(label),
            contents: bytes,
            usage: wgpu::BufferUsages::STORAGE,
        }),
    )
}

/// The geometry buffers: bindings 0 (nodes), 2 (vertices), 7 (primitives), 8 (the
/// nodes' parents), 12 (the instances' placements) and 13 (the triangles' corners).
fn geometry_contents(geometry: &Geometry) -> [(usize, &'static str, &[u8]); 6] {
    // A binding is never empty: a placeholder when there are no primitives.
    const PLACEHOLDER: [GpuPrimitive; 1] = [GpuPrimitive {
        v0: [0.0; 3],
        object: 0,
        v1: [0.0; 3],
        triangle: 0,
        v2: [0.0; 3],
        root: 0,
    }];
    let primitives = if geometry.primitives.is_empty() {
        bytemuck::cast_slice(&PLACEHOLDER)
    } else {
        bytemuck::cast_slice(&geometry.primitives)
    };
    let triangles = if geometry.triangles.is_empty() {
        bytemuck::cast_slice(&[[0u32; 3]])
    } else {
        bytemuck::cast_slice(&geometry.triangles)
    };
    [
        (0, "bvh nodes", bytemuck::cast_slice(&geometry.nodes)),
        (2, "vertices", bytemuck::cast_slice(&geometry.vertices)),
        (7, "primitives", primitives),
        (8, "bvh parents", bytemuck::cast_slice(&geometry.parents)),
        (12, "instances", bytemuck::cast_slice(&geometry.instances)),
        (13, "triangles", triangles),
    ]
}

/// The texture buffer: binding 5 (texels).
fn texture_contents(textures: &Textures) -> [(usize, &'static str, &[u8]); 1] {
    [(5, "texels", bytemuck::cast_slice(&textures.texels))]
}

/// The environment map's buffers: bindings 9 (texels) and 10 (distribution).
fn environment_contents(environment: &EnvironmentData) -> [(usize, &'static str, &[u8]); 2] {
    [
        (
            9,
            "environment map",
            bytemuck::cast_slice(&environment.texels),
        ),
        (
            10,
            "environment map distribution",
            bytemuck::cast_slice(&environment.distribution),
        ),
    ]
}

/// The shading buffers: bindings 1 (objects), 3 (materials), 4 (texture slots), 6
/// (lights) and 11 (parameter blocks).
fn shading_contents(shading: &Shading) -> [(usize, &'static str, &[u8]); 5] {
    [
        (1, "objects", bytemuck::cast_slice(&shading.objects)),
        (3, "materials", bytemuck::cast_slice(&shading.materials)),
        (
            4,
            "texture slots",
            bytemuck::cast_slice(&shading.texture_slots),
        ),
        (6, "lights", bytemuck::cast_slice(&shading.lights)),
        (
            11,
            "parameter blocks",
            bytemuck::cast_slice(&shading.param_blocks),
        ),
    ]
}

impl SceneBuffers {
    /// Uploads `scene`, refusing buffers over the device's binding limit.
    pub fn upload(device: &wgpu::Device, scene: &PreparedScene) -> Result<Self, RenderError> {
        if scene.geometry.nodes.len() >= MAX_NODES {
            return Err(RenderError::Limits(format!(
                "the scene's BVH has {} nodes; the traversal addresses at most {MAX_NODES}",
                scene.geometry.nodes.len()
            )));
        }
        let mut slots: Vec<Option<wgpu::Buffer>> = (0..BINDINGS).map(|_| None).collect();
        let geometry = geometry_contents(&scene.geometry);
        let textures = texture_contents(&scene.textures);
        let environment = environment_contents(&scene.environment);
        let shading = shading_contents(&scene.shading);
        for (binding, label, bytes) in geometry
            .into_iter()
            .chain(textures)
            .chain(environment)
            .chain(shading)
        {
            slots[binding] = Some(storage_buffer(device, label, bytes)?);
        }
        let buffers: Vec<wgpu::Buffer> = slots.into_iter().flatten().collect();
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("scene layout"),
            entries: &(0..BINDINGS as u32)
                .map(|i| storage_entry(i, true))
                .collect::<Vec<_>>(),
        });
        let bind_group = bind_buffers(
            device,
            "scene",
            &layout,
            &buffers.iter().collect::<Vec<_>>(),
        );
        Ok(Self {
            layout,
            bind_group,
            buffers,
        })
    }

    /// Replaces the shading buffers (a light toggle), keeping the geometry and textures.
    pub fn set_shading(
        &mut self,
        device: &wgpu::Device,
        shading: &Shading,
    ) -> Result<(), RenderError> {
        for (binding, label, bytes) in shading_contents(shading) {
            self.buffers[binding] = storage_buffer(device, label, bytes)?;
        }
        self.bind_group = bind_buffers(
            device,
            "scene",
            &self.layout,
            &self.buffers.iter().collect::<Vec<_>>(),
        );
        Ok(())
    }
}
