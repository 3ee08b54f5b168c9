//! From a hit to the local surface. Twin of `surface.wgsl`.

use std::f32::consts::{PI, TAU};

use glam::{Vec2, Vec3A};
use pathlight_core::gpu_types::{
    FLAG_CAPS, FLAG_FLAT, GpuMaterial, GpuTextureInfo, KIND_CYLINDER, KIND_QUAD, KIND_SPHERE,
};

use crate::bvh::Hit;
use crate::cpu_scene::CpuScene;
use crate::intersect::Ray;
use crate::sampling::Frame;

/// The surface at a hit. Twin of WGSL `Surface`.
#[derive(Debug, Clone, Copy)]
pub struct Surface {
    /// World position.
    pub position: Vec3A,
    /// Geometric normal on the shape's front side.
    pub ng: Vec3A,
    /// Shading normal, in the hemisphere of `ng`.
    pub ns: Vec3A,
    /// Texture coordinates.
    pub uv: Vec2,
    /// Material index.
    pub material: u32,
}

/// sRGB decoding. Twin of WGSL `srgb_to_linear`.
fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// Twin of WGSL `texel`.
fn texel(scene: &CpuScene, info: &GpuTextureInfo, x: u32, y: u32) -> Vec3A {
    let packed = scene.texels[(info.offset + y * info.width + x) as usize];
    let [r, g, b, _] = packed.to_le_bytes();
    Vec3A::new(r as f32, g as f32, b as f32).map(|c| srgb_to_linear(c / 255.0))
}

/// Bilinear lookup, u wraps, v clamps. Twin of WGSL `sample_texture`.
fn sample_texture(scene: &CpuScene, index: u32, uv: Vec2) -> Vec3A {
    let info = &scene.textures[index as usize];
    let size = Vec2::new(info.width as f32, info.height as f32);
    let p = Vec2::new(uv.x - uv.x.floor(), uv.y.clamp(0.0, 1.0)) * size - 0.5;
    let f = p - p.floor();
    let base = p.floor();
    let x0 = ((base.x + size.x) as i32 % info.width as i32) as u32;
    let x1 = (x0 + 1) % info.width;
    let y0 = base.y.clamp(0.0, size.y - 1.0) as u32;
    let y1 = (base.y + 1.0).clamp(0.0, size.y - 1.0) as u32;
    let top = texel(scene, info, x0, y0).lerp(texel(scene, info, x1, y0), f.x);
    let bottom = texel(scene, info, x0, y1).lerp(texel(scene, info, x1, y1), f.x);
    top.lerp(bottom, f.y)
}

/// The material's colour at `uv`. Twin of WGSL `base_color`.
#[inline(always)]
pub fn base_color(scene: &CpuScene, material: &GpuMaterial, uv: Vec2) -> Vec3A {
    if material.texture >= 0 {
        sample_texture(scene, material.texture as u32, uv)
    } else {
        Vec3A::from(material.base_color)
    }
}

/// Twin of WGSL `surface_at`, except that sphere and cylinder texture coordinates (`atan2`,
/// `acos`) are computed only for textured materials, the only ones that read them (zero
/// otherwise).
#[inline(always)]
pub fn surface_at(cpu_scene: &CpuScene, hit: &Hit, ray: &Ray) -> Surface {
    let scene = cpu_scene;
    let o = &scene.objects[hit.object as usize];
    let textured = scene.materials[o.material as usize].texture >= 0;
    let [a, b] = [o.a, o.b].map(|v| Vec3A::from_slice(&v));
    let p = Vec3A::from(ray.origin) + hit.t * Vec3A::from(ray.dir);
    let mut s = Surface {
        position: p,
        ng: Vec3A::Y,
        ns: Vec3A::Y,
        uv: Vec2::ZERO,
        material: o.material,
    };
    match o.kind {
        KIND_QUAD => {
            s.ng = cpu_scene.quad_normal(hit.object);
            s.ns = s.ng;
            s.uv = Vec2::new(hit.b1, 1.0 - hit.b2);
        }
        KIND_SPHERE => {
            let n = (p - a).normalize();
            s.ng = n;
            s.ns = n;
            if textured {
                let phi = n.x.atan2(n.z) + o.b[0];
                let u = 0.5 + phi / TAU;
                s.uv = Vec2::new(u - u.floor(), n.y.clamp(-1.0, 1.0).acos() / PI);
            }
        }
        KIND_CYLINDER => {
            let axis_full = b - a;
            let height = axis_full.length();
            let axis = axis_full / height;
            let local = p - a;
            let y = local.dot(axis);
            let radial = local - y * axis;
            let radius = o.a[3];
            let u = if textured {
                let frame = Frame::around(axis);
                let phi = radial.dot(frame.b).atan2(radial.dot(frame.t));
                let u = phi / TAU;
                u - u.floor()
            } else {
                0.0
            };
            if o.flags & FLAG_CAPS != 0 && radial.dot(radial) < radius * radius * 0.999 {
                s.ng = if y < 0.5 * height { -axis } else { axis };
                s.uv = Vec2::new(u, radial.length() / radius);
            } else {
                s.ng = radial.normalize();
                s.uv = Vec2::new(u, 1.0 - y / height);
            }
            s.ns = s.ng;
        }
        _ => {
            let i = 3 * hit.primitive as usize;
            let [v0, v1, v2] = [0, 1, 2].map(|k| scene.vertices[i + k]);
            let b0 = 1.0 - hit.b1 - hit.b2;
            let [p0, p1, p2] = [v0, v1, v2].map(|v| Vec3A::from(v.position));
            s.ng = (p1 - p0).cross(p2 - p0).normalize();
            let n = b0 * Vec3A::from(v0.normal)
                + hit.b1 * Vec3A::from(v1.normal)
                + hit.b2 * Vec3A::from(v2.normal);
            if o.flags & FLAG_FLAT != 0 || n.dot(n) < 1e-12 {
                s.ns = s.ng;
            } else {
                s.ns = n.normalize();
                if s.ns.dot(s.ng) < 0.0 {
                    s.ns = -s.ns;
                }
            }
            s.uv = b0 * Vec2::new(v0.u, v0.v)
                + hit.b1 * Vec2::new(v1.u, v1.v)
                + hit.b2 * Vec2::new(v2.u, v2.v);
        }
    }
    s
}
