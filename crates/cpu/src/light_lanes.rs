//! The light samples taken elsewhere (an environment map's) and given to the lanes of a
//! packet that compute their BSDFs side by side ([`crate::diffuse`], [`crate::bsdf_lanes`]),
//! or a constant sky's or a quad light's, taken here side by side, and the BSDF's
//! evaluations towards them, which those lanes compute. CPU only (on the GPU, threads are
//! lanes already).

use std::f32::consts::PI;

use glam::{Vec2, Vec3A};

use crate::cpu_scene::CpuScene;
use crate::light_sample::{INVALID as INVALID_LIGHT, LightSample};
use crate::microfacet::BsdfEval;
use crate::packet::{Lanes, PACKET};
use crate::soa::{Lanes3, at, cosine_hemisphere, dot, frame_around, lane, set_lane, to_world};

/// A vertex's light sample with the BSDF's evaluation towards it, computed side by side:
/// what its shadow test needs.
#[derive(Debug, Clone, Copy)]
pub struct LitVertex<'a> {
    /// The light sample.
    pub light: &'a LightSample,
    /// The BSDF's evaluation towards it.
    pub eval: BsdfEval,
    /// The vertex.
    pub position: Vec3A,
    /// Its geometric normal (on either side: the shadow ray leaves on the light's).
    pub ng: Vec3A,
}

/// Per lane, a light sample given to it ([`LightLanes::push`]), its direction, and the
/// BSDF's evaluation towards it once the lanes' kind computed it ([`LightLanes::lit`]).
#[derive(Debug, Clone)]
pub struct LightLanes {
    /// Bit `l` set: lane `l` has a light sample.
    pub mask: Lanes,
    /// Bit `l` set: lane `l`'s light sample is the constant sky's, at `sky_u`, still to be
    /// taken ([`LightLanes::push_sky`]).
    pub sky: Lanes,
    sky_u: [[f32; PACKET]; 2],
    /// The sky's radiance, and the probability of choosing it.
    sky_radiance: Vec3A,
    sky_pmf: f32,
    /// Bit `l` set: lane `l`'s light sample is on a quad light, still to be taken
    /// ([`LightLanes::push_quad`]).
    pub quad: Lanes,
    /// Per lane of `quad`: the quad, the probability of having chosen it, its emission, and
    /// the dimensions of the point on it.
    quads: QuadLanes,
    quad_pmf: [f32; PACKET],
    quad_emission: Lanes3,
    quad_u: [[f32; PACKET]; 2],
    samples: [LightSample; PACKET],
    /// The samples' directions.
    pub wi: Lanes3,
    /// The evaluations towards them: `f * |cos(wi, ns)|`.
    pub f: Lanes3,
    /// The evaluations' densities.
    pub pdf: [f32; PACKET],
}

impl Default for LightLanes {
    fn default() -> Self {
        Self {
            mask: 0,
            sky: 0,
            sky_u: [[0.0; PACKET]; 2],
            sky_radiance: Vec3A::ZERO,
            sky_pmf: 0.0,
            quad: 0,
            quads: QuadLanes::default(),
            quad_pmf: [0.0; PACKET],
            quad_emission: [[0.0; PACKET]; 3],
            quad_u: [[0.0; PACKET]; 2],
            samples: [INVALID_LIGHT; PACKET],
            wi: [[0.0; PACKET]; 3],
            f: [[0.0; PACKET]; 3],
            pdf: [0.0; PACKET],
        }
    }
}

impl LightLanes {
    /// No lane has a light sample.
    #[inline(always)]
    pub fn clear(&mut self) {
        self.mask = 0;
        self.sky = 0;
        self.quad = 0;
    }

    /// Lane `l` has the valid light sample `ls`.
    #[inline(always)]
    pub fn push(&mut self, l: usize, ls: &LightSample) {
        self.samples[l] = *ls;
        set_lane(&mut self.wi, l, ls.wi);
        self.mask |= 1 << l;
    }

    /// Lane `l` samples the constant sky of radiance `radiance`, chosen with probability
    /// `pmf`, at `u`, as `sample_environment` would: [`LightLanes::sample_sky`] or
    /// [`LightLanes::sample_skies`] takes the sample.
    #[inline(always)]
    pub fn push_sky(&mut self, l: usize, radiance: Vec3A, pmf: f32, u: Vec2) {
        self.sky_radiance = radiance;
        self.sky_pmf = pmf;
        self.sky_u[0][l] = u.x;
        self.sky_u[1][l] = u.y;
        self.sky |= 1 << l;
        self.mask |= 1 << l;
    }

    /// Lane `l` samples quad light `object` of `scene`, chosen with probability `pmf`, at
    /// `u`, as `sample_area_light` would: [`LightLanes::sample_quad`] or
    /// [`LightLanes::sample_quads`] takes the sample.
    #[inline(always)]
    pub fn push_quad(&mut self, l: usize, scene: &CpuScene, object: u32, pmf: f32, u: Vec2) {
        let emission = self.quads.set(l, scene, object);
        self.quad_pmf[l] = pmf;
        set_lane(&mut self.quad_emission, l, emission);
        self.quad_u[0][l] = u.x;
        self.quad_u[1][l] = u.y;
        self.quad |= 1 << l;
        self.mask |= 1 << l;
    }

    /// Lane `l`'s quad light sample from `p`.
    #[inline(always)]
    fn quad_sample(&self, l: usize, p: [f32; 3]) -> QuadSample {
        let u = (self.quad_u[0][l], self.quad_u[1][l]);
        self.quads.sample(l, p, self.quad_pmf[l], u)
    }

    /// Takes lane `l`'s quad light sample ([`LightLanes::push_quad`]) from `p`.
    #[inline(always)]
    pub fn sample_quad(&mut self, l: usize, p: [f32; 3]) {
        let s = self.quad_sample(l, p);
        for (axis, w) in s.wi.into_iter().enumerate() {
            self.wi[axis][l] = w;
        }
        self.keep_quad(l, s.q, s.pdf, s.sampled);
    }

    /// Takes the quad light samples of the first `N` lanes side by side, from the points
    /// `p(l)` (the other lanes' light samples left as they are).
    #[inline(always)]
    pub fn sample_quads<const N: usize>(&mut self, p: impl Fn(usize) -> [f32; 3]) {
        let mut q = [[0.0; N]; 3];
        let mut pdf = [0.0; N];
        let mut sampled = [false; N];
        for l in 0..N {
            let s = self.quad_sample(l, p(l));
            let mine = self.quad >> l & 1 != 0;
            for (axis, (row, point)) in self.wi.iter_mut().zip(&mut q).enumerate() {
                row[l] = if mine { s.wi[axis] } else { row[l] };
                point[l] = s.q[axis];
            }
            (pdf[l], sampled[l]) = (s.pdf, s.sampled);
        }
        let mut quad = self.quad;
        while quad != 0 {
            let l = quad.trailing_zeros() as usize;
            quad &= quad - 1;
            let point = [q[0][l], q[1][l], q[2][l]];
            self.keep_quad(l, point, pdf[l], sampled[l]);
        }
    }

    /// Lane `l`'s quad light sample, of direction `wi[l]`, point `q` and density `pdf`: kept
    /// where `sampled`, else the lane has none.
    #[inline(always)]
    fn keep_quad(&mut self, l: usize, q: [f32; 3], pdf: f32, sampled: bool) {
        if sampled {
            self.samples[l] = LightSample {
                wi: lane(&self.wi, l),
                point: Vec3A::from(q),
                finite: true,
                radiance: lane(&self.quad_emission, l),
                pdf,
                valid: true,
                mis: true,
                map_cell: None,
            };
        } else {
            self.mask &= !(1 << l);
        }
    }

    /// The sky's direction and density for lane `l` about normal `n` (on the side light is
    /// gathered from): `sample_environment` without a map.
    #[inline(always)]
    fn sky_direction(&self, l: usize, n: [f32; 3]) -> ([f32; 3], f32) {
        let local = cosine_hemisphere(self.sky_u[0][l], self.sky_u[1][l]);
        let wi = to_world(&frame_around(n), local);
        (wi, self.sky_pmf * dot(n, wi).max(0.0) / PI)
    }

    /// Takes lane `l`'s sky sample ([`LightLanes::push_sky`]) about normal `n`.
    #[inline(always)]
    pub fn sample_sky(&mut self, l: usize, n: [f32; 3]) {
        let (wi, pdf) = self.sky_direction(l, n);
        for (axis, w) in wi.into_iter().enumerate() {
            self.wi[axis][l] = w;
        }
        self.keep_sky(l, pdf);
    }

    /// Takes the sky samples of the first `N` lanes side by side, about the normals `n(l)`
    /// (the other lanes' light samples left as they are).
    #[inline(always)]
    pub fn sample_skies<const N: usize>(&mut self, n: impl Fn(usize) -> [f32; 3]) {
        let mut pdf = [0.0; N];
        for l in 0..N {
            let (wi, density) = self.sky_direction(l, n(l));
            let mine = self.sky >> l & 1 != 0;
            for (axis, w) in wi.into_iter().enumerate() {
                let row = &mut self.wi[axis];
                row[l] = if mine { w } else { row[l] };
            }
            pdf[l] = density;
        }
        let mut sky = self.sky;
        while sky != 0 {
            let l = sky.trailing_zeros() as usize;
            sky &= sky - 1;
            self.keep_sky(l, pdf[l]);
        }
    }

    /// Lane `l`'s sky sample, of direction `wi[l]` and density `pdf`: kept where valid
    /// (`pdf > 0`), else the lane has none.
    #[inline(always)]
    fn keep_sky(&mut self, l: usize, pdf: f32) {
        if pdf > 0.0 {
            self.samples[l] = LightSample {
                wi: lane(&self.wi, l),
                radiance: self.sky_radiance,
                pdf,
                valid: true,
                ..INVALID_LIGHT
            };
        } else {
            self.mask &= !(1 << l);
        }
    }

    /// Lane `l`'s light sample, if it has one, with the evaluation towards it, from the
    /// vertex at `position` of geometric normal `ng`.
    #[inline(always)]
    pub fn lit(&self, l: usize, position: Vec3A, ng: Vec3A) -> Option<LitVertex<'_>> {
        (self.mask >> l & 1 != 0).then(|| LitVertex {
            light: &self.samples[l],
            eval: BsdfEval {
                f: lane(&self.f, l),
                pdf: self.pdf[l],
            },
            position,
            ng,
        })
    }
}

/// A quad light's sample: the point on it, the direction towards it, the density, and
/// whether it is valid.
pub(crate) struct QuadSample {
    /// The point.
    pub q: [f32; 3],
    /// The unit direction from the shading point towards it.
    pub wi: [f32; 3],
    /// The solid-angle density, with the light's choice.
    pub pdf: f32,
    /// Whether `sample_area_light` gives a valid sample.
    pub sampled: bool,
}

/// Per lane, a quad light: its corner, edges and unit normal, and its area.
#[derive(Debug, Clone)]
pub(crate) struct QuadLanes {
    shape: [Lanes3; 4],
    area: [f32; PACKET],
}

impl Default for QuadLanes {
    fn default() -> Self {
        Self {
            shape: [[[0.0; PACKET]; 3]; 4],
            area: [1.0; PACKET],
        }
    }
}

impl QuadLanes {
    /// Lane `k` holds quad `object` of `scene`; returns the radiance the quad emits.
    #[inline(always)]
    pub fn set(&mut self, k: usize, scene: &CpuScene, object: u32) -> Vec3A {
        let o = &scene.objects[object as usize];
        let corners = [o.a, o.b, o.c].map(|v| Vec3A::from_slice(&v));
        for (shape, v) in self.shape.iter_mut().zip(corners) {
            set_lane(shape, k, v);
        }
        set_lane(&mut self.shape[3], k, scene.quad_normal(object));
        self.area[k] = scene.quad_area(object);
        Vec3A::from(scene.materials[o.material as usize].emission)
    }

    /// [`quad_sample`] of lane `k`'s quad from `p`, chosen with probability `pmf`, at `u`.
    #[inline(always)]
    pub fn sample(&self, k: usize, p: [f32; 3], pmf: f32, u: (f32, f32)) -> QuadSample {
        // Not `array::map`, whose closure may be left out of line.
        let q = &self.shape;
        let shape = [at(&q[0], k), at(&q[1], k), at(&q[2], k), at(&q[3], k)];
        quad_sample(p, shape, self.area[k], pmf, u)
    }
}

/// `sample_shape` of a quad (corner, edges, unit normal: `shape`) of area `area` at `u`, and
/// `sample_area_light`'s direction from `p` and density, the quad chosen with probability
/// `pmf`.
#[inline(always)]
fn quad_sample(
    p: [f32; 3],
    shape: [[f32; 3]; 4],
    area: f32,
    pmf: f32,
    (ux, uy): (f32, f32),
) -> QuadSample {
    let [a, b, c, normal] = shape;
    let q: [f32; 3] = std::array::from_fn(|i| a[i] + ux * b[i] + uy * c[i]);
    let density = 1.0 / area;
    let to_light: [f32; 3] = std::array::from_fn(|i| q[i] - p[i]);
    let distance = dot(to_light, to_light).sqrt();
    let wi = to_light.map(|v| v / distance);
    let cos_l = dot(normal, wi.map(|v| -v));
    let pdf = pmf * density * distance * distance / cos_l;
    // (A NaN distance or cosine makes `pdf` NaN.)
    let sampled = distance > 0.0 && cos_l > 0.0 && pdf > 0.0 && pdf.is_finite();
    QuadSample {
        q,
        wi,
        pdf,
        sampled,
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use glam::Vec3A;

    use super::LitVertex;
    use crate::microfacet::BsdfEval;

    /// Asserts that lane `l`'s light sample `ours`, as the lanes give it back, is the one given
    /// to them, towards `theirs`' direction, with `theirs`' evaluation bit for bit (or that
    /// neither exists); returns whether that evaluation's density is positive.
    pub(crate) fn assert_lit_as(
        ours: Option<LitVertex>,
        theirs: Option<&(Vec3A, BsdfEval)>,
        l: usize,
        round: usize,
    ) -> bool {
        assert_eq!(ours.is_some(), theirs.is_some(), "lane {l}, round {round}");
        let (Some(ours), Some((wi, theirs))) = (ours, theirs) else {
            return false;
        };
        let bits = |v: Vec3A| v.to_array().map(f32::to_bits);
        assert_eq!(bits(ours.light.wi), bits(*wi), "lane {l}, round {round}");
        let ours = ours.eval;
        assert_eq!(bits(ours.f), bits(theirs.f), "lane {l}, round {round}");
        assert_eq!(ours.pdf.to_bits(), theirs.pdf.to_bits(), "lane {l}");
        theirs.pdf > 0.0
    }
}
