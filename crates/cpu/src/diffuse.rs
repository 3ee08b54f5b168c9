//! The BSDF samples of a packet's lanes whose paths stand on a purely diffuse surface (the
//! lobes model with its Lambert lobe alone), computed side by side: each lane's frame,
//! cosine-weighted direction, validity and weight, written as a loop over the lanes that the
//! compiler turns into SIMD instructions. The values are `sample_lobes`'s bit for bit: the
//! same operations in the same order. CPU only (on the GPU, threads are lanes already).

use std::f32::consts::FRAC_1_PI;

use glam::{Vec2, Vec3A};

use crate::microfacet::{BsdfSample, INVALID};
use crate::packet::{Lanes, PACKET};
use crate::sampling::sin_cos_turns;

/// A vector per lane, stored per axis.
type Lanes3 = [[f32; PACKET]; 3];

/// A diffuse vertex with its BSDF sample, and what the path needs to go on from it.
#[derive(Debug, Clone, Copy)]
pub struct DiffuseVertex {
    /// The BSDF sample.
    pub sample: BsdfSample,
    /// The vertex.
    pub position: Vec3A,
    /// Its geometric normal on the side of `wo`.
    pub ng: Vec3A,
    /// Its shading normal on the side of `wo`.
    pub n: Vec3A,
    /// The dimension deciding Russian roulette there.
    pub u_rr: f32,
}

/// Per lane, a diffuse vertex waiting for the rest of its bounce ([`DiffuseLanes::push`]),
/// and after [`DiffuseLanes::compute`] its sample ([`DiffuseLanes::vertex`]).
#[derive(Debug, Clone)]
pub struct DiffuseLanes {
    /// Bit `l` set: lane `l` waits (or, after `compute`, has its results).
    pub mask: Lanes,
    // Inputs.
    position: Lanes3,
    /// The shading and geometric normals, on the side of `wo`.
    n: Lanes3,
    ng: Lanes3,
    wo: Lanes3,
    color: Lanes3,
    /// The two dimensions the BSDF direction is drawn from, and Russian roulette's.
    u: [[f32; PACKET]; 2],
    u_rr: [f32; PACKET],
    // Outputs.
    wi: Lanes3,
    weight: Lanes3,
    pdf: [f32; PACKET],
    valid: [bool; PACKET],
}

impl Default for DiffuseLanes {
    fn default() -> Self {
        let zero = [[0.0; PACKET]; 3];
        Self {
            mask: 0,
            position: zero,
            n: zero,
            ng: zero,
            wo: zero,
            color: zero,
            u: [[0.0; PACKET]; 2],
            u_rr: [0.0; PACKET],
            wi: zero,
            weight: zero,
            pdf: [0.0; PACKET],
            valid: [false; PACKET],
        }
    }
}

/// Lane `l` of `a` as a vector.
#[inline(always)]
fn lane(a: &Lanes3, l: usize) -> Vec3A {
    Vec3A::new(a[0][l], a[1][l], a[2][l])
}

/// Writes `v` to lane `l` of `a`.
#[inline(always)]
fn set_lane(a: &mut Lanes3, l: usize, v: Vec3A) {
    for (axis, row) in a.iter_mut().enumerate() {
        row[l] = v[axis];
    }
}

/// `a . b` as glam computes it: `(x + y) + z`.
#[inline(always)]
fn dot(a: [f32; 3], b: [f32; 3]) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

impl DiffuseLanes {
    /// Lane `l` waits at `position`, whose Lambert lobe of colour `color` has shading normal
    /// `n` and geometric normal `ng` (both on the side of `wo`), with the dimensions of its
    /// BSDF sample (`u`) and of Russian roulette (`u_rr`).
    #[inline(always)]
    #[expect(
        clippy::too_many_arguments,
        reason = "one lane's vertex, field by field"
    )]
    pub fn push(
        &mut self,
        l: usize,
        position: Vec3A,
        n: Vec3A,
        ng: Vec3A,
        wo: Vec3A,
        color: Vec3A,
        u: Vec2,
        u_rr: f32,
    ) {
        set_lane(&mut self.position, l, position);
        set_lane(&mut self.n, l, n);
        set_lane(&mut self.ng, l, ng);
        set_lane(&mut self.wo, l, wo);
        set_lane(&mut self.color, l, color);
        self.u[0][l] = u.x;
        self.u[1][l] = u.y;
        self.u_rr[l] = u_rr;
        self.mask |= 1 << l;
    }

    /// Computes every lane side by side (those not waiting compute throw-away values).
    #[inline(always)]
    pub fn compute(&mut self) {
        for l in 0..PACKET {
            let at = |a: &Lanes3| [a[0][l], a[1][l], a[2][l]];
            let (n, ng, wo) = (at(&self.n), at(&self.ng), at(&self.wo));
            // The BSDF sample: `sample_cosine_hemisphere`, turned by `Frame::around(n)`.
            let (ux, uy) = (self.u[0][l], self.u[1][l]);
            let r = ux.sqrt();
            let (sin, cos) = sin_cos_turns(uy);
            let local = [r * cos, r * sin, (1.0 - ux).max(0.0).sqrt()];
            let s = if n[2] >= 0.0 { 1.0 } else { -1.0 };
            let a = -1.0 / (s + n[2]);
            let b = n[0] * n[1] * a;
            let t = [1.0 + s * n[0] * n[0] * a, s * b, -s * n[0]];
            let bt = [b, s + n[1] * n[1] * a, -n[1]];
            let wi: [f32; 3] =
                std::array::from_fn(|i| t[i] * local[0] + bt[i] * local[1] + n[i] * local[2]);
            // Its `eval_lobes` and `continuous_sample`.
            let cos_o = dot(wo, n);
            let cos_i = dot(wi, n);
            let pdf = FRAC_1_PI * cos_i;
            let passes = cos_o > 0.0 && dot(wi, ng) > 0.0 && cos_i > 0.0;
            self.valid[l] = passes && pdf > 0.0 && pdf.is_finite();
            for (axis, &w) in wi.iter().enumerate() {
                self.wi[axis][l] = w;
                let f = self.color[axis][l] * FRAC_1_PI * cos_i;
                self.weight[axis][l] = f / pdf;
            }
            self.pdf[l] = pdf;
        }
    }

    /// Lane `l`'s results, once [`DiffuseLanes::compute`] ran.
    #[inline(always)]
    pub fn vertex(&self, l: usize) -> DiffuseVertex {
        let sample = if self.valid[l] {
            BsdfSample {
                wi: lane(&self.wi, l),
                weight: lane(&self.weight, l),
                pdf: self.pdf[l],
                delta: false,
                eta: 1.0,
                valid: true,
            }
        } else {
            INVALID
        };
        DiffuseVertex {
            sample,
            position: lane(&self.position, l),
            ng: lane(&self.ng, l),
            n: lane(&self.n, l),
            u_rr: self.u_rr[l],
        }
    }
}

#[cfg(test)]
mod tests {
    use glam::{Vec2, Vec4};

    use super::*;
    use crate::lobes::{LobesParams, sample_lobes};
    use crate::material::MODEL_PARAMS;
    use crate::surface::Surface;

    /// A unit vector from three uniform numbers in [-1, 1) (not uniform on the sphere).
    fn unit(v: impl Into<Vec3A>) -> Vec3A {
        v.into().normalize()
    }

    /// Three uniform numbers in [-1, 1) drawn from `next`.
    fn r3(next: &mut impl FnMut() -> f32) -> Vec3A {
        Vec3A::new(next(), next(), next()) * 2.0 - 1.0
    }

    /// Every lane's sample is `sample_lobes`'s for a Lambert material bit for bit: shading
    /// normals bent away from the geometric one, both sides of the surface, normals next to
    /// -z (the frame's other branch), and draws at 0 and next to 1. It fails with any
    /// operation reordered (a dot product summed in another order, the frame's terms grouped
    /// otherwise).
    #[test]
    fn lanes_sample_as_sample_lobes_bit_for_bit() {
        let mut block = [Vec4::ZERO; MODEL_PARAMS];
        block[1].y = 1.5;
        let m = LobesParams::decode(&block);
        assert!(m.is_lambert());
        let mut state = 0x9e37_79b9_u32;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            state as f32 / 4_294_967_296.0
        };
        let mut checked = [0; 2];
        for round in 0..64 {
            let mut lanes = DiffuseLanes::default();
            let mut cases = Vec::new();
            for l in 0..PACKET {
                let ng = unit(r3(&mut next));
                let mut ns = unit(r3(&mut next) * 0.3 + ng);
                if l % 8 == 0 {
                    ns = unit([0.01 * next(), -0.01 * next(), -1.0]);
                }
                if ns.dot(ng) < 0.0 {
                    ns = -ns;
                }
                let wo = unit(r3(&mut next));
                let mut u = Vec2::new(next(), next());
                if round % 16 == 0 {
                    u = Vec2::new([0.0, 1.0f32.next_down()][l % 2], [0.0, 0.999_999_9][l / 16]);
                }
                let color = Vec3A::new(next(), next(), next());
                let s = Surface {
                    position: r3(&mut next) * 10.0,
                    ng,
                    ns,
                    nc: ns,
                    uv: Vec2::ZERO,
                    material: 0,
                    color: Vec3A::ONE,
                };
                let side = if wo.dot(ng) >= 0.0 { 1.0 } else { -1.0 };
                let (n, ng_side) = (ns * side, ng * side);
                lanes.push(l, s.position, n, ng_side, wo, color, u, 0.5);
                cases.push(sample_lobes(&m, color, &s, wo, 0.5, 0.5, u));
            }
            lanes.compute();
            for (l, theirs) in cases.iter().enumerate() {
                let ours = lanes.vertex(l).sample;
                let bits = |v: Vec3A| v.to_array().map(f32::to_bits);
                assert_eq!(ours.valid, theirs.valid, "lane {l}, round {round}");
                checked[usize::from(ours.valid)] += 1;
                if !ours.valid {
                    continue;
                }
                assert_eq!(bits(ours.wi), bits(theirs.wi), "lane {l}, round {round}");
                assert_eq!(bits(ours.weight), bits(theirs.weight), "lane {l}");
                assert_eq!(ours.pdf.to_bits(), theirs.pdf.to_bits(), "lane {l}");
                assert_eq!((ours.delta, ours.eta), (theirs.delta, theirs.eta));
            }
        }
        // Both outcomes were met often.
        assert!(checked.iter().all(|&n| n > 200), "{checked:?}");
    }
}
