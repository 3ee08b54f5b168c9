// Texture lookups through a material's texture slots, and the alpha test of cut-out
// triangles that the traversal calls. CPU twin: `crates/cpu/src/textures.rs`.

#import scene

// CPU twin: `srgb_to_linear`.
fn srgb_to_linear(c: vec3f) -> vec3f {
    let low = c / 12.92;
    let high = pow((c + 0.055) / 1.055, vec3f(2.4));
    return select(high, low, c <= vec3f(0.04045));
}

// The texel's channels in [0, 1], its colour decoded from sRGB where `srgb`.
// CPU twin: `texel`.
fn texel(slot: TextureSlot, x: u32, y: u32, srgb: bool) -> vec4f {
    let c = unpack4x8unorm(texels[slot.offset + y * slot.width + x]);
    if srgb {
        return vec4f(srgb_to_linear(c.rgb), c.a);
    }
    return c;
}

// A coordinate folded into [0, 1] by wrap mode `mode`.
// CPU twin: `wrap`.
fn wrap_coordinate(x: f32, mode: u32) -> f32 {
    if mode == WRAP_CLAMP {
        return clamp(x, 0.0, 1.0);
    }
    if mode == WRAP_MIRROR {
        let t = fract(x * 0.5) * 2.0;
        return select(t, 2.0 - t, t > 1.0);
    }
    return fract(x);
}

// Index of the texel at `i` along a side of `n` texels: tiled by WRAP_REPEAT, else clamped.
// CPU twin: `texel_index`.
fn texel_index(i: f32, n: u32, mode: u32) -> u32 {
    if mode == WRAP_REPEAT {
        return u32(i32(i + f32(n)) % i32(n));
    }
    return u32(clamp(i, 0.0, f32(n) - 1.0));
}

// Bilinear RGBA lookup, each texel's colour decoded from sRGB before the filter where
// `srgb` (as sRGB texture formats filter), else as stored; row 0 is v = 0.
// CPU twin: `sample_slot`.
fn sample_slot(slot: TextureSlot, uv: vec2f, srgb: bool) -> vec4f {
    let mode_u = slot.wrap & 3u;
    let mode_v = (slot.wrap >> 2u) & 3u;
    let t = vec2f(dot(slot.u.xy, uv) + slot.u.z, dot(slot.v.xy, uv) + slot.v.z);
    let size = vec2f(f32(slot.width), f32(slot.height));
    let p = vec2f(wrap_coordinate(t.x, mode_u), wrap_coordinate(t.y, mode_v)) * size - 0.5;
    let f = fract(p);
    let base = floor(p);
    let x0 = texel_index(base.x, slot.width, mode_u);
    let x1 = texel_index(base.x + 1.0, slot.width, mode_u);
    let y0 = texel_index(base.y, slot.height, mode_v);
    let y1 = texel_index(base.y + 1.0, slot.height, mode_v);
    let top = mix(texel(slot, x0, y0, srgb), texel(slot, x1, y0, srgb), f.x);
    let bottom = mix(texel(slot, x0, y1, srgb), texel(slot, x1, y1, srgb), f.x);
    return mix(top, bottom, f.y);
}

// Whether material `m` has its texture `which` (a TEXTURE_*).
// CPU twin: `has_texture`.
fn has_texture(m: Material, which: u32) -> bool {
    return TEXTURES && ((m.texture_mask >> which) & 1u) != 0u;
}

// Material `m`'s texture `which` (a TEXTURE_* it has) at `uv`, as stored (linear data).
// CPU twin: `material_texture`.
fn material_texture(m: Material, which: u32, uv: vec2f) -> vec4f {
    return sample_slot(texture_slots[m.textures + which], uv, false);
}

// Material `m`'s colour texture `which` (a TEXTURE_* it has, sRGB-encoded) at `uv`: linear
// RGB, alpha as stored.
// CPU twin: `material_color`.
fn material_color(m: Material, which: u32, uv: vec2f) -> vec4f {
    return sample_slot(texture_slots[m.textures + which], uv, true);
}

// Texture coordinates at barycentrics (b1, b2) of triangle `triangle`.
// CPU twin: `triangle_uv`.
fn triangle_uv(triangle: u32, b1: f32, b2: f32) -> vec2f {
    let i = 3u * triangle;
    let uv0 = vertices[triangles[i]].uv;
    let uv1 = vertices[triangles[i + 1u]].uv;
    let uv2 = vertices[triangles[i + 2u]].uv;
    return (1.0 - b1 - b2) * uv0 + b1 * uv1 + b2 * uv2;
}

// A number in [0, 1) fixed by a triangle and a hit distance: the threshold of stochastic
// (BLEND) transparency, the same for every query of the same ray.
// CPU twin: `blend_threshold`.
fn blend_threshold(triangle: u32, t: f32) -> f32 {
    var h = triangle * 0x9e3779b9u ^ bitcast<u32>(t);
    h = (h ^ (h >> 16u)) * 0x7feb352du;
    h = (h ^ (h >> 15u)) * 0x846ca68bu;
    h = h ^ (h >> 16u);
    return f32(h >> 8u) * (1.0 / 16777216.0);
}

// A vertex colour's code decoded: linear RGBA.
// CPU twin: `vertex_color`.
fn vertex_color(code: u32) -> vec4f {
    let c = unpack4x8unorm(code);
    return vec4f(srgb_to_linear(c.rgb), c.a);
}

// The vertex colour at barycentrics (b1, b2) of `triangle`: opaque white when its corners
// have none.
// CPU twin: `triangle_color`.
fn triangle_color(triangle: u32, b1: f32, b2: f32) -> vec4f {
    let i = 3u * triangle;
    let c0 = vertices[triangles[i]].color;
    let c1 = vertices[triangles[i + 1u]].color;
    let c2 = vertices[triangles[i + 2u]].color;
    if (c0 & c1 & c2) == WHITE {
        return vec4f(1.0);
    }
    return (1.0 - b1 - b2) * vertex_color(c0) + b1 * vertex_color(c1) + b2 * vertex_color(c2);
}

// Whether a ray stops at (b1, b2), distance t, on triangle `triangle` of `object` (whose
// material has alpha holes): its alpha reaches the cutoff (MASK) or the blend threshold.
// CPU twin: `alpha_stops`.
fn alpha_stops(object: u32, triangle: u32, b1: f32, b2: f32, t: f32) -> bool {
    let m = materials[objects[object].material];
    var alpha = m.alpha_factor * triangle_color(triangle, b1, b2).a;
    if has_texture(m, TEXTURE_BASE) {
        alpha *= material_texture(m, TEXTURE_BASE, triangle_uv(triangle, b1, b2)).a;
    }
    if (m.flags & MATERIAL_MASK) != 0u {
        return alpha >= m.alpha_cutoff;
    }
    return alpha > blend_threshold(triangle, t);
}
