//! The BSDF samples of paths on rough glass (the lobes model with its rough transmission
//! lobe alone) for [`SampleLanes`]: the visible GGX normal, the Fresnel choice between its
//! reflection and refraction, and the mixture's evaluation there (`eval_rough_dielectric`,
//! read twice over for its density), the longest chain of dependent square roots and
//! divisions of any bounce; and the same evaluation towards a light sample. The values are
//! the one-path functions' bit for bit (`sample_lobes` through `rough_dielectric_direction`,
//! `eval_lobes` and `continuous_sample`), and a test holds each lane to `sample_lobes` and
//! `eval_lobes`.

use crate::bsdf_lanes::{LaneBsdf, LaneEval, LaneSample, LaneVertex, SampleLanes};
use crate::lobes::LobesParams;
use crate::microfacet::fresnel_dielectric_local;
use crate::packet::PACKET;
use crate::soa::{
    add, dot, frame_around, ggx_d, ggx_g1, ggx_sample_visible, normalize, scale, to_local, to_world,
};

/// Rough glass lanes waiting for their BSDF samples.
pub type GlassLanes = SampleLanes<RoughGlass>;

/// Per lane, rough glass's inside index of refraction, GGX alpha and the transmission's tint.
#[derive(Debug, Clone)]
pub struct RoughGlass {
    ior: [f32; PACKET],
    alpha: [f32; PACKET],
    tint: [f32; PACKET],
}

impl Default for RoughGlass {
    fn default() -> Self {
        Self {
            ior: [1.0; PACKET],
            alpha: [1.0; PACKET],
            tint: [0.0; PACKET],
        }
    }
}

impl LaneBsdf for RoughGlass {
    type Params = LobesParams;

    #[inline(always)]
    fn set(&mut self, l: usize, m: &LobesParams) {
        let alpha = m.refract_roughness * m.refract_roughness;
        (self.ior[l], self.alpha[l], self.tint[l]) = (m.ior, alpha, m.refract_tint);
    }

    #[inline(always)]
    fn sample(&self, l: usize, v: &LaneVertex) -> LaneSample {
        sample_lane(v, self.ior[l], self.alpha[l], self.tint[l])
    }

    #[inline(always)]
    fn eval(&self, l: usize, v: &LaneVertex, wi: [f32; 3]) -> LaneEval {
        let frame = frame_around(v.ns);
        let wo_l = to_local(&frame, v.wo);
        eval_lane(
            v,
            &frame,
            wo_l,
            wi,
            self.ior[l],
            self.alpha[l],
            self.tint[l],
        )
    }
}

/// `sample_lobes` of rough glass alone: `rough_dielectric_direction`, then `eval_lobes`
/// (`eval_rough_dielectric` with weight 1) and `continuous_sample` at the direction.
#[inline(always)]
fn sample_lane(v: &LaneVertex, ior: f32, alpha: f32, tint: f32) -> LaneSample {
    let LaneVertex {
        ns,
        ng,
        wo,
        u_fresnel,
        u,
        ..
    } = *v;
    // `rough_dielectric_direction`.
    let frame = frame_around(ns);
    let wo_l = to_local(&frame, wo);
    let h = ggx_sample_visible(wo_l, alpha, u);
    let cos_oh = dot(wo_l, h);
    let reflect = u_fresnel < fresnel_dielectric_local(cos_oh, ior);
    let (eta, hf, c) = if cos_oh >= 0.0 {
        (ior, h, cos_oh)
    } else {
        (1.0 / ior, h.map(|v| -v), -cos_oh)
    };
    let sin2_t = (1.0 - c * c) / (eta * eta);
    let bend = c / eta - (1.0 - sin2_t).sqrt();
    let wi_l: [f32; 3] = std::array::from_fn(|i| {
        if reflect {
            2.0 * cos_oh * h[i] - wo_l[i]
        } else {
            -wo_l[i] / eta + bend * hf[i]
        }
    });
    let sampled =
        wo_l[2] != 0.0 && (reflect || sin2_t < 1.0) && (wi_l[2] * wo_l[2] > 0.0) == reflect;
    let wi = to_world(&frame, wi_l);
    let LaneEval { f, pdf } = eval_lane(v, &frame, wo_l, wi, ior, alpha, tint);
    // `continuous_sample`.
    let (wo_front, wi_front) = (dot(wo, ng) >= 0.0, dot(wi, ng) >= 0.0);
    let eta = if wo_front == wi_front {
        1.0
    } else if wo_front {
        ior
    } else {
        1.0 / ior
    };
    LaneSample {
        valid: sampled && pdf > 0.0 && pdf.is_finite(),
        wi,
        weight: f.map(|v| v / pdf),
        pdf,
        eta,
    }
}

/// `eval_lobes` of rough glass alone at `wi`, in the frame `frame` around the vertex's
/// shading normal where `wo` is `wo_l`: `eval_rough_dielectric`, with weight 1 in the
/// mixture's sum.
#[inline(always)]
fn eval_lane(
    v: &LaneVertex,
    frame: &[[f32; 3]; 3],
    wo_l: [f32; 3],
    wi: [f32; 3],
    ior: f32,
    alpha: f32,
    tint: f32,
) -> LaneEval {
    let LaneVertex { ng, wo, color, .. } = *v;
    let wi_l = to_local(frame, wi);
    let (cos_o, cos_i) = (wo_l[2], wi_l[2]);
    let (wo_front, wi_front) = (dot(wo, ng) >= 0.0, dot(wi, ng) >= 0.0);
    let reflect = cos_o * cos_i > 0.0;
    let etap = if reflect {
        1.0
    } else if cos_o > 0.0 {
        ior
    } else {
        1.0 / ior
    };
    let m = add(scale(etap, wi_l), wo_l);
    let mut seen = cos_o != 0.0 && cos_i != 0.0 && reflect == (wo_front == wi_front);
    seen &= dot(m, m) != 0.0;
    let m = normalize(m);
    let m = if m[2] < 0.0 { m.map(|v| -v) } else { m };
    let (cos_im, cos_om) = (dot(m, wi_l), dot(m, wo_l));
    seen &= !(cos_im * cos_i < 0.0 || cos_om * cos_o < 0.0);
    let fr = fresnel_dielectric_local(cos_om, ior);
    let d = ggx_d(m, alpha);
    let g1_o = ggx_g1(wo_l, alpha);
    let g = g1_o * ggx_g1(wi_l, alpha);
    let pdf_m = g1_o * cos_om.abs() * d / cos_o.abs();
    let (f, pdf) = if reflect {
        let f = d * g * fr / (4.0 * cos_o.abs());
        ([f; 3], pdf_m / (4.0 * cos_om.abs()) * fr)
    } else {
        let denom = (cos_im + cos_om / etap) * (cos_im + cos_om / etap);
        let ft =
            (1.0 - fr) * d * g * (cos_im * cos_om).abs() / (cos_o.abs() * denom) / (etap * etap);
        let f = color.map(|c| ((1.0 - tint) + c * tint) * ft);
        (f, pdf_m * cos_im.abs() / denom * (1.0 - fr))
    };
    // `eval_lobes`' sum over its one lobe.
    LaneEval {
        f: f.map(|v| 0.0 + 1.0 * if seen { v } else { 0.0 }),
        pdf: 0.0 + 1.0 * if seen { pdf } else { 0.0 },
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec4;

    use super::*;
    use crate::bsdf_lanes::tests::assert_lanes_as_one_path;
    use crate::lobes::{eval_lobes, sample_lobes};
    use crate::material::MODEL_PARAMS;

    /// Every lane's sample, and its evaluation towards a light sample, are `sample_lobes`'s
    /// and `eval_lobes`'s for rough glass alone bit for bit (`assert_lanes_as_one_path`): indices above and below 1 (thin films of air),
    /// roughnesses from nearly smooth to 1, tints, Fresnel draws choosing each branch, total
    /// internal reflection. It fails with an operation regrouped (a quotient taken as a
    /// product by the reciprocal, a density's factors grouped otherwise).
    #[test]
    fn lanes_sample_as_sample_lobes_bit_for_bit() {
        let outcomes = assert_lanes_as_one_path::<RoughGlass>(
            0x51ed_270b,
            (sample_lobes, eval_lobes),
            |l, next| {
                let mut block = [Vec4::ZERO; MODEL_PARAMS];
                let ior = [1.5, 1.33, 0.75, 2.4][l % 4];
                let roughness = 0.04 + 0.96 * next();
                let tint = [0.0, 1.0, next()][l % 3];
                block[0].w = 1.0;
                block[1] = Vec4::new(tint, ior, roughness, 0.0);
                let m = LobesParams::decode(&block);
                assert!(m.is_rough_glass());
                m
            },
            |sample, _| sample.eta != 1.0,
        );
        // Invalid samples, reflections, refractions and evaluations not zero were all met
        // often.
        assert!(outcomes.iter().all(|&n| n > 300), "{outcomes:?}");
    }
}
