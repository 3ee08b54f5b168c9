//! Acceleration structure: a BLAS per mesh and a top level over all objects, flattened into
//! the buffers the GPU reads; the binary trees are collapsed into 4-wide ones
//! ([`crate::WideBvh`]) for both backends and walked as they are by the viewer's picking
//! ([`crate::trace`]).
//!
//! Both levels are obvhs BVH2s (PLOC build, reinsertion, SAH-driven leaf collapse), laid out
//! in one node array: the top level first (root at 0), then each BLAS with its indices
//! rebased. Leaves index primitives directly: objects and triangles are stored in the order
//! of obvhs' `primitive_indices`.

use std::time::Duration;

use bytemuck::Zeroable;
use glam::{Vec3, Vec3A};
use obvhs::BvhBuildParams;
use obvhs::aabb::Aabb;
use obvhs::bvh2::Bvh2;
use obvhs::bvh2::builder::{build_bvh2, build_bvh2_from_tris};
use obvhs::triangle::Triangle;

use crate::gpu::{
    FLAG_CAPS, FLAG_FLAT, GpuBvhNode, GpuLight, GpuMaterial, GpuObject, GpuTextureInfo, GpuVertex,
    KIND_CYLINDER, KIND_MESH, KIND_QUAD, KIND_SPHERE, NO_LIGHT,
};
use crate::scene::{Object, Scene, Shape, TriangleMesh};

/// The scene in the form the GPU reads it.
#[derive(Debug, Clone, Default)]
pub struct GpuScene {
    /// The binary trees: top level at 0, then every BLAS. Never empty (a placeholder when
    /// there are no objects). The GPU reads their 4-wide form, [`crate::WideBvh`].
    pub nodes: Vec<GpuBvhNode>,
    /// Objects in top-level leaf order.
    pub objects: Vec<GpuObject>,
    /// Triangle corners, three per triangle, in BLAS leaf order. Never empty.
    pub vertices: Vec<GpuVertex>,
    /// Materials.
    pub materials: Vec<GpuMaterial>,
    /// Texture table. Never empty.
    pub textures: Vec<GpuTextureInfo>,
    /// All texels, packed sRGB8 RGBA. Never empty.
    pub texels: Vec<u32>,
    /// Number of real objects (`objects` may hold a placeholder).
    pub object_count: u32,
    /// The light table. Never empty (a placeholder when nothing emits).
    pub lights: Vec<GpuLight>,
    /// Number of real lights (`lights` may hold a placeholder).
    pub light_count: u32,
}

fn node_from(node: &obvhs::bvh2::node::Bvh2Node, index_base: u32) -> GpuBvhNode {
    GpuBvhNode {
        aabb_min: node.aabb.min.to_array(),
        pad0: 0,
        aabb_max: node.aabb.max.to_array(),
        pad1: 0,
        prim_count: node.prim_count,
        first_index: node.first_index + index_base,
        pad2: [0; 2],
    }
}

/// Appends `bvh` to `nodes`: inner nodes rebased by the node offset, leaves by `prim_base`.
fn append_bvh(nodes: &mut Vec<GpuBvhNode>, bvh: &Bvh2, prim_base: u32) -> u32 {
    let node_base = nodes.len() as u32;
    nodes.extend(bvh.nodes.iter().map(|n| {
        let base = if n.prim_count == 0 {
            node_base
        } else {
            prim_base
        };
        node_from(n, base)
    }));
    node_base
}

/// Build settings: obvhs' medium preset (SAH-quality PLOC with reinsertion).
fn build_params() -> BvhBuildParams {
    BvhBuildParams::medium_build()
}

/// Builds the BVH of one mesh's triangles.
pub fn build_mesh_bvh(mesh: &TriangleMesh) -> Bvh2 {
    let triangles: Vec<Triangle> = mesh
        .indices
        .iter()
        .map(|t| {
            let [v0, v1, v2] = t.map(|i| Vec3A::from(mesh.positions[i as usize]));
            Triangle { v0, v1, v2 }
        })
        .collect();
    let mut build_time = Duration::ZERO;
    build_bvh2_from_tris(&triangles, build_params(), &mut build_time)
}

/// World-space bounds of an analytic shape, grown slightly so flat shapes have volume.
fn shape_bounds(shape: &Shape) -> Aabb {
    let (min, max) = match *shape {
        Shape::Quad {
            origin,
            edge_u,
            edge_v,
        } => {
            let corners = [
                origin,
                origin + edge_u,
                origin + edge_v,
                origin + edge_u + edge_v,
            ];
            let min = corners.iter().copied().reduce(Vec3::min).unwrap_or(origin);
            let max = corners.iter().copied().reduce(Vec3::max).unwrap_or(origin);
            (min, max)
        }
        Shape::Sphere { center, radius, .. } => (center - radius, center + radius),
        Shape::Cylinder { p0, p1, radius, .. } => {
            // Bounds of the two end disks: per axis, radius * sqrt(1 - axis_i^2).
            let axis = (p1 - p0).normalize();
            let extent = radius * (Vec3::ONE - axis * axis).max(Vec3::ZERO).powf(0.5);
            (p0.min(p1) - extent, p0.max(p1) + extent)
        }
        Shape::Mesh(ref mesh) => {
            let min = mesh.positions.iter().copied().fold(Vec3::MAX, Vec3::min);
            let max = mesh.positions.iter().copied().fold(Vec3::MIN, Vec3::max);
            (min, max)
        }
    };
    let pad = (max - min).max_element() * 1e-5 + 1e-6;
    Aabb {
        min: Vec3A::from(min - pad),
        max: Vec3A::from(max + pad),
    }
}

fn gpu_material(m: &crate::scene::Material) -> GpuMaterial {
    let conductor = m.conductor.unwrap_or(crate::scene::Conductor {
        eta: Vec3::ONE,
        k: Vec3::ZERO,
    });
    GpuMaterial {
        base_color: m.base_color.to_array(),
        texture: m.texture.map_or(-1, |t| t as i32),
        emission: m.emission.to_array(),
        specular_rate: m.lobes.specular_rate,
        eta: conductor.eta.to_array(),
        specular_tint: m.lobes.specular_tint,
        k: conductor.k.to_array(),
        specular_roughness: m.lobes.specular_roughness,
        refract_rate: m.lobes.refract_rate,
        refract_tint: m.lobes.refract_tint,
        ior: m.lobes.ior,
        refract_roughness: m.lobes.refract_roughness,
        conductor: u32::from(m.conductor.is_some()),
        pad: [0; 3],
    }
}

/// Geometry of an object without its mesh part.
fn gpu_object(object: &Object, id: u32) -> GpuObject {
    let mut o = GpuObject {
        a: [0.0; 4],
        b: [0.0; 4],
        c: [0.0; 4],
        kind: 0,
        material: object.material,
        blas_root: 0,
        id,
        flags: 0,
        light: NO_LIGHT,
        first_triangle: 0,
        triangle_count: 0,
    };
    match object.shape {
        Shape::Quad {
            origin,
            edge_u,
            edge_v,
        } => {
            o.kind = KIND_QUAD;
            o.a = origin.extend(0.0).to_array();
            o.b = edge_u.extend(0.0).to_array();
            o.c = edge_v.extend(0.0).to_array();
        }
        Shape::Sphere {
            center,
            radius,
            texture_rotation,
        } => {
            o.kind = KIND_SPHERE;
            o.a = center.extend(radius).to_array();
            o.b = [texture_rotation, 0.0, 0.0, 0.0];
        }
        Shape::Cylinder {
            p0,
            p1,
            radius,
            caps,
        } => {
            o.kind = KIND_CYLINDER;
            o.a = p0.extend(radius).to_array();
            o.b = p1.extend(0.0).to_array();
            if caps {
                o.flags |= FLAG_CAPS;
            }
        }
        Shape::Mesh(ref mesh) => {
            o.kind = KIND_MESH;
            if mesh.flat {
                o.flags |= FLAG_FLAT;
            }
        }
    }
    o
}

impl GpuScene {
    /// Builds both BVH levels and flattens the scene.
    pub fn build(scene: &Scene) -> Self {
        let mut out = GpuScene {
            materials: scene.materials.iter().map(gpu_material).collect(),
            object_count: scene.objects.len() as u32,
            ..Default::default()
        };
        for texture in &scene.textures {
            out.textures.push(GpuTextureInfo {
                offset: out.texels.len() as u32,
                width: texture.width,
                height: texture.height,
                pad: 0,
            });
            out.texels.extend_from_slice(&texture.texels);
        }
        let bounds: Vec<Aabb> = scene
            .objects
            .iter()
            .map(|o| shape_bounds(&o.shape))
            .collect();
        if bounds.is_empty() {
            out.nodes.push(GpuBvhNode::zeroed());
        } else {
            let mut build_time = Duration::ZERO;
            let top = build_bvh2(&bounds, build_params(), &mut build_time);
            append_bvh(&mut out.nodes, &top, 0);
            for &id in &top.primitive_indices {
                let object = &scene.objects[id as usize];
                let mut gpu = gpu_object(object, id);
                if let Shape::Mesh(mesh) = &object.shape {
                    gpu.first_triangle = (out.vertices.len() / 3) as u32;
                    gpu.blas_root = out.append_mesh(mesh);
                    gpu.triangle_count = (out.vertices.len() / 3) as u32 - gpu.first_triangle;
                }
                out.objects.push(gpu);
            }
        }
        out.build_lights();
        if out.objects.is_empty() {
            out.objects.push(GpuObject::zeroed());
        }
        if out.vertices.is_empty() {
            out.vertices.push(GpuVertex::zeroed());
        }
        if out.textures.is_empty() {
            out.textures.push(GpuTextureInfo::zeroed());
        }
        if out.texels.is_empty() {
            out.texels.push(0);
        }
        if out.materials.is_empty() {
            out.materials.push(GpuMaterial::zeroed());
        }
        if out.lights.is_empty() {
            out.lights.push(GpuLight::zeroed());
        }
        out
    }

    /// Surface area of light-table entry `(object, primitive)`: the whole shape, or
    /// triangle `primitive` of a mesh. Twin of WGSL `emitter_area`.
    pub fn emitter_area(&self, object: &GpuObject, primitive: u32) -> f32 {
        let [a, b, c] = [object.a, object.b, object.c].map(|v| Vec3::from_slice(&v));
        match object.kind {
            KIND_QUAD => b.cross(c).length(),
            KIND_SPHERE => 4.0 * std::f32::consts::PI * object.a[3] * object.a[3],
            KIND_CYLINDER => {
                let r = object.a[3];
                let caps = if object.flags & FLAG_CAPS != 0 {
                    2.0
                } else {
                    0.0
                };
                std::f32::consts::TAU * r * (b - a).length() + caps * std::f32::consts::PI * r * r
            }
            _ => {
                let [v0, v1, v2] = self.triangle(primitive);
                0.5 * (v1 - v0).cross(v2 - v0).length()
            }
        }
    }

    /// Fills the light table from the emissive objects (power = area x luminance) and
    /// points each emissive object at its entries. Rebuild it after changing emission.
    pub fn build_lights(&mut self) {
        self.lights.clear();
        let mut powers = Vec::new();
        for i in 0..self.object_count as usize {
            let object = self.objects[i];
            let e = Vec3::from(self.materials[object.material as usize].emission);
            let luminance = e
                .dot(Vec3::new(0.2126, 0.7152, 0.0722))
                .max(e.max_element() * 1e-3);
            self.objects[i].light = NO_LIGHT;
            if luminance <= 0.0 {
                continue;
            }
            let primitives = if object.kind == KIND_MESH {
                object.first_triangle..object.first_triangle + object.triangle_count
            } else {
                0..1
            };
            let first = self.lights.len() as u32;
            for primitive in primitives {
                powers.push(self.emitter_area(&object, primitive) * luminance);
                self.lights.push(GpuLight {
                    object: i as u32,
                    primitive,
                    cdf: 0.0,
                    pmf: 0.0,
                });
            }
            self.objects[i].light = first;
        }
        let total: f64 = powers.iter().map(|&p| f64::from(p)).sum();
        if total <= 0.0 || !total.is_finite() {
            // Only zero-area emitters: nothing can be sampled (or hit).
            self.lights.clear();
            self.objects.iter_mut().for_each(|o| o.light = NO_LIGHT);
        }
        let mut running = 0.0f64;
        for (light, power) in self.lights.iter_mut().zip(&powers) {
            running += f64::from(*power);
            light.pmf = (f64::from(*power) / total) as f32;
            light.cdf = (running / total) as f32;
        }
        if let Some(last) = self.lights.last_mut() {
            last.cdf = 1.0;
        }
        self.light_count = self.lights.len() as u32;
        if self.lights.is_empty() {
            self.lights.push(GpuLight::zeroed());
        }
    }

    /// Appends a mesh's BLAS and triangles; returns the BLAS root's node index.
    fn append_mesh(&mut self, mesh: &TriangleMesh) -> u32 {
        let bvh = build_mesh_bvh(mesh);
        let triangle_base = (self.vertices.len() / 3) as u32;
        let root = append_bvh(&mut self.nodes, &bvh, triangle_base);
        for &t in &bvh.primitive_indices {
            for i in mesh.indices[t as usize] {
                let i = i as usize;
                let uv = mesh.uvs.get(i).copied().unwrap_or_default();
                self.vertices.push(GpuVertex {
                    position: mesh.positions[i].to_array(),
                    u: uv.x,
                    normal: mesh.normals.get(i).copied().unwrap_or_default().to_array(),
                    v: uv.y,
                });
            }
        }
        root
    }
}
