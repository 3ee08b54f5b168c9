//! The light samples taken elsewhere (an environment map's) and given to the lanes of a
//! packet that compute their BSDFs side by side ([`crate::diffuse`], [`crate::bsdf_lanes`]),
//! and the BSDF's evaluations towards them, which those lanes compute. CPU only (on the GPU,
//! threads are lanes already).

use glam::Vec3A;

use crate::light_sample::{INVALID as INVALID_LIGHT, LightSample};
use crate::microfacet::BsdfEval;
use crate::packet::{Lanes, PACKET};
use crate::soa::{Lanes3, lane, set_lane};

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
    }

    /// Lane `l` has the valid light sample `ls`.
    #[inline(always)]
    pub fn push(&mut self, l: usize, ls: &LightSample) {
        self.samples[l] = *ls;
        set_lane(&mut self.wi, l, ls.wi);
        self.mask |= 1 << l;
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
