//! glTF 2.0's metal-rough material, and the choice between it and the lobe model of
//! [`crate::bsdf`]. Twin of `metal_rough.wgsl`.
//!
//! With base colour `c`, metallic `m`, transmission `t`, roughness `r` (GGX alpha = r^2)
//! and dielectric Schlick F0 `f0 = ((ior - 1) / (ior + 1))^2`, the BSDF is the sum of
//! - a GGX specular lobe (separable Smith, visible-normal sampling) with Schlick Fresnel
//!   `F0 = m c + (1 - m)(1 - t) f0` rising to `F90 = m + (1 - m)(1 - t)` at grazing angles:
//!   glTF's mix of the metal (F0 = c) and the dielectric (F0 = f0) specular, Schlick being
//!   linear in F0;
//! - a diffuse base `(1 - m)(1 - t) c / pi (1 - F(cos_o))(1 - F(cos_i))`, F the dielectric
//!   Schlick Fresnel: light the specular layer reflects never reaches it, so the material
//!   never reflects more than it receives (the coupling Mitsuba's `plastic` uses, without
//!   its internal-reflection term);
//! - a dielectric interface weighted `(1 - m) t` (`KHR_materials_transmission`): a thin wall
//!   (exact Fresnel; the transmitted direction is the reflected one mirrored through the
//!   surface, tinted by `c`; smooth, it passes straight through) or, with
//!   `KHR_materials_volume`, the rough dielectric of the lobe model tinted by `c`.
//!
//! Lobes are sampled in proportion to their estimated albedo at `wo`.

use std::f32::consts::FRAC_1_PI;

use glam::{Vec2, Vec3A};
use pathlight_core::gpu_types::{GpuMaterial, MATERIAL_THIN, MODEL_METAL_ROUGH};

use crate::bsdf::{
    ALPHA_MIN, BsdfEval, BsdfSample, INVALID, eval_bsdf, eval_rough_dielectric, fresnel_dielectric,
    ggx_d, ggx_g1, ggx_sample_visible, has_continuous_lobe, rough_dielectric_direction,
    sample_bsdf, sample_smooth_dielectric,
};
use crate::sampling::{Frame, sample_cosine_hemisphere};
use crate::surface::Surface;

/// The model's lobe weights. Twin of WGSL `MetalRoughLobes`.
#[derive(Debug, Clone, Copy)]
pub struct Lobes {
    /// Schlick reflectance of the specular lobe at normal incidence.
    pub spec_f0: Vec3A,
    /// ... and at grazing incidence.
    pub spec_f90: f32,
    /// Weight of the diffuse base.
    pub diffuse: f32,
    /// Weight of the dielectric interface.
    pub wall: f32,
    /// Schlick F0 of the dielectric.
    pub f0_d: f32,
}

/// Twin of WGSL `mr_lobes`.
#[inline(always)]
pub fn lobes(m: &GpuMaterial) -> Lobes {
    let r = (m.ior - 1.0) / (m.ior + 1.0);
    let f0_d = r * r;
    let dielectric = 1.0 - m.metallic;
    let base = dielectric * (1.0 - m.transmission);
    Lobes {
        spec_f0: m.metallic * Vec3A::from(m.base_color) + Vec3A::splat(base * f0_d),
        spec_f90: m.metallic + base,
        diffuse: base,
        wall: dielectric * m.transmission,
        f0_d,
    }
}

/// Schlick's Fresnel between `f0` and `f90`. Twin of WGSL `schlick`.
#[inline(always)]
pub fn schlick(f0: Vec3A, f90: f32, cos_i: f32) -> Vec3A {
    f0 + (Vec3A::splat(f90) - f0) * (1.0 - cos_i.clamp(0.0, 1.0)).powi(5)
}

/// The dielectric's scalar Schlick Fresnel.
#[inline(always)]
fn schlick_d(f0: f32, cos_i: f32) -> f32 {
    f0 + (1.0 - f0) * (1.0 - cos_i.clamp(0.0, 1.0)).powi(5)
}

/// Probabilities of sampling the specular lobe, the diffuse base and the interface. Twin
/// of WGSL `mr_probabilities`.
#[inline(always)]
fn probabilities(m: &GpuMaterial, l: &Lobes, cos_o: f32) -> Vec3A {
    let lum = Vec3A::new(0.2126, 0.7152, 0.0722);
    let spec = schlick(l.spec_f0, l.spec_f90, cos_o).dot(lum);
    let diffuse = l.diffuse * Vec3A::from(m.base_color).dot(lum) * (1.0 - schlick_d(l.f0_d, cos_o));
    let total = spec + diffuse + l.wall;
    if total > 0.0 {
        Vec3A::new(spec, diffuse, l.wall) / total
    } else {
        Vec3A::ZERO
    }
}

/// The continuous part of the BSDF. Twin of WGSL `eval_metal_rough`.
#[inline(always)]
pub fn eval(m: &GpuMaterial, s: &Surface, wo: Vec3A, wi: Vec3A) -> BsdfEval {
    let sign = if wo.dot(s.ng) >= 0.0 { 1.0 } else { -1.0 };
    let (ng, n) = (s.ng * sign, s.ns * sign);
    let l = lobes(m);
    let (cos_o, cos_i) = (wo.dot(n), wi.dot(n));
    let probs = probabilities(m, &l, cos_o);
    let alpha = m.roughness * m.roughness;
    let thin = m.flags & MATERIAL_THIN != 0;
    let color = Vec3A::from(m.base_color);
    let mut out = BsdfEval {
        f: Vec3A::ZERO,
        pdf: 0.0,
    };
    if cos_o <= 0.0 {
        return out;
    }
    let frame = Frame::around(n);
    let wo_l = frame.to_local(wo);
    if wi.dot(ng) > 0.0 && cos_i > 0.0 {
        if l.diffuse > 0.0 {
            let coupling = (1.0 - schlick_d(l.f0_d, cos_o)) * (1.0 - schlick_d(l.f0_d, cos_i));
            out.f += l.diffuse * coupling * color * (cos_i * FRAC_1_PI);
            out.pdf += probs.y * cos_i * FRAC_1_PI;
        }
        if alpha >= ALPHA_MIN {
            let wi_l = frame.to_local(wi);
            let h = (wo_l + wi_l).normalize();
            let d = ggx_d(h, alpha);
            let g1o = ggx_g1(wo_l, alpha);
            let spec = d * g1o * ggx_g1(wi_l, alpha) / (4.0 * wo_l.z);
            let pdf_r = g1o * d / (4.0 * wo_l.z);
            out.f += schlick(l.spec_f0, l.spec_f90, wo_l.dot(h)) * spec;
            out.pdf += probs.x * pdf_r;
            if thin && l.wall > 0.0 {
                let fr = fresnel_dielectric(wo_l.dot(h), m.ior);
                out.f += Vec3A::splat(l.wall * fr * spec);
                out.pdf += probs.z * fr * pdf_r;
            }
        }
    }
    if l.wall > 0.0 && alpha >= ALPHA_MIN {
        if thin {
            if wi.dot(ng) < 0.0 && cos_i < 0.0 {
                // Through a thin wall: the reflection of the mirrored direction, tinted.
                let wm_l = frame.to_local(wi - 2.0 * cos_i * n);
                let h = (wo_l + wm_l).normalize();
                let d = ggx_d(h, alpha);
                let g1o = ggx_g1(wo_l, alpha);
                let spec = d * g1o * ggx_g1(wm_l, alpha) / (4.0 * wo_l.z);
                let ft = 1.0 - fresnel_dielectric(wo_l.dot(h), m.ior);
                out.f += l.wall * ft * spec * color;
                out.pdf += probs.z * ft * g1o * d / (4.0 * wo_l.z);
            }
        } else {
            let glass = GpuMaterial {
                refract_tint: 1.0,
                ..*m
            };
            let e = eval_rough_dielectric(&glass, color, s, wo, wi, alpha);
            out.f += l.wall * e.f;
            out.pdf += probs.z * e.pdf;
        }
    }
    out
}

/// `eval / pdf` of a continuous sample. Twin of WGSL `mr_mixture_sample`.
#[inline(always)]
fn mixture_sample(m: &GpuMaterial, s: &Surface, wo: Vec3A, wi: Vec3A) -> BsdfSample {
    let e = eval(m, s, wo, wi);
    if e.pdf <= 0.0 || !e.pdf.is_finite() {
        return INVALID;
    }
    let front_o = wo.dot(s.ng) >= 0.0;
    let eta = if front_o != (wi.dot(s.ng) >= 0.0) && m.flags & MATERIAL_THIN == 0 {
        if front_o { m.ior } else { 1.0 / m.ior }
    } else {
        1.0
    };
    BsdfSample {
        wi,
        weight: e.f / e.pdf,
        pdf: e.pdf,
        delta: false,
        eta,
        valid: true,
    }
}

/// A delta sample of weight `weight`.
fn delta(wi: Vec3A, weight: Vec3A, valid: bool) -> BsdfSample {
    BsdfSample {
        wi,
        weight,
        pdf: 0.0,
        delta: true,
        eta: 1.0,
        valid,
    }
}

/// Samples an incident direction. Twin of WGSL `sample_metal_rough`.
#[inline(always)]
pub fn sample(
    m: &GpuMaterial,
    s: &Surface,
    wo: Vec3A,
    u_lobe: f32,
    u_fresnel: f32,
    u: Vec2,
) -> BsdfSample {
    let sign = if wo.dot(s.ng) >= 0.0 { 1.0 } else { -1.0 };
    let (ng, n) = (s.ng * sign, s.ns * sign);
    let cos_o = wo.dot(n);
    if cos_o <= 0.0 {
        return INVALID;
    }
    let l = lobes(m);
    let probs = probabilities(m, &l, cos_o);
    let alpha = m.roughness * m.roughness;
    let frame = Frame::around(n);
    let wo_l = frame.to_local(wo);
    let color = Vec3A::from(m.base_color);
    if u_lobe < probs.x {
        if alpha < ALPHA_MIN {
            let wi = 2.0 * cos_o * n - wo;
            if wi.dot(ng) <= 0.0 {
                return INVALID;
            }
            return delta(wi, schlick(l.spec_f0, l.spec_f90, cos_o) / probs.x, true);
        }
        let h = ggx_sample_visible(wo_l, alpha, u);
        let wi_l = 2.0 * wo_l.dot(h) * h - wo_l;
        if wi_l.z <= 0.0 {
            return INVALID;
        }
        return mixture_sample(m, s, wo, frame.to_world(wi_l));
    }
    if u_lobe < probs.x + probs.z {
        if m.flags & MATERIAL_THIN != 0 {
            if alpha < ALPHA_MIN {
                let fr = fresnel_dielectric(cos_o, m.ior);
                if u_fresnel < fr {
                    let wi = 2.0 * cos_o * n - wo;
                    return delta(wi, Vec3A::splat(l.wall / probs.z), wi.dot(ng) > 0.0);
                }
                return delta(-wo, l.wall / probs.z * color, true);
            }
            let h = ggx_sample_visible(wo_l, alpha, u);
            let wr_l = 2.0 * wo_l.dot(h) * h - wo_l;
            if wr_l.z <= 0.0 {
                return INVALID;
            }
            let fr = fresnel_dielectric(wo_l.dot(h), m.ior);
            let wi_l = if u_fresnel < fr {
                wr_l
            } else {
                Vec3A::new(wr_l.x, wr_l.y, -wr_l.z)
            };
            return mixture_sample(m, s, wo, frame.to_world(wi_l));
        }
        if alpha < ALPHA_MIN {
            let glass = GpuMaterial {
                refract_tint: 1.0,
                ..*m
            };
            let mut bs = sample_smooth_dielectric(&glass, color, s, wo, u_fresnel);
            bs.weight *= l.wall / probs.z;
            return bs;
        }
        return match rough_dielectric_direction(m.ior, s, wo, alpha, u_fresnel, u) {
            Some(wi) => mixture_sample(m, s, wo, wi),
            None => INVALID,
        };
    }
    let wi = frame.to_world(sample_cosine_hemisphere(u));
    if wi.dot(ng) <= 0.0 {
        return INVALID;
    }
    mixture_sample(m, s, wo, wi)
}

/// The BSDF of either model. Twin of WGSL `eval_material`.
#[inline(always)]
pub fn eval_material(m: &GpuMaterial, s: &Surface, wo: Vec3A, wi: Vec3A) -> BsdfEval {
    if m.model == MODEL_METAL_ROUGH {
        eval(m, s, wo, wi)
    } else {
        eval_bsdf(m, Vec3A::from(m.base_color), s, wo, wi)
    }
}

/// A direction sampled from either model. Twin of WGSL `sample_material`.
#[inline(always)]
pub fn sample_material(
    m: &GpuMaterial,
    s: &Surface,
    wo: Vec3A,
    u_lobe: f32,
    u_fresnel: f32,
    u: Vec2,
) -> BsdfSample {
    if m.model == MODEL_METAL_ROUGH {
        sample(m, s, wo, u_lobe, u_fresnel, u)
    } else {
        sample_bsdf(m, Vec3A::from(m.base_color), s, wo, u_lobe, u_fresnel, u)
    }
}

/// Whether either model has a non-delta lobe. Twin of WGSL `has_continuous_material_lobe`.
#[inline(always)]
pub fn has_continuous_material_lobe(m: &GpuMaterial) -> bool {
    if m.model == MODEL_METAL_ROUGH {
        lobes(m).diffuse > 0.0 || m.roughness * m.roughness >= ALPHA_MIN
    } else {
        has_continuous_lobe(m)
    }
}
