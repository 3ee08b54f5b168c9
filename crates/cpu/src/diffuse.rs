//! The rest of a bounce for the lanes of a packet whose paths stand on a purely diffuse
//! surface (the lobes model with its Lambert lobe alone), computed side by side: each lane's
//! BSDF sample (frame, cosine-weighted direction, validity, weight) and, where its light
//! sample is on a quad, of a constant sky, or of a point, spot or sun light without size,
//! that sample with the BSDF towards it, its multiple-importance weight and shadow ray;
//! where the sample was taken elsewhere (an environment map's), the BSDF towards it.
//! Written as loops over the lanes that the compiler turns into SIMD instructions, they take
//! the place of long chains of scalar square roots and divisions per path. The values are
//! the one-path functions' bit for bit (`sample_lobes`, `sample_area_light`,
//! `sample_environment`, `sample_point_light`, `sample_sun_light`, `eval_lobes`,
//! `power_heuristic`, `shadow_ray`): the same operations in the same order. Scalar helpers
//! are called as they are (`sin_cos_turns`, `power_heuristic`); those written on glam's
//! `Vec3A` are written again on `[f32; 3]` (`Frame`, the dot product and
//! `sample_cosine_hemisphere` in `soa.rs`), as the packet code keeps its lanes in plain arrays, and
//! the tests hold each copy to its original. CPU only (on the GPU, threads are lanes
//! already).

use std::f32::consts::{FRAC_1_PI, PI};

use glam::{Vec2, Vec3A};
use pathlight_core::gpu_types::{GpuLight, LIGHT_SUN};

use crate::cpu_scene::CpuScene;
use crate::integrator::{ShadowTest, T_MAX};
use crate::intersect::Ray;
use crate::light_lanes::{LightLanes, LitVertex, QuadLanes, QuadSample};
use crate::light_sample::LightSample;
use crate::microfacet::{BsdfSample, INVALID};
use crate::packet::{Lanes, PACKET};
use crate::sampling::power_heuristic;
use crate::slots::{Slots, in_groups};
use crate::soa::{Lanes3, cosine_hemisphere, dot, frame_around, lane, set_lane, to_world};

/// A diffuse vertex with its BSDF sample, and what the path needs to go on from it.
#[derive(Debug, Clone, Copy)]
pub struct DiffuseVertex {
    /// The shadow test of its light sample where the lanes took it
    /// ([`DiffuseLanes::push_quad_light`], [`DiffuseLanes::push_sky_light`],
    /// [`DiffuseLanes::push_punctual_light`]), unless the BSDF passes nothing of it on.
    pub shadow: Option<ShadowTest>,
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
/// and after [`DiffuseLanes::compute`] its results ([`DiffuseLanes::vertex`]). The waiting
/// lanes' values are packed in [`Slots`], in the order the lanes come, so that `compute`
/// works on as many groups of eight slots as there are lanes waiting, not on the whole
/// packet (a packet with a third of its paths on diffuse surfaces costs half the work).
#[derive(Debug, Clone)]
pub struct DiffuseLanes {
    /// The lanes waiting (or, after `compute`, with their results), and each one's slot:
    /// the index of its values below (and in the bit masks below).
    slots: Slots,
    // Inputs, per slot.
    position: Lanes3,
    /// The shading and geometric normals, on the side of `wo`.
    n: Lanes3,
    ng: Lanes3,
    wo: Lanes3,
    color: Lanes3,
    /// The two dimensions the BSDF direction is drawn from, and Russian roulette's.
    u: [[f32; PACKET]; 2],
    u_rr: [f32; PACKET],
    /// Bit `k` set: slot `k`'s light sample is of a constant environment instead
    /// ([`DiffuseLanes::push_sky_light`]), of probability `sky_pmf`.
    sky_light: Lanes,
    sky_pmf: f32,
    /// Bit `k` set: slot `k`'s light sample is on a quad light, and waits too
    /// ([`DiffuseLanes::push_quad_light`]).
    quad_light: Lanes,
    /// The quad (corner, edges, unit normal, area).
    quad: QuadLanes,
    /// Bit `k` set: slot `k`'s light sample is of a point or spot light without a radius, or
    /// of a sun without a disk ([`DiffuseLanes::push_punctual_light`]), and waits too.
    punctual_light: Lanes,
    /// Per slot of `punctual_light`: a sun (or else a point or spot light).
    sun: [bool; PACKET],
    /// The point or spot light's position (a sun's direction towards it), and the spot's
    /// axis, cosine of its outer angle and falloff scale (`sample_point_light`'s block).
    punctual: [Lanes3; 2],
    spot: [[f32; PACKET]; 2],
    /// The probability of having chosen the light (quad or punctual), its radiance (a point
    /// light's intensity, a sun's irradiance), the dimensions of the point on it, and the
    /// path's throughput.
    light_pmf: [f32; PACKET],
    emission: Lanes3,
    u_light: [[f32; PACKET]; 2],
    throughput: Lanes3,
    /// The light samples taken elsewhere, given to lanes ([`DiffuseLanes::push_light`]), and
    /// after `compute` the evaluations towards them, by slot.
    given: LightLanes,
    // Outputs, per slot.
    lit: [bool; PACKET],
    shadow_origin: Lanes3,
    shadow_dir: Lanes3,
    shadow_t_max: [f32; PACKET],
    unblocked: Lanes3,
    wi: Lanes3,
    weight: Lanes3,
    pdf: [f32; PACKET],
    valid: [bool; PACKET],
}

impl Default for DiffuseLanes {
    fn default() -> Self {
        let zero = [[0.0; PACKET]; 3];
        Self {
            slots: Slots::default(),
            position: zero,
            n: zero,
            ng: zero,
            wo: zero,
            color: zero,
            u: [[0.0; PACKET]; 2],
            u_rr: [0.0; PACKET],
            sky_light: 0,
            sky_pmf: 0.0,
            quad_light: 0,
            quad: QuadLanes::default(),
            punctual_light: 0,
            sun: [false; PACKET],
            punctual: [zero; 2],
            spot: [[0.0; PACKET]; 2],
            light_pmf: [0.0; PACKET],
            emission: zero,
            u_light: [[0.0; PACKET]; 2],
            throughput: zero,
            given: LightLanes::default(),
            lit: [false; PACKET],
            shadow_origin: zero,
            shadow_dir: zero,
            shadow_t_max: [0.0; PACKET],
            unblocked: zero,
            wi: zero,
            weight: zero,
            pdf: [0.0; PACKET],
            valid: [false; PACKET],
        }
    }
}

impl DiffuseLanes {
    /// No lane waits.
    #[inline(always)]
    pub fn clear(&mut self) {
        self.slots.clear();
        self.quad_light = 0;
        self.sky_light = 0;
        self.punctual_light = 0;
        self.given.clear();
    }

    /// Bit `l` set: lane `l` waits (or, after `compute`, has its results).
    #[inline(always)]
    pub fn mask(&self) -> Lanes {
        self.slots.mask
    }

    /// Lane `l` (also [`DiffuseLanes::push`]ed) has the valid light sample `ls`, taken
    /// elsewhere: the BSDF is evaluated towards it.
    #[inline(always)]
    pub fn push_light(&mut self, l: usize, ls: &LightSample) {
        let k = self.slots.slot(l);
        self.given.push(k, ls);
    }

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
        let k = self.slots.slot_or_take(l);
        set_lane(&mut self.position, k, position);
        set_lane(&mut self.n, k, n);
        set_lane(&mut self.ng, k, ng);
        set_lane(&mut self.wo, k, wo);
        set_lane(&mut self.color, k, color);
        self.u[0][k] = u.x;
        self.u[1][k] = u.y;
        self.u_rr[k] = u_rr;
    }

    /// Lane `l` (also [`DiffuseLanes::push`]ed) samples quad `object` of `scene`, chosen with
    /// probability `pmf`, at `u_light`, as `sample_area_light` would, for a path of
    /// throughput `throughput`.
    #[inline(always)]
    pub fn push_quad_light(
        &mut self,
        l: usize,
        scene: &CpuScene,
        object: u32,
        pmf: f32,
        u_light: Vec2,
        throughput: Vec3A,
    ) {
        let k = self.slots.slot_or_take(l);
        let emission = self.quad.set(k, scene, object);
        self.light_pmf[k] = pmf;
        set_lane(&mut self.emission, k, emission);
        self.u_light[0][k] = u_light.x;
        self.u_light[1][k] = u_light.y;
        set_lane(&mut self.throughput, k, throughput);
        self.quad_light |= 1 << k;
    }

    /// Lane `l` (also [`DiffuseLanes::push`]ed) samples the constant environment of radiance
    /// `radiance`, chosen with probability `pmf`, at `u_light`, as `sample_environment`
    /// would, for a path of throughput `throughput`.
    #[inline(always)]
    pub fn push_sky_light(
        &mut self,
        l: usize,
        radiance: Vec3A,
        pmf: f32,
        u_light: Vec2,
        throughput: Vec3A,
    ) {
        let k = self.slots.slot_or_take(l);
        set_lane(&mut self.emission, k, radiance);
        self.sky_pmf = pmf;
        self.u_light[0][k] = u_light.x;
        self.u_light[1][k] = u_light.y;
        set_lane(&mut self.throughput, k, throughput);
        self.sky_light |= 1 << k;
    }

    /// Lane `l` (also [`DiffuseLanes::push`]ed) samples `light`, a point or spot light
    /// without a radius or a sun without a disk ([`crate::lights::is_delta_light`]), chosen
    /// with probability `pmf`, as `sample_point_light` or `sample_sun_light` would, for a
    /// path of throughput `throughput`.
    #[inline(always)]
    pub fn push_punctual_light(
        &mut self,
        l: usize,
        scene: &CpuScene,
        light: &GpuLight,
        pmf: f32,
        throughput: Vec3A,
    ) {
        let k = self.slots.slot_or_take(l);
        let block = light.index as usize;
        let b = &scene.param_blocks[block..block + 2];
        set_lane(
            &mut self.punctual[0],
            k,
            Vec3A::new(b[0][0], b[0][1], b[0][2]),
        );
        set_lane(&mut self.emission, k, Vec3A::new(b[1][0], b[1][1], b[1][2]));
        let sun = light.kind == LIGHT_SUN;
        if !sun {
            let axis = scene.param_blocks[block + 2];
            set_lane(
                &mut self.punctual[1],
                k,
                Vec3A::new(axis[0], axis[1], axis[2]),
            );
            self.spot[0][k] = axis[3];
            self.spot[1][k] = b[1][3];
        }
        self.sun[k] = sun;
        self.light_pmf[k] = pmf;
        set_lane(&mut self.throughput, k, throughput);
        self.punctual_light |= 1 << k;
    }

    /// Computes the waiting lanes' slots side by side, in as many groups of eight as
    /// they fill (the rest of the last group computes throw-away values).
    #[inline(always)]
    pub fn compute(&mut self) {
        in_groups!(self.slots.count(), N => self.compute_slots::<N>());
    }

    /// [`DiffuseLanes::compute`] of the first `N` slots, a count the loops know.
    #[inline(always)]
    fn compute_slots<const N: usize>(&mut self) {
        // The quads' loop writes every slot; the sky's and the punctual lights' then their
        // own slots only, where a kind before them wrote too.
        if self.quad_light != 0 {
            self.light_quads::<N>();
        }
        match (self.sky_light != 0, self.quad_light != 0) {
            (true, true) => self.light_skies::<true, N>(),
            (true, false) => self.light_skies::<false, N>(),
            _ => {}
        }
        match (
            self.punctual_light != 0,
            self.quad_light | self.sky_light != 0,
        ) {
            (true, true) => self.light_punctuals::<true, N>(),
            (true, false) => self.light_punctuals::<false, N>(),
            _ => {}
        }
        for l in 0..N {
            let at = |a: &Lanes3| [a[0][l], a[1][l], a[2][l]];
            let (n, ng, wo) = (at(&self.n), at(&self.ng), at(&self.wo));
            // The BSDF sample: `sample_cosine_hemisphere`, turned by `Frame::around(n)`.
            let local = cosine_hemisphere(self.u[0][l], self.u[1][l]);
            let wi = to_world(&frame_around(n), local);
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
        if self.given.mask != 0 {
            for l in 0..N {
                let at = |a: &Lanes3| [a[0][l], a[1][l], a[2][l]];
                let (n, ng, wo, wi) = (at(&self.n), at(&self.ng), at(&self.wo), at(&self.given.wi));
                // `eval_lobes` of the Lambert lobe alone, as `next_event` computes it.
                let cos_o = dot(wo, n);
                let cos_i = dot(wi, n);
                let seen = dot(wi, ng) > 0.0 && cos_o > 0.0 && cos_i > 0.0;
                for axis in 0..3 {
                    let f = self.color[axis][l] * FRAC_1_PI * cos_i;
                    self.given.f[axis][l] = if seen { f } else { 0.0 };
                }
                self.given.pdf[l] = if seen { FRAC_1_PI * cos_i } else { 0.0 };
            }
        }
    }

    /// The quad lights' samples side by side: `sample_area_light` of a quad, then what
    /// `Path::step` does with it: `eval_lobes` of the Lambert lobe alone, `power_heuristic`,
    /// `shadow_ray`.
    #[inline(always)]
    fn light_quads<const N: usize>(&mut self) {
        for l in 0..N {
            let at = |a: &Lanes3| [a[0][l], a[1][l], a[2][l]];
            let p = at(&self.position);
            let u = (self.u_light[0][l], self.u_light[1][l]);
            let QuadSample {
                q,
                wi,
                pdf,
                sampled,
            } = self.quad.sample(l, p, self.light_pmf[l], u);
            let radiance = at(&self.emission);
            let (lit, origin, unblocked) = self.next_event(l, wi, pdf, sampled, radiance, true);
            let to_light: [f32; 3] = std::array::from_fn(|i| q[i] - origin[i]);
            let distance = dot(to_light, to_light).sqrt();
            let dir = to_light.map(|v| v / distance);
            let t_max = distance * (1.0 - 1e-4);
            self.set_shadow(l, true, lit, origin, dir, t_max, unblocked);
        }
    }

    /// The constant environment's samples side by side: `sample_environment` without a map
    /// (a cosine-weighted direction about `n`), then what `Path::step` does with it, as
    /// [`DiffuseLanes::light_quads`]; `MASKED`: leaving the other slots' results as they are.
    #[inline(always)]
    fn light_skies<const MASKED: bool, const N: usize>(&mut self) {
        for l in 0..N {
            let n = [self.n[0][l], self.n[1][l], self.n[2][l]];
            let frame = frame_around(n);
            let local = cosine_hemisphere(self.u_light[0][l], self.u_light[1][l]);
            let wi = to_world(&frame, local);
            let pdf = self.sky_pmf * dot(n, wi).max(0.0) / PI;
            let radiance = [
                self.emission[0][l],
                self.emission[1][l],
                self.emission[2][l],
            ];
            let (lit, origin, unblocked) = self.next_event(l, wi, pdf, pdf > 0.0, radiance, true);
            let mine = !MASKED || self.sky_light >> l & 1 != 0;
            self.set_shadow(l, mine, lit, origin, wi, T_MAX, unblocked);
        }
    }

    /// The point, spot and sun lights' samples side by side: `sample_point_light` without
    /// a radius (towards the point, the spot's falloff, the inverse square) or
    /// `sample_sun_light` without a disk (along its direction), then what `Path::step` does
    /// with it, as [`DiffuseLanes::light_quads`] but without a multiple-importance weight (no
    /// ray hits such a light); `MASKED`: leaving the other slots' results as they are.
    #[inline(always)]
    fn light_punctuals<const MASKED: bool, const N: usize>(&mut self) {
        for l in 0..N {
            let at = |a: &Lanes3| [a[0][l], a[1][l], a[2][l]];
            let (p, target, axis) = (
                at(&self.position),
                at(&self.punctual[0]),
                at(&self.punctual[1]),
            );
            let intensity = at(&self.emission);
            let sun = self.sun[l];
            // `sample_point_light`. Channel by channel, not `array::from_fn` or `map`, whose
            // closures may be left out of line.
            let to_center = [target[0] - p[0], target[1] - p[1], target[2] - p[2]];
            let d2 = dot(to_center, to_center);
            let d = d2.sqrt();
            let towards = [to_center[0] / d, to_center[1] / d, to_center[2] / d];
            let away = [-towards[0], -towards[1], -towards[2]];
            let t = (dot(away, axis) - self.spot[0][l]) * self.spot[1][l];
            let t = t.clamp(0.0, 1.0);
            let falloff = t * t;
            let fraction = falloff / d2;
            let point_radiance = [
                intensity[0] * fraction,
                intensity[1] * fraction,
                intensity[2] * fraction,
            ];
            let pdf = self.light_pmf[l];
            let point_valid = d2 > 0.0
                && falloff > 0.0
                && point_radiance[0].is_finite()
                && point_radiance[1].is_finite()
                && point_radiance[2].is_finite();
            // `sample_sun_light`: the direction and irradiance as they are.
            let wi = if sun { target } else { towards };
            let radiance = if sun { intensity } else { point_radiance };
            let sampled = (sun || point_valid) && pdf > 0.0 && pdf.is_finite();
            let (lit, origin, unblocked) = self.next_event(l, wi, pdf, sampled, radiance, false);
            // `shadow_ray`: to the point, stopping short of it, or along the sun's direction.
            let to_light = [
                target[0] - origin[0],
                target[1] - origin[1],
                target[2] - origin[2],
            ];
            let distance = dot(to_light, to_light).sqrt();
            let dir = if sun {
                wi
            } else {
                [
                    to_light[0] / distance,
                    to_light[1] / distance,
                    to_light[2] / distance,
                ]
            };
            let t_max = if sun { T_MAX } else { distance * (1.0 - 1e-4) };
            let mine = !MASKED || self.punctual_light >> l & 1 != 0;
            self.set_shadow(l, mine, lit, origin, dir, t_max, unblocked);
        }
    }

    /// What `Path::step` does with lane `l`'s light sample (direction `wi`, density `pdf`,
    /// `sampled` where valid): `eval_lobes` of the Lambert lobe towards it, then whether it
    /// lights the vertex, the shadow ray's origin (`shadow_ray`'s, on the side of `ng` the
    /// light is on, as a lit lane's is), and the radiance it adds unblocked for the light's
    /// `radiance` (`power_heuristic` weighted where `mis`).
    #[inline(always)]
    fn next_event(
        &self,
        l: usize,
        wi: [f32; 3],
        pdf: f32,
        sampled: bool,
        radiance: [f32; 3],
        mis: bool,
    ) -> (bool, [f32; 3], [f32; 3]) {
        let at = |a: &Lanes3| [a[0][l], a[1][l], a[2][l]];
        let (p, n, ng, wo) = (at(&self.position), at(&self.n), at(&self.ng), at(&self.wo));
        let cos_o = dot(wo, n);
        let cos_i = dot(wi, n);
        let seen = dot(wi, ng) > 0.0 && cos_o > 0.0 && cos_i > 0.0;
        // Channel by channel, not `array::from_fn`, whose closure may be left out of line.
        let f = if seen {
            let c = |i: usize| self.color[i][l] * FRAC_1_PI * cos_i;
            [c(0), c(1), c(2)]
        } else {
            [0.0; 3]
        };
        let bsdf_pdf = if seen { FRAC_1_PI * cos_i } else { 0.0 };
        let lit = sampled && f[0].max(f[1]).max(f[2]) > 0.0;
        let weight = if mis {
            power_heuristic(pdf, bsdf_pdf)
        } else {
            1.0
        };
        let eps = 1e-4 * (1.0 + p[0].abs().max(p[1].abs()).max(p[2].abs()));
        let origin = [p[0] + ng[0] * eps, p[1] + ng[1] * eps, p[2] + ng[2] * eps];
        let unblocked = |i: usize| self.throughput[i][l] * f[i] * radiance[i] * weight / pdf;
        let unblocked = [unblocked(0), unblocked(1), unblocked(2)];
        (lit, origin, unblocked)
    }

    /// Sets lane `l`'s shadow test where `mine`: whether the light sample lights it, the
    /// shadow ray and the end of its interval, the radiance added unblocked.
    #[inline(always)]
    #[expect(clippy::too_many_arguments, reason = "a shadow test, field by field")]
    fn set_shadow(
        &mut self,
        l: usize,
        mine: bool,
        lit: bool,
        origin: [f32; 3],
        dir: [f32; 3],
        t_max: f32,
        unblocked: [f32; 3],
    ) {
        // Written as selects, so that the loops stay SIMD.
        let pick = |new: f32, old: f32| if mine { new } else { old };
        self.lit[l] = if mine { lit } else { self.lit[l] };
        self.shadow_t_max[l] = pick(t_max, self.shadow_t_max[l]);
        for i in 0..3 {
            self.shadow_origin[i][l] = pick(origin[i], self.shadow_origin[i][l]);
            self.shadow_dir[i][l] = pick(dir[i], self.shadow_dir[i][l]);
            self.unblocked[i][l] = pick(unblocked[i], self.unblocked[i][l]);
        }
    }

    /// Lane `l`'s results, once [`DiffuseLanes::compute`] ran.
    #[inline(always)]
    pub fn vertex(&self, l: usize) -> DiffuseVertex {
        let l = self.slots.slot(l);
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
        let shadow = ((self.quad_light | self.sky_light | self.punctual_light) >> l & 1 != 0
            && self.lit[l])
            .then(|| ShadowTest {
                ray: Ray::new(lane(&self.shadow_origin, l), lane(&self.shadow_dir, l)),
                t_max: self.shadow_t_max[l],
                radiance: lane(&self.unblocked, l),
            });
        DiffuseVertex {
            shadow,
            sample,
            position: lane(&self.position, l),
            ng: lane(&self.ng, l),
            n: lane(&self.n, l),
            u_rr: self.u_rr[l],
        }
    }

    /// Lane `l`'s light sample given to the lanes ([`DiffuseLanes::push_light`]), if it has
    /// one, and the BSDF's evaluation towards it, once [`DiffuseLanes::compute`] ran.
    #[inline(always)]
    pub fn given_light(&self, l: usize) -> Option<LitVertex<'_>> {
        let l = self.slots.slot(l);
        let (position, ng) = (lane(&self.position, l), lane(&self.ng, l));
        self.given.lit(l, position, ng)
    }
}

#[cfg(test)]
mod tests {
    use glam::{Vec2, Vec3, Vec4};

    use pathlight_core::gpu_types::{GpuRenderParams, KIND_QUAD, LIGHT_AREA};

    use super::*;
    use crate::bsdf_lanes::tests::uniform;
    use crate::integrator::shadow_ray;
    use crate::light_lanes::tests::assert_lit_as;
    use crate::light_sample::INVALID as INVALID_LIGHT;
    use crate::lights::{
        choose_light, is_delta_light, light_radiance, sample_light, sample_table_light,
    };
    use crate::lobes::{LobesParams, eval_lobes, sample_lobes};
    use crate::material::MODEL_PARAMS;
    use crate::surface::Surface;

    /// A unit vector from three uniform numbers in [-1, 1) (not uniform on the sphere).
    fn unit(v: impl Into<Vec3A>) -> Vec3A {
        v.into().normalize()
    }

    /// The surface at `position` with geometric normal `ng` and shading normal `ns`.
    fn surface(position: Vec3A, ng: Vec3A, ns: Vec3A) -> Surface {
        Surface {
            position,
            ng,
            ns,
            nc: ns,
            uv: Vec2::ZERO,
            material: 0,
            color: Vec3A::ONE,
        }
    }

    /// The lanes a round of the tests pushes, in the order pushed: all of them, or some (so
    /// that the slots in use end within each group of eight, and no slot is its lane), in
    /// rising or falling order.
    fn lanes_of_round(round: usize) -> Vec<usize> {
        let count = [PACKET, 5, 13, 20, 27, 1, 31][round % 7];
        // (13 l + 7 round) mod 32 takes every value once over the lanes.
        let mut lanes: Vec<usize> = (0..PACKET)
            .filter(|l| (l * 13 + round * 7) % PACKET < count)
            .collect();
        if round % 2 == 1 {
            lanes.reverse();
        }
        lanes
    }

    /// Three uniform numbers in [-1, 1) drawn from `next`.
    fn r3(next: &mut impl FnMut() -> f32) -> Vec3A {
        Vec3A::new(next(), next(), next()) * 2.0 - 1.0
    }

    /// Every lane's sample (of all lanes, or of some pushed in any order: `lanes_of_round`)
    /// is `sample_lobes`'s for a Lambert material bit for bit, and its
    /// evaluation towards a light sample given to it (two lanes in three: a random direction
    /// or the lane's own sampled one) `eval_lobes`'s: shading normals bent away from the
    /// geometric one, both sides of the surface, normals next to -z (the frame's other
    /// branch), and draws at 0 and next to 1. It fails with any operation reordered (a dot
    /// product summed in another order, the frame's terms grouped otherwise).
    #[test]
    fn lanes_sample_as_sample_lobes_bit_for_bit() {
        let mut block = [Vec4::ZERO; MODEL_PARAMS];
        block[1].y = 1.5;
        let m = LobesParams::decode(&block);
        assert!(m.is_lambert());
        let mut next = uniform(0x9e37_79b9);
        let mut checked = [0; 3];
        for round in 0..128 {
            let mut lanes = DiffuseLanes::default();
            let mut cases = Vec::new();
            for l in lanes_of_round(round) {
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
                let s = surface(r3(&mut next) * 10.0, ng, ns);
                let side = if wo.dot(ng) >= 0.0 { 1.0 } else { -1.0 };
                let (n, ng_side) = (ns * side, ng * side);
                lanes.push(l, s.position, n, ng_side, wo, color, u, 0.5);
                let sample = sample_lobes(&m, color, &s, wo, 0.5, 0.5, u);
                let light = (l % 3 != 1).then(|| {
                    let wi = if l % 2 == 0 && sample.valid {
                        sample.wi
                    } else {
                        unit(r3(&mut next))
                    };
                    let ls = crate::light_sample::LightSample {
                        wi,
                        ..INVALID_LIGHT
                    };
                    lanes.push_light(l, &ls);
                    (wi, eval_lobes(&m, color, &s, wo, wi))
                });
                cases.push((l, sample, light));
            }
            lanes.compute();
            let bits = |v: Vec3A| v.to_array().map(f32::to_bits);
            let pushed = cases.iter().fold(0, |mask: Lanes, (l, ..)| mask | 1 << l);
            assert_eq!(lanes.mask(), pushed, "round {round}");
            for (l, theirs, light) in &cases {
                let l = *l;
                let vertex = lanes.vertex(l);
                let ours = lanes.given_light(l);
                checked[2] += usize::from(assert_lit_as(ours, light.as_ref(), l, round));
                let ours = vertex.sample;
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
        // Both outcomes, and evaluations not zero, were met often.
        assert!(checked.iter().all(|&n| n > 200), "{checked:?}");
    }

    /// Which lights [`light_lanes_as_path_step`] samples (several: in one packet, each
    /// kind's results staying in its lanes).
    #[derive(Clone, Copy)]
    struct Wanted {
        quad: bool,
        sky: bool,
        /// Point, spot and sun lights without size.
        punctual: bool,
    }

    const NONE: Wanted = Wanted {
        quad: false,
        sky: false,
        punctual: false,
    };

    /// A point light, a spot light and a sun without size, and a point light with a radius
    /// and a sun with a disk (which the lanes leave to `Path::step`), above the Cornell box.
    fn punctual_lights() -> Vec<pathlight_scene::Light> {
        use pathlight_scene::{Cone, Light as SceneLight, LightKind};
        let light = |intensity: f32, kind| SceneLight {
            name: "l".into(),
            intensity: Vec3::new(1.0, 0.8, 0.6) * intensity,
            kind,
        };
        let point = |position: Vec3, radius: f32, cone| LightKind::Point {
            position,
            radius,
            cone,
        };
        let sun = |angular_diameter_deg: f32| LightKind::Sun {
            direction: Vec3::new(0.3, -1.0, -0.2),
            angular_diameter_deg,
        };
        let cone = Cone {
            axis: Vec3::new(0.2, -1.0, 0.1),
            inner_deg: 20.0,
            outer_deg: 40.0,
        };
        vec![
            light(2.0, point(Vec3::new(0.3, 1.5, 0.2), 0.0, None)),
            light(5.0, point(Vec3::new(-0.4, 1.7, 0.4), 0.0, Some(cone))),
            light(1.0, sun(0.0)),
            light(2.0, point(Vec3::new(0.5, 1.2, -0.3), 0.1, None)),
            light(1.0, sun(2.0)),
        ]
    }

    /// Every lane's light sample of the kinds `kind` in the reference scene `name` (with
    /// [`punctual_lights`] added where `add_lights`) gives `Path::step`'s shadow test bit for
    /// bit (the light's sampling, `eval_lobes`, `power_heuristic`, `shadow_ray`, the
    /// radiance it adds), from random points, normals and views: lit lanes, and unlit ones
    /// (the light behind the surface, the surface seen from behind).
    fn light_lanes_as_path_step(name: &str, kind: Wanted, add_lights: bool) {
        let path = format!(
            "{}/../../scenes/refs/{name}.toml",
            env!("CARGO_MANIFEST_DIR")
        );
        let mut scene = pathlight_scene::load_scene_file(std::path::Path::new(&path)).unwrap();
        if add_lights {
            scene.lights.extend(punctual_lights());
        }
        let prepared = pathlight_core::PreparedScene::new(&scene).unwrap();
        let cpu_scene = CpuScene::new(&prepared);
        let mut params = GpuRenderParams::new(&scene.camera, &scene.settings, &prepared.shading);
        if kind.sky {
            // A share of the light samples other than 1, so that its arithmetic shows, and a
            // sky of some colour.
            params.env_pmf = 0.37;
            params.environment = [0.3, 0.5, 0.7];
        }
        let m = LobesParams::decode(&[Vec4::ZERO; MODEL_PARAMS]);
        let mut next = uniform(0x1234_5679);
        let (mut lit, mut unlit) = (0, 0);
        for round in 0..128 {
            let mut lanes = DiffuseLanes::default();
            let mut cases = Vec::new();
            for l in lanes_of_round(round) {
                // Draw until the choice is the light wanted.
                let (u_select, choice) = loop {
                    let u_select = next();
                    let choice = choose_light(&cpu_scene, &params, u_select);
                    let wanted = match choice {
                        Some((light, _, _)) if light.kind == LIGHT_AREA => {
                            kind.quad && cpu_scene.objects[light.index as usize].kind == KIND_QUAD
                        }
                        Some((light, _, _)) => kind.punctual && is_delta_light(&cpu_scene, &light),
                        None => kind.sky && u_select < params.env_pmf,
                    };
                    if wanted {
                        break (u_select, choice);
                    }
                };
                let ng = unit(r3(&mut next));
                let ns = unit(r3(&mut next) * 0.3 + ng);
                let ns = if ns.dot(ng) < 0.0 { -ns } else { ns };
                let wo = unit(r3(&mut next));
                let s = surface(r3(&mut next) * 0.9, ng, ns);
                let color = Vec3A::new(next(), next(), next());
                let throughput = Vec3A::new(next(), next(), next()) * 3.0;
                let u_light = Vec2::new(next(), next());
                let side = if wo.dot(ng) >= 0.0 { 1.0 } else { -1.0 };
                let n = ns * side;
                lanes.push(l, s.position, n, ng * side, wo, color, u_light, 0.5);
                let ls = match choice {
                    Some((light, pmf, _)) => {
                        if light.kind == LIGHT_AREA {
                            let index = light.index;
                            lanes.push_quad_light(l, &cpu_scene, index, pmf, u_light, throughput);
                        } else {
                            lanes.push_punctual_light(l, &cpu_scene, &light, pmf, throughput);
                        }
                        sample_table_light(&cpu_scene, light, pmf, s.position, u_light, 0.5)
                    }
                    None => {
                        let sky = Vec3A::from(params.environment);
                        lanes.push_sky_light(l, sky, params.env_pmf, u_light, throughput);
                        sample_light(&cpu_scene, &params, s.position, n, u_select, u_light)
                    }
                };
                // What `Path::step` does with it.
                let e = eval_lobes(&m, color, &s, wo, ls.wi);
                cases.push((
                    l,
                    (ls.valid && e.f.max_element() > 0.0).then(|| {
                        let (ray, t_max) = shadow_ray(s.position, s.ng, &ls);
                        let weight = if ls.mis {
                            power_heuristic(ls.pdf, e.pdf)
                        } else {
                            1.0
                        };
                        let radiance = light_radiance(&cpu_scene, &params, &ls);
                        (ray, t_max, throughput * e.f * radiance * weight / ls.pdf)
                    }),
                ));
            }
            lanes.compute();
            for (l, theirs) in cases {
                let ours = lanes.vertex(l).shadow;
                assert_eq!(ours.is_some(), theirs.is_some(), "lane {l}");
                let (Some(ours), Some((ray, t_max, radiance))) = (ours, theirs) else {
                    unlit += 1;
                    continue;
                };
                lit += 1;
                let bits = |v: Vec3A| v.to_array().map(f32::to_bits);
                assert_eq!(
                    bits(ours.ray.origin.into()),
                    bits(ray.origin.into()),
                    "lane {l}"
                );
                assert_eq!(bits(ours.ray.dir.into()), bits(ray.dir.into()), "lane {l}");
                assert_eq!(ours.t_max.to_bits(), t_max.to_bits(), "lane {l}");
                assert_eq!(bits(ours.radiance), bits(radiance), "lane {l}");
            }
        }
        assert!(lit > 100 && unlit > 100, "lit {lit}, unlit {unlit}");
    }

    /// On cornell-materials' ceiling light. Fails with any operation reordered.
    #[test]
    fn quad_lights_as_path_step_bit_for_bit() {
        let kind = Wanted { quad: true, ..NONE };
        light_lanes_as_path_step("cornell-materials", kind, false);
    }

    /// Under the furnace's constant sky.
    #[test]
    fn sky_lights_as_path_step_bit_for_bit() {
        let kind = Wanted { sky: true, ..NONE };
        light_lanes_as_path_step("furnace-0.8", kind, false);
    }

    /// Both in one packet (the sky's results written only to its own lanes). Fails with
    /// them written to every lane.
    #[test]
    fn quad_and_sky_lights_as_path_step_bit_for_bit() {
        let kind = Wanted {
            quad: true,
            sky: true,
            ..NONE
        };
        light_lanes_as_path_step("cornell-materials", kind, false);
    }

    /// The sun, point light and hard-edged spot of the reference scene `lights`.
    #[test]
    fn punctual_lights_as_path_step_bit_for_bit() {
        let kind = Wanted {
            punctual: true,
            ..NONE
        };
        light_lanes_as_path_step("lights", kind, false);
    }

    /// All three kinds in one packet, the spot's falloff smooth (the punctual lights'
    /// results written only to their own lanes).
    #[test]
    fn every_kind_of_light_as_path_step_bit_for_bit() {
        let kind = Wanted {
            quad: true,
            sky: true,
            punctual: true,
        };
        light_lanes_as_path_step("cornell-materials", kind, true);
    }
}
