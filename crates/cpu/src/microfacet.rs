//! What every material model shares: the result types of a BSDF, Fresnel reflectance, the
//! GGX microfacet distribution (Mitsuba 3's separable Smith term G1(wo) G1(wi), alpha =
//! roughness^2, visible-normal sampling after Heitz 2018), smooth and rough dielectric
//! interfaces (Walter et al. 2007 in pbrt-v4's formulation, exact Fresnel), and the sample
//! of a continuous mixture. Lobes with alpha below [`ALPHA_MIN`] are smooth (delta) lobes.
//! Twin of `microfacet.wgsl`.

use std::f32::consts::PI;

use glam::{Vec2, Vec3A};

use crate::sampling::{Frame, sin_cos_turns};
use crate::surface::Surface;

/// GGX alpha below which a lobe is treated as perfectly smooth.
pub const ALPHA_MIN: f32 = 1e-3;

/// The continuous part of the BSDF in one direction. Twin of WGSL `BsdfEval`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BsdfEval {
    /// `f * |cos(wi, ns)|`.
    pub f: Vec3A,
    /// Density of `sample` producing `wi` (solid angle).
    pub pdf: f32,
}

/// A sampled direction. Twin of WGSL `BsdfSample`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BsdfSample {
    /// Incident direction (unit, pointing away from the surface).
    pub wi: Vec3A,
    /// `f * |cos| / pdf` (for a delta lobe: its reflectance or transmittance).
    pub weight: Vec3A,
    /// Solid-angle density of the whole mixture at `wi`; 0 for a delta lobe.
    pub pdf: f32,
    /// Sampled from a delta lobe (no next-event estimation or MIS applies).
    pub delta: bool,
    /// Relative IOR n_transmitted / n_incident crossed by a refraction, else 1 (Russian
    /// roulette undoes the 1/eta^2 radiance scaling with it, as Mitsuba does).
    pub eta: f32,
    /// False when no direction could be produced.
    pub valid: bool,
}

/// No sample (twin of WGSL `invalid_sample`).
pub const INVALID: BsdfSample = BsdfSample {
    wi: Vec3A::ZERO,
    weight: Vec3A::ZERO,
    pdf: 0.0,
    delta: false,
    eta: 1.0,
    valid: false,
};

/// Unpolarised dielectric Fresnel reflectance; `eta` = n_transmitted / n_incident, `cos_i`
/// >= 0. Twin of WGSL `fresnel_dielectric`.
#[inline(always)]
pub fn fresnel_dielectric(cos_i: f32, eta: f32) -> f32 {
    let sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    let rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    let rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    0.5 * (rs * rs + rp * rp)
}

/// Unpolarised conductor Fresnel reflectance for IOR eta + i k (Mitsuba 3's
/// `fresnel_conductor`). Twin of WGSL `fresnel_conductor`.
#[inline(always)]
pub fn fresnel_conductor(cos_i: f32, eta: Vec3A, k: Vec3A) -> Vec3A {
    let cos2 = cos_i * cos_i;
    let sin2 = 1.0 - cos2;
    let eta2 = eta * eta;
    let k2 = k * k;
    let t0 = eta2 - k2 - sin2;
    let a2pb2 = sqrt3((t0 * t0 + 4.0 * eta2 * k2).max(Vec3A::ZERO));
    let a = sqrt3((0.5 * (a2pb2 + t0)).max(Vec3A::ZERO));
    let t1 = a2pb2 + cos2;
    let t2 = 2.0 * cos_i * a;
    let rs = (t1 - t2) / (t1 + t2).max(Vec3A::splat(1e-20));
    let t3 = cos2 * a2pb2 + sin2 * sin2;
    let t4 = t2 * sin2;
    let rp = rs * (t3 - t4) / (t3 + t4).max(Vec3A::splat(1e-20));
    0.5 * (rp + rs)
}

/// The square root of each component of `v`, in one instruction where the vector is a SIMD
/// register (glam's `Vec3A::sqrt` takes three; the roots are the same, each correctly
/// rounded).
#[inline(always)]
fn sqrt3(v: Vec3A) -> Vec3A {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: SSE is part of x86-64's baseline.
    return Vec3A::from(unsafe { std::arch::x86_64::_mm_sqrt_ps(v.into()) });
    #[cfg(not(target_arch = "x86_64"))]
    v.map(f32::sqrt)
}

/// GGX normal distribution, local `m`. Twin of WGSL `ggx_d`.
#[inline(always)]
pub fn ggx_d(m: Vec3A, alpha: f32) -> f32 {
    let a2 = alpha * alpha;
    let t = (m.x * m.x + m.y * m.y) / a2 + m.z * m.z;
    1.0 / (PI * a2 * t * t)
}

/// Smith masking of one direction (either hemisphere). Twin of WGSL `ggx_g1`.
#[inline(always)]
pub fn ggx_g1(w: Vec3A, alpha: f32) -> f32 {
    let z2 = w.z * w.z;
    if z2 <= 0.0 {
        return 0.0;
    }
    let tan2 = (w.x * w.x + w.y * w.y) / z2;
    2.0 / (1.0 + (1.0 + alpha * alpha * tan2).sqrt())
}

/// A GGX normal visible from `wo` (flipped into the upper hemisphere), Heitz 2018.
/// Twin of WGSL `ggx_sample_visible`.
#[inline(always)]
pub fn ggx_sample_visible(wo: Vec3A, alpha: f32, u: Vec2) -> Vec3A {
    let w = if wo.z < 0.0 { -wo } else { wo };
    let vh = Vec3A::new(alpha * w.x, alpha * w.y, w.z).normalize();
    let len2 = vh.x * vh.x + vh.y * vh.y;
    let t1 = if len2 > 0.0 {
        Vec3A::new(-vh.y, vh.x, 0.0) / len2.sqrt()
    } else {
        Vec3A::X
    };
    let t2 = vh.cross(t1);
    let r = u.x.sqrt();
    let (sin, cos) = sin_cos_turns(u.y);
    let p1 = r * cos;
    let s = 0.5 * (1.0 + vh.z);
    let p2 = (1.0 - s) * (1.0 - p1 * p1).max(0.0).sqrt() + s * r * sin;
    let nh = p1 * t1 + p2 * t2 + (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt() * vh;
    Vec3A::new(alpha * nh.x, alpha * nh.y, nh.z.max(1e-7)).normalize()
}

/// The reflection of `wo_l` (local to `frame`) about a GGX normal of `alpha` visible from
/// it, in world space; `None` when it points below the surface. Twin of WGSL
/// `ggx_reflection`.
#[inline(always)]
pub fn ggx_reflection(frame: &Frame, wo_l: Vec3A, alpha: f32, u: Vec2) -> Option<Vec3A> {
    let h = ggx_sample_visible(wo_l, alpha, u);
    let wi_l = 2.0 * wo_l.dot(h) * h - wo_l;
    (wi_l.z > 0.0).then(|| frame.to_world(wi_l))
}

/// Density of `ggx_sample_visible` producing `m`. Twin of WGSL `ggx_pdf_visible`.
#[inline(always)]
pub fn ggx_pdf_visible(wo: Vec3A, m: Vec3A, alpha: f32) -> f32 {
    ggx_g1(wo, alpha) * wo.dot(m).abs() * ggx_d(m, alpha) / wo.z.abs()
}

/// Dielectric Fresnel for local `wo` and microfacet `m` with the inside IOR `ior`
/// (either side). Twin of WGSL `fresnel_dielectric_local`.
#[inline(always)]
pub fn fresnel_dielectric_local(cos_om: f32, ior: f32) -> f32 {
    if cos_om >= 0.0 {
        fresnel_dielectric(cos_om, ior)
    } else {
        fresnel_dielectric(-cos_om, 1.0 / ior)
    }
}

/// Rough dielectric of inside index `ior` (pbrt-v4 `DielectricBxDF::f` and `PDF`, separable
/// Smith) in the frame of the outward shading normal, the transmission tinted by
/// `lerp(1, color, tint)`. Twin of WGSL `eval_rough_dielectric`.
#[inline(always)]
pub fn eval_rough_dielectric(
    ior: f32,
    color: Vec3A,
    tint: f32,
    s: &Surface,
    wo: Vec3A,
    wi: Vec3A,
    alpha: f32,
) -> BsdfEval {
    let none = BsdfEval {
        f: Vec3A::ZERO,
        pdf: 0.0,
    };
    let frame = Frame::around(s.ns);
    let (wo_l, wi_l) = (frame.to_local(wo), frame.to_local(wi));
    let (cos_o, cos_i) = (wo_l.z, wi_l.z);
    // The geometric normal decides which side each direction is on.
    let geo_reflect = (wo.dot(s.ng) >= 0.0) == (wi.dot(s.ng) >= 0.0);
    let reflect = cos_o * cos_i > 0.0;
    if cos_o == 0.0 || cos_i == 0.0 || reflect != geo_reflect {
        return none;
    }
    let etap = if reflect {
        1.0
    } else if cos_o > 0.0 {
        ior
    } else {
        1.0 / ior
    };
    let mut h = wi_l * etap + wo_l;
    if h.length_squared() == 0.0 {
        return none;
    }
    h = h.normalize();
    if h.z < 0.0 {
        h = -h;
    }
    if h.dot(wi_l) * cos_i < 0.0 || h.dot(wo_l) * cos_o < 0.0 {
        return none;
    }
    let fr = fresnel_dielectric_local(wo_l.dot(h), ior);
    let d = ggx_d(h, alpha);
    let g = ggx_g1(wo_l, alpha) * ggx_g1(wi_l, alpha);
    let pdf_h = ggx_pdf_visible(wo_l, h, alpha);
    if reflect {
        BsdfEval {
            f: Vec3A::splat(d * g * fr / (4.0 * cos_o.abs())),
            pdf: pdf_h / (4.0 * wo_l.dot(h).abs()) * fr,
        }
    } else {
        let denom = (wi_l.dot(h) + wo_l.dot(h) / etap).powi(2);
        let tint = Vec3A::ONE.lerp(color, tint);
        let ft = (1.0 - fr) * d * g * (wi_l.dot(h) * wo_l.dot(h)).abs()
            / (cos_o.abs() * denom)
            / (etap * etap);
        BsdfEval {
            f: tint * ft,
            pdf: pdf_h * wi_l.dot(h).abs() / denom * (1.0 - fr),
        }
    }
}

/// A direction sampled from a rough dielectric interface of relative index `ior` about
/// `s.ns`: reflection or refraction of a visible GGX normal, chosen by its Fresnel
/// reflectance. Twin of WGSL `rough_dielectric_direction`.
#[inline(always)]
pub fn rough_dielectric_direction(
    ior: f32,
    s: &Surface,
    wo: Vec3A,
    alpha: f32,
    u_fresnel: f32,
    u: Vec2,
) -> Option<Vec3A> {
    let frame = Frame::around(s.ns);
    let wo_l = frame.to_local(wo);
    if wo_l.z == 0.0 {
        return None;
    }
    let h = ggx_sample_visible(wo_l, alpha, u);
    let cos_oh = wo_l.dot(h);
    let fr = fresnel_dielectric_local(cos_oh, ior);
    let reflect = u_fresnel < fr;
    let wi_l = if reflect {
        2.0 * cos_oh * h - wo_l
    } else {
        // Refract wo through h: relative IOR seen from wo's side.
        let (eta, hf, c) = if cos_oh >= 0.0 {
            (ior, h, cos_oh)
        } else {
            (1.0 / ior, -h, -cos_oh)
        };
        let sin2_t = (1.0 - c * c) / (eta * eta);
        if sin2_t >= 1.0 {
            return None;
        }
        -wo_l / eta + (c / eta - (1.0 - sin2_t).sqrt()) * hf
    };
    // Through a microfacet, a reflection can point below the surface and a refraction
    // above it: such a direction belongs to the other lobe, whose density does not
    // count this way of reaching it, so it is discarded (as pbrt-v4 and Mitsuba do).
    if (wi_l.z * wo_l.z > 0.0) != reflect {
        return None;
    }
    Some(frame.to_world(wi_l))
}

/// Smooth dielectric of inside index `ior`: reflect with probability F, else refract, tinted
/// by `lerp(1, color, tint)`; radiance scaled by 1/eta^2 on refraction (as Mitsuba and pbrt
/// do). Twin of WGSL `sample_smooth_dielectric`.
#[inline(always)]
pub fn sample_smooth_dielectric(
    ior: f32,
    color: Vec3A,
    tint: f32,
    s: &Surface,
    wo: Vec3A,
    u_fresnel: f32,
) -> BsdfSample {
    let front = wo.dot(s.ng) >= 0.0;
    let sign = if front { 1.0 } else { -1.0 };
    let ng = s.ng * sign;
    let n = s.ns * sign;
    let cos_o = wo.dot(n);
    if cos_o <= 0.0 {
        return INVALID;
    }
    let eta = if front { ior } else { 1.0 / ior };
    let f = fresnel_dielectric(cos_o, eta);
    if u_fresnel < f {
        let wi = 2.0 * cos_o * n - wo;
        let valid = wi.dot(ng) > 0.0;
        return BsdfSample {
            wi,
            weight: Vec3A::ONE,
            pdf: 0.0,
            delta: true,
            eta: 1.0,
            valid,
        };
    }
    let sin2_t = (1.0 - cos_o * cos_o) / (eta * eta);
    let cos_t = (1.0 - sin2_t).max(0.0).sqrt();
    let wi = -wo / eta + (cos_o / eta - cos_t) * n;
    let weight = Vec3A::ONE.lerp(color, tint) / (eta * eta);
    BsdfSample {
        wi,
        weight,
        pdf: 0.0,
        delta: true,
        eta,
        valid: wi.dot(ng) < 0.0,
    }
}

/// The sample of a mixture's continuous lobe in direction `wi`: eval / pdf of the whole
/// mixture (`e`, evaluated at `wi`), and the relative IOR crossed when `wi` lies across the
/// geometric surface from `wo` (an interface of inside index `ior`; 1 for a thin wall).
/// Twin of WGSL `continuous_sample`.
#[inline(always)]
pub fn continuous_sample(e: BsdfEval, s: &Surface, wo: Vec3A, wi: Vec3A, ior: f32) -> BsdfSample {
    if e.pdf <= 0.0 || !e.pdf.is_finite() {
        return INVALID;
    }
    // A direction on the other side of the geometric surface crossed the dielectric.
    let eta = if (wo.dot(s.ng) >= 0.0) == (wi.dot(s.ng) >= 0.0) {
        1.0
    } else if wo.dot(s.ng) >= 0.0 {
        ior
    } else {
        1.0 / ior
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sqrt3_is_each_components_square_root_bit_for_bit() {
        let mut values = vec![0.0, -0.0, 1.0, 2.0, f32::MIN_POSITIVE, 1e-45, f32::MAX];
        values.extend([f32::INFINITY, 0.1, 3.0, 1e-30, 1e30]);
        let mut state = 0x2545_f491_u32;
        for _ in 0..10_000 {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            values.push(f32::from_bits(state >> 1)); // every positive float, NaNs among them
        }
        for v in values.chunks_exact(3) {
            let got = sqrt3(Vec3A::new(v[0], v[1], v[2])).to_array();
            for (g, x) in got.iter().zip(v) {
                let want = x.sqrt();
                assert!(
                    g.to_bits() == want.to_bits() || (g.is_nan() && want.is_nan()),
                    "sqrt({x}) = {g}, want {want}"
                );
            }
        }
    }
}
