//! The BSDF samples of paths on a rough mirror (the lobes model with its rough specular
//! lobe alone: a conductor of complex index, or Schlick's Fresnel from the specular colour)
//! for [`SampleLanes`]: the visible GGX normal, its reflection, and the mixture's evaluation
//! there (the Fresnel term, D and the two G1); and the same evaluation towards a light
//! sample. The values are the one-path functions' bit for bit (`sample_lobes` through
//! `ggx_reflection`, `eval_lobes` and `continuous_sample`), and a test holds each lane to
//! `sample_lobes` and `eval_lobes`.

use crate::bsdf_lanes::{LaneBsdf, LaneEval, LaneSample, LaneVertex, SampleLanes, Side, side};
use crate::lobes::LobesParams;
use crate::packet::PACKET;
use crate::soa::{
    Lanes3, add, at, dot, ggx_d, ggx_g1, ggx_sample_visible, max_ps, normalize, set_lane, to_local,
    to_world,
};

/// Rough mirror lanes waiting for their BSDF samples.
pub type GlossyLanes = SampleLanes<RoughMirror>;

/// Per lane, a rough mirror's GGX alpha, whether its Fresnel is a conductor's, its
/// specular tint (Schlick's), and its complex index of refraction (a conductor's).
#[derive(Debug, Clone)]
pub struct RoughMirror {
    alpha: [f32; PACKET],
    conductor: [bool; PACKET],
    tint: [f32; PACKET],
    eta: Lanes3,
    k: Lanes3,
}

impl Default for RoughMirror {
    fn default() -> Self {
        Self {
            alpha: [1.0; PACKET],
            conductor: [false; PACKET],
            tint: [0.0; PACKET],
            eta: [[1.0; PACKET]; 3],
            k: [[0.0; PACKET]; 3],
        }
    }
}

impl LaneBsdf for RoughMirror {
    type Params = LobesParams;

    #[inline(always)]
    fn set(&mut self, l: usize, m: &LobesParams) {
        self.alpha[l] = m.specular_roughness * m.specular_roughness;
        self.conductor[l] = m.conductor;
        self.tint[l] = m.specular_tint;
        set_lane(&mut self.eta, l, m.eta);
        set_lane(&mut self.k, l, m.k);
    }

    #[inline(always)]
    fn sample(&self, l: usize, v: &LaneVertex) -> LaneSample {
        sample_lane(v, self.alpha[l], &self.fresnel(l, v))
    }

    #[inline(always)]
    fn eval(&self, l: usize, v: &LaneVertex, wi: [f32; 3]) -> LaneEval {
        eval_lane(v, &side(v), wi, self.alpha[l], &self.fresnel(l, v))
    }
}

impl RoughMirror {
    /// Lane `l`'s Fresnel term at vertex `v`.
    #[inline(always)]
    fn fresnel(&self, l: usize, v: &LaneVertex) -> Fresnel {
        Fresnel {
            conductor: self.conductor[l],
            tint: self.tint[l],
            color: v.color,
            eta: at(&self.eta, l),
            k: at(&self.k, l),
        }
    }
}

/// What the specular lobe's reflectance reads.
struct Fresnel {
    conductor: bool,
    tint: f32,
    color: [f32; 3],
    eta: [f32; 3],
    k: [f32; 3],
}

/// `fresnel_conductor`, one channel.
#[inline(always)]
fn fresnel_conductor(cos_i: f32, eta: f32, k: f32) -> f32 {
    let cos2 = cos_i * cos_i;
    let sin2 = 1.0 - cos2;
    let eta2 = eta * eta;
    let k2 = k * k;
    let t0 = eta2 - k2 - sin2;
    let a2pb2 = max_ps(t0 * t0 + 4.0 * eta2 * k2, 0.0).sqrt();
    let a = max_ps(0.5 * (a2pb2 + t0), 0.0).sqrt();
    let t1 = a2pb2 + cos2;
    let t2 = 2.0 * cos_i * a;
    let rs = (t1 - t2) / max_ps(t1 + t2, 1e-20);
    let t3 = cos2 * a2pb2 + sin2 * sin2;
    let t4 = t2 * sin2;
    let rp = rs * (t3 - t4) / max_ps(t3 + t4, 1e-20);
    0.5 * (rp + rs)
}

/// `specular_reflectance`.
#[inline(always)]
fn specular_reflectance(f: &Fresnel, cos_i: f32) -> [f32; 3] {
    let schlick = (1.0 - cos_i.clamp(0.0, 1.0)).powi(5);
    // Channel by channel, not `array::from_fn`, whose closure may be left out of line.
    [
        reflectance_channel(f, cos_i, schlick, 0),
        reflectance_channel(f, cos_i, schlick, 1),
        reflectance_channel(f, cos_i, schlick, 2),
    ]
}

/// Channel `i` of [`specular_reflectance`].
#[inline(always)]
fn reflectance_channel(f: &Fresnel, cos_i: f32, schlick: f32, i: usize) -> f32 {
    let f0 = (1.0 - f.tint) + f.color[i] * f.tint;
    let dielectric = f0 + (1.0 - f0) * schlick;
    let conductor = fresnel_conductor(cos_i, f.eta[i], f.k[i]);
    if f.conductor { conductor } else { dielectric }
}

/// `sample_lobes` of a rough mirror alone: `ggx_reflection`, then `eval_lobes` (the
/// specular lobe with weight 1) and `continuous_sample` at the direction.
#[inline(always)]
fn sample_lane(v: &LaneVertex, alpha: f32, fresnel: &Fresnel) -> LaneSample {
    let side = side(v);
    let Side { n, frame, wo_l, .. } = side;
    let cos_o = dot(v.wo, n);
    // `ggx_reflection`.
    let h = ggx_sample_visible(wo_l, alpha, v.u);
    let twice_cos = 2.0 * dot(wo_l, h);
    let wi_l: [f32; 3] = std::array::from_fn(|i| twice_cos * h[i] - wo_l[i]);
    let sampled = cos_o > 0.0 && wi_l[2] > 0.0;
    let wi = to_world(&frame, wi_l);
    LaneSample::reflected(sampled, wi, eval_lane(v, &side, wi, alpha, fresnel))
}

/// `eval_lobes` of a rough mirror alone at `wi`: its specular lobe, with weight 1.
#[inline(always)]
fn eval_lane(v: &LaneVertex, side: &Side, wi: [f32; 3], alpha: f32, fresnel: &Fresnel) -> LaneEval {
    let Side { ng, n, frame, wo_l } = *side;
    let cos_o = dot(v.wo, n);
    let cos_i = dot(wi, n);
    let seen = dot(wi, ng) > 0.0 && cos_o > 0.0 && cos_i > 0.0;
    let wi_l = to_local(&frame, wi);
    let m = normalize(add(wo_l, wi_l));
    let reflectance = specular_reflectance(fresnel, dot(wo_l, m));
    let d = ggx_d(m, alpha);
    let g1_o = ggx_g1(wo_l, alpha);
    let g1_i = ggx_g1(wi_l, alpha);
    // Not `array::map`, whose closure may be left out of line.
    let lobe = |r: f32| {
        0.0 + if seen {
            1.0 * r * d * g1_o * g1_i / (4.0 * wo_l[2])
        } else {
            0.0
        }
    };
    let f = [
        lobe(reflectance[0]),
        lobe(reflectance[1]),
        lobe(reflectance[2]),
    ];
    let pdf = 0.0
        + if seen {
            1.0 * g1_o * d / (4.0 * wo_l[2])
        } else {
            0.0
        };
    LaneEval { f, pdf }
}

#[cfg(test)]
mod tests {
    use glam::{Vec3A, Vec4};

    use super::*;
    use crate::bsdf_lanes::tests::assert_lanes_as_one_path;
    use crate::lobes::{eval_lobes, sample_lobes};
    use crate::material::MODEL_PARAMS;

    /// Every lane's sample, and its evaluation towards a light sample, are `sample_lobes`'s
    /// and `eval_lobes`'s for a rough mirror alone bit for bit (`assert_lanes_as_one_path`): conductors (gold, aluminium, an index with no
    /// absorption) and Schlick's Fresnel with any tint, roughnesses from nearly smooth to 1.
    /// It fails with any operation regrouped (a quotient taken before a product, the
    /// conductor's `eta^2 - k^2 - sin^2` summed in another order).
    #[test]
    fn lanes_sample_as_sample_lobes_bit_for_bit() {
        let outcomes = assert_lanes_as_one_path::<RoughMirror>(
            0x3c6e_f372,
            (sample_lobes, eval_lobes),
            |l, next| {
                let mut block = [Vec4::ZERO; MODEL_PARAMS];
                let roughness = 0.04 + 0.96 * next();
                let conductor = l % 4 != 3;
                block[0] = Vec4::new(1.0, [0.0, 1.0, next()][l % 3], roughness, 0.0);
                block[1] = Vec4::new(0.0, 1.5, 0.0, if conductor { 1.0 } else { 0.0 });
                let (eta, k) = [
                    ([0.143, 0.375, 1.442], [3.983, 2.386, 1.603]),
                    ([1.657, 0.880, 0.521], [9.224, 6.270, 4.837]),
                    ([1.5, 1.5, 1.5], [0.0, 0.0, 0.0]),
                ][l % 3];
                block[2] = Vec3A::from(eta).extend(0.0);
                block[3] = Vec3A::from(k).extend(0.0);
                let m = LobesParams::decode(&block);
                assert!(m.is_rough_mirror());
                m
            },
            |_, m| m.conductor,
        );
        // Invalid samples, valid ones of both Fresnel terms, and evaluations not zero were all
        // met often.
        assert!(outcomes.iter().all(|&n| n > 300), "{outcomes:?}");
    }
}
