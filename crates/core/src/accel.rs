//! Acceleration structure: one BVH over every primitive of the scene (each quad, sphere and
//! cylinder, and each triangle of every mesh), flattened into the buffers the GPU reads; the
//! binary tree is collapsed into a 4-wide one ([`crate::WideBvh`]) for both backends and
//! walked as it is by the viewer's picking ([`crate::trace`]).
//!
//! The tree is an obvhs BVH2 (PLOC build, reinsertion, SAH-driven leaf collapse). Its leaves
//! index [`GpuScene::primitives`], stored in the order of obvhs' `primitive_indices`. Meshes
//! are not instanced (their triangles are in world space), so one tree over everything is
//! as tight as two levels and sends no ray from a top-level walk into a mesh's.

use std::time::Duration;

use bytemuck::Zeroable;
use glam::{Vec3, Vec3A};
use obvhs::BvhBuildParams;
use obvhs::aabb::Aabb;
use obvhs::bvh2::builder::build_bvh2;
use rayon::prelude::*;

use crate::gpu::{
    FLAG_CAPS, FLAG_FLAT, GpuBvhNode, GpuLight, GpuMaterial, GpuObject, GpuPrimitive,
    GpuTextureInfo, GpuVertex, KIND_CYLINDER, KIND_MESH, KIND_QUAD, KIND_SPHERE, NO_LIGHT,
    NO_TRIANGLE,
};
use crate::scene::{Object, Scene, Shape, TriangleMesh};

/// The scene in the form the GPU reads it.
#[derive(Debug, Clone, Default)]
pub struct GpuScene {
    /// The binary tree over [`Self::primitives`], root at 0. Never empty (a placeholder that
    /// nothing walks when there are no primitives). The GPU reads its 4-wide form,
    /// [`crate::WideBvh`].
    pub nodes: Vec<GpuBvhNode>,
    /// Every shape and triangle, in leaf order.
    pub primitives: Vec<GpuPrimitive>,
    /// Objects in the scene's order.
    pub objects: Vec<GpuObject>,
    /// Triangle corners, three per triangle, each mesh's triangles together (in leaf
    /// order). Never empty.
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

fn node_from(node: &obvhs::bvh2::node::Bvh2Node) -> GpuBvhNode {
    GpuBvhNode {
        aabb_min: node.aabb.min.to_array(),
        pad0: 0,
        aabb_max: node.aabb.max.to_array(),
        pad1: 0,
        prim_count: node.prim_count,
        first_index: node.first_index,
        pad2: [0; 2],
    }
}

/// Build settings: obvhs' medium preset (SAH-quality PLOC with reinsertion).
fn build_params() -> BvhBuildParams {
    BvhBuildParams::medium_build()
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

/// An object's geometry; a mesh's triangle range is set by [`GpuScene::build`].
fn gpu_object(object: &Object, bounds: &Aabb) -> GpuObject {
    let mut o = GpuObject {
        material: object.material,
        light: NO_LIGHT,
        ..GpuObject::zeroed()
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
            o.a = Vec3::from(bounds.min).extend(0.0).to_array();
            o.b = Vec3::from(bounds.max).extend(0.0).to_array();
            if mesh.flat {
                o.flags |= FLAG_FLAT;
            }
        }
    }
    o
}

/// Box around triangle `t` of `mesh`.
fn triangle_bounds(mesh: &TriangleMesh, t: usize) -> Aabb {
    let [v0, v1, v2] = mesh.indices[t].map(|i| Vec3A::from(mesh.positions[i as usize]));
    Aabb {
        min: v0.min(v1).min(v2),
        max: v0.max(v1).max(v2),
    }
}

/// A primitive before the build: object `object`, and `triangle` of its mesh or
/// [`NO_TRIANGLE`] for a whole shape.
#[derive(Clone, Copy)]
struct PrimitiveRef {
    object: u32,
    triangle: u32,
}

impl GpuScene {
    /// Builds the BVH over every primitive and flattens the scene.
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
        let mut refs = Vec::new();
        let mut bounds = Vec::new();
        for (i, object) in scene.objects.iter().enumerate() {
            let object_bounds = shape_bounds(&object.shape);
            out.objects.push(gpu_object(object, &object_bounds));
            let i = i as u32;
            if let Shape::Mesh(mesh) = &object.shape {
                refs.extend((0..mesh.indices.len() as u32).map(|t| PrimitiveRef {
                    object: i,
                    triangle: t,
                }));
                bounds.par_extend(
                    (0..mesh.indices.len())
                        .into_par_iter()
                        .map(|t| triangle_bounds(mesh, t)),
                );
            } else {
                refs.push(PrimitiveRef {
                    object: i,
                    triangle: NO_TRIANGLE,
                });
                bounds.push(object_bounds);
            }
        }
        if refs.is_empty() {
            out.nodes.push(GpuBvhNode::zeroed());
        } else {
            let mut build_time = Duration::ZERO;
            let tree = build_bvh2(&bounds, build_params(), &mut build_time);
            out.nodes = tree.nodes.iter().map(node_from).collect();
            let leaf_order: Vec<PrimitiveRef> = tree
                .primitive_indices
                .iter()
                .map(|&p| refs[p as usize])
                .collect();
            out.lay_out_primitives(scene, &leaf_order);
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

    /// Fills the vertex buffer, each mesh's triangles together in the order the leaves hold
    /// them (so that a leaf's triangles lie side by side for shading too), and the
    /// primitives in leaf order. One pass numbers the triangles; both buffers are then
    /// written in parallel, each in its own order (a 1M-triangle mesh: 150 MB).
    fn lay_out_primitives(&mut self, scene: &Scene, leaf_order: &[PrimitiveRef]) {
        // Per object, the vertex-buffer triangle its next leaf-order triangle takes.
        let mut next = vec![0u32; scene.objects.len()];
        let mut total = 0u32;
        for (i, object) in scene.objects.iter().enumerate() {
            if let Shape::Mesh(mesh) = &object.shape {
                let count = mesh.indices.len() as u32;
                self.objects[i].first_triangle = total;
                self.objects[i].triangle_count = count;
                next[i] = total;
                total += count;
            }
        }
        // Per leaf, its vertex-buffer triangle; per vertex-buffer triangle, its leaf's.
        let mut held = vec![
            PrimitiveRef {
                object: 0,
                triangle: 0,
            };
            total as usize
        ];
        let slots: Vec<u32> = leaf_order
            .iter()
            .map(|p| {
                if p.triangle == NO_TRIANGLE {
                    return NO_TRIANGLE;
                }
                let slot = next[p.object as usize];
                next[p.object as usize] += 1;
                held[slot as usize] = *p;
                slot
            })
            .collect();
        let mesh_of = |p: &PrimitiveRef| match &scene.objects[p.object as usize].shape {
            Shape::Mesh(mesh) => Some(mesh),
            _ => None,
        };
        self.vertices = held
            .par_iter()
            .map(|p| {
                let Some(mesh) = mesh_of(p) else {
                    return [GpuVertex::zeroed(); 3]; // Not reached: every slot is a mesh's.
                };
                mesh.indices[p.triangle as usize].map(|v| {
                    let v = v as usize;
                    let uv = mesh.uvs.get(v).copied().unwrap_or_default();
                    GpuVertex {
                        position: mesh.positions[v].to_array(),
                        u: uv.x,
                        normal: mesh.normals.get(v).copied().unwrap_or_default().to_array(),
                        v: uv.y,
                    }
                })
            })
            .collect::<Vec<[GpuVertex; 3]>>()
            .into_flattened();
        self.primitives = leaf_order
            .par_iter()
            .zip(slots)
            .map(|(p, slot)| {
                let mut primitive = GpuPrimitive {
                    object: p.object,
                    triangle: slot,
                    ..GpuPrimitive::zeroed()
                };
                if let Some(mesh) = mesh_of(p) {
                    let corners = mesh.indices[p.triangle as usize];
                    let [v0, v1, v2] = corners.map(|v| mesh.positions[v as usize]);
                    primitive.v0 = v0.to_array();
                    primitive.e1 = (v1 - v0).to_array();
                    primitive.e2 = (v2 - v0).to_array();
                }
                primitive
            })
            .collect();
    }

    /// Surface area of light-table entry `(object, primitive)`: the whole shape, or
    /// triangle `primitive` of a mesh. Twin of WGSL `emitter_area`. Inlined into the CPU
    /// backend's row renderer, which a call would make save its vector registers.
    #[inline(always)]
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
}
