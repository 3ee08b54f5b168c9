//! The area light: an emissive quad, sphere or cylinder, or one triangle of an emissive mesh
//! (a light-table entry of kind `LIGHT_AREA`, `index` its object). Quads, cylinders and
//! triangles are sampled by area, spheres by the solid angle they subtend (uniform in the
//! cone) from outside; the radiance is the material's emission (a mesh's, textured at the
//! point). Twin of `area_light.wgsl`.

use std::f32::consts::{PI, TAU};

use glam::{Vec2, Vec3A};
use pathlight_core::gpu_types::{
    FLAG_CAPS, GpuObject, KIND_CYLINDER, KIND_MESH, KIND_QUAD, KIND_SPHERE,
};
use pathlight_core::instance::world_triangle;
use pathlight_core::light_table;

use crate::cpu_scene::CpuScene;
use crate::intersect::{MISS, Ray, intersect_sphere};
use crate::light_sample::{INVALID, LightSample};
use crate::material::emission_at;
use crate::sampling::{Frame, sample_cone, sample_disk, sample_uniform_sphere, sin_cos_turns};
use crate::textures::triangle_uv;

/// The area of light-table entry `(object, primitive)` (`o` is its object): the whole
/// shape, or triangle `primitive` of a mesh. Twin of WGSL `emitter_area`.
#[inline(always)]
fn emitter_area(scene: &CpuScene, object: u32, o: &GpuObject, primitive: u32) -> f32 {
    if o.kind == KIND_QUAD {
        scene.quad_area(object)
    } else {
        light_table::emitter_area(
            o,
            scene.vertices,
            scene.triangles,
            scene.instances,
            primitive,
        )
    }
}

/// `1 - cos` of the half-angle of the cone a sphere subtends from `p`, or a negative value
/// when `p` is inside it. Twin of WGSL `sphere_cone`.
#[inline(always)]
pub fn sphere_cone(center: Vec3A, radius: f32, p: Vec3A) -> f32 {
    let d2 = (center - p).length_squared();
    let r2 = radius * radius;
    if d2 <= r2 * 1.0001 {
        return -1.0;
    }
    let sin2_max = r2 / d2;
    let cos_max = (1.0 - sin2_max).max(0.0).sqrt();
    sin2_max / (1.0 + cos_max)
}

/// Density (solid angle) of sampling point `p_light` with normal `n_light` on entry
/// `(object, primitive)` (`o` is the object) from `p`, which was chosen with probability
/// `pmf`. Twin of WGSL `area_light_pdf`.
#[inline(always)]
#[expect(
    clippy::too_many_arguments,
    reason = "the object both by index and looked up"
)]
pub fn area_light_pdf(
    scene: &CpuScene,
    o: &GpuObject,
    object: u32,
    primitive: u32,
    pmf: f32,
    p: Vec3A,
    p_light: Vec3A,
    n_light: Vec3A,
) -> f32 {
    let to_light = p_light - p;
    let d2 = to_light.length_squared();
    let cos_l = n_light.dot(-to_light).abs() / d2.sqrt();
    if o.kind == KIND_SPHERE {
        let one_minus_cos = sphere_cone(Vec3A::from_slice(&o.a), o.a[3], p);
        if one_minus_cos > 0.0 {
            return pmf / (TAU * one_minus_cos);
        }
    }
    let area = emitter_area(scene, object, o, primitive);
    if cos_l <= 0.0 || area <= 0.0 {
        return 0.0;
    }
    pmf * d2 / (cos_l * area)
}

/// A point on the shape of entry `(object, primitive)`: (point, normal, area density); spheres seen from
/// outside return a cone sample and its solid-angle density as a negative value. Twin of
/// WGSL `sample_shape`.
#[inline(always)]
fn sample_shape(
    scene: &CpuScene,
    object: u32,
    primitive: u32,
    p: Vec3A,
    u: Vec2,
    u_part: f32,
) -> (Vec3A, Vec3A, f32) {
    let o = &scene.objects[object as usize];
    let [a, b, c] = [o.a, o.b, o.c].map(|v| Vec3A::from_slice(&v));
    match o.kind {
        KIND_QUAD => (
            a + u.x * b + u.y * c,
            scene.quad_normal(object),
            1.0 / emitter_area(scene, object, o, primitive),
        ),
        KIND_SPHERE => {
            let radius = o.a[3];
            let one_minus_cos = sphere_cone(a, radius, p);
            if one_minus_cos > 0.0 {
                let dir = sample_cone((a - p).normalize(), one_minus_cos, u);
                let mut t = intersect_sphere(a.into(), radius, &Ray::new(p, dir), 1e30);
                if t == MISS {
                    t = (a - p).dot(dir);
                }
                let q = p + t * dir;
                return (q, (q - a).normalize(), -1.0 / (TAU * one_minus_cos));
            }
            let n = sample_uniform_sphere(u);
            (a + radius * n, n, 1.0 / (4.0 * PI * radius * radius))
        }
        KIND_CYLINDER => {
            let radius = o.a[3];
            let axis_full = b - a;
            let height = axis_full.length();
            let axis = axis_full / height;
            let frame = Frame::around(axis);
            let area = emitter_area(scene, object, o, primitive);
            let side = TAU * radius * height;
            if u_part * area < side || o.flags & FLAG_CAPS == 0 {
                let (sin, cos) = sin_cos_turns(u.x);
                let radial = frame.t * cos + frame.b * sin;
                (
                    a + axis * (u.y * height) + radial * radius,
                    radial,
                    1.0 / area,
                )
            } else {
                let top = u_part * area >= side + 0.5 * (area - side);
                let d = sample_disk(u) * radius;
                let center = if top { b } else { a };
                (
                    center + frame.t * d.x + frame.b * d.y,
                    if top { axis } else { -axis },
                    1.0 / area,
                )
            }
        }
        _ => {
            let [v0, v1, v2] = world_triangle(
                o,
                scene.vertices,
                scene.triangles,
                scene.instances,
                primitive,
            );
            let su = u.x.sqrt();
            let (b1, b2) = (1.0 - su, u.y * su);
            let cross = (v1 - v0).cross(v2 - v0);
            (
                v0 + b1 * (v1 - v0) + b2 * (v2 - v0),
                cross.normalize(),
                2.0 / cross.length(),
            )
        }
    }
}

/// A point on entry `(object, primitive)`, chosen with probability `pmf`, as seen from `p`;
/// `u_part` picks a cylinder's side or cap. Twin of WGSL `sample_area_light`.
#[inline(always)]
pub fn sample_area_light(
    scene: &CpuScene,
    object: u32,
    primitive: u32,
    pmf: f32,
    p: Vec3A,
    u: Vec2,
    u_part: f32,
) -> LightSample {
    let o = &scene.objects[object as usize];
    let (q, n, density) = sample_shape(scene, object, primitive, p, u, u_part);
    let to_light = q - p;
    let distance = to_light.length();
    if distance <= 0.0 {
        return INVALID;
    }
    let wi = to_light / distance;
    let cos_l = n.dot(-wi);
    if cos_l <= 0.0 {
        return INVALID;
    }
    let pdf = if density < 0.0 {
        pmf * -density
    } else {
        pmf * density * distance * distance / cos_l
    };
    let radiance = if o.kind == KIND_MESH {
        // The barycentrics `sample_shape` drew the point at.
        let su = u.x.sqrt();
        let uv = triangle_uv(scene, primitive, 1.0 - su, u.y * su);
        emission_at(scene, o.material, uv)
    } else {
        Vec3A::from(scene.materials[o.material as usize].emission)
    };
    LightSample {
        wi,
        point: q,
        finite: true,
        radiance,
        pdf,
        valid: pdf > 0.0 && pdf.is_finite(),
        mis: true,
        map_cell: None,
    }
}
