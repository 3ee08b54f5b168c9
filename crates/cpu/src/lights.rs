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

/// Whether `light` is a point or spot light without a radius or a sun without a disk: light
/// from one point or along one direction, whose sample draws no numbers (the first `vec4` of
/// both kinds' blocks ends with the radius or the disk's `1 - cos`).
#[inline(always)]
pub fn is_delta_light(scene: &CpuScene, light: &GpuLight) -> bool {
    matches!(light.kind, LIGHT_POINT | LIGHT_SUN)
        && scene.param_blocks[light.index as usize][3] <= 0.0
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Over a fine grid of `u_select` (so frequencies are exact to about a grid step per
    /// slot), in reference scenes of unequal lights (ten area-light entries; a sun, a point
    /// and a spot light): the environment takes its share, each entry is chosen with its
    /// probability (to 2e-5), and the part of `u_select` each entry passes on is uniform (its
    /// mean and its fraction below 1/4 within 2e-3 of 1/2 and 1/4).
    #[test]
    fn lights_are_chosen_by_probability_with_a_uniform_rest() {
        for name in ["cornell-materials", "lights"] {
            let path = format!(
                "{}/../../scenes/refs/{name}.toml",
                env!("CARGO_MANIFEST_DIR")
            );
            let scene = pathlight_scene::load_scene_file(std::path::Path::new(&path)).unwrap();
            let prepared = pathlight_core::PreparedScene::new(&scene).unwrap();
            let cpu_scene = CpuScene::new(&prepared);
            let mut params =
                GpuRenderParams::new(&scene.camera, &scene.settings, &prepared.shading);
            params.env_pmf = 0.37;
            let n = params.light_count as usize;
            assert!(n >= 3, "{name}: {n} lights");
            const STEPS: u32 = 1 << 20;
            let (mut env, mut count) = (0u32, vec![0u32; n]);
            let (mut part_sum, mut part_low) = (vec![0.0f64; n], vec![0u32; n]);
            for k in 0..STEPS {
                let u_select = (k as f32 + 0.5) / STEPS as f32;
                let Some((light, pmf, u_part)) = choose_light(&cpu_scene, &params, u_select) else {
                    env += 1;
                    continue;
                };
                let entry = (0..n)
                    .find(|&i| cpu_scene.lights.at(i as u32) == light)
                    .unwrap();
                assert_eq!(pmf, light.pmf * (1.0 - params.env_pmf), "{name}");
                assert!((0.0..=1.0).contains(&u_part), "{name}: {u_part}");
                count[entry] += 1;
                part_sum[entry] += f64::from(u_part);
                part_low[entry] += u32::from(u_part < 0.25);
            }
            let share = |c: u32| f64::from(c) / f64::from(STEPS);
            assert!((share(env) - 0.37).abs() < 2e-5, "{name}: {}", share(env));
            for i in 0..n {
                let want = f64::from(cpu_scene.lights.at(i as u32).pmf) * 0.63;
                assert!(
                    (share(count[i]) - want).abs() < 2e-5,
                    "{name} {i}: {count:?}"
                );
                if count[i] > 2000 {
                    let mean = part_sum[i] / f64::from(count[i]);
                    let low = f64::from(part_low[i]) / f64::from(count[i]);
                    assert!((mean - 0.5).abs() < 2e-3, "{name} {i}: mean {mean}");
                    assert!((low - 0.25).abs() < 2e-3, "{name} {i}: {low} below 1/4");
                }
            }
        }
    }

    /// The lights of the reference scene `lights` (a sun, a point and a spot light, none
    /// with a size) are delta lights; a sun with a disk, a point light with a radius and
    /// area lights are not.
    #[test]
    fn delta_lights_are_those_without_size() {
        use pathlight_scene::LightKind;

        let path = format!(
            "{}/../../scenes/refs/lights.toml",
            env!("CARGO_MANIFEST_DIR")
        );
        let mut scene = pathlight_scene::load_scene_file(std::path::Path::new(&path)).unwrap();
        let delta = |scene: &pathlight_scene::Scene| {
            let prepared = pathlight_core::PreparedScene::new(scene).unwrap();
            let cpu_scene = CpuScene::new(&prepared);
            let n = prepared.shading.light_count;
            (0..n)
                .map(|i| is_delta_light(&cpu_scene, &cpu_scene.lights.at(i)))
                .collect::<Vec<_>>()
        };
        assert_eq!(delta(&scene), [true; 3]);
        for light in &mut scene.lights {
            match &mut light.kind {
                LightKind::Point { radius, .. } => *radius = 0.1,
                LightKind::Sun {
                    angular_diameter_deg,
                    ..
                } => *angular_diameter_deg = 0.5,
            }
        }
        assert_eq!(delta(&scene), [false; 3]);
        let path = format!(
            "{}/../../scenes/refs/cornell-materials.toml",
            env!("CARGO_MANIFEST_DIR")
        );
        let boxed = pathlight_scene::load_scene_file(std::path::Path::new(&path)).unwrap();
        assert!(delta(&boxed).iter().all(|d| !d));
    }
}
