//! Unidirectional path tracing with next-event estimation and MIS. Twin of
//! `integrator.wgsl` (same loop, same order of sample dimensions).

use glam::Vec3;
use pathlight_core::Tracer;
use pathlight_core::gpu::{GpuFrameParams, NO_LIGHT};
use pathlight_core::trace::Ray;

use crate::bsdf::{eval_bsdf, has_continuous_lobe, sample_bsdf};
use crate::lights::{LightSample, env_pdf, light_pdf, sample_light};
use crate::sampler::{Draw, Sampler};
use crate::sampling::power_heuristic;
use crate::surface::{base_color, surface_at};

/// Largest radiance one sample may add per channel (WGSL `SAMPLE_MAX`).
pub const SAMPLE_MAX: f32 = 16_777_216.0;
const T_MAX: f32 = 1.0e30;

/// Start of a ray leaving `p` on the side of `ng` that `dir` points to. Twin of WGSL
/// `offset_origin`.
#[inline(always)]
fn offset_origin(p: Vec3, ng: Vec3, dir: Vec3) -> Vec3 {
    let eps = 1e-4 * (1.0 + p.abs().max_element());
    p + if dir.dot(ng) > 0.0 { ng } else { -ng } * eps
}

/// Camera ray through a jittered point of pixel (x, y). Twin of WGSL `camera_ray`.
#[inline(always)]
pub fn camera_ray(params: &GpuFrameParams, x: u32, y: u32, sampler: &mut Sampler) -> Ray {
    let jitter = sampler.next_2d();
    let ndc_x = 2.0 * (x as f32 + jitter.x) / params.width as f32 - 1.0;
    let ndc_y = 1.0 - 2.0 * (y as f32 + jitter.y) / params.height as f32;
    let dir = Vec3::from(params.camera_forward)
        + ndc_x * Vec3::from(params.camera_right)
        + ndc_y * Vec3::from(params.camera_up);
    Ray {
        origin: params.camera_position.into(),
        dir: dir.normalize(),
    }
}

/// Whether anything blocks the light sample `ls` from surface point `p` (normal `ng`).
/// The shadow ray runs from the offset origin to the light point itself, stopping just
/// short of it, so the light never shadows itself. Twin of WGSL `occluded`.
#[inline(always)]
fn occluded(tracer: &mut Tracer, p: Vec3, ng: Vec3, ls: &LightSample) -> bool {
    let origin = offset_origin(p, ng, ls.wi);
    if !ls.finite {
        return tracer.occluded(&Ray { origin, dir: ls.wi }, T_MAX);
    }
    let to_light = ls.point - origin;
    let distance = to_light.length();
    let ray = Ray {
        origin,
        dir: to_light / distance,
    };
    tracer.occluded(&ray, distance * (1.0 - 1e-4))
}

/// What one camera path brought back.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PathSample {
    /// Radiance along the path.
    pub radiance: Vec3,
    /// Rays traced for it (camera, extension and shadow rays).
    pub rays: u32,
}

/// Radiance along one camera path, its rays traced by `tracer`. Twin of WGSL `trace_path`.
#[inline(always)]
pub fn trace_path(
    tracer: &mut Tracer,
    params: &GpuFrameParams,
    first: Ray,
    sampler: &mut Sampler,
) -> PathSample {
    let mut rays = 0;
    let mut ray = first;
    let mut radiance = Vec3::ZERO;
    let mut throughput = Vec3::ONE;
    // Density of the BSDF sample that produced `ray`, and whether it came from a delta lobe
    // (camera rays count as delta: emitters they see get full weight).
    let mut prev_pdf = 0.0f32;
    let mut prev_delta = true;
    let mut prev_position = ray.origin;
    // Normal (on the side of wo) at the vertex that produced `ray`: environment sampling
    // there was cosine-weighted about it.
    let mut prev_normal = Vec3::ZERO;
    // Product of the relative IORs crossed: throughput * eta_scale^2 is the throughput
    // without the 1/eta^2 radiance scaling, which Russian roulette should see.
    let mut eta_scale = 1.0f32;
    let scene = tracer.scene;
    let environment = Vec3::from(params.environment);
    for depth in 1..=params.max_depth {
        rays += 1;
        let Some(hit) = tracer.intersect(&ray, T_MAX) else {
            let w = if prev_delta {
                1.0
            } else {
                power_heuristic(prev_pdf, env_pdf(params, prev_normal, ray.dir))
            };
            radiance += throughput * environment * w;
            break;
        };
        let s = surface_at(scene, &hit, &ray);
        let material = &scene.materials[s.material as usize];
        let wo = -ray.dir;
        let emission = Vec3::from(material.emission);
        if wo.dot(s.ng) > 0.0 && emission.max_element() > 0.0 {
            let object = &scene.objects[hit.object as usize];
            let w = if prev_delta || object.light == NO_LIGHT {
                1.0
            } else {
                let pdf_light = light_pdf(
                    scene,
                    params,
                    hit.object,
                    hit.primitive,
                    prev_position,
                    s.position,
                    s.ng,
                );
                power_heuristic(prev_pdf, pdf_light)
            };
            radiance += throughput * emission * w;
        }
        if depth == params.max_depth {
            break;
        }
        // Every bounce draws the same dimensions in the same order.
        let [u_light_select, u_light, u_lobe, u_fresnel, u_bsdf, u_rr] = sampler.next_batch([
            Draw::One,
            Draw::Two,
            Draw::One,
            Draw::One,
            Draw::Two,
            Draw::One,
        ]);
        let [u_light_select, u_lobe, u_fresnel, u_rr] =
            [u_light_select, u_lobe, u_fresnel, u_rr].map(|u| u.x);
        let color = base_color(scene, material, s.uv);
        let n = if wo.dot(s.ng) >= 0.0 { s.ns } else { -s.ns };
        if has_continuous_lobe(material) {
            let ls = sample_light(scene, params, s.position, n, u_light_select, u_light);
            if ls.valid {
                let e = eval_bsdf(material, color, &s, wo, ls.wi);
                if e.f.max_element() > 0.0 {
                    rays += 1;
                    if !occluded(tracer, s.position, s.ng, &ls) {
                        radiance += throughput * e.f * ls.radiance * power_heuristic(ls.pdf, e.pdf)
                            / ls.pdf;
                    }
                }
            }
        }
        let bs = sample_bsdf(material, color, &s, wo, u_lobe, u_fresnel, u_bsdf);
        if !bs.valid {
            break;
        }
        throughput *= bs.weight;
        prev_pdf = bs.pdf;
        prev_delta = bs.delta;
        prev_position = s.position;
        prev_normal = n;
        eta_scale *= bs.eta;
        if depth >= params.rr_depth {
            let q = (throughput.max_element() * eta_scale * eta_scale).min(0.95);
            if u_rr >= q {
                break;
            }
            throughput /= q;
        }
        ray = Ray {
            origin: offset_origin(s.position, s.ng, bs.wi),
            dir: bs.wi,
        };
    }
    PathSample { radiance, rays }
}

/// A sample as it is accumulated: non-finite samples count as zero, channels are clamped to
/// [0, SAMPLE_MAX]. Twin of the checks in WGSL `render` and `add_sample`.
#[inline(always)]
pub fn accumulated_value(radiance: Vec3) -> Vec3 {
    if radiance.is_finite() {
        radiance.clamp(Vec3::ZERO, Vec3::splat(SAMPLE_MAX))
    } else {
        Vec3::ZERO
    }
}
