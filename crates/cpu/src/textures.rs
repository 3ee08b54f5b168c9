//! Texture lookups through a material's texture slots, and the alpha test of cut-out
//! triangles. Twin of `textures.wgsl`.

use glam::{Vec2, Vec3A, Vec4};
use pathlight_core::gpu_types::{
    GpuMaterial, GpuTextureSlot, MATERIAL_MASK, TEXTURE_BASE, TEXTURE_COAT_NORMAL, TEXTURE_NORMAL,
    WHITE, WRAP_CLAMP, WRAP_MIRROR, WRAP_REPEAT,
};

use crate::cpu_scene::CpuScene;
use crate::prefetch::prefetch;

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

/// The texel's channels in [0, 1], its colour decoded from sRGB where `srgb` (by the
/// scene's table of the 256 codes). Twin of WGSL `texel`.
#[inline(always)]
fn texel(scene: &CpuScene, slot: &GpuTextureSlot, x: u32, y: u32, srgb: bool) -> Vec4 {
    let packed = scene.texels[(slot.offset + y * slot.width + x) as usize];
    let codes = packed.to_le_bytes();
    let stored = Vec4::from_array(codes.map(f32::from)) / 255.0;
    if srgb {
        let linear = |code: u8| scene.srgb_linear[usize::from(code)];
        Vec4::new(
            linear(codes[0]),
            linear(codes[1]),
            linear(codes[2]),
            stored.w,
        )
    } else {
        stored
    }
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

/// Twin of WGSL `texel_index`, its `%` taken by at most two subtractions instead of a
/// division: the same index for every `i` that [`taps`] gives (a corner in [-1, n], or not
/// a number), where `(i + n) as u32` lies in [n - 1, 2n] (0 for not a number).
#[inline(always)]
fn texel_index(i: f32, n: u32, mode: u32) -> u32 {
    if mode == WRAP_REPEAT {
        let j = (i + n as f32) as u32;
        let j = if j >= n { j - n } else { j };
        if j >= n { j - n } else { j }
    } else {
        i.clamp(0.0, n as f32 - 1.0) as u32
    }
}

/// The texels a bilinear lookup in a slot reads: columns `x` and rows `y` of the slot's
/// image, and the weights between them (of the second column and the second row).
struct Taps {
    x: [u32; 2],
    y: [u32; 2],
    f: Vec2,
}

/// The texels a bilinear lookup in `slot` at `uv` reads (the slot's transform and wrap
/// modes applied); row 0 is v = 0.
#[inline(always)]
fn taps(slot: &GpuTextureSlot, uv: Vec2) -> Taps {
    let (mode_u, mode_v) = (slot.wrap & 3, (slot.wrap >> 2) & 3);
    let t = Vec2::new(
        slot.u[0] * uv.x + slot.u[1] * uv.y + slot.u[2],
        slot.v[0] * uv.x + slot.v[1] * uv.y + slot.v[2],
    );
    let size = Vec2::new(slot.width as f32, slot.height as f32);
    let p = Vec2::new(wrap(t.x, mode_u), wrap(t.y, mode_v)) * size - 0.5;
    let base = p.floor();
    Taps {
        x: [
            texel_index(base.x, slot.width, mode_u),
            texel_index(base.x + 1.0, slot.width, mode_u),
        ],
        y: [
            texel_index(base.y, slot.height, mode_v),
            texel_index(base.y + 1.0, slot.height, mode_v),
        ],
        f: p - base,
    }
}

/// Bilinear RGBA lookup, each texel's colour decoded from sRGB before the filter where
/// `srgb` (as a GPU's sRGB texture formats and Mitsuba's bitmap textures filter), else as
/// stored; row 0 is v = 0. Twin of WGSL `sample_slot`.
#[inline(always)]
pub fn sample_slot(scene: &CpuScene, slot: &GpuTextureSlot, uv: Vec2, srgb: bool) -> Vec4 {
    let Taps {
        x: [x0, x1],
        y: [y0, y1],
        f,
    } = taps(slot, uv);
    let texel = |x, y| texel(scene, slot, x, y, srgb);
    let top = texel(x0, y0).lerp(texel(x1, y0), f.x);
    let bottom = texel(x0, y1).lerp(texel(x1, y1), f.x);
    top.lerp(bottom, f.y)
}

/// Asks for the cache lines of the texels that material `index`'s textures but its normal
/// maps (which `surface_at` reads) give at `uv`, ahead of [`crate::material::material_at`]:
/// a texture of megabytes read where bounces land misses the caches, and the misses of a
/// packet's hits overlap when asked for together. Reads no texel.
#[inline(always)]
pub fn prefetch_texels(scene: &CpuScene, index: u32, uv: Vec2) {
    let m = &scene.materials[index as usize];
    let mut left = m.texture_mask & !((1 << TEXTURE_NORMAL) | (1 << TEXTURE_COAT_NORMAL));
    while left != 0 {
        let which = left.trailing_zeros();
        left &= left - 1;
        let slot = &scene.texture_slots[(m.textures + which) as usize];
        let Taps { x: [x0, _], y, .. } = taps(slot, uv);
        // The second column lies in the first's line but where a line or the image ends.
        for row in y {
            prefetch(scene.texels, (slot.offset + row * slot.width + x0) as usize);
        }
    }
}

/// Whether material `m` has its texture `which` (a `TEXTURE_*`). Twin of WGSL `has_texture`.
#[inline(always)]
pub fn has_texture(m: &GpuMaterial, which: u32) -> bool {
    (m.texture_mask >> which) & 1 != 0
}

/// Material `m`'s texture `which` (a `TEXTURE_*` it has) at `uv`, as stored (linear data:
/// normals, factors). Twin of WGSL `material_texture`.
#[inline(always)]
pub fn material_texture(scene: &CpuScene, m: &GpuMaterial, which: u32, uv: Vec2) -> Vec4 {
    let slot = &scene.texture_slots[(m.textures + which) as usize];
    sample_slot(scene, slot, uv, false)
}

/// Material `m`'s colour texture `which` (a `TEXTURE_*` it has, sRGB-encoded: base,
/// emission, specular and sheen colour) at `uv`: linear RGB, alpha as stored. Twin of WGSL
/// `material_color`.
#[inline(always)]
pub fn material_color(scene: &CpuScene, m: &GpuMaterial, which: u32, uv: Vec2) -> Vec4 {
    let slot = &scene.texture_slots[(m.textures + which) as usize];
    sample_slot(scene, slot, uv, true)
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

/// A vertex colour's code decoded: linear RGBA (by the scene's table). Twin of WGSL
/// `vertex_color`.
#[inline(always)]
fn vertex_color(scene: &CpuScene, code: u32) -> Vec4 {
    let [r, g, b, a] = code.to_le_bytes();
    let linear = |code: u8| scene.srgb_linear[usize::from(code)];
    Vec4::new(linear(r), linear(g), linear(b), f32::from(a) / 255.0)
}

/// The vertex colour at barycentrics (b1, b2) of `triangle`: opaque white when its corners
/// have none. Twin of WGSL `triangle_color`.
#[inline(always)]
pub fn triangle_color(scene: &CpuScene, triangle: u32, b1: f32, b2: f32) -> Vec4 {
    let [c0, c1, c2] = scene.corners(triangle).map(|v| v.color);
    if c0 & c1 & c2 == WHITE {
        return Vec4::ONE;
    }
    let color = |code| vertex_color(scene, code);
    (1.0 - b1 - b2) * color(c0) + b1 * color(c1) + b2 * color(c2)
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

#[cfg(test)]
mod tests {
    use super::*;

    /// WGSL `texel_index`'s repeat: a division.
    fn repeated_by_division(i: f32, n: u32) -> u32 {
        ((i + n as f32) as i32 % n as i32) as u32
    }

    #[test]
    fn repeat_matches_the_division_at_every_corner_a_lookup_takes() {
        for n in [1, 2, 3, 7, 64, 1000, 2048, 4096, 16384] {
            for i in -1..=n as i32 {
                let i = i as f32;
                assert_eq!(
                    texel_index(i, n, WRAP_REPEAT),
                    repeated_by_division(i, n),
                    "corner {i} of {n} texels"
                );
            }
            assert_eq!(texel_index(f32::NAN, n, WRAP_REPEAT), 0, "{n} texels");
        }
    }

    #[test]
    fn every_wrap_mode_gives_corners_within_a_column_of_the_image() {
        // Texture coordinates far outside [0, 1], at the edges and between texels.
        let coordinates = [
            -7.3,
            -1.0,
            -1e-9,
            0.0,
            1e-9,
            0.37,
            0.999_999_9,
            1.0,
            2.5,
            1e6,
        ];
        for mode in [WRAP_REPEAT, WRAP_CLAMP, WRAP_MIRROR] {
            for n in [1, 5, 2048] {
                let slot = GpuTextureSlot {
                    width: n,
                    height: n,
                    wrap: mode | (mode << 2),
                    u: [1.0, 0.0, 0.0],
                    v: [0.0, 1.0, 0.0],
                    offset: 0,
                    pad: [0; 2],
                };
                for x in coordinates {
                    let Taps { x: [x0, x1], y, f } = taps(&slot, Vec2::new(x, 0.25));
                    assert!(
                        x0 < n && x1 < n && y[0] < n && y[1] < n,
                        "{x} of {n}, mode {mode}"
                    );
                    assert!(
                        (0.0..=1.0).contains(&f.x),
                        "{x} of {n}, mode {mode}: weight {f}"
                    );
                }
            }
        }
    }
}
