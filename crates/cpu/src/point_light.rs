//! Point and spot lights (light-table entries of kind `LIGHT_POINT`, `index` their
//! parameter block, laid out by `pathlight_core::light_table`): a point, or a
//! small sphere of radius `radius` seen by light samples alone, shining with radiant
//! intensity `I` in every direction or within a cone, glTF's smooth falloff `t^2` between
//! its inner and outer angle. No ray hits one, so a sample takes no MIS weight. Twin of
//! `point_light.wgsl`.

use std::f32::consts::{PI, TAU};

use glam::{Vec2, Vec3A};

use crate::area_light::sphere_cone;
use crate::cpu_scene::CpuScene;
use crate::light_sample::{INVALID, LightSample};
use crate::sampling::sample_cone;

/// The light of the point or spot light whose block starts at `block`, chosen with
/// probability `pmf`, as seen from `p`: from its centre (radiance `I falloff / d^2` over a
/// density of `pmf`), or from a direction towards its sphere (radiance
/// `I falloff / (pi r^2)`, uniform in the cone the sphere subtends). Twin of WGSL
/// `sample_point_light`.
#[inline(always)]
pub fn sample_point_light(
    scene: &CpuScene,
    block: u32,
    pmf: f32,
    p: Vec3A,
    u: Vec2,
) -> LightSample {
    let b = &scene.param_blocks[block as usize..block as usize + 3];
    let center = Vec3A::new(b[0][0], b[0][1], b[0][2]);
    let radius = b[0][3];
    let intensity = Vec3A::new(b[1][0], b[1][1], b[1][2]);
    let axis = Vec3A::new(b[2][0], b[2][1], b[2][2]);
    let to_center = center - p;
    let d2 = to_center.length_squared();
    if d2 <= 0.0 {
        return INVALID;
    }
    let towards = to_center / d2.sqrt();
    let t = ((-towards).dot(axis) - b[2][3]) * b[1][3];
    let t = t.clamp(0.0, 1.0);
    let falloff = t * t;
    let (wi, point, radiance, pdf) = if radius > 0.0 {
        let one_minus_cos = sphere_cone(center, radius, p);
        if one_minus_cos <= 0.0 {
            return INVALID;
        }
        let wi = sample_cone(towards, one_minus_cos, u);
        // The near side of the sphere along wi.
        let along = to_center.dot(wi);
        let distance = along - (radius * radius - (d2 - along * along)).max(0.0).sqrt();
        (
            wi,
            p + distance * wi,
            intensity * (falloff / (PI * radius * radius)),
            pmf / (TAU * one_minus_cos),
        )
    } else {
        (towards, center, intensity * (falloff / d2), pmf)
    };
    LightSample {
        wi,
        point,
        finite: true,
        radiance,
        pdf,
        valid: falloff > 0.0 && pdf > 0.0 && pdf.is_finite() && radiance.is_finite(),
        mis: false,
        map_cell: None,
    }
}
