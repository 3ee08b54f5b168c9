//! The seed's material model. Twin of `lobes.wgsl`.
//!
//! A mixture of lobes with the seed's weights: Lambert (`1 - specular_rate - refract_rate`),
//! specular reflection (`specular_rate`) and transmission (`refract_rate`). The specular lobe
//! is a smooth mirror or a GGX microfacet conductor (Fresnel from a complex IOR, or Schlick
//! from the specular colour); transmission is a smooth or GGX-rough dielectric
//! ([`crate::microfacet`]).
//!
//! `eval` returns the non-delta part: `f * |cos_i|` and the density with which `sample`
//! produces `wi` (its lobe's weight times the lobe's pdf, summed over non-delta lobes).
//! `sample` picks a lobe with probability equal to its weight; a non-delta sample returns
//! `eval / pdf` of the whole mixture (one-sample MIS over the lobes).

use std::f32::consts::FRAC_1_PI;

use glam::{Vec2, Vec3A, Vec4};

use crate::material::MODEL_PARAMS;
use crate::microfacet::{
    ALPHA_MIN, BsdfEval, BsdfSample, INVALID, continuous_sample, eval_rough_dielectric,
    fresnel_conductor, ggx_d, ggx_g1, ggx_reflection, rough_dielectric_direction,
    sample_smooth_dielectric,
};
use crate::sampling::{Frame, sample_cosine_hemisphere};
use crate::surface::Surface;

/// The model's parameters: its block of the material parameters, as
/// `pathlight_core::materials` lays it out (`lobes_block`). Twin of WGSL `LobesParams`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LobesParams {
    /// Weight of the specular lobe.
    pub specular_rate: f32,
    /// Specular colour between white and the base colour.
    pub specular_tint: f32,
    /// Roughness of the specular lobe.
    pub specular_roughness: f32,
    /// Weight of the transmission lobe.
    pub refract_rate: f32,
    /// Transmitted colour between white and the base colour.
    pub refract_tint: f32,
    /// Index of refraction of the inside.
    pub ior: f32,
    /// Roughness of transmission.
    pub refract_roughness: f32,
    /// The specular lobe's Fresnel: the conductor of complex IOR `eta + i k`, else Schlick.
    pub conductor: bool,
    /// Conductor IOR, real part.
    pub eta: Vec3A,
    /// Conductor IOR, imaginary part.
    pub k: Vec3A,
}

impl LobesParams {
    /// The parameters in block `p`. Twin of WGSL `lobes_params`.
    #[inline(always)]
    pub fn decode(p: &[Vec4; MODEL_PARAMS]) -> Self {
        Self {
            specular_rate: p[0].x,
            specular_tint: p[0].y,
            specular_roughness: p[0].z,
            refract_rate: p[0].w,
            refract_tint: p[1].x,
            ior: p[1].y,
            refract_roughness: p[1].z,
            conductor: p[1].w != 0.0,
            eta: p[2].truncate().into(),
            k: p[3].truncate().into(),
        }
    }

    /// Whether the Lambert lobe is the only one (weight 1): [`crate::diffuse`] samples it.
    #[inline(always)]
    pub fn is_lambert(&self) -> bool {
        self.specular_rate == 0.0 && self.refract_rate == 0.0
    }

    /// Whether rough transmission is the only lobe (weight 1): [`crate::glass`] samples it.
    #[inline(always)]
    pub fn is_rough_glass(&self) -> bool {
        let alpha = self.refract_roughness * self.refract_roughness;
        self.specular_rate == 0.0 && self.refract_rate == 1.0 && alpha >= ALPHA_MIN
    }

    /// Whether rough specular reflection is the only lobe (weight 1): [`crate::glossy`]
    /// samples it.
    #[inline(always)]
    pub fn is_rough_mirror(&self) -> bool {
        let alpha = self.specular_roughness * self.specular_roughness;
        self.specular_rate == 1.0 && self.refract_rate == 0.0 && alpha >= ALPHA_MIN
    }
}

/// Reflectance of the specular lobe at `cos_i`. Twin of WGSL `specular_reflectance`.
#[inline(always)]
fn specular_reflectance(m: &LobesParams, color: Vec3A, cos_i: f32) -> Vec3A {
    if m.conductor {
        return fresnel_conductor(cos_i, m.eta, m.k);
    }
    let f0 = Vec3A::ONE.lerp(color, m.specular_tint);
    f0 + (1.0 - f0) * (1.0 - cos_i.clamp(0.0, 1.0)).powi(5)
}

/// Lobe weights (diffuse, specular, transmission). Twin of WGSL `lobe_weights`.
#[inline(always)]
fn lobe_weights(m: &LobesParams) -> Vec3A {
    Vec3A::new(
        (1.0 - m.specular_rate - m.refract_rate).max(0.0),
        m.specular_rate,
        m.refract_rate,
    )
}

/// The continuous part of the BSDF: `f * |cos_i|` and the density with which
/// [`sample_lobes`] produces `wi`. Twin of WGSL `eval_lobes`.
#[inline(always)]
pub fn eval_lobes(m: &LobesParams, color: Vec3A, s: &Surface, wo: Vec3A, wi: Vec3A) -> BsdfEval {
    let weights = lobe_weights(m);
    let front = wo.dot(s.ng) >= 0.0;
    let sign = if front { 1.0 } else { -1.0 };
    let ng = s.ng * sign;
    let n = s.ns * sign;
    let mut out = BsdfEval {
        f: Vec3A::ZERO,
        pdf: 0.0,
    };
    let same_side = wi.dot(ng) > 0.0;
    let cos_o = wo.dot(n);
    let cos_i = wi.dot(n);
    if same_side && cos_o > 0.0 && cos_i > 0.0 {
        if weights.x > 0.0 {
            out.f += weights.x * color * FRAC_1_PI * cos_i;
            out.pdf += weights.x * FRAC_1_PI * cos_i;
        }
        let alpha = m.specular_roughness * m.specular_roughness;
        if weights.y > 0.0 && alpha >= ALPHA_MIN {
            let frame = Frame::around(n);
            let (wo_l, wi_l) = (frame.to_local(wo), frame.to_local(wi));
            let h = (wo_l + wi_l).normalize();
            let f = specular_reflectance(m, color, wo_l.dot(h));
            let d = ggx_d(h, alpha);
            let g1o = ggx_g1(wo_l, alpha);
            out.f += weights.y * f * d * g1o * ggx_g1(wi_l, alpha) / (4.0 * wo_l.z);
            out.pdf += weights.y * g1o * d / (4.0 * wo_l.z);
        }
    }
    let alpha_t = m.refract_roughness * m.refract_roughness;
    if weights.z > 0.0 && alpha_t >= ALPHA_MIN {
        let e = eval_rough_dielectric(m.ior, color, m.refract_tint, s, wo, wi, alpha_t);
        out.f += weights.z * e.f;
        out.pdf += weights.z * e.pdf;
    }
    out
}

/// `f / pdf` of the whole mixture at a sampled non-delta `wi`. Twin of WGSL `lobes_sample`.
#[inline(always)]
fn lobes_sample(m: &LobesParams, color: Vec3A, s: &Surface, wo: Vec3A, wi: Vec3A) -> BsdfSample {
    continuous_sample(eval_lobes(m, color, s, wo, wi), s, wo, wi, m.ior)
}

/// Samples an incident direction: a lobe chosen by its weight, and a direction from it.
/// Twin of WGSL `sample_lobes`.
#[inline(always)]
pub fn sample_lobes(
    m: &LobesParams,
    color: Vec3A,
    s: &Surface,
    wo: Vec3A,
    u_lobe: f32,
    u_fresnel: f32,
    u: Vec2,
) -> BsdfSample {
    let weights = lobe_weights(m);
    let front = wo.dot(s.ng) >= 0.0;
    let sign = if front { 1.0 } else { -1.0 };
    let ng = s.ng * sign;
    let n = s.ns * sign;
    let cos_o = wo.dot(n);
    if u_lobe < weights.y {
        if cos_o <= 0.0 {
            return INVALID;
        }
        let alpha = m.specular_roughness * m.specular_roughness;
        if alpha < ALPHA_MIN {
            let wi = 2.0 * cos_o * n - wo;
            if wi.dot(ng) <= 0.0 {
                return INVALID;
            }
            let weight = specular_reflectance(m, color, cos_o);
            return BsdfSample {
                wi,
                weight,
                pdf: 0.0,
                delta: true,
                eta: 1.0,
                valid: true,
            };
        }
        let frame = Frame::around(n);
        return match ggx_reflection(&frame, frame.to_local(wo), alpha, u) {
            Some(wi) => lobes_sample(m, color, s, wo, wi),
            None => INVALID,
        };
    }
    if u_lobe < weights.y + weights.z {
        let alpha = m.refract_roughness * m.refract_roughness;
        if alpha < ALPHA_MIN {
            return sample_smooth_dielectric(m.ior, color, m.refract_tint, s, wo, u_fresnel);
        }
        return match rough_dielectric_direction(m.ior, s, wo, alpha, u_fresnel, u) {
            Some(wi) => lobes_sample(m, color, s, wo, wi),
            None => INVALID,
        };
    }
    if cos_o <= 0.0 {
        return INVALID;
    }
    let wi = Frame::around(n).to_world(sample_cosine_hemisphere(u));
    if wi.dot(ng) <= 0.0 {
        return INVALID;
    }
    lobes_sample(m, color, s, wo, wi)
}

/// The albedo a denoiser reads (in [0, 1] for colours in [0, 1]): the lobes' weighted
/// colours, a conductor's reflectance at normal incidence, Schlick's F0 otherwise. Twin of
/// WGSL `lobes_albedo`.
#[inline(always)]
pub fn lobes_albedo(m: &LobesParams, color: Vec3A) -> Vec3A {
    let w = lobe_weights(m);
    let specular = if m.conductor {
        fresnel_conductor(1.0, m.eta, m.k)
    } else {
        Vec3A::ONE.lerp(color, m.specular_tint)
    };
    w.x * color + w.y * specular + w.z * Vec3A::ONE.lerp(color, m.refract_tint)
}

/// Whether the material has a non-delta lobe (next-event estimation is worth doing).
/// Twin of WGSL `has_continuous_lobes`.
#[inline(always)]
pub fn has_continuous_lobes(m: &LobesParams) -> bool {
    let w = lobe_weights(m);
    w.x > 0.0
        || (w.y > 0.0 && m.specular_roughness * m.specular_roughness >= ALPHA_MIN)
        || (w.z > 0.0 && m.refract_roughness * m.refract_roughness >= ALPHA_MIN)
}
