//! Next-event estimation: choosing a light and a point on it, and the density of doing so,
//! with the one dispatch on the light type. The environment ([`crate::environment`]) is
//! chosen first, with probability `env_pmf`; otherwise an entry of the light table by power,
//! sampled by its type's module: `LIGHT_AREA`, [`crate::area_light`] (each `match` on the
//! type has one arm per type; with one type, a single arm). Twin of `lights.wgsl`.

use glam::{Vec2, Vec3A};
use pathlight_core::gpu_types::{GpuRenderParams, KIND_MESH};

use crate::area_light::{area_light_pdf, sample_area_light};
use crate::cpu_scene::CpuScene;
use crate::environment::sample_environment;
use crate::light_sample::{INVALID, LightSample};
use crate::sampling::first_above;

/// Density (solid angle, including the choice of the light) with which [`sample_light`]
/// from `p` gives point `p_light` (normal `n_light`) of the emitter a ray hit: triangle
/// `primitive` of `object` (or the whole shape). Twin of WGSL `light_pdf`.
#[inline(always)]
#[expect(clippy::match_single_binding, reason = "one arm per light type")]
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
    let light = &scene.lights[entry as usize];
    let pmf = light.pmf * (1.0 - params.env_pmf);
    match light.kind {
        _ => area_light_pdf(scene, o, object, primitive, pmf, p, p_light, n_light),
    }
}

/// A light and a point on it as seen from `p` with normal `n` (on the side light is
/// gathered from): `u_select` chooses the light, `u` the point. Twin of WGSL `sample_light`.
#[inline(always)]
#[expect(clippy::match_single_binding, reason = "one arm per light type")]
pub fn sample_light(
    scene: &CpuScene,
    params: &GpuRenderParams,
    p: Vec3A,
    n: Vec3A,
    u_select: f32,
    u: Vec2,
) -> LightSample {
    if u_select < params.env_pmf {
        return sample_environment(scene, params, n, u);
    }
    if params.light_count == 0 {
        return INVALID;
    }
    let u_light = ((u_select - params.env_pmf) / (1.0 - params.env_pmf)).min(0.999_999_94);
    // First entry whose cumulative probability exceeds u_light.
    let entry = first_above(params.light_count, u_light, |i| {
        scene.lights[i as usize].cdf
    });
    let light = scene.lights[entry as usize];
    // The part of u_light inside the chosen entry, for the light's own choices.
    let below = light.cdf - light.pmf;
    let u_part = ((u_light - below) / light.pmf.max(1e-30)).clamp(0.0, 1.0);
    let pmf = light.pmf * (1.0 - params.env_pmf);
    match light.kind {
        _ => sample_area_light(scene, light.index, light.primitive, pmf, p, u, u_part),
    }
}
