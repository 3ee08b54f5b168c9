//! Camera rays. Twin of `camera.wgsl`.

use glam::{Vec2, Vec3A};
use pathlight_core::gpu_types::GpuRenderParams;

use crate::intersect::Ray;
use crate::sampler::Sampler;

/// The ray from the eye through film point `film` (in pixels from the image's top-left
/// corner; fractions address points inside a pixel). Twin of WGSL `primary_ray`.
#[inline(always)]
pub fn primary_ray(params: &GpuRenderParams, film: Vec2) -> Ray {
    let c = &params.camera;
    let ndc_x = 2.0 * film.x / params.width as f32 - 1.0;
    let ndc_y = 1.0 - 2.0 * film.y / params.height as f32;
    let dir = Vec3A::from(c.forward) + ndc_x * Vec3A::from(c.right) + ndc_y * Vec3A::from(c.up);
    Ray::new(c.position, dir.normalize())
}

/// The camera ray through a jittered point of pixel (x, y): a box-filtered sample. Twin of
/// WGSL `camera_ray`.
#[inline(always)]
pub fn camera_ray(params: &GpuRenderParams, x: u32, y: u32, sampler: &mut Sampler) -> Ray {
    let jitter = sampler.next_2d();
    primary_ray(params, Vec2::new(x as f32 + jitter.x, y as f32 + jitter.y))
}
