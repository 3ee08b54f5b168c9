//! Camera rays. Twin of `camera.wgsl`.

use glam::{Vec2, Vec3A};
use pathlight_core::gpu_types::GpuRenderParams;

use crate::intersect::Ray;
use crate::packet::PACKET;
use crate::sampler::Sampler;
use crate::sampling::sample_disk;

/// The direction from the eye through film point `film` (in pixels from the image's top-left
/// corner; fractions address points inside a pixel), unnormalised: its component along the
/// view direction is 1. Twin of WGSL `film_direction`.
#[inline(always)]
fn film_direction(params: &GpuRenderParams, film: Vec2) -> Vec3A {
    let c = &params.camera;
    let ndc_x = 2.0 * film.x / params.width as f32 - 1.0;
    let ndc_y = 1.0 - 2.0 * film.y / params.height as f32;
    Vec3A::from(c.forward) + ndc_x * Vec3A::from(c.right) + ndc_y * Vec3A::from(c.up)
}

/// The pinhole ray from the eye through film point `film`. Twin of WGSL `primary_ray`.
#[inline(always)]
pub fn primary_ray(params: &GpuRenderParams, film: Vec2) -> Ray {
    Ray::new(
        params.camera.position,
        film_direction(params, film).normalize(),
    )
}

/// The pinhole rays' unit directions, per axis, through film points `(x[l], y[l])` of
/// [`PACKET`] lanes side by side: [`primary_ray`]'s bit for bit (per lane the same operations
/// in the same order), computed in SIMD lanes, so that a packet's new paths do not each wait
/// on their own division and square root.
#[inline(always)]
pub fn primary_directions(
    params: &GpuRenderParams,
    x: &[f32; PACKET],
    y: &[f32; PACKET],
) -> [[f32; PACKET]; 3] {
    let c = &params.camera;
    let (width, height) = (params.width as f32, params.height as f32);
    let mut dir = [[0.0; PACKET]; 3];
    for l in 0..PACKET {
        let ndc_x = 2.0 * x[l] / width - 1.0;
        let ndc_y = 1.0 - 2.0 * y[l] / height;
        let v: [f32; 3] =
            std::array::from_fn(|a| c.forward[a] + ndc_x * c.right[a] + ndc_y * c.up[a]);
        // glam's `normalize`: the dot product summed x, y, then z; a division by its root.
        let length = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        for a in 0..3 {
            dir[a][l] = v[a] / length;
        }
    }
    dir
}

/// The point of film a sample of pixel (x, y) aims through, jittered by `jitter` in [0, 1)^2
/// (the sampler's first point: a box filter).
#[inline(always)]
pub fn film_point(x: u32, y: u32, jitter: Vec2) -> Vec2 {
    Vec2::new(x as f32 + jitter.x, y as f32 + jitter.y)
}

/// The ray through film point `film` of a camera with a lens: from the point of the lens
/// that `u` in [0, 1)^2 (the sampler's second point) maps to, uniform over the lens, towards
/// the plane in focus.
#[inline(always)]
pub fn lens_ray(params: &GpuRenderParams, film: Vec2, u: Vec2) -> Ray {
    let c = &params.camera;
    let lens = sample_disk(u) * c.lens_radius;
    let position = Vec3A::from(c.position);
    let origin = position
        + lens.x * Vec3A::from(c.right).normalize()
        + lens.y * Vec3A::from(c.up).normalize();
    let focus = position + film_direction(params, film) * c.focus_distance;
    Ray::new(origin, (focus - origin).normalize())
}

/// The camera ray through a jittered point of pixel (x, y): a box-filtered sample, from a
/// uniform point of the lens towards the plane in focus when there is a lens (a pinhole
/// draws no lens sample). Twin of WGSL `camera_ray`.
#[inline(always)]
pub fn camera_ray(params: &GpuRenderParams, x: u32, y: u32, sampler: &mut Sampler) -> Ray {
    let film = film_point(x, y, sampler.next_2d());
    if params.camera.lens_radius <= 0.0 {
        return primary_ray(params, film);
    }
    lens_ray(params, film, sampler.next_2d())
}

#[cfg(test)]
mod tests {
    use glam::Vec3;
    use pathlight_core::gpu_types::SAMPLER_SOBOL;
    use pathlight_scene::testing::scene_of;

    use super::*;

    fn params(aperture_radius: f32, focus_distance: f32) -> GpuRenderParams {
        let mut scene = scene_of(Vec::new());
        scene.camera.position = Vec3::new(0.5, 1.0, 4.0);
        scene.camera.look_at = Vec3::new(0.0, 0.5, 0.0);
        scene.camera.width = 40;
        scene.camera.height = 30;
        scene.camera.aperture_radius = aperture_radius;
        scene.camera.focus_distance = focus_distance;
        let prepared = pathlight_core::PreparedScene::new(&scene).unwrap();
        GpuRenderParams::new(&scene.camera, &scene.settings, &prepared.shading)
    }

    /// The lane-wise directions are `primary_ray`'s bit for bit, at film points across the
    /// image, its corners and edges, and beyond them.
    #[test]
    fn lanes_aim_as_primary_ray_bit_for_bit() {
        let params = params(0.0, 1.0);
        let mut state = 0x9e37_79b9_u32;
        for round in 0..64 {
            let (mut x, mut y) = ([0.0; PACKET], [0.0; PACKET]);
            for l in 0..PACKET {
                state ^= state << 13;
                state ^= state >> 17;
                state ^= state << 5;
                let u = state as f32 / 4_294_967_296.0;
                x[l] = if round == 0 {
                    [0.0, 40.0, -3.0, 41.5][l % 4]
                } else {
                    u * 46.0 - 3.0
                };
                y[l] = if round == 0 {
                    [0.0, 30.0, 30.0, -0.5][l % 4]
                } else {
                    (1.0 - u) * 36.0 - 3.0
                };
            }
            let dir = primary_directions(&params, &x, &y);
            for l in 0..PACKET {
                let single = primary_ray(&params, Vec2::new(x[l], y[l])).dir;
                let lane = Vec3::new(dir[0][l], dir[1][l], dir[2][l]);
                assert_eq!(
                    lane.to_array().map(f32::to_bits),
                    single.to_array().map(f32::to_bits),
                    "({}, {})",
                    x[l],
                    y[l]
                );
            }
        }
    }

    #[test]
    fn a_lens_of_radius_zero_is_the_pinhole_bit_for_bit() {
        let pinhole = params(0.0, 1.0);
        let focused_elsewhere = params(0.0, 7.5);
        for i in 0..64 {
            let (x, y) = (i % 40, i % 30);
            let mut a = Sampler::new(SAMPLER_SOBOL, i, 3, 0);
            let mut b = a.clone();
            let (ra, rb) = (
                camera_ray(&pinhole, x, y, &mut a),
                camera_ray(&focused_elsewhere, x, y, &mut b),
            );
            assert_eq!((ra.origin, ra.dir), (rb.origin, rb.dir));
            // No lens sample is drawn: the next dimension is the same.
            assert_eq!(a.next_2d(), b.next_2d());
        }
    }

    #[test]
    fn lens_rays_leave_the_disk_and_meet_on_the_plane_in_focus() {
        let (radius, focus) = (0.2, 3.0);
        let lens = params(radius, focus);
        let c = &lens.camera;
        let (position, forward) = (Vec3A::from(c.position), Vec3A::from(c.forward));
        let mut spread = 0.0f32;
        for i in 0..256 {
            let (x, y) = (i % 40, (i * 7) % 30);
            let mut sampler = Sampler::new(SAMPLER_SOBOL, i, 0, 0);
            let jitter = sampler.clone().next_2d();
            let ray = camera_ray(&lens, x, y, &mut sampler);
            let pinhole = primary_ray(&lens, Vec2::new(x as f32 + jitter.x, y as f32 + jitter.y));
            let (origin, dir) = (Vec3A::from(ray.origin), Vec3A::from(ray.dir));
            // The origin lies on the lens disk: in the plane through the eye across the view.
            let offset = origin - position;
            assert!(offset.dot(forward).abs() < 1e-6 && offset.length() <= radius * 1.0001);
            spread = spread.max(offset.length());
            // Both rays reach the plane in focus at the same point.
            let on_plane = |o: Vec3A, d: Vec3A| {
                o + d * ((focus - (o - position).dot(forward)) / d.dot(forward))
            };
            let (a, b) = (
                on_plane(origin, dir),
                on_plane(position, Vec3A::from(pinhole.dir)),
            );
            assert!((a - b).length() < 1e-5, "pixel ({x}, {y}): {a} vs {b}");
        }
        assert!(spread > 0.9 * radius, "lens samples reach only {spread}");
    }
}
