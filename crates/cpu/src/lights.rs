//! Next-event estimation: choosing a light and a point on it, and the density of doing so,
//! with the one dispatch on the light type. The environment ([`crate::environment`]) is
//! chosen first, with probability `env_pmf`; otherwise an entry of the light table by power,
//! sampled by its type's module: `LIGHT_AREA`, [`crate::area_light`]; `LIGHT_POINT`,
//! [`crate::point_light`]; `LIGHT_SUN`, [`crate::sun_light`]. Only area lights can be hit
//! by a ray, so only they have a density for [`light_pdf`]. Twin of `lights.wgsl`.

use glam::{Vec2, Vec3A};
use pathlight_core::gpu_types::{GpuLight, GpuRenderParams, KIND_MESH, LIGHT_POINT, LIGHT_SUN};

use crate::area_light::{area_light_pdf, sample_area_light};
use crate::cpu_scene::CpuScene;
use crate::environment::{cell_radiance, sample_environment};
use crate::light_sample::{INVALID, LightSample};
use crate::point_light::sample_point_light;
use crate::sampling::first_above;
use crate::sun_light::sample_sun_light;

/// Density (solid angle, including the choice of the light) with which [`sample_light`]
/// from `p` gives point `p_light` (normal `n_light`) of the emitter a ray hit: triangle
/// `primitive` of `object` (or the whole shape): an area light's, the only kind a ray hits.
/// Twin of WGSL `light_pdf`.
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
    let pmf = scene.lights.at(entry).pmf * (1.0 - params.env_pmf);
    area_light_pdf(scene, o, object, primitive, pmf, p, p_light, n_light)
}

/// A light of the table chosen with `u_select` (the environment's share, `env_pmf`, below):
/// its entry, the probability of choosing it (the environment's share included), and the
/// part of `u_select` inside its entry, for the light's own choices. `None` where
/// `u_select` chooses the environment or the table is empty.
#[inline(always)]
pub fn choose_light(
    scene: &CpuScene,
    params: &GpuRenderParams,
    u_select: f32,
) -> Option<(GpuLight, f32, f32)> {
    if u_select < params.env_pmf || params.light_count == 0 {
        return None;
    }
    let u_light = ((u_select - params.env_pmf) / (1.0 - params.env_pmf)).min(0.999_999_94);
    // First entry whose cumulative probability exceeds u_light.
    let entry = first_above(params.light_count, u_light, |i| scene.lights.at(i).cdf);
    let light = scene.lights.at(entry);
    // The part of u_light inside the chosen entry, for the light's own choices.
    let below = light.cdf - light.pmf;
    let u_part = ((u_light - below) / light.pmf.max(1e-30)).clamp(0.0, 1.0);
    let pmf = light.pmf * (1.0 - params.env_pmf);
    Some((light, pmf, u_part))
}

/// A light and a point on it as seen from `p` with normal `n` (on the side light is
/// gathered from): `u_select` chooses the light ([`choose_light`]), `u` the point. Twin of
/// WGSL `sample_light`.
#[inline(always)]
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
    match choose_light(scene, params, u_select) {
        Some((light, pmf, u_part)) => sample_table_light(scene, light, pmf, p, u, u_part),
        None => INVALID,
    }
}

/// A point on `light` (chosen with probability `pmf`) as seen from `p`, by its type's
/// module.
#[inline(always)]
pub fn sample_table_light(
    scene: &CpuScene,
    light: GpuLight,
    pmf: f32,
    p: Vec3A,
    u: Vec2,
    u_part: f32,
) -> LightSample {
    match light.kind {
        LIGHT_POINT => sample_point_light(scene, light.index, pmf, p, u),
        LIGHT_SUN => sample_sun_light(scene, light.index, pmf, u),
        _ => sample_area_light(scene, light.index, light.primitive, pmf, p, u, u_part),
    }
}

/// The radiance `ls` brings: its own, or the environment map's at its cell (looked up now;
/// WGSL `sample_environment` looks it up at once).
#[inline(always)]
pub fn light_radiance(scene: &CpuScene, params: &GpuRenderParams, ls: &LightSample) -> Vec3A {
    match &ls.map_cell {
        Some(cell) => cell_radiance(scene, params, cell),
        None => ls.radiance,
    }
}
