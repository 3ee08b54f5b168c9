//! Camera rays. Twin of `camera.wgsl`.

use glam::{Vec2, Vec3A};
use pathlight_core::gpu_types::GpuRenderParams;

use crate::intersect::Ray;
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

/// The camera ray through a jittered point of pixel (x, y): a box-filtered sample, from a
/// uniform point of the lens towards the plane in focus when there is a lens (a pinhole
/// draws no lens sample). Twin of WGSL `camera_ray`.
#[inline(always)]
pub fn camera_ray(params: &GpuRenderParams, x: u32, y: u32, sampler: &mut Sampler) -> Ray {
    let jitter = sampler.next_2d();
    let film = Vec2::new(x as f32 + jitter.x, y as f32 + jitter.y);
    let c = &params.camera;
    if c.lens_radius <= 0.0 {
        return primary_ray(params, film);
    }
    let lens = sample_disk(sampler.next_2d()) * c.lens_radius;
    let position = Vec3A::from(c.position);
    let origin = position
        + lens.x * Vec3A::from(c.right).normalize()
        + lens.y * Vec3A::from(c.up).normalize();
    let focus = position + film_direction(params, film) * c.focus_distance;
    Ray::new(origin, (focus - origin).normalize())
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
