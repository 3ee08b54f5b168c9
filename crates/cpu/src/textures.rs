//! Texture lookups through a material's texture slots, and the alpha test of cut-out
//! triangles. Twin of `textures.wgsl`.

use glam::{Vec2, Vec3A, Vec4};
use pathlight_core::gpu_types::{
    GpuMaterial, GpuTextureSlot, MATERIAL_MASK, TEXTURE_BASE, WHITE, WRAP_CLAMP, WRAP_MIRROR,
    WRAP_REPEAT,
};

use crate::cpu_scene::CpuScene;

/// sRGB decoding. Twin of WGSL `srgb_to_linear`.
#[inline(always)]
pub fn srgb_to_linear(c: Vec3A) -> Vec3A {
    c.map(|c| {
        if c <= 0.04045 {
            c / 12.92
        } else {
            ((c + 0.055) / 1.055).powf(2.4)
        }
    })
}

/// Twin of WGSL `texel`.
#[inline(always)]
fn texel(scene: &CpuScene, slot: &GpuTextureSlot, x: u32, y: u32) -> Vec4 {
    let packed = scene.texels[(slot.offset + y * slot.width + x) as usize];
    Vec4::from_array(packed.to_le_bytes().map(f32::from)) / 255.0
}

/// Twin of WGSL `wrap_coordinate`.
#[inline(always)]
fn wrap(x: f32, mode: u32) -> f32 {
    match mode {
        WRAP_CLAMP => x.clamp(0.0, 1.0),
        WRAP_MIRROR => {
            let t = (x * 0.5 - (x * 0.5).floor()) * 2.0;
            if t > 1.0 { 2.0 - t } else { t }
        }
        _ => x - x.floor(),
    }
}

/// Twin of WGSL `texel_index`.
#[inline(always)]
fn texel_index(i: f32, n: u32, mode: u32) -> u32 {
    if mode == WRAP_REPEAT {
        ((i + n as f32) as i32 % n as i32) as u32
    } else {
        i.clamp(0.0, n as f32 - 1.0) as u32
    }
}

/// Bilinear RGBA lookup as stored (sRGB not decoded); row 0 is v = 0. Twin of WGSL
/// `sample_slot`.
#[inline(always)]
pub fn sample_slot(scene: &CpuScene, slot: &GpuTextureSlot, uv: Vec2) -> Vec4 {
    let info = slot;
    let (mode_u, mode_v) = (slot.wrap & 3, (slot.wrap >> 2) & 3);
    let t = Vec2::new(
        slot.u[0] * uv.x + slot.u[1] * uv.y + slot.u[2],
        slot.v[0] * uv.x + slot.v[1] * uv.y + slot.v[2],
    );
    let size = Vec2::new(info.width as f32, info.height as f32);
    let p = Vec2::new(wrap(t.x, mode_u), wrap(t.y, mode_v)) * size - 0.5;
    let base = p.floor();
    let f = p - base;
    let x0 = texel_index(base.x, info.width, mode_u);
    let x1 = texel_index(base.x + 1.0, info.width, mode_u);
    let y0 = texel_index(base.y, info.height, mode_v);
    let y1 = texel_index(base.y + 1.0, info.height, mode_v);
    let top = texel(scene, info, x0, y0).lerp(texel(scene, info, x1, y0), f.x);
    let bottom = texel(scene, info, x0, y1).lerp(texel(scene, info, x1, y1), f.x);
    top.lerp(bottom, f.y)
}

/// Whether material `m` has its texture `which` (a `TEXTURE_*`). Twin of WGSL `has_texture`.
#[inline(always)]
pub fn has_texture(m: &GpuMaterial, which: u32) -> bool {
    (m.texture_mask >> which) & 1 != 0
}

/// Material `m`'s texture `which` (a `TEXTURE_*` it has) at `uv`. Twin of WGSL
/// `material_texture`.
#[inline(always)]
pub fn material_texture(scene: &CpuScene, m: &GpuMaterial, which: u32, uv: Vec2) -> Vec4 {
    sample_slot(
        scene,
        &scene.texture_slots[(m.textures + which) as usize],
        uv,
    )
}

/// Texture coordinates at barycentrics (b1, b2) of `triangle`. Twin of WGSL `triangle_uv`.
#[inline(always)]
pub fn triangle_uv(scene: &CpuScene, triangle: u32, b1: f32, b2: f32) -> Vec2 {
    let [v0, v1, v2] = scene.corners(triangle).map(|v| Vec2::from(v.uv));
    (1.0 - b1 - b2) * v0 + b1 * v1 + b2 * v2
}

/// A number in [0, 1) fixed by a triangle and a hit distance. Twin of WGSL
/// `blend_threshold`.
fn blend_threshold(triangle: u32, t: f32) -> f32 {
    let mut h = triangle.wrapping_mul(0x9e37_79b9) ^ t.to_bits();
    h = (h ^ (h >> 16)).wrapping_mul(0x7feb_352d);
    h = (h ^ (h >> 15)).wrapping_mul(0x846c_a68b);
    h ^= h >> 16;
    (h >> 8) as f32 * (1.0 / 16_777_216.0)
}

/// A vertex colour's code decoded: linear RGBA. Twin of WGSL `vertex_color`.
#[inline(always)]
fn vertex_color(code: u32) -> Vec4 {
    let c = Vec4::from_array(code.to_le_bytes().map(f32::from)) / 255.0;
    srgb_to_linear(c.truncate().into()).extend(c.w)
}

/// The vertex colour at barycentrics (b1, b2) of `triangle`: opaque white when its corners
/// have none. Twin of WGSL `triangle_color`.
#[inline(always)]
pub fn triangle_color(scene: &CpuScene, triangle: u32, b1: f32, b2: f32) -> Vec4 {
    let [c0, c1, c2] = scene.corners(triangle).map(|v| v.color);
    if c0 & c1 & c2 == WHITE {
        return Vec4::ONE;
    }
    (1.0 - b1 - b2) * vertex_color(c0) + b1 * vertex_color(c1) + b2 * vertex_color(c2)
}

/// Whether a ray stops at (b1, b2), distance `t`, on `triangle` of `object`, whose
/// material has alpha holes. Twin of WGSL `alpha_stops`.
#[inline(never)]
pub fn alpha_stops(scene: &CpuScene, object: u32, triangle: u32, b1: f32, b2: f32, t: f32) -> bool {
    let m = &scene.materials[scene.objects[object as usize].material as usize];
    let mut alpha = m.alpha_factor * triangle_color(scene, triangle, b1, b2).w;
    if has_texture(m, TEXTURE_BASE) {
        let uv = triangle_uv(scene, triangle, b1, b2);
        alpha *= material_texture(scene, m, TEXTURE_BASE, uv).w;
    }
    if m.flags & MATERIAL_MASK != 0 {
        alpha >= m.alpha_cutoff
    } else {
        alpha > blend_threshold(triangle, t)
    }
}
