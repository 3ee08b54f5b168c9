//! glTF 2.0's metallic-roughness material model. Twin of `metal_rough.wgsl`.
//!
//! With base colour `c`, metallic `m`, transmission `t`, roughness `r` (GGX alpha = r^2),
//! specular strength `s` and colour `sc` (`KHR_materials_specular`; 1 and white by
//! default) and dielectric Schlick F0 `f0 = min(((ior - 1) / (ior + 1))^2 sc, 1)`, the BSDF
//! is the sum of
//! - a GGX specular lobe (separable Smith, visible-normal sampling) with Schlick Fresnel
//!   `F0 = m c + (1 - m)(1 - t) s f0` rising to `F90 = m + (1 - m)(1 - t) s` at grazing
//!   angles: glTF's mix of the metal (F0 = c) and the dielectric (F0 = f0, weight s)
//!   specular, Schlick being linear in F0;
//! - a diffuse base `(1 - m)(1 - t) c / pi (1 - s max(F(wo.h)))`, F the dielectric's
//!   coloured Schlick Fresnel and h the half vector of `wo` and `wi`: the glTF
//!   specification's `fresnel_mix` (Appendix B and `KHR_materials_specular`). Like the specification's, this model reflects more than it
//!   receives where the specular lobe is strong and the diffuse weight stays near
//!   `1 - f0`: glossy dielectrics seen at grazing angles (a white one of roughness 0.2 at
//!   `cos_o` 0.18 reflects 1.30 of what it receives, 1.03 at `cos_o` 0.5; at roughness 1
//!   at most 0.98; docs/scene-format.md has the table);
//! - a dielectric interface weighted `(1 - m) t` (`KHR_materials_transmission`): a thin wall
//!   (exact Fresnel; the transmitted direction is the reflected one mirrored through the
//!   surface, tinted by `c`; smooth, it passes straight through) or, with
//!   `KHR_materials_volume`, the rough dielectric of [`crate::microfacet`] tinted by `c`.
//!
//! A clear coat of strength `k` and roughness `r_c` (`KHR_materials_clearcoat`) lies over
//! all of it: the extension's `fresnel_coat`, the material above weighted by
//! `1 - k F_c(n.wo)` and a GGX lobe of alpha `r_c^2` without Fresnel by `k F_c(n.wo)`, F_c
//! Schlick's from 0.04 (ior 1.5) at the shading normal (the coat's own normal map is not
//! read).
//!
//! A sheen of colour `c_s` and roughness `r_s` (`KHR_materials_sheen`) lies between the
//! coat and the rest: the lobe of [`crate::sheen`] tinted by `c_s`, over the rest scaled by
//! the extension's `1 - max(c_s) E(n.wo)`, E the lobe's albedo (at most 1).
//!
//! Lobes are sampled in proportion to their estimated albedo at `wo`; the coat with
//! probability `k F_c(n.wo)`, its weight; then the sheen (uniformly over the hemisphere)
//! with probability `max(c_s) E(n.wo)`.

use std::f32::consts::{FRAC_1_PI, PI};

use glam::{Vec2, Vec3A, Vec4};
use pathlight_core::gpu_types::{
    GpuMaterial, TEXTURE_CLEARCOAT, TEXTURE_CLEARCOAT_ROUGHNESS, TEXTURE_MODEL,
    TEXTURE_SHEEN_COLOR, TEXTURE_SHEEN_ROUGHNESS, TEXTURE_SPECULAR, TEXTURE_SPECULAR_COLOR,
    TEXTURE_TRANSMISSION,
};

use crate::cpu_scene::CpuScene;
use crate::material::MODEL_PARAMS;
use crate::microfacet::{
    ALPHA_MIN, BsdfEval, BsdfSample, INVALID, continuous_sample, eval_rough_dielectric,
    fresnel_dielectric, ggx_d, ggx_g1, ggx_reflection, ggx_sample_visible,
    rough_dielectric_direction, sample_smooth_dielectric,
};
use crate::sampling::{Frame, sample_cone, sample_cosine_hemisphere};
use crate::sheen::{eval_sheen, sheen_reflectance};
use crate::surface::Surface;
use crate::textures::{has_texture, material_color, material_texture};

/// The model's parameters: its block of the material parameters, as
/// `pathlight_core::materials` lays it out (`metal_rough_block`), with its texture
/// applied. Twin of WGSL `MetalRoughParams`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MetalRoughParams {
    /// 0 dielectric, 1 metal.
    pub metallic: f32,
    /// Perceptual roughness; GGX alpha is its square.
    pub roughness: f32,
    /// Fraction of the dielectric base that transmits.
    pub transmission: f32,
    /// Index of refraction of the dielectric.
    pub ior: f32,
    /// Transmission through a thin wall rather than into a volume.
    pub thin: bool,
    /// Strength of the dielectric's specular reflection (`KHR_materials_specular`).
    pub specular: f32,
    /// Colour multiplying the dielectric's F0.
    pub specular_color: Vec3A,
    /// Strength of the clear coat (`KHR_materials_clearcoat`).
    pub clearcoat: f32,
    /// The coat's perceptual roughness.
    pub clearcoat_roughness: f32,
    /// Absorption coefficient per unit length inside a solid material.
    pub attenuation: Vec3A,
    /// Colour of the sheen (`KHR_materials_sheen`; black: none).
    pub sheen_color: Vec3A,
    /// The sheen's perceptual roughness.
    pub sheen_roughness: f32,
}

impl MetalRoughParams {
    /// The parameters in block `p`. Twin of WGSL `metal_rough_params`.
    #[inline(always)]
    pub fn decode(p: &[Vec4; MODEL_PARAMS]) -> Self {
        Self {
            metallic: p[0].x,
            roughness: p[0].y,
            transmission: p[0].z,
            ior: p[0].w,
            thin: p[1].x != 0.0,
            specular: p[1].y,
            specular_color: Vec3A::new(p[2].x, p[2].y, p[2].z),
            clearcoat: p[1].z,
            clearcoat_roughness: p[1].w,
            attenuation: Vec3A::new(p[3].x, p[3].y, p[3].z),
            sheen_color: Vec3A::new(p[4].x, p[4].y, p[4].z),
            sheen_roughness: p[4].w,
        }
    }

    /// Whether the material has neither clear coat, sheen nor transmission and is rough
    /// (GGX alpha at least `ALPHA_MIN`): a specular lobe over a diffuse base, which
    /// [`crate::metal_rough_lanes`] samples side by side.
    #[inline(always)]
    pub fn is_rough_opaque(&self) -> bool {
        self.clearcoat <= 0.0
            && self.sheen_color.max_element() <= 0.0
            && self.transmission == 0.0
            && self.roughness * self.roughness >= ALPHA_MIN
    }
}

/// The model's texture step on block `p`: metallic times the blue and roughness times the
/// green channel of its texture (slot [`TEXTURE_MODEL`], linear) at `uv`, then the
/// extensions' textures on their factors (glTF's channels; colours sRGB). Twin of WGSL
/// `metal_rough_textured`.
#[inline(always)]
pub fn metal_rough_textured(
    scene: &CpuScene,
    p: &mut [Vec4; MODEL_PARAMS],
    m: &GpuMaterial,
    uv: Vec2,
) {
    if has_texture(m, TEXTURE_MODEL) {
        let t = material_texture(scene, m, TEXTURE_MODEL, uv);
        p[0].y *= t.y;
        p[0].x *= t.z;
    }
    if m.texture_mask >> TEXTURE_TRANSMISSION == 0 {
        return;
    }
    let texel = |which: u32| material_texture(scene, m, which, uv);
    if has_texture(m, TEXTURE_TRANSMISSION) {
        p[0].z *= texel(TEXTURE_TRANSMISSION).x;
    }
    if has_texture(m, TEXTURE_SPECULAR) {
        p[1].y *= texel(TEXTURE_SPECULAR).w;
    }
    if has_texture(m, TEXTURE_SPECULAR_COLOR) {
        p[2] *= material_color(scene, m, TEXTURE_SPECULAR_COLOR, uv)
            .truncate()
            .extend(1.0);
    }
    if has_texture(m, TEXTURE_CLEARCOAT) {
        p[1].z *= texel(TEXTURE_CLEARCOAT).x;
    }
    if has_texture(m, TEXTURE_CLEARCOAT_ROUGHNESS) {
        p[1].w *= texel(TEXTURE_CLEARCOAT_ROUGHNESS).y;
    }
    if has_texture(m, TEXTURE_SHEEN_COLOR) {
        p[4] *= material_color(scene, m, TEXTURE_SHEEN_COLOR, uv)
            .truncate()
            .extend(1.0);
    }
    if has_texture(m, TEXTURE_SHEEN_ROUGHNESS) {
        p[4].w *= texel(TEXTURE_SHEEN_ROUGHNESS).w;
    }
}

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
    /// Weight of the dielectric's specular layer in `spec_f0` and `spec_f90` (the rest is
    /// the metal's).
    pub layer: f32,
    /// Schlick F0 of the dielectric's specular reflection, coloured (at most 1).
    pub f0_d: Vec3A,
    /// Its strength (`KHR_materials_specular`'s weight).
    pub specular: f32,
}

/// The lobe weights of `m` over base colour `color`. Twin of WGSL `mr_lobes`.
#[inline(always)]
pub fn lobes(m: &MetalRoughParams, color: Vec3A) -> Lobes {
    let r = (m.ior - 1.0) / (m.ior + 1.0);
    let f0_d = (r * r * m.specular_color).min(Vec3A::ONE);
    let dielectric = 1.0 - m.metallic;
    let base = dielectric * (1.0 - m.transmission);
    let layer = base * m.specular;
    Lobes {
        spec_f0: m.metallic * color + layer * f0_d,
        spec_f90: m.metallic + layer,
        diffuse: base,
        wall: dielectric * m.transmission,
        layer,
        f0_d,
        specular: m.specular,
    }
}

/// Schlick's Fresnel between `f0` and `f90`. Twin of WGSL `schlick`.
#[inline(always)]
pub fn schlick(f0: Vec3A, f90: f32, cos_i: f32) -> Vec3A {
    f0 + (Vec3A::splat(f90) - f0) * (1.0 - cos_i.clamp(0.0, 1.0)).powi(5)
}

/// What the dielectric's specular layer passes to the diffuse base at `cos_i` (the cosine
/// with the half vector): glTF's `fresnel_mix`, `1 - specular max(F)`, F its coloured
/// Schlick Fresnel rising to 1. Twin of WGSL `mr_coupling`.
#[inline(always)]
fn coupling(l: &Lobes, cos_i: f32) -> f32 {
    1.0 - l.specular * schlick(l.f0_d, 1.0, cos_i).max_element()
}

/// Estimated albedos of the specular lobe, the diffuse base and the interface at `cos_o`.
/// Twin of WGSL `mr_lobe_albedos`.
#[inline(always)]
fn lobe_albedos(color: Vec3A, l: &Lobes, cos_o: f32) -> Vec3A {
    let lum = Vec3A::new(0.2126, 0.7152, 0.0722);
    let spec = schlick(l.spec_f0, l.spec_f90, cos_o).dot(lum);
    let diffuse = l.diffuse * color.dot(lum) * coupling(l, cos_o);
    Vec3A::new(spec, diffuse, l.wall)
}

/// Probabilities of sampling the specular lobe, the diffuse base and the interface. Twin
/// of WGSL `mr_probabilities`.
#[inline(always)]
fn probabilities(color: Vec3A, l: &Lobes, cos_o: f32) -> Vec3A {
    let albedos = lobe_albedos(color, l, cos_o);
    let total = albedos.element_sum();
    if total > 0.0 {
        albedos / total
    } else {
        Vec3A::ZERO
    }
}

/// The continuous part of the BSDF: the coat over the sheen over the rest. Twin of WGSL
/// `eval_metal_rough`.
#[inline(always)]
pub fn eval(m: &MetalRoughParams, color: Vec3A, s: &Surface, wo: Vec3A, wi: Vec3A) -> BsdfEval {
    let mut base = eval_base(m, color, s, wo, wi);
    if m.sheen_color.max_element() > 0.0 {
        base = sheen_over(m, color, s, wo, wi, base);
    }
    if m.clearcoat <= 0.0 {
        return base;
    }
    let sign = if wo.dot(s.ng) >= 0.0 { 1.0 } else { -1.0 };
    // The coat's own shading normal.
    let (ng, n) = (s.ng * sign, s.nc * sign);
    let weight = coat_weight(m, wo.dot(n));
    let mut out = BsdfEval {
        f: base.f * (1.0 - weight),
        pdf: base.pdf * (1.0 - weight),
    };
    let alpha = m.clearcoat_roughness * m.clearcoat_roughness;
    if alpha >= ALPHA_MIN && wi.dot(ng) > 0.0 && wi.dot(n) > 0.0 && wo.dot(n) > 0.0 {
        let frame = Frame::around(n);
        let (wo_l, wi_l) = (frame.to_local(wo), frame.to_local(wi));
        let h = (wo_l + wi_l).normalize();
        let d = ggx_d(h, alpha);
        let g1o = ggx_g1(wo_l, alpha);
        out.f += Vec3A::splat(weight * d * g1o * ggx_g1(wi_l, alpha) / (4.0 * wo_l.z));
        out.pdf += weight * g1o * d / (4.0 * wo_l.z);
    }
    out
}

/// The probability of sampling the sheen rather than the layer under it: its estimated
/// albedo at `cos_o`, `max(c_s) E`, over that plus the layer's, scaled (1 without a layer
/// to sample). Twin of WGSL `mr_sheen_probability`.
#[inline(always)]
fn sheen_probability(m: &MetalRoughParams, color: Vec3A, cos_o: f32) -> f32 {
    let sheen = m.sheen_color.max_element() * sheen_reflectance(cos_o, m.sheen_roughness);
    let under = (1.0 - sheen) * lobe_albedos(color, &lobes(m, color), cos_o).element_sum();
    if under > 0.0 {
        sheen / (sheen + under)
    } else {
        1.0
    }
}

/// What the sheen lets through to the layer under it at `cos_o`: the extension's albedo
/// scaling in its `VdotN` form, `1 - max(c_s) E(cos_o)`, which keeps a white sheen over a
/// white base at albedo 1 (the reciprocal form, with `max(E(cos_o), E(cos_i))`, loses up to
/// 10% of it). Twin of WGSL `mr_sheen_scaling`.
#[inline(always)]
fn sheen_scaling(m: &MetalRoughParams, cos_o: f32) -> f32 {
    1.0 - m.sheen_color.max_element() * sheen_reflectance(cos_o, m.sheen_roughness)
}

/// The sheen over `under` (the layer below it, evaluated). Twin of WGSL `mr_sheen_over`.
#[inline(always)]
fn sheen_over(
    m: &MetalRoughParams,
    color: Vec3A,
    s: &Surface,
    wo: Vec3A,
    wi: Vec3A,
    under: BsdfEval,
) -> BsdfEval {
    let sign = if wo.dot(s.ng) >= 0.0 { 1.0 } else { -1.0 };
    let (ng, n) = (s.ng * sign, s.ns * sign);
    let (cos_o, cos_i) = (wo.dot(n), wi.dot(n));
    let q = sheen_probability(m, color, cos_o);
    let mut out = BsdfEval {
        f: under.f * sheen_scaling(m, cos_o),
        pdf: under.pdf * (1.0 - q),
    };
    if cos_o > 0.0 && cos_i > 0.0 && wi.dot(ng) > 0.0 {
        let cos_h = (wo + wi).normalize().dot(n);
        out.f += m.sheen_color * eval_sheen(m.sheen_roughness, cos_o, cos_i, cos_h);
        out.pdf += q / (2.0 * PI);
    }
    out
}

/// The coat's weight at `cos_o` (the cosine of `wo` with the shading normal): its strength
/// times Schlick's Fresnel from 0.04, which is also its sampling probability. Twin of WGSL
/// `mr_coat_weight`.
#[inline(always)]
fn coat_weight(m: &MetalRoughParams, cos_o: f32) -> f32 {
    m.clearcoat * schlick(Vec3A::splat(0.04), 1.0, cos_o).x
}

/// The continuous part of the BSDF under the coat. Twin of WGSL `eval_metal_rough_base`.
#[inline(always)]
fn eval_base(m: &MetalRoughParams, color: Vec3A, s: &Surface, wo: Vec3A, wi: Vec3A) -> BsdfEval {
    let sign = if wo.dot(s.ng) >= 0.0 { 1.0 } else { -1.0 };
    let (ng, n) = (s.ng * sign, s.ns * sign);
    let l = lobes(m, color);
    let (cos_o, cos_i) = (wo.dot(n), wi.dot(n));
    let probs = probabilities(color, &l, cos_o);
    let alpha = m.roughness * m.roughness;
    let thin = m.thin;
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
            // glTF's fresnel_mix: what the specular layer's Fresnel at the half vector passes.
            let passed = coupling(&l, wo.dot((wo + wi).normalize()));
            out.f += l.diffuse * passed * color * (cos_i * FRAC_1_PI);
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
            let e = eval_rough_dielectric(m.ior, color, 1.0, s, wo, wi, alpha);
            out.f += l.wall * e.f;
            out.pdf += probs.z * e.pdf;
        }
    }
    out
}

/// `eval / pdf` of a continuous sample; a thin wall refracts nothing. Twin of WGSL
/// `mr_mixture_sample`.
#[inline(always)]
fn mixture_sample(
    m: &MetalRoughParams,
    color: Vec3A,
    s: &Surface,
    wo: Vec3A,
    wi: Vec3A,
) -> BsdfSample {
    let ior = if m.thin { 1.0 } else { m.ior };
    continuous_sample(eval(m, color, s, wo, wi), s, wo, wi, ior)
}

/// A delta sample of weight `weight`.
#[inline(always)]
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

/// Samples an incident direction: the coat with probability its weight, else the
/// material under it. Twin of WGSL `sample_metal_rough`.
#[inline(always)]
pub fn sample(
    m: &MetalRoughParams,
    color: Vec3A,
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
    // The coat, about its own shading normal.
    let nc = s.nc * sign;
    let cos_c = wo.dot(nc);
    let coat = if m.clearcoat > 0.0 {
        coat_weight(m, cos_c)
    } else {
        0.0
    };
    if u_lobe < coat {
        let alpha = m.clearcoat_roughness * m.clearcoat_roughness;
        if alpha < ALPHA_MIN {
            // A mirror coat: its weight over its probability is 1.
            let wi = 2.0 * cos_c * nc - wo;
            return delta(wi, Vec3A::ONE, wi.dot(ng) > 0.0);
        }
        let frame = Frame::around(nc);
        return match ggx_reflection(&frame, frame.to_local(wo), alpha, u) {
            Some(wi) => mixture_sample(m, color, s, wo, wi),
            None => INVALID,
        };
    }
    // The material under the coat, from what is left of u_lobe: the sheen, or under it.
    let u_lobe = (u_lobe - coat) / (1.0 - coat);
    if m.sheen_color.max_element() <= 0.0 {
        return sample_base(m, color, s, wo, u_lobe, u_fresnel, u);
    }
    let q = sheen_probability(m, color, cos_o);
    if u_lobe < q {
        let wi = sample_cone(n, 1.0, u);
        if wi.dot(ng) <= 0.0 {
            return INVALID;
        }
        return mixture_sample(m, color, s, wo, wi);
    }
    let mut bs = sample_base(m, color, s, wo, (u_lobe - q) / (1.0 - q), u_fresnel, u);
    if bs.delta {
        bs.weight *= sheen_scaling(m, cos_o) / (1.0 - q);
    }
    bs
}

/// Samples the material under the coat and the sheen. Twin of WGSL `sample_metal_rough_base`.
#[inline(always)]
fn sample_base(
    m: &MetalRoughParams,
    color: Vec3A,
    s: &Surface,
    wo: Vec3A,
    u_lobe: f32,
    u_fresnel: f32,
    u: Vec2,
) -> BsdfSample {
    let sign = if wo.dot(s.ng) >= 0.0 { 1.0 } else { -1.0 };
    let (ng, n) = (s.ng * sign, s.ns * sign);
    let cos_o = wo.dot(n);
    let l = lobes(m, color);
    let probs = probabilities(color, &l, cos_o);
    let alpha = m.roughness * m.roughness;
    let frame = Frame::around(n);
    let wo_l = frame.to_local(wo);
    if u_lobe < probs.x {
        if alpha < ALPHA_MIN {
            let wi = 2.0 * cos_o * n - wo;
            if wi.dot(ng) <= 0.0 {
                return INVALID;
            }
            return delta(wi, schlick(l.spec_f0, l.spec_f90, cos_o) / probs.x, true);
        }
        return match ggx_reflection(&frame, wo_l, alpha, u) {
            Some(wi) => mixture_sample(m, color, s, wo, wi),
            None => INVALID,
        };
    }
    if u_lobe < probs.x + probs.z {
        if m.thin {
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
            return mixture_sample(m, color, s, wo, frame.to_world(wi_l));
        }
        if alpha < ALPHA_MIN {
            let mut bs = sample_smooth_dielectric(m.ior, color, 1.0, s, wo, u_fresnel);
            bs.weight *= l.wall / probs.z;
            return bs;
        }
        return match rough_dielectric_direction(m.ior, s, wo, alpha, u_fresnel, u) {
            Some(wi) => mixture_sample(m, color, s, wo, wi),
            None => INVALID,
        };
    }
    let wi = frame.to_world(sample_cosine_hemisphere(u));
    if wi.dot(ng) <= 0.0 {
        return INVALID;
    }
    mixture_sample(m, color, s, wo, wi)
}

/// The albedo a denoiser reads: the specular F0, the diffuse base's colour under what the
/// specular layer lets through at normal incidence, and the tinted wall, under the sheen's
/// albedo at normal incidence. Twin of WGSL `metal_rough_albedo`.
#[inline(always)]
pub fn metal_rough_albedo(m: &MetalRoughParams, color: Vec3A) -> Vec3A {
    let l = lobes(m, color);
    let under = l.spec_f0 + (l.diffuse * coupling(&l, 1.0)) * color + l.wall * color;
    let sheen = sheen_reflectance(1.0, m.sheen_roughness);
    let base = under * (1.0 - m.sheen_color.max_element() * sheen) + m.sheen_color * sheen;
    let coat = coat_weight(m, 1.0);
    base * (1.0 - coat) + Vec3A::splat(coat)
}

/// Whether the model has a non-delta lobe. Twin of WGSL `has_continuous_metal_rough`.
#[inline(always)]
pub fn has_continuous_metal_rough(m: &MetalRoughParams, color: Vec3A) -> bool {
    lobes(m, color).diffuse > 0.0
        || m.roughness * m.roughness >= ALPHA_MIN
        || (m.clearcoat > 0.0 && m.clearcoat_roughness * m.clearcoat_roughness >= ALPHA_MIN)
        || m.sheen_color.max_element() > 0.0
}
