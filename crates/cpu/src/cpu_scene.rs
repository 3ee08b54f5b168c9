//! The prepared scene as the CPU backend reads it: the buffers the WGSL twin binds, as
//! slices, and per object what shading would otherwise recompute on every hit and light
//! sample.

use glam::{Vec3, Vec3A};
use pathlight_core::PreparedScene;
use pathlight_core::gpu_types::{
    GpuInstance, GpuLight, GpuMaterial, GpuObject, GpuPrimitive, GpuTextureSlot, GpuVertex,
    GpuWideNode, KIND_QUAD,
};

use crate::table::Table;
use crate::textures::srgb_to_linear;

/// The light table's one entry where a scene has none (never chosen: `light_count` is 0).
const NO_LIGHT: GpuLight = GpuLight {
    kind: 0,
    index: 0,
    primitive: 0,
    cdf: 0.0,
    pmf: 0.0,
};

/// A view of a [`PreparedScene`] with the buffers of bind group 0 (`scene.wgsl`) side by
/// side, and per object a quad's unit normal and area (the same values, bit for bit, as
/// computing them where they are used).
#[derive(Debug, Clone)]
pub struct CpuScene<'a> {
    /// The 4-wide BVH (WGSL `nodes`).
    pub nodes: &'a [GpuWideNode],
    /// The BVH's primitives in leaf order (WGSL `primitives`).
    pub primitives: &'a [GpuPrimitive],
    /// The meshes' vertices (WGSL `vertices`).
    pub vertices: &'a [GpuVertex],
    /// Per triangle, its corners' indices into `vertices` (WGSL `triangles`).
    pub triangles: &'a [[u32; 3]],
    /// The placements of instances (WGSL `instances`).
    pub instances: &'a [GpuInstance],
    /// Objects with their materials (WGSL `objects`).
    pub objects: &'a [GpuObject],
    /// Materials' common parts (WGSL `materials`).
    pub materials: &'a [GpuMaterial],
    /// The materials' and the point and sun lights' parameter blocks (WGSL `param_blocks`).
    pub param_blocks: &'a [[f32; 4]],
    /// The materials' texture slots (WGSL `texture_slots`).
    pub texture_slots: &'a [GpuTextureSlot],
    /// The light table (WGSL `lights`; read without bounds checks, one entry of nothing
    /// where the scene has no lights).
    pub lights: Table<'a, GpuLight>,
    /// Texels (WGSL `texels`).
    pub texels: &'a [u32],
    /// The environment map's RGB9E5 texels (WGSL `env_texels`).
    pub env_texels: Table<'a, u32>,
    /// The environment map's sampling distribution (WGSL `env_distribution`).
    pub env_distribution: Table<'a, f32>,
    /// Its CDFs' guide tables (the CPU's alone: `EnvironmentData::guides`; one zero without
    /// a map).
    pub env_guides: Table<'a, u16>,
    /// Per object: a quad's unit normal and area; zero for other kinds.
    quads: Vec<(Vec3A, f32)>,
    /// Per 8-bit code of an sRGB colour channel, its linear value (`srgb_to_linear` of
    /// the code over 255, bit for bit).
    pub srgb_linear: [f32; 256],
    /// Whether a material has a texture.
    pub textured: bool,
}

impl<'a> CpuScene<'a> {
    /// The view of `scene`.
    pub fn new(scene: &'a PreparedScene) -> Self {
        let objects = &scene.shading.objects;
        let quads = objects
            .iter()
            .map(|o| {
                if o.kind != KIND_QUAD {
                    return (Vec3A::ZERO, 0.0);
                }
                let normal = Vec3A::from_slice(&o.b).cross(Vec3A::from_slice(&o.c));
                (normal.normalize(), normal.length())
            })
            .collect();
        Self {
            nodes: &scene.geometry.nodes,
            primitives: &scene.geometry.primitives,
            vertices: &scene.geometry.vertices,
            triangles: &scene.geometry.triangles,
            instances: &scene.geometry.instances,
            objects,
            materials: &scene.shading.materials,
            param_blocks: &scene.shading.param_blocks,
            texture_slots: &scene.shading.texture_slots,
            lights: Table::new(&scene.shading.lights, &[NO_LIGHT]),
            texels: &scene.textures.texels,
            env_texels: Table::new(&scene.environment.texels, &[0]),
            env_distribution: Table::new(&scene.environment.distribution, &[0.0]),
            env_guides: Table::new(&scene.environment.guides, &[0]),
            quads,
            textured: scene.shading.materials.iter().any(|m| m.texture_mask != 0),
            srgb_linear: std::array::from_fn(|code| {
                srgb_to_linear(Vec3A::splat(code as f32 / 255.0)).x
            }),
        }
    }

    /// The unit normal of quad `object` (the direction of `edge_u x edge_v`).
    #[inline(always)]
    pub fn quad_normal(&self, object: u32) -> Vec3A {
        self.quads[object as usize].0
    }

    /// The area of quad `object`.
    #[inline(always)]
    pub fn quad_area(&self, object: u32) -> f32 {
        self.quads[object as usize].1
    }

    /// Triangle `i`'s corner positions (`i` in `triangles`).
    #[inline(always)]
    pub fn triangle(&self, i: u32) -> [Vec3; 3] {
        self.corners(i).map(|v| Vec3::from(v.position))
    }

    /// Triangle `i`'s three corners.
    #[inline(always)]
    pub fn corners(&self, i: u32) -> [GpuVertex; 3] {
        let [a, b, c] = self.triangles[i as usize];
        [
            self.vertices[a as usize],
            self.vertices[b as usize],
            self.vertices[c as usize],
        ]
    }
}
