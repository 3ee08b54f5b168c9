//! The light samples taken elsewhere (an environment map's) and given to the lanes of a
//! packet that compute their BSDFs side by side ([`crate::diffuse`], [`crate::bsdf_lanes`]),
//! or a constant sky's, taken here side by side, and the BSDF's evaluations towards them,
//! which those lanes compute. CPU only (on the GPU, threads are lanes already).

use std::f32::consts::PI;

use glam::{Vec2, Vec3A};

use crate::light_sample::{INVALID as INVALID_LIGHT, LightSample};
use crate::microfacet::BsdfEval;
use crate::packet::{Lanes, PACKET};
use crate::soa::{Lanes3, cosine_hemisphere, dot, frame_around, lane, set_lane, to_world};

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
