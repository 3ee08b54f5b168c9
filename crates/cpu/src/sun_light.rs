//! The sun (light-table entries of kind `LIGHT_SUN`, `index` its parameter block, laid out
//! by `pathlight_core::light_table`): light of irradiance `E` arriving along one direction
//! from infinitely far away, or from a disk of the sky of uniform radiance
//! `E / (pi sin^2 a)` (`a` its angular radius), sampled uniformly in its cone. No ray hits
//! it, so a sample takes no MIS weight. Twin of `sun_light.wgsl`.

use std::f32::consts::TAU;

use glam::{Vec2, Vec3A};

use crate::cpu_scene::CpuScene;
use crate::light_sample::LightSample;
use crate::sampling::sample_cone;

/// The light of the sun whose block starts at `block`, chosen with probability `pmf`.
/// Twin of WGSL `sample_sun_light`.
#[inline(always)]
pub fn sample_sun_light(scene: &CpuScene, block: u32, pmf: f32, u: Vec2) -> LightSample {
    let b = &scene.param_blocks[block as usize..block as usize + 2];
    let towards = Vec3A::new(b[0][0], b[0][1], b[0][2]);
    let one_minus_cos = b[0][3];
    let irradiance = Vec3A::new(b[1][0], b[1][1], b[1][2]);
    let (wi, radiance, pdf) = if one_minus_cos > 0.0 {
        (
            sample_cone(towards, one_minus_cos, u),
            irradiance * b[1][3],
            pmf / (TAU * one_minus_cos),
        )
    } else {
        (towards, irradiance, pmf)
    };
    LightSample {
        wi,
        point: Vec3A::ZERO,
        finite: false,
        radiance,
        pdf,
        valid: pdf > 0.0 && pdf.is_finite(),
        mis: false,
        map_cell: None,
    }
}
