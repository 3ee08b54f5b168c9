//! The scene's shapes as the backends trace them, built once per scene: every quad, sphere
//! and cylinder, every triangle of every world-space mesh and every placement of a shared
//! mesh as one primitive of the top-level BVH ([`crate::bvh`]); each shared mesh's triangles
//! in a tree of their own, in the mesh's space, which a ray entering a placement walks; the
//! primitives in leaf order, the meshes' vertices and their triangles' corner indices.
//!
//! A mesh placed once is in world space among the top level's primitives: one tree over
//! it is tighter than two levels and sends no ray from a top-level walk into a mesh's.

use std::collections::HashMap;
use std::sync::Arc;
use std::time::{Duration, Instant};

use bytemuck::Zeroable;
use glam::{Affine3A, Mat4, Vec3, Vec3A, Vec4};
use obvhs::aabb::Aabb;
use pathlight_scene::settings::MAX_COORDINATE;
use pathlight_scene::texture::linear_to_srgb;
use pathlight_scene::{Instance, Object, Shape, TriangleMesh};
use rayon::prelude::*;

use crate::bvh;
use crate::error::GeometryError;
use crate::gpu_types::{
    FLAG_CAPS, FLAG_FLAT, FLAG_INSTANCE, FLAG_MIRRORED, GpuInstance, GpuObject, GpuPrimitive,
    GpuVertex, GpuWideNode, INSTANCE, KIND_CYLINDER, KIND_MESH, KIND_QUAD, KIND_SPHERE, NO_LIGHT,
    NO_TRIANGLE, WHITE,
};
use crate::octahedral;

/// The traced form of a scene's objects. It does not depend on materials, lights or the
/// camera, so it is built once and shared (both backends read it, and a light toggle or a
/// camera move keeps it).
#[derive(Debug, Clone)]
pub struct Geometry {
    /// The 4-wide BVH over [`Self::primitives`], root at 0. Never empty (a node that no ray
    /// enters when there are no primitives).
    pub nodes: Vec<GpuWideNode>,
    /// Every shape and triangle, in leaf order.
    pub primitives: Vec<GpuPrimitive>,
    /// The meshes' vertices, each mesh's together in the order its triangles (in
    /// [`Self::triangles`]) first name them: one per vertex a triangle names of a mesh
    /// without tangents, one per triangle corner of a mesh with them (its tangents are a
    /// corner's). Never empty.
    pub vertices: Vec<GpuVertex>,
    /// Per triangle, its corners' indices into [`Self::vertices`], each mesh's triangles
    /// together, in the order its leaves hold them (a triangle's index here is
    /// [`GpuPrimitive::triangle`]).
    pub triangles: Vec<[u32; 3]>,
    /// Per object (the scene's order): its shape, with material 0 and no light (the
    /// materials and the light table are [`crate::Shading`]'s).
    pub shapes: Vec<GpuObject>,
    /// The placements of the instances among [`Self::shapes`]. Never empty (a placeholder
    /// keeps the buffer bindable).
    pub instances: Vec<GpuInstance>,
    /// Per node, its parent and lane ([`bvh::parents`]).
    pub parents: Vec<u32>,
    /// Most entries the GPU's traversal stack needs to finish every walk without climbing
    /// [`Self::parents`] ([`bvh::stack_bound`]).
    pub stack_bound: u32,
    /// How long the build took.
    pub build_time: Duration,
}

/// A primitive before the build: object `object`, and `triangle` of its mesh or
/// [`NO_TRIANGLE`] for a whole shape.
#[derive(Clone, Copy)]
struct PrimitiveRef {
    object: u32,
    triangle: u32,
}

impl Geometry {
    /// Builds the BVH over every primitive of `objects` and flattens them; refuses
    /// geometry that is not finite or beyond the coordinate limit. Each shared mesh (the
    /// meshes of [`Shape::Instance`]s) gets a tree of its own, built once in its own space;
    /// its placements are primitives of the top-level tree, whose walk enters the mesh's.
    pub fn build(objects: &[Object]) -> Result<Self, GeometryError> {
        Self::build_in(objects, bvh::Chunks::DEFAULT)
    }

    /// [`Self::build`], each tree built in `chunks` ([`bvh::build`]).
    fn build_in(objects: &[Object], chunks: bvh::Chunks) -> Result<Self, GeometryError> {
        let shared = SharedMeshes::of(objects);
        for (k, mesh) in shared.meshes.iter().enumerate() {
            let first = shared.placed_by[k];
            check_mesh(mesh).map_err(|message| GeometryError {
                object: objects[first as usize].name.clone(),
                message: format!("its mesh: {message}"),
            })?;
        }
        for object in objects {
            check_shape(&object.shape).map_err(|message| GeometryError {
                object: object.name.clone(),
                message,
            })?;
        }
        let started = Instant::now();
        let mut shapes = Vec::with_capacity(objects.len());
        let mut instances = Vec::new();
        let mut refs = Vec::new();
        let mut object_bounds = Vec::with_capacity(objects.len());
        for (i, object) in objects.iter().enumerate() {
            let bounds = shape_bounds(&object.shape);
            let mut shape = gpu_shape(&object.shape, &bounds);
            let i = i as u32;
            match &object.shape {
                Shape::Mesh(mesh) => {
                    refs.extend((0..mesh.indices.len() as u32).map(|t| PrimitiveRef {
                        object: i,
                        triangle: t,
                    }));
                }
                Shape::Instance(instance) => {
                    shape.instance = instances.len() as u32;
                    instances.push(gpu_instance(instance));
                    if !instance.mesh.indices.is_empty() {
                        refs.push(PrimitiveRef {
                            object: i,
                            triangle: INSTANCE,
                        });
                    }
                }
                _ => {
                    refs.push(PrimitiveRef {
                        object: i,
                        triangle: NO_TRIANGLE,
                    });
                }
            }
            object_bounds.push(bounds);
            shapes.push(shape);
        }
        let mut out = Geometry {
            nodes: Vec::new(),
            primitives: Vec::new(),
            vertices: Vec::new(),
            triangles: Vec::new(),
            shapes,
            instances,
            parents: vec![bvh::NO_PARENT],
            stack_bound: 1,
            build_time: Duration::ZERO,
        };
        if refs.is_empty() {
            out.nodes = bvh::empty_tree();
        } else {
            let bound_of = |p: u32| {
                let r = refs[p as usize];
                match &objects[r.object as usize].shape {
                    Shape::Mesh(mesh) => triangle_bounds(mesh, r.triangle as usize),
                    _ => object_bounds[r.object as usize],
                }
            };
            let is_shape = |p: u32| {
                let t = refs[p as usize].triangle;
                t == NO_TRIANGLE || t == INSTANCE
            };
            let (_, order) =
                bvh::build(refs.len(), &bound_of, &is_shape, 0, chunks, &mut out.nodes);
            let leaf_order: Vec<PrimitiveRef> =
                order.into_iter().map(|p| refs[p as usize]).collect();
            drop(refs);
            out.lay_out_primitives(objects, &leaf_order);
            drop(leaf_order);
            // Each shared mesh's tree after the top level's, and its primitives and
            // triangles after the top level's.
            let mut mesh_roots = Vec::with_capacity(shared.meshes.len());
            for (k, mesh) in shared.meshes.iter().enumerate() {
                let root = out.lay_out_shared_mesh(mesh, shared.placed_by[k], chunks);
                mesh_roots.push(root);
            }
            for p in out.primitives.iter_mut().filter(|p| p.triangle == INSTANCE) {
                let mesh = shared.mesh_of[p.object as usize] as usize;
                p.root = mesh_roots[mesh].map_or(0, |(root, _)| root);
            }
            for (i, shape) in out.shapes.iter_mut().enumerate() {
                let mesh = shared.mesh_of[i];
                if let Some((_, first)) = mesh_roots.get(mesh as usize).copied().flatten() {
                    shape.first_triangle = first;
                    shape.triangle_count = shared.meshes[mesh as usize].indices.len() as u32;
                }
            }
            out.parents = bvh::parents(&out.nodes);
            out.stack_bound = bvh::stack_bound(&out.nodes, &out.primitives);
        }
        if out.vertices.is_empty() {
            out.vertices.push(GpuVertex::zeroed());
        }
        if out.instances.is_empty() {
            out.instances.push(GpuInstance::zeroed());
        }
        out.build_time = started.elapsed();
        Ok(out)
    }

    /// Triangle `i`'s corner positions (`i` in [`Self::triangles`]).
    #[inline(always)]
    pub fn triangle(&self, i: u32) -> [Vec3; 3] {
        self.triangles[i as usize].map(|v| Vec3::from(self.vertices[v as usize].position))
    }

    /// Radius of the sphere around the box that holds every primitive (0 without any): how
    /// far a sun's light reaches across the scene.
    pub fn bounding_radius(&self) -> f32 {
        let root = &self.nodes[0];
        let (mut lo, mut hi) = (Vec3::MAX, Vec3::MIN);
        for lane in 0..4 {
            let (l, h) = (
                Vec3::new(root.lo_x[lane], root.lo_y[lane], root.lo_z[lane]),
                Vec3::new(root.hi_x[lane], root.hi_y[lane], root.hi_z[lane]),
            );
            if l.cmple(h).all() {
                (lo, hi) = (lo.min(l), hi.max(h));
            }
        }
        if lo.cmple(hi).all() {
            0.5 * (hi - lo).length()
        } else {
            0.0
        }
    }

    /// Number of triangles the scene keeps (a shared mesh's once).
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// Whether any object is a placed instance of a shared mesh.
    pub fn has_instances(&self) -> bool {
        self.shapes.iter().any(|s| s.flags & FLAG_INSTANCE != 0)
    }

    /// Number of triangles the scene shows (a shared mesh's once per placement).
    pub fn placed_triangle_count(&self) -> usize {
        self.shapes.iter().map(|s| s.triangle_count as usize).sum()
    }

    /// Fills the triangles (each mesh's together, in the order the leaves hold them, so
    /// that a leaf's triangles lie side by side for shading too), the vertex buffer (each
    /// mesh's vertices in the order its triangles first name them, [`Self::push_mesh`]) and
    /// the primitives in leaf order. One pass numbers the triangles; the buffers are then
    /// written each to its exact size (a 1M-triangle mesh without tangents: 16 MB of
    /// vertices, 12 MB of triangles, 48 MB of primitives).
    fn lay_out_primitives(&mut self, objects: &[Object], leaf_order: &[PrimitiveRef]) {
        // Per object, the triangle its next leaf-order triangle takes.
        let mut next = vec![0u32; objects.len()];
        let mut total = 0u32;
        for (i, object) in objects.iter().enumerate() {
            if let Shape::Mesh(mesh) = &object.shape {
                let count = mesh.indices.len() as u32;
                self.shapes[i].first_triangle = total;
                self.shapes[i].triangle_count = count;
                next[i] = total;
                total += count;
            }
        }
        // Per triangle, its mesh's triangle; per leaf, its triangle.
        let mut held = vec![0u32; total as usize];
        let slots: Vec<u32> = leaf_order
            .iter()
            .map(|p| {
                if p.triangle == NO_TRIANGLE || p.triangle == INSTANCE {
                    return p.triangle;
                }
                let slot = next[p.object as usize];
                next[p.object as usize] += 1;
                held[slot as usize] = p.triangle;
                slot
            })
            .collect();
        self.triangles.reserve_exact(total as usize);
        for (i, object) in objects.iter().enumerate() {
            if let Shape::Mesh(mesh) = &object.shape {
                let first = self.shapes[i].first_triangle as usize;
                self.push_mesh(mesh, &held[first..first + mesh.indices.len()]);
            }
        }
        drop(held);
        let mesh_of = |p: &PrimitiveRef| match &objects[p.object as usize].shape {
            Shape::Mesh(mesh) => Some(mesh),
            _ => None,
        };
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
                    primitive.v1 = v1.to_array();
                    primitive.v2 = v2.to_array();
                }
                primitive
            })
            .collect();
    }
}

impl Geometry {
    /// Appends the tree of shared mesh `mesh` (its triangles in its own space) to the nodes,
    /// its triangles in leaf order to the primitives and the vertex buffer (the primitives
    /// naming `object`, its first placement); returns its root node and its first triangle
    /// in the vertex buffer, `None` for a mesh without triangles.
    fn lay_out_shared_mesh(
        &mut self,
        mesh: &TriangleMesh,
        object: u32,
        chunks: bvh::Chunks,
    ) -> Option<(u32, u32)> {
        if mesh.indices.is_empty() {
            return None;
        }
        let first_primitive = self.primitives.len() as u32;
        let (root, order) = bvh::build(
            mesh.indices.len(),
            &|t| triangle_bounds(mesh, t as usize),
            &|_| false,
            first_primitive,
            chunks,
            &mut self.nodes,
        );
        let first_triangle = self.triangles.len() as u32;
        self.push_mesh(mesh, &order);
        self.primitives
            .par_extend(order.par_iter().enumerate().map(|(slot, &t)| {
                let [v0, v1, v2] =
                    mesh.indices[t as usize].map(|v| mesh.positions[v as usize].to_array());
                GpuPrimitive {
                    v0,
                    object,
                    v1,
                    triangle: first_triangle + slot as u32,
                    v2,
                    root: 0,
                }
            }));
        Some((root, first_triangle))
    }

    /// Appends triangles `order` of `mesh` (in that order) to the triangles and their
    /// vertices to the vertex buffer: each vertex once, numbered as the triangles first name
    /// it (so that the corners of a leaf's triangles lie close together, as its triangles
    /// do), or for a mesh with tangents (one a corner) three vertices a triangle.
    fn push_mesh(&mut self, mesh: &TriangleMesh, order: &[u32]) {
        let first = self.vertices.len() as u32;
        if !mesh.tangents.is_empty() {
            self.vertices
                .par_extend((0..3 * order.len()).into_par_iter().map(|c| {
                    let corner = 3 * order[c / 3] as usize + c % 3;
                    let t = mesh.tangents[corner];
                    let tangent = octahedral::encode_tangent(t.truncate(), t.w);
                    gpu_vertex(mesh, mesh.indices[corner / 3][corner % 3], tangent)
                }));
            self.triangles
                .extend((0..order.len() as u32).map(|s| [0, 1, 2].map(|k| first + 3 * s + k)));
            return;
        }
        // Per vertex of the mesh, its number here; per number, the mesh's vertex.
        let mut number = vec![u32::MAX; mesh.positions.len()];
        let mut named = Vec::with_capacity(mesh.positions.len());
        for &t in order {
            let corners = mesh.indices[t as usize].map(|v| {
                let n = &mut number[v as usize];
                if *n == u32::MAX {
                    *n = named.len() as u32;
                    named.push(v);
                }
                first + *n
            });
            self.triangles.push(corners);
        }
        drop(number);
        self.vertices.par_extend(
            named
                .par_iter()
                .map(|&v| gpu_vertex(mesh, v, octahedral::ZERO)),
        );
    }
}

/// The meshes that [`Shape::Instance`]s share, each once (in the order of their first
/// placement), and per object the one it places.
struct SharedMeshes<'a> {
    meshes: Vec<&'a TriangleMesh>,
    /// Per shared mesh, the first object that places it.
    placed_by: Vec<u32>,
    /// Per object, its shared mesh, or `u32::MAX` for one that is not an instance.
    mesh_of: Vec<u32>,
}

impl<'a> SharedMeshes<'a> {
    fn of(objects: &'a [Object]) -> Self {
        let mut index: HashMap<*const TriangleMesh, u32> = HashMap::new();
        let mut out = Self {
            meshes: Vec::new(),
            placed_by: Vec::new(),
            mesh_of: vec![u32::MAX; objects.len()],
        };
        for (i, object) in objects.iter().enumerate() {
            if let Shape::Instance(instance) = &object.shape {
                let next = out.meshes.len() as u32;
                let k = *index.entry(Arc::as_ptr(&instance.mesh)).or_insert(next);
                if k == next {
                    out.meshes.push(&instance.mesh);
                    out.placed_by.push(i as u32);
                }
                out.mesh_of[i] = k;
            }
        }
        out
    }
}

/// The placement of `instance` as the backends read it.
fn gpu_instance(instance: &Instance) -> GpuInstance {
    let rows = |m: Affine3A| {
        let m = Mat4::from(m).transpose();
        [m.x_axis, m.y_axis, m.z_axis].map(|r| r.to_array())
    };
    GpuInstance {
        to_object: rows(instance.to_world.inverse()),
        to_world: rows(instance.to_world),
    }
}

/// Why `shape` cannot be built, if it cannot: a value not finite or beyond
/// [`MAX_COORDINATE`].
fn check_shape(shape: &Shape) -> Result<(), String> {
    let point = |what: &str, p: Vec3| {
        if p.abs().cmple(Vec3::splat(MAX_COORDINATE)).all() {
            Ok(())
        } else {
            Err(format!(
                "{what} {p} is not finite or beyond +-{MAX_COORDINATE:e}"
            ))
        }
    };
    let length = |what: &str, r: f32| {
        if r > 0.0 && r <= MAX_COORDINATE {
            Ok(())
        } else {
            Err(format!("{what} {r} is not in (0, {MAX_COORDINATE:e}]"))
        }
    };
    match shape {
        Shape::Quad {
            origin,
            edge_u,
            edge_v,
        } => {
            point("origin", *origin)?;
            point("edge_u", *edge_u)?;
            point("edge_v", *edge_v)
        }
        Shape::Sphere {
            center,
            radius,
            texture_rotation,
        } => {
            point("center", *center)?;
            length("radius", *radius)?;
            if texture_rotation.is_finite() {
                Ok(())
            } else {
                Err(format!("texture rotation {texture_rotation} is not finite"))
            }
        }
        Shape::Cylinder { p0, p1, radius, .. } => {
            point("p0", *p0)?;
            point("p1", *p1)?;
            length("radius", *radius)?;
            if p0 == p1 {
                return Err("its axis has no length (p0 = p1)".into());
            }
            Ok(())
        }
        Shape::Mesh(mesh) => check_mesh(mesh),
        Shape::Instance(instance) => {
            // Its mesh is checked once, with the other placements' (`Geometry::build`).
            if !instance.to_world.is_finite() {
                return Err("its placement is not finite".into());
            }
            if instance.mesh.indices.is_empty() {
                return Ok(());
            }
            let (min, max) = instance.bounds();
            point("its placed box's corner", min)?;
            point("its placed box's corner", max)
        }
    }
}

/// Why `mesh` cannot be built, if it cannot: a vertex not finite or beyond
/// [`MAX_COORDINATE`], a triangle naming a vertex it does not have, tangents not one a
/// triangle corner.
fn check_mesh(mesh: &TriangleMesh) -> Result<(), String> {
    let limit = Vec3::splat(MAX_COORDINATE);
    if let Some(i) = mesh
        .positions
        .par_iter()
        .position_first(|p| !p.abs().cmple(limit).all())
    {
        let p = mesh.positions[i];
        return Err(format!(
            "vertex {i} {p} is not finite or beyond +-{MAX_COORDINATE:e}"
        ));
    }
    if !mesh.tangents.is_empty() && mesh.tangents.len() != 3 * mesh.indices.len() {
        return Err(format!(
            "it has {} tangents for {} triangle corners",
            mesh.tangents.len(),
            3 * mesh.indices.len()
        ));
    }
    let count = mesh.positions.len() as u32;
    match mesh
        .indices
        .par_iter()
        .position_first(|t| t.iter().any(|&i| i >= count))
    {
        Some(t) => Err(format!(
            "triangle {t} names vertex {:?}; the mesh has {count}",
            mesh.indices[t]
        )),
        None => Ok(()),
    }
}

/// World-space bounds of a shape, grown slightly so flat shapes have volume.
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
        Shape::Mesh(ref mesh) => mesh.bounds(),
        Shape::Instance(ref instance) if !instance.mesh.indices.is_empty() => instance.bounds(),
        Shape::Instance(_) => (Vec3::ZERO, Vec3::ZERO),
    };
    let pad = (max - min).max_element() * 1e-5 + 1e-6;
    Aabb {
        min: Vec3A::from(min - pad),
        max: Vec3A::from(max + pad),
    }
}

/// An object's shape; a mesh's triangle range is set by [`Geometry::lay_out_primitives`].
fn gpu_shape(shape: &Shape, bounds: &Aabb) -> GpuObject {
    let mut o = GpuObject {
        light: NO_LIGHT,
        ..GpuObject::zeroed()
    };
    match *shape {
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
        Shape::Instance(ref instance) => {
            o.kind = KIND_MESH;
            o.a = Vec3::from(bounds.min).extend(0.0).to_array();
            o.b = Vec3::from(bounds.max).extend(0.0).to_array();
            o.flags |= FLAG_INSTANCE;
            if instance.mesh.flat {
                o.flags |= FLAG_FLAT;
            }
            if instance.to_world.matrix3.determinant() < 0.0 {
                o.flags |= FLAG_MIRRORED;
            }
        }
    }
    o
}

/// Vertex `v` of `mesh` as the vertex buffer holds it, with tangent code `tangent`.
fn gpu_vertex(mesh: &TriangleMesh, v: u32, tangent: u32) -> GpuVertex {
    let v = v as usize;
    GpuVertex {
        position: mesh.positions[v].to_array(),
        normal: octahedral::encode(mesh.normals.get(v).copied().unwrap_or_default()),
        uv: mesh.uvs.get(v).copied().unwrap_or_default().to_array(),
        tangent,
        color: mesh.colors.get(v).map_or(WHITE, |&c| pack_color(c)),
    }
}

/// Box around triangle `t` of `mesh`.
fn triangle_bounds(mesh: &TriangleMesh, t: usize) -> Aabb {
    let [v0, v1, v2] = mesh.indices[t].map(|i| Vec3A::from(mesh.positions[i as usize]));
    Aabb {
        min: v0.min(v1).min(v2),
        max: v0.max(v1).max(v2),
    }
}

/// Linear RGBA `c` (clamped to [0, 1]) as [`GpuVertex::color`]: the colour channels
/// sRGB-encoded, so that 8 bits keep dark colours apart.
fn pack_color(c: Vec4) -> u32 {
    let byte = |x: f32| (x.clamp(0.0, 1.0) * 255.0).round() as u8;
    let srgb = |x: f32| byte(linear_to_srgb(x.clamp(0.0, 1.0)));
    u32::from_le_bytes([srgb(c.x), srgb(c.y), srgb(c.z), byte(c.w)])
}

#[cfg(test)]
mod tests {
    use glam::Vec3;
    use pathlight_scene::testing::{
        coincident_triangles, degenerate_objects, icosphere, instances_of, mesh_of, object,
        random_mesh, random_objects, random_placements, scene_of,
    };
    use pathlight_scene::{Object, Shape};
    use rand::SeedableRng;
    use rand::rngs::StdRng;

    use super::Geometry;
    use crate::bvh::{self, lane_used};
    use crate::gpu_types::{
        FLAG_INSTANCE, FLAG_MIRRORED, GpuInstance, GpuObject, GpuPrimitive, GpuVertex, GpuWideNode,
        INSTANCE, KIND_MESH, NO_TRIANGLE, SHAPE_LEAF,
    };

    #[test]
    fn a_triangle_keeps_its_primitive_its_corner_indices_and_a_share_of_vertices_and_tree() {
        // The buffers the backends keep per triangle of a closed mesh without tangents
        // (BENCHMARKS.md, "Where a million triangles' memory goes"): a 48-byte primitive,
        // three corner indices (12 bytes), a share of the 32-byte vertices (about half a
        // vertex a triangle), of the 4-wide nodes (128 bytes each) and of their parent
        // entries (4 bytes). The build's peak comes before and is not counted here.
        let mesh = pathlight_scene::testing::torus(1.0, 0.3, 200, 100);
        let (triangles, vertices) = (mesh.indices.len(), mesh.positions.len());
        let g = Geometry::build(&[object("torus", Shape::Mesh(mesh))]).unwrap();
        assert_eq!(
            g.vertices.len(),
            vertices,
            "one vertex buffer entry a vertex"
        );
        assert_eq!(g.triangles.len(), triangles);
        assert_eq!(g.primitives.len(), triangles);
        let tree = g.nodes.len() * size_of::<GpuWideNode>() + g.parents.len() * 4;
        let per_triangle = |bytes: usize| bytes as f64 / triangles as f64;
        let kept = per_triangle(
            tree + g.primitives.len() * size_of::<GpuPrimitive>()
                + g.triangles.len() * 12
                + g.vertices.len() * size_of::<GpuVertex>(),
        );
        // Measured: 15.6 bytes of tree, 91.6 in all, for this 40,000-triangle torus.
        assert!(
            per_triangle(tree) < 24.0,
            "tree {:.1} B a triangle",
            per_triangle(tree)
        );
        assert!((84.0..100.0).contains(&kept), "{kept:.1} B a triangle");
    }

    /// A mesh with tangents (one a triangle corner) keeps a vertex a corner, each with its
    /// corner's tangent; the triangles name their own three.
    #[test]
    fn a_mesh_with_tangents_keeps_a_vertex_a_corner() {
        let mut mesh = pathlight_scene::testing::torus(1.0, 0.3, 8, 6);
        let corners = 3 * mesh.indices.len();
        mesh.tangents = (0..corners)
            .map(|c| {
                let angle = c as f32 * 0.37;
                glam::Vec4::new(
                    angle.cos(),
                    angle.sin(),
                    0.0,
                    if c % 2 == 0 { 1.0 } else { -1.0 },
                )
            })
            .collect();
        let g = Geometry::build(&[object("torus", Shape::Mesh(mesh.clone()))]).unwrap();
        validate(&g);
        assert_eq!(g.vertices.len(), corners);
        for (slot, p) in g.primitives.iter().enumerate() {
            // The torus is one mesh: its leaf order is the primitives' order.
            let tri = p.triangle as usize;
            assert_eq!(tri, slot);
            let original = mesh
                .indices
                .iter()
                .position(|t| {
                    t.map(|v| mesh.positions[v as usize].to_array()) == [p.v0, p.v1, p.v2]
                })
                .expect("a triangle of the mesh");
            for k in 0..3 {
                let v = g.vertices[g.triangles[tri][k] as usize];
                let t = mesh.tangents[3 * original + k];
                assert_eq!(
                    v.tangent,
                    crate::octahedral::encode_tangent(t.truncate(), t.w),
                    "triangle {original} corner {k}"
                );
            }
        }
    }

    /// Whether box `lane` of `node` holds the box from `min` to `max` (with a margin).
    fn contains(node: &GpuWideNode, lane: usize, min: Vec3, max: Vec3) -> bool {
        let lo = Vec3::new(node.lo_x[lane], node.lo_y[lane], node.lo_z[lane]);
        let hi = Vec3::new(node.hi_x[lane], node.hi_y[lane], node.hi_z[lane]);
        lo.cmple(min + 1e-4).all() && hi.cmpge(max - 1e-4).all()
    }

    /// The box around the used lanes of node `index`.
    fn node_bounds(g: &Geometry, index: u32) -> (Vec3, Vec3) {
        let n = &g.nodes[index as usize];
        (0..4).filter(|&lane| lane_used(n, lane)).fold(
            (Vec3::MAX, Vec3::MIN),
            |(min, max), lane| {
                let lo = Vec3::new(n.lo_x[lane], n.lo_y[lane], n.lo_z[lane]);
                let hi = Vec3::new(n.hi_x[lane], n.hi_y[lane], n.hi_z[lane]);
                (min.min(lo), max.max(hi))
            },
        )
    }

    /// Every child box holds its node's or its leaf's contents; every node is reached once
    /// (a shared mesh's tree from its placements' primitives); every primitive is in exactly
    /// one leaf, marked SHAPE_LEAF exactly when it holds a shape or an instance; every shape,
    /// every placement and every mesh triangle (a shared mesh's once) is exactly one
    /// primitive, a triangle one with the vertex buffer's corners and its mesh's triangle
    /// range.
    fn validate(g: &Geometry) {
        let mut seen = Vec::new();
        let mut nodes_seen = vec![0u32; g.nodes.len()];
        // Trees to walk: the top level's, then each shared mesh's (with a placing object).
        let mut trees = vec![(0u32, None::<u32>)];
        let mut walked = std::collections::HashSet::new();
        while let Some((root, placed_by)) = trees.pop() {
            if !walked.insert(root) {
                continue;
            }
            let mut stack = vec![root];
            while let Some(index) = stack.pop() {
                nodes_seen[index as usize] += 1;
                let n = g.nodes[index as usize];
                for lane in (0..4).filter(|&lane| lane_used(&n, lane)) {
                    let count = n.count[lane] & !SHAPE_LEAF;
                    if count == 0 {
                        let (min, max) = node_bounds(g, n.first[lane]);
                        assert!(contains(&n, lane, min, max), "node {index} lane {lane}");
                        assert_eq!(
                            g.parents[n.first[lane] as usize],
                            index << 2 | lane as u32,
                            "parent of node {}",
                            n.first[lane]
                        );
                        stack.push(n.first[lane]);
                        continue;
                    }
                    let primitives = n.first[lane]..n.first[lane] + count;
                    let holds_shape = primitives.clone().any(|p| {
                        let t = g.primitives[p as usize].triangle;
                        t == NO_TRIANGLE || t == INSTANCE
                    });
                    assert_eq!(n.count[lane] & SHAPE_LEAF != 0, holds_shape, "SHAPE_LEAF");
                    for p in primitives {
                        let prim = g.primitives[p as usize];
                        seen.push(p);
                        let owner = g.shapes[placed_by.unwrap_or(prim.object) as usize];
                        if prim.triangle == NO_TRIANGLE {
                            assert_ne!(owner.kind, KIND_MESH, "primitive {p}: a mesh as a shape");
                            continue;
                        }
                        if prim.triangle == INSTANCE {
                            assert!(placed_by.is_none(), "an instance inside a mesh's tree");
                            assert_ne!(owner.flags & FLAG_INSTANCE, 0, "primitive {p}");
                            let (min, max) =
                                (Vec3::from_slice(&owner.a), Vec3::from_slice(&owner.b));
                            assert!(
                                contains(&n, lane, min, max),
                                "placement {p} escapes its leaf"
                            );
                            assert_eq!(g.parents[prim.root as usize], bvh::NO_PARENT);
                            trees.push((prim.root, Some(prim.object)));
                            continue;
                        }
                        let tri = prim.triangle;
                        let range =
                            owner.first_triangle..owner.first_triangle + owner.triangle_count;
                        assert!(
                            owner.kind == KIND_MESH && range.contains(&tri),
                            "triangle {tri}"
                        );
                        let [v0, v1, v2] = g.triangle(tri);
                        assert_eq!(
                            [prim.v0, prim.v1, prim.v2],
                            [v0, v1, v2].map(|v| v.to_array()),
                            "primitive {p}: not triangle {tri}'s corners"
                        );
                        for v in [v0, v1, v2] {
                            assert!(contains(&n, lane, v, v), "triangle {tri} escapes its leaf");
                        }
                    }
                }
            }
        }
        if !g.primitives.is_empty() {
            assert!(
                nodes_seen.iter().all(|&n| n == 1),
                "every node reached once"
            );
        }
        seen.sort_unstable();
        assert_eq!(seen, (0..g.primitives.len() as u32).collect::<Vec<_>>());
        let mut shapes: Vec<u32> = g
            .primitives
            .iter()
            .filter(|p| p.triangle == NO_TRIANGLE || p.triangle == INSTANCE)
            .map(|p| p.object)
            .collect();
        shapes.sort_unstable();
        let expected: Vec<u32> = (0..g.shapes.len() as u32)
            .filter(|&i| {
                let shape = &g.shapes[i as usize];
                shape.kind != KIND_MESH || shape.flags & FLAG_INSTANCE != 0
            })
            .collect();
        assert_eq!(
            shapes, expected,
            "every shape and placement is one primitive"
        );
        let mut triangles: Vec<u32> = g
            .primitives
            .iter()
            .filter(|p| p.triangle != NO_TRIANGLE && p.triangle != INSTANCE)
            .map(|p| p.triangle)
            .collect();
        triangles.sort_unstable();
        assert_eq!(
            triangles,
            (0..g.triangle_count() as u32).collect::<Vec<_>>(),
            "every triangle is one primitive"
        );
    }

    #[test]
    fn scenes_with_instances_build_valid_trees() {
        let mut rng = StdRng::seed_from_u64(29);
        let mut objects = random_objects(&mut rng, 20);
        let rocks = random_placements(&mut rng, 50);
        objects.extend(instances_of(
            "rocks",
            random_mesh(&mut rng, 500, Vec3::ZERO),
            &rocks,
        ));
        let balls = random_placements(&mut rng, 7);
        objects.extend(instances_of("balls", icosphere(2), &balls));
        let g = Geometry::build(&objects).unwrap();
        validate(&g);
        assert_eq!(g.instances.len(), 57);
        for (k, o) in g
            .shapes
            .iter()
            .enumerate()
            .filter(|(_, o)| o.flags & FLAG_INSTANCE != 0)
        {
            let mirrored = o.flags & FLAG_MIRRORED != 0;
            let Shape::Instance(instance) = &objects[k].shape else {
                panic!("object {k} is not an instance")
            };
            assert_eq!(mirrored, instance.to_world.matrix3.determinant() < 0.0);
        }
    }

    /// A mesh placed N times keeps one copy of its triangles and tree: the backends' buffers
    /// grow with N by the placement's records alone (its object, its transforms, its
    /// top-level primitive and a share of the top-level tree).
    #[test]
    fn a_mesh_placed_n_times_grows_by_its_placements_alone() {
        let mesh = pathlight_scene::testing::torus(1.0, 0.3, 100, 50);
        let bytes_for = |n: usize| {
            let mut rng = StdRng::seed_from_u64(31);
            let placements = random_placements(&mut rng, n);
            let g = Geometry::build(&instances_of("torus", mesh.clone(), &placements)).unwrap();
            assert_eq!(g.triangle_count(), mesh.indices.len(), "{n} placements");
            g.nodes.len() * size_of::<GpuWideNode>()
                + g.parents.len() * 4
                + g.primitives.len() * size_of::<GpuPrimitive>()
                + g.vertices.len() * size_of::<GpuVertex>()
                + g.triangles.len() * 12
                + g.shapes.len() * size_of::<GpuObject>()
                + g.instances.len() * size_of::<GpuInstance>()
        };
        let (few, many) = (bytes_for(10), bytes_for(2010));
        let per_placement = (many - few) as f64 / 2000.0;
        // Measured: 236.6 bytes (80 object + 96 transforms + 48 primitive + 12.6 tree).
        assert!(
            (224.0..260.0).contains(&per_placement),
            "{per_placement:.1} B a placement"
        );
        // Ten placements keep one torus (10,000 triangles of 60 bytes of primitive and
        // corner indices, 5,000 vertices, a share of tree), not ten: well under two tori's.
        assert!(
            few < 2 * (10_000 * (48 + 12) + 5_000 * 32),
            "{few} bytes for 10 placements: the torus is not kept once"
        );
    }

    #[test]
    fn random_scenes_build_valid_trees() {
        let mut rng = StdRng::seed_from_u64(7);
        for count in [1, 2, 5, 40] {
            validate(&Geometry::build(&random_objects(&mut rng, count)).unwrap());
        }
        let big = vec![object(
            "big",
            Shape::Mesh(random_mesh(&mut rng, 20_000, Vec3::ZERO)),
        )];
        validate(&Geometry::build(&big).unwrap());
    }

    /// Trees built in chunks (small ones here: 256 primitives, above 1,000) are valid: shapes
    /// among the triangles, coincident triangles longer than a chunk, shared meshes.
    #[test]
    fn scenes_built_in_chunks_build_valid_trees() {
        let chunks = bvh::Chunks {
            above: 1000,
            size: 256,
        };
        let mut rng = StdRng::seed_from_u64(37);
        let mut objects = random_objects(&mut rng, 30);
        objects.push(object(
            "big",
            Shape::Mesh(random_mesh(&mut rng, 5000, Vec3::ZERO)),
        ));
        objects.extend(coincident_triangles(700));
        let rocks = random_placements(&mut rng, 20);
        objects.extend(instances_of(
            "rocks",
            random_mesh(&mut rng, 3000, Vec3::ZERO),
            &rocks,
        ));
        let g = Geometry::build_in(&objects, chunks).unwrap();
        validate(&g);
        let whole = Geometry::build(&objects).unwrap();
        assert_eq!(g.primitives.len(), whole.primitives.len());
    }

    /// The expected cost of a ray through `g`'s top-level tree by the surface-area heuristic
    /// (node visits and leaf primitives, each weighted by its box's area over the root's).
    fn sah_cost(g: &Geometry) -> f64 {
        let area = |n: &GpuWideNode, lane: usize| {
            let d = Vec3::new(
                n.hi_x[lane] - n.lo_x[lane],
                n.hi_y[lane] - n.lo_y[lane],
                n.hi_z[lane] - n.lo_z[lane],
            );
            f64::from(d.x * d.y + d.y * d.z + d.z * d.x)
        };
        let (lo, hi) = node_bounds(g, 0);
        let d = hi - lo;
        let root = f64::from(d.x * d.y + d.y * d.z + d.z * d.x);
        let mut cost = 1.0;
        let mut stack = vec![0u32];
        while let Some(index) = stack.pop() {
            let n = &g.nodes[index as usize];
            for lane in (0..4).filter(|&lane| lane_used(n, lane)) {
                let weight = area(n, lane) / root;
                match n.count[lane] & !SHAPE_LEAF {
                    0 => {
                        cost += weight;
                        stack.push(n.first[lane]);
                    }
                    count => cost += weight * f64::from(count),
                }
            }
        }
        cost
    }

    /// Chunks cut at Morton cells cost a ray little: on a 40,000-triangle torus in chunks of
    /// 2,048 the tree's expected cost stays within 10% of the tree built whole.
    #[test]
    fn a_tree_built_in_chunks_costs_a_ray_about_as_much_as_one_built_whole() {
        let torus = [object(
            "torus",
            Shape::Mesh(pathlight_scene::testing::torus(1.0, 0.3, 200, 100)),
        )];
        let chunks = bvh::Chunks {
            above: 1000,
            size: 2048,
        };
        let chunked = sah_cost(&Geometry::build_in(&torus, chunks).unwrap());
        let whole = sah_cost(&Geometry::build(&torus).unwrap());
        assert!(
            chunked < 1.1 * whole,
            "chunked {chunked:.1} against whole {whole:.1}"
        );
    }

    #[test]
    fn an_empty_scene_has_one_node_that_no_ray_enters() {
        let g = Geometry::build(&[]).unwrap();
        validate(&g);
        assert_eq!(g.nodes.len(), 1);
        assert!((0..4).all(|lane| !lane_used(&g.nodes[0], lane)));
        assert_eq!(g.stack_bound, 1);
        assert_eq!(
            g.vertices.len(),
            1,
            "a placeholder vertex keeps the buffer bindable"
        );
    }

    #[test]
    fn degenerate_and_coincident_triangles_build_valid_trees() {
        validate(&Geometry::build(&degenerate_objects()).unwrap());
        validate(&Geometry::build(&coincident_triangles(5000)).unwrap());
    }

    /// Identical boxes share a leaf. PLOC alone chained them n/3 deep in O(n^2) time (20,000
    /// coincident triangles: 11 s, a traversal stack bound of 19,992).
    #[test]
    fn coincident_primitives_share_one_leaf() {
        let mut objects = coincident_triangles(20_000);
        objects.extend(random_objects(&mut StdRng::seed_from_u64(3), 50));
        let g = Geometry::build(&objects).unwrap();
        validate(&g);
        assert!(g.stack_bound < 64, "stack bound {}", g.stack_bound);
        assert_eq!(g.parents[0], bvh::NO_PARENT);
    }

    /// Geometry whose boxes or areas would not be finite is refused before the BVH build
    /// (obvhs panicked on it), naming the object; so is a triangle naming a vertex the mesh
    /// does not have.
    #[test]
    fn geometry_that_would_overflow_is_refused_by_name() {
        let triangle = [Vec3::ZERO, Vec3::X, Vec3::Y];
        let mut nan = mesh_of(&[triangle]);
        nan.positions[1].y = f32::NAN;
        let mut huge = mesh_of(&[triangle]);
        huge.positions[2] = Vec3::splat(1e38);
        let mut dangling = mesh_of(&[triangle]);
        dangling.indices[0][2] = 7;
        let cases = [
            Shape::Mesh(nan),
            Shape::Mesh(huge),
            Shape::Mesh(dangling),
            Shape::Sphere {
                center: Vec3::ZERO,
                radius: f32::INFINITY,
                texture_rotation: 0.0,
            },
            Shape::Quad {
                origin: Vec3::splat(-3e38),
                edge_u: Vec3::X,
                edge_v: Vec3::Y,
            },
            Shape::Cylinder {
                p0: Vec3::ZERO,
                p1: Vec3::ZERO,
                radius: 1.0,
                caps: true,
            },
        ];
        for shape in cases {
            let objects = [
                object("fine", Shape::Mesh(mesh_of(&[triangle]))),
                object("bad", shape),
            ];
            let err = Geometry::build(&objects).expect_err("refused");
            assert_eq!(err.object, "bad", "{err}");
        }
    }

    #[test]
    fn the_build_does_not_depend_on_the_thread_count() {
        // obvhs' build, the chunks' builds and the buffer fill run on rayon: one thread and
        // four give the same tree and buffers, whole or in chunks (of 1,000 here, some
        // built at once), so a seeded render is the same image on any machine.
        let mut rng = StdRng::seed_from_u64(13);
        let mut objects: Vec<Object> = random_objects(&mut rng, 40);
        objects.push(object(
            "big",
            Shape::Mesh(random_mesh(&mut rng, 30_000, Vec3::ZERO)),
        ));
        let scene = scene_of(objects);
        let build_on = |threads, chunks| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .expect("a thread pool")
                .install(|| Geometry::build_in(&scene.objects, chunks).unwrap())
        };
        let chunked = bvh::Chunks {
            above: 10_000,
            size: 1000,
        };
        for chunks in [bvh::Chunks::DEFAULT, chunked] {
            let (one, four) = (build_on(1, chunks), build_on(4, chunks));
            validate(&four);
            let bytes = |g: &Geometry| {
                [
                    bytemuck::cast_slice::<_, u8>(&g.nodes).to_vec(),
                    bytemuck::cast_slice(&g.primitives).to_vec(),
                    bytemuck::cast_slice(&g.vertices).to_vec(),
                    bytemuck::cast_slice(&g.triangles).to_vec(),
                    bytemuck::cast_slice(&g.shapes).to_vec(),
                ]
            };
            assert!(
                bytes(&one) == bytes(&four),
                "the buffers differ ({chunks:?})"
            );
        }
    }
}
