// A material at a surface point, and the one dispatch on its model: the common textures
// (base colour, emission) applied here, the model's own texture step, BSDF evaluation and
// sampling in the model's file (`lobes.wgsl`, `metal_rough.wgsl`). A new model adds a
// MODEL_ constant and a branch to each dispatch below (each
// compiled out when the scene has no material of the model: `METAL_ROUGH`) (ARCHITECTURE.md, "How to add a material
// model"). CPU twin: `crates/cpu/src/material.rs`.

#import scene
#import textures
#import surface
#import microfacet
#import lobes
#import metal_rough

// `Material.model` (host: `pathlight_core::materials`).
const MODEL_LOBES: u32 = 0u;
const MODEL_METAL_ROUGH: u32 = 1u;

// A material with its textures applied at a point: what its model's BSDF reads.
// CPU twin: `MaterialPoint`.
struct MaterialPoint {
    model: u32,
    // Base colour (texture times factor).
    base_color: vec3f,
    // Emitted radiance (texture times factor).
    emission: vec3f,
    // The model's parameter block, its texture step applied; its file decodes it.
    params: array<vec4f, MODEL_PARAMS>,
}

// The material of surface `s` at its texture coordinates, its base colour times the
// vertex colour.
// CPU twin: `material_at`.
fn material_at(s: Surface) -> MaterialPoint {
    let index = s.material;
    let uv = s.uv;
    let m = materials[index];
    // Loaded with constant indices (MODEL_PARAMS of them): an array indexed at run time
    // would be kept in memory rather than in registers.
    // The last vector only for a material with a long block.
    var params = array<vec4f, MODEL_PARAMS>(param_blocks[m.params], param_blocks[m.params + 1u], param_blocks[m.params + 2u], param_blocks[m.params + 3u], vec4f(0.0));
    if (m.flags & MATERIAL_LONG_BLOCK) != 0u {
        params[4] = param_blocks[m.params + 4u];
    }
    var base_color = m.base_color * s.color;
    if has_texture(m, TEXTURE_BASE) {
        base_color *= material_color(m, TEXTURE_BASE, uv).rgb;
    }
    if METAL_ROUGH && m.model == MODEL_METAL_ROUGH {
        metal_rough_textured(&params, m, uv);
    }
    return MaterialPoint(m.model, base_color, emission_at(index, uv), params);
}

// The radiance material `index` emits at `uv` (its front side).
// CPU twin: `emission_at`.
fn emission_at(index: u32, uv: vec2f) -> vec3f {
    let m = materials[index];
    if has_texture(m, TEXTURE_EMISSION) {
        return m.emission * material_color(m, TEXTURE_EMISSION, uv).rgb;
    }
    return m.emission;
}

// f * |cos_i| of the non-delta part of the BSDF and the density with which
// `sample_material` produces wi.
// CPU twin: `eval_material`.
fn eval_material(p: MaterialPoint, s: Surface, wo: vec3f, wi: vec3f) -> BsdfEval {
    if METAL_ROUGH && p.model == MODEL_METAL_ROUGH {
        return eval_metal_rough(metal_rough_params(p.params), p.base_color, s, wo, wi);
    }
    return eval_lobes(lobes_params(p.params), p.base_color, s, wo, wi);
}

// A direction sampled from the BSDF.
// CPU twin: `sample_material`.
fn sample_material(p: MaterialPoint, s: Surface, wo: vec3f, u_lobe: f32, u_fresnel: f32, u: vec2f) -> BsdfSample {
    if METAL_ROUGH && p.model == MODEL_METAL_ROUGH {
        return sample_metal_rough(metal_rough_params(p.params), p.base_color, s, wo, u_lobe, u_fresnel, u);
    }
    return sample_lobes(lobes_params(p.params), p.base_color, s, wo, u_lobe, u_fresnel, u);
}

// The material's albedo for a denoiser's auxiliary image (the approximate colour of the
// surface, independent of light and view; in [0, 1] for colours in [0, 1]).
// CPU twin: `material_albedo`.
fn material_albedo(p: MaterialPoint) -> vec3f {
    if METAL_ROUGH && p.model == MODEL_METAL_ROUGH {
        return metal_rough_albedo(metal_rough_params(p.params), p.base_color);
    }
    return lobes_albedo(lobes_params(p.params), p.base_color);
}

// What the inside of a solid material absorbs per unit length (zero for every other): a
// path that reaches it from inside keeps exp(-absorption t) of its segment of length t.
// CPU twin: `material_absorption`.
fn material_absorption(p: MaterialPoint) -> vec3f {
    if METAL_ROUGH && p.model == MODEL_METAL_ROUGH {
        let m = metal_rough_params(p.params);
        return select(m.attenuation, vec3f(0.0), m.thin);
    }
    return vec3f(0.0);
}

// Whether the BSDF has a non-delta lobe (next-event estimation is worth doing).
// CPU twin: `has_continuous_material_lobe`.
fn has_continuous_material_lobe(p: MaterialPoint) -> bool {
    if METAL_ROUGH && p.model == MODEL_METAL_ROUGH {
        return has_continuous_metal_rough(metal_rough_params(p.params), p.base_color);
    }
    return has_continuous_lobes(lobes_params(p.params));
}
