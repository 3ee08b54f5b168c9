// Next-event estimation: choosing a light and a point on it, and the density of doing so,
// with the one dispatch on the light type. The environment (`environment.wgsl`) is chosen
// first, with probability env_pmf; otherwise an entry of the light table by power (a binary
// search over its CDF), sampled by its type's file: LIGHT_AREA, `area_light.wgsl`;
// LIGHT_POINT, `point_light.wgsl`; LIGHT_SUN, `sun_light.wgsl`. Only area lights can be hit
// by a ray, so only they have a density for `light_pdf`. A new light type adds a LIGHT_
// constant and a case to the switch below (ARCHITECTURE.md, "How to add a light type").
// CPU twin: `crates/cpu/src/lights.rs`.

#import scene
#import params
#import light_sample
#import environment
#import area_light
#import point_light
#import sun_light

// `Light.kind` (host: `pathlight_core::gpu_types`): an emissive shape or triangle, a point
// or spot light, a sun.
const LIGHT_AREA: u32 = 0u;
const LIGHT_POINT: u32 = 1u;
const LIGHT_SUN: u32 = 2u;

// Density (solid angle, including the choice of the light) with which `sample_light` from
// `p` gives point `p_light` (normal `n_light`) of the emitter a ray hit: triangle
// `primitive` of `object` (or the whole shape): an area light's, the only kind a ray hits.
// CPU twin: `light_pdf`.
fn light_pdf(object: u32, primitive: u32, p: vec3f, p_light: vec3f, n_light: vec3f) -> f32 {
    let o = objects[object];
    var entry = o.light;
    if o.kind == KIND_MESH {
        entry = o.light + primitive - o.first_triangle;
    }
    let pmf = lights[entry].pmf * (1.0 - params.env_pmf);
    return area_light_pdf(object, primitive, pmf, p, p_light, n_light);
}

// A light and a point on it as seen from `p` with normal `n` (on the side light is gathered
// from): `u_select` chooses the light, `u` the point.
// CPU twin: `sample_light`.
fn sample_light(p: vec3f, n: vec3f, u_select: f32, u: vec2f) -> LightSample {
    if u_select < params.env_pmf {
        return sample_environment(n, u);
    }
    if params.light_count == 0u {
        return invalid_light_sample();
    }
    let u_light = min((u_select - params.env_pmf) / (1.0 - params.env_pmf), 0.99999994);
    // The first entry whose cumulative probability exceeds u_light (the last when none
    // does): a window of fixed sizes halved, the steps not depending on the data.
    var base = 0u;
    var size = params.light_count;
    while size > 1u {
        let half = size / 2u;
        base += select(0u, half, lights[base + half - 1u].cdf <= u_light);
        size -= half;
    }
    let light = lights[base];
    // The part of u_light inside the chosen entry, for the light's own choices.
    let below = light.cdf - light.pmf;
    let u_part = clamp((u_light - below) / max(light.pmf, 1e-30), 0.0, 1.0);
    let pmf = light.pmf * (1.0 - params.env_pmf);
    switch light.kind {
        case LIGHT_POINT: {
            return sample_point_light(light.index, pmf, p, u);
        }
        case LIGHT_SUN: {
            return sample_sun_light(light.index, pmf, u);
        }
        case LIGHT_AREA, default: {
            return sample_area_light(light.index, light.primitive, pmf, p, u, u_part);
        }
    }
}
