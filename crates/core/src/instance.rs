//! The transforms of a placed instance ([`GpuInstance`]), as both backends apply them: rays
//! into the mesh's space, hit normals, tangents and light samples back out. WGSL twins:
//! `to_object_point` and its kin in `scene.wgsl`.

use glam::{Vec3A, Vec4};

use crate::gpu_types::{FLAG_INSTANCE, GpuInstance, GpuObject, GpuVertex};

/// `rows` (of a 3x4 affine matrix) applied to `v` extended by `w` (1: a point, 0: a
/// direction).
#[inline(always)]
fn apply(rows: &[[f32; 4]; 3], v: Vec3A, w: f32) -> Vec3A {
    let x = v.extend(w);
    Vec3A::new(
        Vec4::from(rows[0]).dot(x),
        Vec4::from(rows[1]).dot(x),
        Vec4::from(rows[2]).dot(x),
    )
}

impl GpuInstance {
    /// World point `p` in the mesh's space. Twin of WGSL `to_object_point`.
    #[inline(always)]
    pub fn to_object_point(&self, p: Vec3A) -> Vec3A {
        apply(&self.to_object, p, 1.0)
    }

    /// World direction `d` in the mesh's space, not renormalised (so that distances along a
    /// ray stay the same). Twin of WGSL `to_object_vector`.
    #[inline(always)]
    pub fn to_object_vector(&self, d: Vec3A) -> Vec3A {
        apply(&self.to_object, d, 0.0)
    }

    /// The mesh's point `p` in the world. Twin of WGSL `to_world_point`.
    #[inline(always)]
    pub fn to_world_point(&self, p: Vec3A) -> Vec3A {
        apply(&self.to_world, p, 1.0)
    }

    /// The mesh's direction `d` (a tangent) in the world, not renormalised. Twin of WGSL
    /// `to_world_vector`.
    #[inline(always)]
    pub fn to_world_vector(&self, d: Vec3A) -> Vec3A {
        apply(&self.to_world, d, 0.0)
    }

    /// The mesh's normal `n` in the world (by the inverse transpose: the transpose of
    /// [`GpuInstance::to_object`]), not renormalised. Twin of WGSL `to_world_normal`.
    #[inline(always)]
    pub fn to_world_normal(&self, n: Vec3A) -> Vec3A {
        let [r0, r1, r2] = self.to_object.map(|r| Vec3A::new(r[0], r[1], r[2]));
        r0 * n.x + r1 * n.y + r2 * n.z
    }
}

/// The world corners of triangle `triangle` (in `triangles`, its corners' indices into
/// `vertices`) of mesh `object`: placed by its transform when the object is an instance.
/// Twin of WGSL `world_triangle`.
#[inline(always)]
pub fn world_triangle(
    object: &GpuObject,
    vertices: &[GpuVertex],
    triangles: &[[u32; 3]],
    instances: &[GpuInstance],
    triangle: u32,
) -> [Vec3A; 3] {
    // Not `array::map`: the CPU backend's row renderer inlines this, and a closure of
    // `array::map` may be left out of line (compiled for the baseline instruction set).
    let [a, b, c] = triangles[triangle as usize];
    let corner = |v: u32| Vec3A::from(vertices[v as usize].position);
    let corners = [corner(a), corner(b), corner(c)];
    if object.flags & FLAG_INSTANCE == 0 {
        return corners;
    }
    let instance = &instances[object.instance as usize];
    let [a, b, c] = corners;
    [
        instance.to_world_point(a),
        instance.to_world_point(b),
        instance.to_world_point(c),
    ]
}
