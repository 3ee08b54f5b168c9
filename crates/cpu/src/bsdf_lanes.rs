//! The BSDF samples, and the evaluations towards light samples, of the lanes of a packet
//! whose paths stand on one kind of material, computed side by side:
//! [`SampleLanes`] holds each waiting lane's vertex and runs the kind's sample and
//! evaluation ([`LaneBsdf`]: rough glass in [`crate::glass`], rough mirrors in
//! [`crate::glossy`], glTF's opaque rough materials in [`crate::metal_rough_lanes`]) for every
//! lane in loops that the compiler turns into SIMD instructions, in place of a chain of
//! dependent square roots and divisions per path. Each kind computes the one-path
//! functions' values bit for bit (`sample_lobes` and `eval_lobes`, `metal_rough::sample`
//! and `metal_rough::eval`): the same operations in the same order, the early returns
//! turned into a validity mask.
//! CPU only (on the GPU, threads are lanes already).

use glam::{Vec2, Vec3A};

use crate::cpu_scene::CpuScene;
use crate::light_lanes::{LightLanes, LitVertex};
use crate::light_sample::LightSample;
use crate::microfacet::{BsdfSample, INVALID};
use crate::packet::{Lanes, PACKET};
use crate::slots::{Slots, in_groups};
use crate::soa::{Lanes3, at, dot, frame_around, lane, set_lane, to_local};

/// Waiting lanes [`SampleLanes::compute`] computes one by one rather than side by side at the
/// AVX-512 level: with four, env-sun, cornell-materials and lights rendered 2-3% sooner than
/// with none or eight on a Zen 5 (a packet on a room's walls holds a lane or two on a
/// sphere).
pub const ONE_BY_ONE_WIDE: usize = 4;

/// The same at AVX2 and below: none, every waiting lane side by side (on a Zen 3, untrained,
/// env-sky, cornell-materials and env-sun 1.6-2.9% sooner than with four).
pub const ONE_BY_ONE_NARROW: usize = 0;

/// One lane's vertex, as a kind's sample reads it.
#[derive(Debug, Clone, Copy)]
pub struct LaneVertex {
    /// The shading normal on the shape's front side.
    pub ns: [f32; 3],
    /// The geometric normal on the shape's front side.
    pub ng: [f32; 3],
    /// The direction the path arrived from.
    pub wo: [f32; 3],
    /// The material's base colour there.
    pub color: [f32; 3],
    /// The dimension of the lobe choice.
    pub u_lobe: f32,
    /// The dimension of the Fresnel choice.
    pub u_fresnel: f32,
    /// The dimensions of the direction.
    pub u: [f32; 2],
}

/// One lane's BSDF sample: what `BsdfSample` holds of a continuous lobe's sample.
pub struct LaneSample {
    /// False when no direction was produced.
    pub valid: bool,
    /// The direction.
    pub wi: [f32; 3],
    /// `f * |cos| / pdf`.
    pub weight: [f32; 3],
    /// The density of the whole mixture at `wi`.
    pub pdf: f32,
    /// The relative index of refraction crossed, else 1.
    pub eta: f32,
}

impl LaneSample {
    /// `continuous_sample` of a reflection: direction `wi` (`sampled`: it lies where the
    /// lobe that drew it leaves the surface) and the BSDF's evaluation there; valid where
    /// that density is positive and finite. No interface is crossed.
    #[inline(always)]
    pub fn reflected(sampled: bool, wi: [f32; 3], eval: LaneEval) -> Self {
        let LaneEval { f, pdf } = eval;
        Self {
            valid: sampled && pdf > 0.0 && pdf.is_finite(),
            wi,
            weight: f.map(|v| v / pdf),
            pdf,
            eta: 1.0,
        }
    }
}

/// One lane's BSDF evaluation: what `BsdfEval` holds.
pub struct LaneEval {
    /// `f * |cos(wi, ns)|`.
    pub f: [f32; 3],
    /// The density of the whole mixture at `wi`.
    pub pdf: f32,
}

/// A kind of material whose BSDF samples and evaluations [`SampleLanes`] computes side by
/// side: its parameters per lane, and one lane's sample and evaluation.
pub trait LaneBsdf: Default {
    /// The parameters of its material model.
    type Params;
    /// Stores lane `l`'s material parameters.
    fn set(&mut self, l: usize, params: &Self::Params);
    /// Lane `l`'s sample at vertex `v`: its model's one-path sample's bit for bit.
    fn sample(&self, l: usize, v: &LaneVertex) -> LaneSample;
    /// Lane `l`'s evaluation at vertex `v` towards `wi`: its model's one-path evaluation's
    /// bit for bit.
    fn eval(&self, l: usize, v: &LaneVertex, wi: [f32; 3]) -> LaneEval;
}

/// A vertex with its BSDF sample, and what the path needs to go on from it.
#[derive(Debug, Clone, Copy)]
pub struct SampledVertex {
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

/// Per lane, a vertex on a material of kind `M` waiting for its BSDF sample
/// ([`SampleLanes::push`]), and after [`SampleLanes::compute`] its results
/// ([`SampleLanes::vertex`]). The waiting lanes' values are packed in slots, in the order
/// the lanes come, so that `compute` works on as many groups of
/// [`GROUP`](crate::slots::GROUP) slots as there are lanes waiting, not on the whole packet.
#[derive(Debug, Clone)]
pub struct SampleLanes<M> {
    /// The lanes waiting (or, after `compute`, with their results), and each one's slot.
    slots: Slots,
    // Inputs, per slot.
    position: Lanes3,
    /// The shading and geometric normals on the shape's front side.
    ns: Lanes3,
    ng: Lanes3,
    wo: Lanes3,
    color: Lanes3,
    /// The dimensions of the lobe and the Fresnel choices, of the direction, and of Russian
    /// roulette.
    u_lobe: [f32; PACKET],
    u_fresnel: [f32; PACKET],
    u: [[f32; PACKET]; 2],
    u_rr: [f32; PACKET],
    /// The material parameters.
    model: M,
    /// The light samples given to lanes ([`SampleLanes::push_light`]), and after `compute`
    /// the evaluations towards them.
    lights: LightLanes,
    // Outputs.
    wi: Lanes3,
    weight: Lanes3,
    pdf: [f32; PACKET],
    eta: [f32; PACKET],
    valid: [bool; PACKET],
}

impl<M: Default> Default for SampleLanes<M> {
    fn default() -> Self {
        let zero = [[0.0; PACKET]; 3];
        Self {
            slots: Slots::default(),
            position: zero,
            ns: zero,
            ng: zero,
            wo: zero,
            color: zero,
            u_lobe: [0.0; PACKET],
            u_fresnel: [0.0; PACKET],
            u: [[0.0; PACKET]; 2],
            u_rr: [0.0; PACKET],
            model: M::default(),
            lights: LightLanes::default(),
            wi: zero,
            weight: zero,
            pdf: [0.0; PACKET],
            eta: [1.0; PACKET],
            valid: [false; PACKET],
        }
    }
}

impl<M: LaneBsdf> SampleLanes<M> {
    /// No lane waits.
    #[inline(always)]
    pub fn clear(&mut self) {
        self.slots.clear();
        self.lights.clear();
    }

    /// Bit `l` set: lane `l` waits (or, after `compute`, has its results).
    #[inline(always)]
    pub fn mask(&self) -> Lanes {
        self.slots.mask
    }

    /// Lane `l`, which waits ([`SampleLanes::push`]), has the valid light sample `ls`: the
    /// BSDF is evaluated towards it too.
    #[inline(always)]
    pub fn push_light(&mut self, l: usize, ls: &LightSample) {
        self.lights.push(self.slots.slot(l), ls);
    }

    /// Lane `l`, which waits ([`SampleLanes::push`]), samples quad light `object` of
    /// `scene`, chosen with probability `pmf`, at `u_light`: [`SampleLanes::compute`] takes
    /// that sample as `sample_area_light` would (where it is valid, the BSDF is evaluated
    /// towards it).
    #[inline(always)]
    pub fn push_quad_light(
        &mut self,
        l: usize,
        scene: &CpuScene,
        object: u32,
        pmf: f32,
        u_light: Vec2,
    ) {
        self.lights
            .push_quad(self.slots.slot(l), scene, object, pmf, u_light);
    }

    /// Lane `l`, which waits ([`SampleLanes::push`]), samples the constant sky of radiance
    /// `radiance`, chosen with probability `pmf`, at `u_light`: [`SampleLanes::compute`]
    /// takes that sample as `sample_environment` would (where it is valid, the BSDF is
    /// evaluated towards it).
    #[inline(always)]
    pub fn push_sky_light(&mut self, l: usize, radiance: Vec3A, pmf: f32, u_light: Vec2) {
        self.lights
            .push_sky(self.slots.slot(l), radiance, pmf, u_light);
    }

    /// Lane `l` waits at `position`, on a material of parameters `params` and base colour
    /// `color`, with shading normal `ns` and geometric normal `ng` (both on the shape's
    /// front side), seen from `wo`, with the dimensions (`u_lobe`, `u_fresnel`, `u`, `u_rr`)
    /// of its lobe and Fresnel choices, of its direction and of Russian roulette.
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
        params: &M::Params,
        (u_lobe, u_fresnel, u, u_rr): (f32, f32, Vec2, f32),
    ) {
        let k = self.slots.take(l);
        set_lane(&mut self.position, k, position);
        set_lane(&mut self.ns, k, ns);
        set_lane(&mut self.ng, k, ng);
        set_lane(&mut self.wo, k, wo);
        set_lane(&mut self.color, k, color);
        self.model.set(k, params);
        self.u_lobe[k] = u_lobe;
        self.u_fresnel[k] = u_fresnel;
        self.u[0][k] = u.x;
        self.u[1][k] = u.y;
        self.u_rr[k] = u_rr;
    }

    /// Computes the waiting lanes' samples and the evaluations towards their light samples:
    /// up to `one_by_one` slots one after another ([`ONE_BY_ONE_WIDE`],
    /// [`ONE_BY_ONE_NARROW`]), more side by side in as many groups of
    /// [`GROUP`](crate::slots::GROUP) as they fill (the rest of the last group computes
    /// throw-away values).
    #[inline(always)]
    pub fn compute(&mut self, one_by_one: usize) {
        let count = self.slots.count();
        if count <= one_by_one {
            for k in 0..count {
                self.compute_lane(k);
                if self.lights.sky >> k & 1 != 0 {
                    self.lights.sample_sky(k, self.gathering_normal(k));
                }
                if self.lights.quad >> k & 1 != 0 {
                    self.lights.sample_quad(k, at(&self.position, k));
                }
                if self.lights.mask >> k & 1 != 0 {
                    self.compute_light(k);
                }
            }
            return;
        }
        in_groups!(count, N => self.compute_slots::<N>());
    }

    /// [`SampleLanes::compute`] side by side over the first `N` slots, a count the loops
    /// know.
    #[inline(always)]
    fn compute_slots<const N: usize>(&mut self) {
        for k in 0..N {
            self.compute_lane(k);
        }
        if self.lights.sky != 0 {
            let (ns, ng, wo) = (&self.ns, &self.ng, &self.wo);
            self.lights
                .sample_skies::<N>(|k| gathering_normal(at(ns, k), at(ng, k), at(wo, k)));
        }
        if self.lights.quad != 0 {
            let position = &self.position;
            self.lights.sample_quads::<N>(|k| at(position, k));
        }
        if self.lights.mask != 0 {
            for k in 0..N {
                self.compute_light(k);
            }
        }
    }

    /// Slot `l`'s shading normal on the side of `wo`.
    #[inline(always)]
    fn gathering_normal(&self, l: usize) -> [f32; 3] {
        gathering_normal(at(&self.ns, l), at(&self.ng, l), at(&self.wo, l))
    }

    /// Slot `l`'s vertex.
    #[inline(always)]
    fn lane_vertex(&self, l: usize) -> LaneVertex {
        LaneVertex {
            ns: at(&self.ns, l),
            ng: at(&self.ng, l),
            wo: at(&self.wo, l),
            color: at(&self.color, l),
            u_lobe: self.u_lobe[l],
            u_fresnel: self.u_fresnel[l],
            u: [self.u[0][l], self.u[1][l]],
        }
    }

    /// Computes the evaluation towards slot `l`'s light sample.
    #[inline(always)]
    fn compute_light(&mut self, l: usize) {
        let e = self
            .model
            .eval(l, &self.lane_vertex(l), at(&self.lights.wi, l));
        for axis in 0..3 {
            self.lights.f[axis][l] = e.f[axis];
        }
        self.lights.pdf[l] = e.pdf;
    }

    /// Computes slot `l`'s sample.
    #[inline(always)]
    fn compute_lane(&mut self, l: usize) {
        let s = self.model.sample(l, &self.lane_vertex(l));
        self.valid[l] = s.valid;
        for axis in 0..3 {
            self.wi[axis][l] = s.wi[axis];
            self.weight[axis][l] = s.weight[axis];
        }
        self.pdf[l] = s.pdf;
        self.eta[l] = s.eta;
    }

    /// Lane `l`'s results, once [`SampleLanes::compute`] ran.
    #[inline(always)]
    pub fn vertex(&self, l: usize) -> SampledVertex {
        let l = self.slots.slot(l);
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
        SampledVertex {
            sample,
            position: lane(&self.position, l),
            ng: lane(&self.ng, l),
            n: Vec3A::from_array(self.gathering_normal(l)),
            u_rr: self.u_rr[l],
        }
    }

    /// Lane `l`'s light sample ([`SampleLanes::push_light`]), if it has one, and the
    /// BSDF's evaluation towards it, once [`SampleLanes::compute`] ran.
    #[inline(always)]
    pub fn light(&self, l: usize) -> Option<LitVertex<'_>> {
        let l = self.slots.slot(l);
        let (position, ng) = (lane(&self.position, l), lane(&self.ng, l));
        self.lights.lit(l, position, ng)
    }
}

/// Shading normal `ns` (on the shape's front side, whose geometric normal is `ng`) on the
/// side of `wo`, as `Path::step` turns it.
#[inline(always)]
fn gathering_normal(ns: [f32; 3], ng: [f32; 3], wo: [f32; 3]) -> [f32; 3] {
    if dot(wo, ng) >= 0.0 {
        ns
    } else {
        ns.map(|c| -c)
    }
}

/// A vertex's normals turned to the side of `wo`, as `eval_lobes` and `metal_rough::eval`
/// turn them, and `wo` in the frame around the shading one.
pub(crate) struct Side {
    /// The geometric normal.
    pub ng: [f32; 3],
    /// The shading normal.
    pub n: [f32; 3],
    /// The frame around it.
    pub frame: [[f32; 3]; 3],
    /// `wo` in that frame.
    pub wo_l: [f32; 3],
}

/// The side of `v`'s `wo`.
#[inline(always)]
pub(crate) fn side(v: &LaneVertex) -> Side {
    let LaneVertex { ns, ng, wo, .. } = *v;
    let sign = if dot(wo, ng) >= 0.0 { 1.0 } else { -1.0 };
    let n = ns.map(|c| c * sign);
    let frame = frame_around(n);
    Side {
        ng: ng.map(|c| c * sign),
        n,
        frame,
        wo_l: to_local(&frame, wo),
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::environment::sample_environment;
    use crate::light_lanes::tests::assert_lit_as;
    use crate::light_sample::INVALID as INVALID_LIGHT;
    use crate::lights::{choose_light, sample_table_light};
    use crate::microfacet::BsdfEval;
    use crate::surface::Surface;
    use pathlight_core::PreparedScene;
    use pathlight_core::gpu_types::{GpuRenderParams, KIND_QUAD, LIGHT_AREA};

    /// Uniform numbers in [0, 1) (xorshift from `state`).
    pub(crate) fn uniform(mut state: u32) -> impl FnMut() -> f32 {
        move || {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            state as f32 / 4_294_967_296.0
        }
    }

    /// A unit vector from three uniform numbers in [-1, 1) (not uniform on the sphere).
    fn unit(next: &mut dyn FnMut() -> f32) -> Vec3A {
        (Vec3A::new(next(), next(), next()) * 2.0 - 1.0).normalize()
    }

    /// A one-path BSDF sample: `sample_lobes`'s arguments.
    pub(crate) type OnePathSample<P> = fn(&P, Vec3A, &Surface, Vec3A, f32, f32, Vec2) -> BsdfSample;

    /// A one-path BSDF evaluation: `eval_lobes`'s arguments.
    pub(crate) type OnePathEval<P> = fn(&P, Vec3A, &Surface, Vec3A, Vec3A) -> BsdfEval;

    /// Checks that lanes of kind `M` compute the samples of `sample` (a model's one-path
    /// function, such as `sample_lobes`) bit for bit, and the evaluations of `eval` (such
    /// as `eval_lobes`) towards light samples (three lanes in four have one: a random
    /// direction or the lane's own sampled one, a constant sky's sample, which the lanes
    /// take as `sample_environment` does, or a quad light's, which they take as
    /// `sample_area_light` does), over 512 packets from one lane waiting to all, in
    /// any order: materials from `material` (given the lane and the random numbers), random
    /// geometric normals, shading normals bent away from them and next to -z (the frame's
    /// other branch), views from both sides, draws at 0 and next to 1. Returns how many
    /// samples were invalid, how many valid ones `class` put in each of its two classes,
    /// and how many evaluations were not zero.
    pub(crate) fn assert_lanes_as_one_path<M: LaneBsdf>(
        seed: u32,
        (sample, eval): (OnePathSample<M::Params>, OnePathEval<M::Params>),
        mut material: impl FnMut(usize, &mut dyn FnMut() -> f32) -> M::Params,
        class: impl Fn(&BsdfSample, &M::Params) -> bool,
    ) -> [usize; 4] {
        let mut next = uniform(seed);
        let mut outcomes = [0; 4];
        // A scene with a quad light (cornell-materials' ceiling light; its glowing spheres
        // are left to `Path::step`).
        let path = format!(
            "{}/../../scenes/refs/cornell-materials.toml",
            env!("CARGO_MANIFEST_DIR")
        );
        let scene = pathlight_scene::load_scene_file(std::path::Path::new(&path)).unwrap();
        let prepared = PreparedScene::new(&scene).unwrap();
        let cpu_scene = CpuScene::new(&prepared);
        let mut params = GpuRenderParams::new(&scene.camera, &scene.settings, &prepared.shading);
        // A share of the light samples other than 1, so that its arithmetic shows, and a sky
        // of some colour.
        params.env_pmf = 0.37;
        params.environment = [0.3, 0.5, 0.7];
        let sky = Vec3A::from(params.environment);
        for round in 0..512 {
            let mut lanes = SampleLanes::<M>::default();
            let mut cases = Vec::new();
            for l in 0..1 + round % PACKET {
                let m = material(l, &mut next);
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
                let (u_lobe, u_fresnel) = (next(), next());
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
                let lane = (l * 7 + round) % PACKET;
                let u_all = (u_lobe, u_fresnel, u, 0.5);
                lanes.push(lane, s.position, ns, ng, wo, color, &m, u_all);
                let theirs = sample(&m, color, &s, wo, u_lobe, u_fresnel, u);
                // The light sample the lanes take, where they take it.
                let mut taken = None;
                let light = match l % 4 {
                    0 => {
                        let wi = if l % 2 == 0 && theirs.valid {
                            theirs.wi
                        } else {
                            unit(&mut next)
                        };
                        let ls = LightSample {
                            wi,
                            ..INVALID_LIGHT
                        };
                        lanes.push_light(lane, &ls);
                        Some((wi, eval(&m, color, &s, wo, wi)))
                    }
                    2 => {
                        let u_light = Vec2::new(next(), next());
                        lanes.push_sky_light(lane, sky, params.env_pmf, u_light);
                        let n = if wo.dot(ng) >= 0.0 { ns } else { -ns };
                        let ls = sample_environment(&cpu_scene, &params, n, u_light);
                        taken = ls.valid.then_some(ls);
                        ls.valid.then(|| (ls.wi, eval(&m, color, &s, wo, ls.wi)))
                    }
                    3 => {
                        let (light, pmf) = loop {
                            if let Some((light, pmf, _)) = choose_light(&cpu_scene, &params, next())
                                && light.kind == LIGHT_AREA
                                && cpu_scene.objects[light.index as usize].kind == KIND_QUAD
                            {
                                break (light, pmf);
                            }
                        };
                        let u_light = Vec2::new(next(), next());
                        lanes.push_quad_light(lane, &cpu_scene, light.index, pmf, u_light);
                        let ls =
                            sample_table_light(&cpu_scene, light, pmf, s.position, u_light, 0.5);
                        taken = ls.valid.then_some(ls);
                        ls.valid.then(|| (ls.wi, eval(&m, color, &s, wo, ls.wi)))
                    }
                    _ => None,
                };
                cases.push((m, theirs, light, taken));
            }
            // Both ways, whatever the count.
            lanes.compute([0, ONE_BY_ONE_WIDE][round % 2]);
            assert_eq!(lanes.mask().count_ones() as usize, cases.len());
            let bits = |v: Vec3A| v.to_array().map(f32::to_bits);
            for (l, (m, theirs, light, taken)) in cases.iter().enumerate() {
                let vertex = lanes.vertex((l * 7 + round) % PACKET);
                let ours = lanes.light((l * 7 + round) % PACKET);
                if let (Some(ours), Some(theirs)) = (&ours, taken) {
                    let ours = ours.light;
                    assert_eq!(ours.pdf.to_bits(), theirs.pdf.to_bits(), "lane {l}");
                    assert_eq!(bits(ours.point), bits(theirs.point), "lane {l}");
                    assert_eq!(ours.radiance, theirs.radiance, "lane {l}");
                    assert_eq!((ours.mis, ours.finite), (theirs.mis, theirs.finite));
                    assert!(ours.map_cell.is_none());
                }
                outcomes[3] += usize::from(assert_lit_as(ours, light.as_ref(), l, round));
                let ours = vertex.sample;
                assert_eq!(ours.valid, theirs.valid, "lane {l}, round {round}");
                if !ours.valid {
                    outcomes[0] += 1;
                    continue;
                }
                outcomes[1 + usize::from(class(&ours, m))] += 1;
                assert_eq!(bits(ours.wi), bits(theirs.wi), "lane {l}, round {round}");
                assert_eq!(bits(ours.weight), bits(theirs.weight), "lane {l}");
                assert_eq!(ours.pdf.to_bits(), theirs.pdf.to_bits(), "lane {l}");
                assert_eq!(ours.eta.to_bits(), theirs.eta.to_bits(), "lane {l}");
                assert_eq!(ours.delta, theirs.delta);
            }
        }
        outcomes
    }
}
