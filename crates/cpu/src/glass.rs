//! The BSDF samples of the lanes of a packet whose paths stand on rough glass (the lobes
//! model with its rough transmission lobe alone), computed side by side: the visible GGX
//! normal, the Fresnel choice between its reflection and refraction, and the mixture's
//! evaluation there (`eval_rough_dielectric`, read twice over for its density), the
//! longest chain of dependent square roots and divisions of any bounce. Written as a loop
//! over the lanes that the compiler turns into SIMD instructions, in place of that chain
//! per path. The values are the one-path functions' bit for bit (`sample_lobes` through
//! `rough_dielectric_direction`, `eval_lobes` and `continuous_sample`): the same operations
//! in the same order, the early returns turned into a validity mask, and a test holds each
//! lane to `sample_lobes`. CPU only (on the GPU, threads are lanes already).

use std::f32::consts::PI;

use glam::{Vec2, Vec3A};

use crate::microfacet::{BsdfSample, INVALID, fresnel_dielectric_local};
use crate::packet::{Lanes, PACKET};
use crate::sampling::sin_cos_turns;
use crate::soa::{
    Lanes3, add, at, cross, dot, frame_around, lane, normalize, scale, set_lane, to_local, to_world,
};

/// A rough glass vertex with its BSDF sample, and what the path needs to go on from it.
#[derive(Debug, Clone, Copy)]
pub struct GlassVertex {
    /// The BSDF sample.
    pub sample: BsdfSample,
    /// The vertex.
    pub position: Vec3A,
    /// Its geometric normal (on the shape's front side).
    pub ng: Vec3A,
    /// Its shading normal on the side of `wo`.
    pub n: Vec3A,
    /// The dimension deciding Russian roulette there.
    pub u_rr: f32,
}

/// Per lane, a rough glass vertex waiting for its BSDF sample ([`GlassLanes::push`]), and
/// after [`GlassLanes::compute`] its results ([`GlassLanes::vertex`]).
#[derive(Debug, Clone)]
pub struct GlassLanes {
    /// Bit `l` set: lane `l` waits (or, after `compute`, has its results).
    pub mask: Lanes,
    // Inputs.
    position: Lanes3,
    /// The shading and geometric normals on the shape's front side.
    ns: Lanes3,
    ng: Lanes3,
    wo: Lanes3,
    color: Lanes3,
    /// The inside's index of refraction, the GGX alpha, the transmission's tint.
    ior: [f32; PACKET],
    alpha: [f32; PACKET],
    tint: [f32; PACKET],
    /// The dimensions of the Fresnel choice, of the normal, and of Russian roulette.
    u_fresnel: [f32; PACKET],
    u: [[f32; PACKET]; 2],
    u_rr: [f32; PACKET],
    // Outputs.
    wi: Lanes3,
    weight: Lanes3,
    pdf: [f32; PACKET],
    eta: [f32; PACKET],
    valid: [bool; PACKET],
}

impl Default for GlassLanes {
    fn default() -> Self {
        let zero = [[0.0; PACKET]; 3];
        Self {
            mask: 0,
            position: zero,
            ns: zero,
            ng: zero,
            wo: zero,
            color: zero,
            ior: [1.0; PACKET],
            alpha: [1.0; PACKET],
            tint: [0.0; PACKET],
            u_fresnel: [0.0; PACKET],
            u: [[0.0; PACKET]; 2],
            u_rr: [0.0; PACKET],
            wi: zero,
            weight: zero,
            pdf: [0.0; PACKET],
            eta: [1.0; PACKET],
            valid: [false; PACKET],
        }
    }
}

/// What one lane's sample gives.
struct LaneSample {
    valid: bool,
    wi: [f32; 3],
    weight: [f32; 3],
    pdf: f32,
    eta: f32,
}

/// `ggx_d`.
#[inline(always)]
fn ggx_d(m: [f32; 3], alpha: f32) -> f32 {
    let a2 = alpha * alpha;
    let t = (m[0] * m[0] + m[1] * m[1]) / a2 + m[2] * m[2];
    1.0 / (PI * a2 * t * t)
}

/// `ggx_g1`.
#[inline(always)]
fn ggx_g1(w: [f32; 3], alpha: f32) -> f32 {
    let z2 = w[2] * w[2];
    let tan2 = (w[0] * w[0] + w[1] * w[1]) / z2;
    let g1 = 2.0 / (1.0 + (1.0 + alpha * alpha * tan2).sqrt());
    if z2 <= 0.0 { 0.0 } else { g1 }
}

/// `ggx_sample_visible`.
#[inline(always)]
fn ggx_sample_visible(wo: [f32; 3], alpha: f32, u: [f32; 2]) -> [f32; 3] {
    let w = if wo[2] < 0.0 { wo.map(|c| -c) } else { wo };
    let vh = normalize([alpha * w[0], alpha * w[1], w[2]]);
    let len2 = vh[0] * vh[0] + vh[1] * vh[1];
    let length = len2.sqrt();
    let t1 = if len2 > 0.0 {
        [-vh[1] / length, vh[0] / length, 0.0 / length]
    } else {
        [1.0, 0.0, 0.0]
    };
    let t2 = cross(vh, t1);
    let r = u[0].sqrt();
    let (sin, cos) = sin_cos_turns(u[1]);
    let p1 = r * cos;
    let s = 0.5 * (1.0 + vh[2]);
    let p2 = (1.0 - s) * (1.0 - p1 * p1).max(0.0).sqrt() + s * r * sin;
    let k = (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt();
    let nh = add(add(scale(p1, t1), scale(p2, t2)), scale(k, vh));
    normalize([alpha * nh[0], alpha * nh[1], nh[2].max(1e-7)])
}

/// `sample_lobes` of rough glass alone: `rough_dielectric_direction`, then `eval_lobes`
/// (`eval_rough_dielectric` with weight 1) and `continuous_sample` at the direction.
#[inline(always)]
#[expect(
    clippy::too_many_arguments,
    reason = "one lane's vertex, field by field"
)]
fn sample_lane(
    ns: [f32; 3],
    ng: [f32; 3],
    wo: [f32; 3],
    color: [f32; 3],
    ior: f32,
    alpha: f32,
    tint: f32,
    u_fresnel: f32,
    u: [f32; 2],
) -> LaneSample {
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
    // `eval_rough_dielectric` at `wi`.
    let wi_l = to_local(&frame, wi);
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
    // `eval_lobes`' sum over its one lobe, and `continuous_sample`.
    let f = f.map(|v| 0.0 + 1.0 * if seen { v } else { 0.0 });
    let pdf = 0.0 + 1.0 * if seen { pdf } else { 0.0 };
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

impl GlassLanes {
    /// No lane waits.
    #[inline(always)]
    pub fn clear(&mut self) {
        self.mask = 0;
    }

    /// Lane `l` waits at `position`, on rough glass of inside index `ior`, GGX `alpha` and
    /// transmission tinted by `tint` towards `color`, with shading normal `ns` and
    /// geometric normal `ng` (both on the shape's front side), seen from `wo`, with the
    /// dimensions of its Fresnel choice (`u_fresnel`), of its normal (`u`) and of Russian
    /// roulette (`u_rr`).
    #[inline(always)]
    #[expect(
        clippy::too_many_arguments,
        reason = "one lane's vertex, field by field"
    )]
    pub fn push(
        &mut self,
        l: usize,
        position: Vec3A,
        ns: Vec3A,
        ng: Vec3A,
        wo: Vec3A,
        color: Vec3A,
        [ior, alpha, tint]: [f32; 3],
        u_fresnel: f32,
        u: Vec2,
        u_rr: f32,
    ) {
        set_lane(&mut self.position, l, position);
        set_lane(&mut self.ns, l, ns);
        set_lane(&mut self.ng, l, ng);
        set_lane(&mut self.wo, l, wo);
        set_lane(&mut self.color, l, color);
        (self.ior[l], self.alpha[l], self.tint[l]) = (ior, alpha, tint);
        self.u_fresnel[l] = u_fresnel;
        self.u[0][l] = u.x;
        self.u[1][l] = u.y;
        self.u_rr[l] = u_rr;
        self.mask |= 1 << l;
    }

    /// Computes every lane side by side (those not waiting compute throw-away values: a
    /// packet holds a few rough glass lanes, but computing only theirs, gathered into as few
    /// AVX-512 registers as they fill, was slower).
    #[inline(always)]
    pub fn compute(&mut self) {
        for l in 0..PACKET {
            self.compute_lane(l);
        }
    }

    /// Computes lane `l`.
    #[inline(always)]
    fn compute_lane(&mut self, l: usize) {
        let s = sample_lane(
            at(&self.ns, l),
            at(&self.ng, l),
            at(&self.wo, l),
            at(&self.color, l),
            self.ior[l],
            self.alpha[l],
            self.tint[l],
            self.u_fresnel[l],
            [self.u[0][l], self.u[1][l]],
        );
        self.valid[l] = s.valid;
        for axis in 0..3 {
            self.wi[axis][l] = s.wi[axis];
            self.weight[axis][l] = s.weight[axis];
        }
        self.pdf[l] = s.pdf;
        self.eta[l] = s.eta;
    }

    /// Lane `l`'s results, once [`GlassLanes::compute`] ran.
    #[inline(always)]
    pub fn vertex(&self, l: usize) -> GlassVertex {
        let sample = if self.valid[l] {
            BsdfSample {
                wi: lane(&self.wi, l),
                weight: lane(&self.weight, l),
                pdf: self.pdf[l],
                delta: false,
                eta: self.eta[l],
                valid: true,
            }
        } else {
            INVALID
        };
        let (ns, ng) = (lane(&self.ns, l), lane(&self.ng, l));
        GlassVertex {
            sample,
            position: lane(&self.position, l),
            ng,
            n: if lane(&self.wo, l).dot(ng) >= 0.0 {
                ns
            } else {
                -ns
            },
            u_rr: self.u_rr[l],
        }
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec4;

    use super::*;
    use crate::lobes::{LobesParams, sample_lobes};
    use crate::material::MODEL_PARAMS;
    use crate::surface::Surface;

    /// Uniform numbers in [0, 1) (xorshift from `seed`).
    fn uniform(mut state: u32) -> impl FnMut() -> f32 {
        move || {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            state as f32 / 4_294_967_296.0
        }
    }

    /// Three uniform numbers in [-1, 1) drawn from `next`, normalised.
    fn unit(next: &mut impl FnMut() -> f32) -> Vec3A {
        (Vec3A::new(next(), next(), next()) * 2.0 - 1.0).normalize()
    }

    /// Every lane's sample is `sample_lobes`'s for rough glass alone bit for bit: indices
    /// above and below 1 (thin films of air), roughnesses from nearly smooth to 1, tints,
    /// both sides of the surface, shading normals bent away from the geometric one and
    /// next to -z (the frame's other branch), Fresnel draws choosing each branch, total
    /// internal reflection, draws at 0 and next to 1; from one lane waiting to all. It fails with any operation reordered
    /// (a dot product summed in another order, a quotient taken as a product by the
    /// reciprocal, the mixture's sum over its lobe left out).
    #[test]
    fn lanes_sample_as_sample_lobes_bit_for_bit() {
        let mut next = uniform(0x51ed_270b);
        let mut outcomes = [0; 3];
        for round in 0..512 {
            let mut lanes = GlassLanes::default();
            let mut cases = Vec::new();
            // Any number of lanes waiting, in any order.
            for l in 0..1 + round % PACKET {
                let mut block = [Vec4::ZERO; MODEL_PARAMS];
                let ior = [1.5, 1.33, 0.75, 2.4][l % 4];
                let roughness = 0.04 + 0.96 * next();
                let tint = [0.0, 1.0, next()][l % 3];
                block[0].w = 1.0;
                block[1] = Vec4::new(tint, ior, roughness, 0.0);
                let m = LobesParams::decode(&block);
                let ng = unit(&mut next);
                let mut ns = (unit(&mut next) * 0.3 + ng).normalize();
                if l % 8 == 0 {
                    ns = Vec3A::new(0.01 * next(), -0.01 * next(), -1.0).normalize();
                }
                if ns.dot(ng) < 0.0 {
                    ns = -ns;
                }
                let wo = unit(&mut next);
                let mut u = Vec2::new(next(), next());
                if round % 16 == 0 {
                    u = Vec2::new([0.0, 1.0f32.next_down()][l % 2], [0.0, 0.999_999_9][l / 16]);
                }
                let u_fresnel = next();
                let color = Vec3A::new(next(), next(), next());
                let s = Surface {
                    position: (Vec3A::new(next(), next(), next()) - 0.5) * 20.0,
                    ng,
                    ns,
                    nc: ns,
                    uv: Vec2::ZERO,
                    material: 0,
                    color: Vec3A::ONE,
                };
                let alpha = roughness * roughness;
                let params = [ior, alpha, tint];
                let lane = (l * 7 + round) % PACKET;
                lanes.push(
                    lane, s.position, ns, ng, wo, color, params, u_fresnel, u, 0.5,
                );
                cases.push(sample_lobes(&m, color, &s, wo, 0.5, u_fresnel, u));
            }
            lanes.compute();
            assert_eq!(lanes.mask.count_ones() as usize, cases.len());
            for (l, theirs) in cases.iter().enumerate() {
                let ours = lanes.vertex((l * 7 + round) % PACKET).sample;
                let bits = |v: Vec3A| v.to_array().map(f32::to_bits);
                assert_eq!(ours.valid, theirs.valid, "lane {l}, round {round}");
                if !ours.valid {
                    outcomes[0] += 1;
                    continue;
                }
                outcomes[1 + usize::from(ours.eta != 1.0)] += 1;
                assert_eq!(bits(ours.wi), bits(theirs.wi), "lane {l}, round {round}");
                assert_eq!(bits(ours.weight), bits(theirs.weight), "lane {l}");
                assert_eq!(ours.pdf.to_bits(), theirs.pdf.to_bits(), "lane {l}");
                assert_eq!(ours.eta.to_bits(), theirs.eta.to_bits(), "lane {l}");
                assert_eq!(ours.delta, theirs.delta);
            }
        }
        // Invalid samples, reflections and refractions were all met often.
        assert!(outcomes.iter().all(|&n| n > 300), "{outcomes:?}");
    }
}
