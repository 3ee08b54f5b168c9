//! The BSDF samples of paths on glTF's metallic-roughness material without clear coat,
//! sheen or transmission, and rough (most glTF files' every material: a GGX specular lobe
//! over a diffuse base, from metal to dielectric) for [`SampleLanes`]: the lobe choice by
//! the lobes' estimated albedos, the visible GGX normal's reflection or a cosine-weighted
//! direction, and the mixture's evaluation there (the base under glTF's `fresnel_mix`, the
//! Schlick-weighted GGX lobe); and the same evaluation towards a light sample. The values
//! are `metal_rough::sample`'s and `metal_rough::eval`'s bit for bit (through
//! `sample_base`, `eval_base` and `continuous_sample`), and a test holds each lane to them.

use std::f32::consts::FRAC_1_PI;

use glam::Vec3A;

use crate::bsdf_lanes::{LaneBsdf, LaneEval, LaneSample, LaneVertex, SampleLanes, Side, side};
use crate::metal_rough::{MetalRoughParams, lobes};
use crate::packet::PACKET;
use crate::soa::{
    Lanes3, add, at, cosine_hemisphere, dot, ggx_d, ggx_g1, ggx_sample_visible, max_ps, normalize,
    set_lane, to_local, to_world,
};

/// Lanes on glTF's opaque rough materials waiting for their BSDF samples.
pub type MetalRoughLanes = SampleLanes<RoughOpaque>;

/// Per lane, the weights of an opaque rough metallic-roughness material
/// ([`MetalRoughParams::is_rough_opaque`]) that do not depend on the base colour: what
/// `metal_rough::lobes` computes of them, and GGX alpha.
#[derive(Debug, Clone)]
pub struct RoughOpaque {
    alpha: [f32; PACKET],
    metallic: [f32; PACKET],
    /// The dielectric specular layer's weight, its reflectance at grazing incidence and at
    /// normal incidence (coloured, at most 1), and `KHR_materials_specular`'s strength.
    layer: [f32; PACKET],
    spec_f90: [f32; PACKET],
    f0_d: Lanes3,
    specular: [f32; PACKET],
    /// The diffuse base's and the interface's weights (the interface's zero).
    diffuse: [f32; PACKET],
    wall: [f32; PACKET],
}

impl Default for RoughOpaque {
    fn default() -> Self {
        Self {
            alpha: [1.0; PACKET],
            metallic: [0.0; PACKET],
            layer: [0.0; PACKET],
            spec_f90: [0.0; PACKET],
            f0_d: [[0.0; PACKET]; 3],
            specular: [0.0; PACKET],
            diffuse: [0.0; PACKET],
            wall: [0.0; PACKET],
        }
    }
}

impl LaneBsdf for RoughOpaque {
    type Params = MetalRoughParams;

    #[inline(always)]
    fn set(&mut self, l: usize, m: &MetalRoughParams) {
        // The weights `lobes` gives whatever the colour (its `spec_f0` is recomputed per lane).
        let w = lobes(m, Vec3A::ZERO);
        self.alpha[l] = m.roughness * m.roughness;
        self.metallic[l] = m.metallic;
        self.layer[l] = w.layer;
        self.spec_f90[l] = w.spec_f90;
        set_lane(&mut self.f0_d, l, w.f0_d);
        self.specular[l] = w.specular;
        self.diffuse[l] = w.diffuse;
        self.wall[l] = w.wall;
    }

    #[inline(always)]
    fn sample(&self, l: usize, v: &LaneVertex) -> LaneSample {
        sample_lane(v, &self.weights(l, v))
    }

    #[inline(always)]
    fn eval(&self, l: usize, v: &LaneVertex, wi: [f32; 3]) -> LaneEval {
        let side = side(v);
        let w = self.weights(l, v);
        let probs = probabilities(v, &w, dot(v.wo, side.n));
        eval_lane(v, &side, &w, probs, wi)
    }
}

impl RoughOpaque {
    /// Lane `l`'s weights at vertex `v` (its base colour).
    #[inline(always)]
    fn weights(&self, l: usize, v: &LaneVertex) -> Weights {
        let (metallic, layer, f0_d) = (self.metallic[l], self.layer[l], at(&self.f0_d, l));
        Weights {
            alpha: self.alpha[l],
            // `metallic * color + layer * f0_d`, channel by channel.
            spec_f0: [
                metallic * v.color[0] + layer * f0_d[0],
                metallic * v.color[1] + layer * f0_d[1],
                metallic * v.color[2] + layer * f0_d[2],
            ],
            spec_f90: self.spec_f90[l],
            f0_d,
            specular: self.specular[l],
            diffuse: self.diffuse[l],
            wall: self.wall[l],
        }
    }
}

/// One lane's `metal_rough::Lobes` and GGX alpha.
struct Weights {
    alpha: f32,
    spec_f0: [f32; 3],
    spec_f90: f32,
    f0_d: [f32; 3],
    specular: f32,
    diffuse: f32,
    wall: f32,
}

/// Rec. 709 luminance, as `mr_lobe_albedos` weighs the lobes' reflectances.
const LUMINANCE: [f32; 3] = [0.2126, 0.7152, 0.0722];

/// `schlick(f0, f90, cos_i)`.
#[inline(always)]
fn schlick(f0: [f32; 3], f90: f32, cos_i: f32) -> [f32; 3] {
    let p = (1.0 - cos_i.clamp(0.0, 1.0)).powi(5);
    [
        f0[0] + (f90 - f0[0]) * p,
        f0[1] + (f90 - f0[1]) * p,
        f0[2] + (f90 - f0[2]) * p,
    ]
}

/// `coupling`: what the dielectric's specular layer passes to the base at `cos_i`.
#[inline(always)]
fn coupling(w: &Weights, cos_i: f32) -> f32 {
    let f = schlick(w.f0_d, 1.0, cos_i);
    // `Vec3A::max_element`: the larger of x and y, then of that and z.
    1.0 - w.specular * max_ps(max_ps(f[0], f[1]), f[2])
}

/// `probabilities` of the specular lobe and the diffuse base at `cos_o` (the interface's
/// is zero, and `sample_base` never takes it).
#[inline(always)]
fn probabilities(v: &LaneVertex, w: &Weights, cos_o: f32) -> [f32; 2] {
    let spec = dot(schlick(w.spec_f0, w.spec_f90, cos_o), LUMINANCE);
    let diffuse = w.diffuse * dot(v.color, LUMINANCE) * coupling(w, cos_o);
    // `Vec3A::element_sum`.
    let total = spec + diffuse + w.wall;
    if total > 0.0 {
        [spec / total, diffuse / total]
    } else {
        [0.0, 0.0]
    }
}

/// `metal_rough::sample` of an opaque rough material: `sample_base`'s GGX reflection or
/// cosine-weighted direction, then `eval_base` and `continuous_sample` at the direction.
#[inline(always)]
fn sample_lane(v: &LaneVertex, w: &Weights) -> LaneSample {
    let side = side(v);
    let Side { ng, n, frame, wo_l } = side;
    let cos_o = dot(v.wo, n);
    let probs = probabilities(v, w, cos_o);
    // Both lobes' directions (they share the square root and the sine and cosine of `u`),
    // then the one chosen.
    let h = ggx_sample_visible(wo_l, w.alpha, v.u);
    let twice_cos = 2.0 * dot(wo_l, h);
    let reflected: [f32; 3] = std::array::from_fn(|i| twice_cos * h[i] - wo_l[i]);
    let diffused = cosine_hemisphere(v.u[0], v.u[1]);
    let specular = v.u_lobe < probs[0];
    let wi_l = if specular { reflected } else { diffused };
    let wi = to_world(&frame, wi_l);
    let sampled = cos_o > 0.0
        && if specular {
            reflected[2] > 0.0
        } else {
            dot(wi, ng) > 0.0
        };
    LaneSample::reflected(sampled, wi, eval_lane(v, &side, w, probs, wi))
}

/// `eval_base` of an opaque rough material at `wi`, the lobes sampled with probabilities
/// `probs`: the diffuse base under `fresnel_mix`, then the specular lobe.
#[inline(always)]
fn eval_lane(v: &LaneVertex, side: &Side, w: &Weights, probs: [f32; 2], wi: [f32; 3]) -> LaneEval {
    let Side { ng, n, frame, wo_l } = *side;
    let (wo, color) = (v.wo, v.color);
    let cos_o = dot(wo, n);
    let cos_i = dot(wi, n);
    let seen = cos_o > 0.0 && dot(wi, ng) > 0.0 && cos_i > 0.0;
    let diffuse = seen && w.diffuse > 0.0;
    let passed = coupling(w, dot(wo, normalize(add(wo, wi))));
    let base = w.diffuse * passed;
    let cos_pi = cos_i * FRAC_1_PI;
    let wi_l = to_local(&frame, wi);
    let h = normalize(add(wo_l, wi_l));
    let d = ggx_d(h, w.alpha);
    let g1_o = ggx_g1(wo_l, w.alpha);
    let spec = d * g1_o * ggx_g1(wi_l, w.alpha) / (4.0 * wo_l[2]);
    let pdf_r = g1_o * d / (4.0 * wo_l[2]);
    let reflectance = schlick(w.spec_f0, w.spec_f90, dot(wo_l, h));
    // Not `array::map`, whose closure may be left out of line.
    let channel = |i: usize| {
        let d = if diffuse {
            base * color[i] * cos_pi
        } else {
            0.0
        };
        let s = if seen { reflectance[i] * spec } else { 0.0 };
        0.0 + d + s
    };
    let pdf_d = if diffuse {
        probs[1] * cos_i * FRAC_1_PI
    } else {
        0.0
    };
    let pdf_s = if seen { probs[0] * pdf_r } else { 0.0 };
    LaneEval {
        f: [channel(0), channel(1), channel(2)],
        pdf: 0.0 + pdf_d + pdf_s,
    }
}

#[cfg(test)]
mod tests {
    use glam::{Vec3A, Vec4};

    use super::*;
    use crate::bsdf_lanes::tests::assert_lanes_as_one_path;
    use crate::material::MODEL_PARAMS;
    use crate::metal_rough::{eval, sample};

    /// Every lane's sample, and its evaluation towards a light sample, are
    /// `metal_rough::sample`'s and `metal_rough::eval`'s for an opaque rough material bit
    /// for bit (`assert_lanes_as_one_path`): metals, dielectrics and mixtures of the two,
    /// specular strengths from 0 to 1 and coloured, indices of refraction, roughnesses from
    /// nearly smooth to 1, every lobe chosen. It fails with an operation regrouped (the
    /// diffuse term's factors taken in another order, the luminance summed otherwise).
    #[test]
    fn lanes_sample_as_metal_rough_bit_for_bit() {
        let outcomes = assert_lanes_as_one_path::<RoughOpaque>(
            0x1f83_d9ab,
            (sample, eval),
            |l, next| {
                let mut block = [Vec4::ZERO; MODEL_PARAMS];
                let metallic = [0.0, 1.0, next()][l % 3];
                let roughness = 0.04 + 0.96 * next();
                let ior = [1.5, 1.0 + next(), 2.4][l % 3];
                block[0] = Vec4::new(metallic, roughness, 0.0, ior);
                let specular = [1.0, 0.0, next()][l % 3];
                block[1] = Vec4::new(0.0, specular, 0.0, 0.0);
                let specular_color = if l % 4 == 0 {
                    Vec3A::new(next(), next(), next()) * 3.0
                } else {
                    Vec3A::ONE
                };
                block[2] = specular_color.extend(0.0);
                let m = MetalRoughParams::decode(&block);
                assert!(m.is_rough_opaque());
                m
            },
            // The specular lobe's samples: a glossy reflection, not a cosine-weighted one
            // (the diffuse lobe samples lie anywhere on the hemisphere).
            |bs, m| bs.pdf > 0.0 && m.metallic == 1.0,
        );
        // Invalid samples, valid ones of metals and of the rest, and evaluations not zero
        // were all met often.
        assert!(outcomes.iter().all(|&n| n > 300), "{outcomes:?}");
    }
}
