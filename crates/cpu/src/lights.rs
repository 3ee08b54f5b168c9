//! Next-event estimation: choosing a light and a point on it, and the density of doing so.
//! Twin of `lights.wgsl`.
//!
//! The environment is chosen with probability `env_pmf`, its directions from its map's
//! distribution or, for a constant environment, cosine-weighted about the shading normal
//! (the ideal density at a diffuse point); otherwise a shape light by power from the table.
//! Quads, cylinders and triangles are sampled by area, spheres by the solid angle they
//! subtend (uniform in the cone) from outside.

use std::f32::consts::{PI, TAU};

use glam::{Vec2, Vec3A};
use pathlight_core::gpu_types::{
    FLAG_CAPS, GpuObject, GpuRenderParams, KIND_CYLINDER, KIND_MESH, KIND_QUAD, KIND_SPHERE,
};
use pathlight_core::light_table;

use crate::cpu_scene::CpuScene;
use crate::environment::{env_map_pdf, env_radiance, has_env_map, sample_env_map};
use crate::intersect::{MISS, Ray, intersect_sphere};
use crate::material::emission_at;
use crate::sampling::{
    Frame, sample_cosine_hemisphere, sample_disk, sample_uniform_sphere, sin_cos_turns,
};
use crate::textures::triangle_uv;

/// A sampled light direction. Twin of WGSL `LightSample`.
#[derive(Debug, Clone, Copy)]
pub struct LightSample {
    /// Unit direction from the shading point to the light.
    pub wi: Vec3A,
    /// The sampled point on the light (unused for the environment).
    pub point: Vec3A,
    /// False for the environment (infinitely far).
    pub finite: bool,
    /// Emitted radiance towards the shading point.
    pub radiance: Vec3A,
    /// Solid-angle density, including the choice of the light.
    pub pdf: f32,
    /// False when the sample cannot contribute (back side, zero density).
    pub valid: bool,
}

const INVALID: LightSample = LightSample {
    wi: Vec3A::ZERO,
    point: Vec3A::ZERO,
    finite: false,
    radiance: Vec3A::ZERO,
    pdf: 0.0,
    valid: false,
};

/// Density of choosing the environment and direction `wi` from a point with normal `n`
/// (on the side light is gathered from). Twin of WGSL `env_pdf`.
#[inline(always)]
pub fn env_pdf(scene: &CpuScene, params: &GpuRenderParams, n: Vec3A, wi: Vec3A) -> f32 {
    if has_env_map(params) {
        return params.env_pmf * env_map_pdf(scene, params, wi);
    }
    params.env_pmf * n.dot(wi).max(0.0) / PI
}

/// The area of light-table entry `(object, primitive)` (`o` is its object): the whole
/// shape, or triangle `primitive` of a mesh. Twin of WGSL `emitter_area`.
#[inline(always)]
fn emitter_area(scene: &CpuScene, object: u32, o: &GpuObject, primitive: u32) -> f32 {
    if o.kind == KIND_QUAD {
        scene.quad_area(object)
    } else {
        light_table::emitter_area(o, scene.vertices, primitive)
    }
}

/// `1 - cos` of the half-angle of the cone a sphere subtends from `p`, or a negative value
/// when `p` is inside it. Twin of WGSL `sphere_cone`.
fn sphere_cone(center: Vec3A, radius: f32, p: Vec3A) -> f32 {
    let d2 = (center - p).length_squared();
    let r2 = radius * radius;
    if d2 <= r2 * 1.0001 {
        return -1.0;
    }
    let sin2_max = r2 / d2;
    let cos_max = (1.0 - sin2_max).max(0.0).sqrt();
    sin2_max / (1.0 + cos_max)
}

/// Density (solid angle, including the choice of the light) of sampling point `p_light`
/// with normal `n_light` on light-table entry `(object, primitive)` from `p`. Twin of WGSL
/// `light_pdf`.
#[inline(always)]
pub fn light_pdf(
    scene: &CpuScene,
    params: &GpuRenderParams,
    object: u32,
    primitive: u32,
    p: Vec3A,
    p_light: Vec3A,
    n_light: Vec3A,
) -> f32 {
    let o = &scene.objects[object as usize];
    let entry = if o.kind == KIND_MESH {
        o.light + primitive - o.first_triangle
    } else {
        o.light
    };
    let pmf = scene.lights[entry as usize].pmf * (1.0 - params.env_pmf);
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

/// A point on entry `entry`'s shape: (point, normal, area density); spheres seen from
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
                let cos_theta = 1.0 - u.x * one_minus_cos;
                let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
                let (sin, cos) = sin_cos_turns(u.y);
                let dir = Frame::around((a - p).normalize()).to_world(Vec3A::new(
                    sin_theta * cos,
                    sin_theta * sin,
                    cos_theta,
                ));
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
            let [v0, v1, v2] = scene.triangle(primitive).map(Vec3A::from);
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

/// Chooses a light and a point on it as seen from `p` with normal `n` (on the side light
/// is gathered from). Twin of WGSL `sample_light`.
#[inline(always)]
pub fn sample_light(
    cpu_scene: &CpuScene,
    params: &GpuRenderParams,
    p: Vec3A,
    n: Vec3A,
    u_select: f32,
    u: Vec2,
) -> LightSample {
    if u_select < params.env_pmf {
        if has_env_map(params) {
            let (wi, pdf) = sample_env_map(cpu_scene, params, u);
            let pdf = params.env_pmf * pdf;
            return LightSample {
                wi,
                point: Vec3A::ZERO,
                finite: false,
                radiance: env_radiance(cpu_scene, params, wi),
                pdf,
                valid: pdf > 0.0 && pdf.is_finite(),
            };
        }
        let wi = Frame::around(n).to_world(sample_cosine_hemisphere(u));
        let radiance = Vec3A::from(params.environment);
        let pdf = env_pdf(cpu_scene, params, n, wi);
        return LightSample {
            wi,
            point: Vec3A::ZERO,
            finite: false,
            radiance,
            pdf,
            valid: pdf > 0.0,
        };
    }
    if params.light_count == 0 {
        return INVALID;
    }
    let scene = cpu_scene;
    let u_light = ((u_select - params.env_pmf) / (1.0 - params.env_pmf)).min(0.999_999_94);
    // First entry whose cumulative probability exceeds u_light.
    let (mut lo, mut hi) = (0u32, params.light_count - 1);
    while lo < hi {
        let mid = (lo + hi) / 2;
        if scene.lights[mid as usize].cdf > u_light {
            hi = mid;
        } else {
            lo = mid + 1;
        }
    }
    let light = scene.lights[lo as usize];
    // Reuse the part of u_light inside the chosen entry to pick a cylinder's part.
    let below = light.cdf - light.pmf;
    let u_part = ((u_light - below) / light.pmf.max(1e-30)).clamp(0.0, 1.0);
    let o = &scene.objects[light.object as usize];
    let (q, n, density) = sample_shape(cpu_scene, light.object, light.primitive, p, u, u_part);
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
    let pmf = light.pmf * (1.0 - params.env_pmf);
    let pdf = if density < 0.0 {
        pmf * -density
    } else {
        pmf * density * distance * distance / cos_l
    };
    let radiance = if o.kind == KIND_MESH {
        // The barycentrics `sample_shape` drew the point at.
        let su = u.x.sqrt();
        let uv = triangle_uv(scene, light.primitive, 1.0 - su, u.y * su);
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
    }
}
