//! Unidirectional path tracing with next-event estimation and MIS. Twin of
//! `integrator.wgsl` (same loop, same order of sample dimensions).

use glam::{Vec2, Vec3A};
use pathlight_core::gpu_types::{
    GpuAccumPixel, GpuAovPixel, GpuRenderParams, KIND_QUAD, LIGHT_AREA, NO_LIGHT,
};
use pathlight_core::materials::MODEL_METAL_ROUGH;

use crate::bsdf_lanes::{LaneBsdf, ONE_BY_ONE_WIDE, SampleLanes};
use crate::bvh::Hit;
use crate::camera::camera_ray;
use crate::cpu_scene::CpuScene;
use crate::diffuse::DiffuseLanes;
use crate::environment::{env_escape, has_env_map};
use crate::glass::GlassLanes;
use crate::glossy::GlossyLanes;
use crate::intersect::Ray;
use crate::light_lanes::LitVertex;
use crate::light_sample::LightSample;
use crate::lights::{
    choose_light, is_delta_light, light_pdf, light_radiance, sample_light, sample_table_light,
};
use crate::lobes::LobesParams;
use crate::map_lanes::{MapEscapes, sample_env_maps};
use crate::material::{
    MaterialPoint, eval_material, has_continuous_material_lobe, is_lambert, material_absorption,
    material_albedo, material_at, sample_material,
};
use crate::metal_rough::MetalRoughParams;
use crate::metal_rough_lanes::MetalRoughLanes;
use crate::microfacet::{BsdfEval, BsdfSample};
use crate::packet::{Lanes, PACKET};
use crate::sampler::{BOUNCE_DRAWS, Sampler};
use crate::sampling::power_heuristic;
use crate::surface::{Surface, surface_at};
use crate::tracer::Tracer;

/// Largest radiance one sample may add per channel (WGSL `SAMPLE_MAX`).
pub const SAMPLE_MAX: f32 = 16_777_216.0;
/// End of the interval searched by extension rays.
pub const T_MAX: f32 = 1.0e30;

/// Start of a ray leaving `p` on the side of `ng` that `dir` points to. Twin of WGSL
/// `offset_origin`.
#[inline(always)]
fn offset_origin(p: Vec3A, ng: Vec3A, dir: Vec3A) -> Vec3A {
    let eps = 1e-4 * (1.0 + p.abs().max_element());
    p + if dir.dot(ng) > 0.0 { ng } else { -ng } * eps
}

/// The shadow ray testing whether anything blocks the light sample `ls` from surface point
/// `p` (normal `ng`), and the end of its interval. It runs from the offset origin to the
/// light point itself, stopping just short of it, so the light never shadows itself. Twin of
/// WGSL `shadow_ray`.
#[inline(always)]
pub(crate) fn shadow_ray(p: Vec3A, ng: Vec3A, ls: &LightSample) -> (Ray, f32) {
    let origin = offset_origin(p, ng, ls.wi);
    if !ls.finite {
        return (Ray::new(origin, ls.wi), T_MAX);
    }
    let to_light = ls.point - origin;
    let distance = to_light.length();
    (
        Ray::new(origin, to_light / distance),
        distance * (1.0 - 1e-4),
    )
}

/// What one camera path brought back. Twin of WGSL `PathResult`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PathSample {
    /// Radiance along the path.
    pub radiance: Vec3A,
    /// With auxiliary images: the albedo of the first surface it met that is not a perfect
    /// mirror or glass (through those, weighted by what they pass on).
    pub albedo: Vec3A,
    /// With auxiliary images: that surface's shading normal (zero where the path escaped
    /// at once).
    pub normal: Vec3A,
    /// Rays traced for it (camera, extension and shadow rays).
    pub rays: u32,
}

/// A light sample's shadow ray, and the radiance it adds unless something blocks it.
#[derive(Debug, Clone, Copy)]
pub struct ShadowTest {
    /// The shadow ray.
    pub ray: Ray,
    /// The end of its interval.
    pub t_max: f32,
    /// Radiance added to the path when nothing blocks the ray.
    pub radiance: Vec3A,
}

/// The vertices of a packet's paths whose shading waits to be computed side by side, by
/// kind of material: [`Path::step`] leaves them here, the caller computes them
/// ([`ShadingLanes::compute`]), takes the shadow tests of the light samples left to them
/// ([`Path::left_light_test`]) and goes on with [`Path::leave_diffuse`] and
/// [`Path::leave_sampled`].
#[derive(Debug, Clone)]
pub struct ShadingLanes {
    /// Purely diffuse vertices.
    pub diffuse: DiffuseLanes,
    /// Rough glass vertices (the lobes model's rough transmission alone).
    pub glass: GlassLanes,
    /// Rough mirror vertices (the lobes model's rough specular reflection alone).
    pub glossy: GlossyLanes,
    /// Vertices on glTF's opaque rough materials
    /// ([`MetalRoughParams::is_rough_opaque`]).
    pub metal_rough: MetalRoughLanes,
    /// Bit `l` set: lane `l` (a vertex of one of the kinds above) samples the environment
    /// map at `map_u[l]`, its light sample still to be taken.
    map_lights: Lanes,
    map_u: [Vec2; PACKET],
    /// Bit `l` set: lane `l` (a vertex of a kind whose BSDF samples [`SampleLanes`] computes)
    /// gave its kind a light sample
    /// taken in its step, for the kind to evaluate the BSDF towards it.
    given_lights: Lanes,
    /// What the environment map shows the lanes whose rays escaped, computed before their
    /// steps ([`ShadingLanes::escape`]).
    escapes: MapEscapes,
}

impl Default for ShadingLanes {
    // Out of line, and allowed so by `tools/check-inlined.sh`: a row makes its lanes once,
    // and inlined they cost cornell-materials and lights 2-3% (the row's code generation).
    #[inline(never)]
    fn default() -> Self {
        Self {
            diffuse: DiffuseLanes::default(),
            glass: GlassLanes::default(),
            glossy: GlossyLanes::default(),
            metal_rough: MetalRoughLanes::default(),
            map_lights: 0,
            map_u: [Vec2::ZERO; PACKET],
            given_lights: 0,
            escapes: MapEscapes::default(),
        }
    }
}

impl ShadingLanes {
    /// No lane waits.
    #[inline(always)]
    pub fn clear(&mut self) {
        self.diffuse.clear();
        self.glass.clear();
        self.glossy.clear();
        self.metal_rough.clear();
        self.map_lights = 0;
        self.given_lights = 0;
    }

    /// With an environment map, computes what it shows the lanes in `escaped`, whose rays
    /// (`dir(l)`) hit nothing, side by side, for their steps ([`Path::step`]) to take.
    #[inline(always)]
    pub fn escape(
        &mut self,
        scene: &CpuScene,
        params: &GpuRenderParams,
        escaped: Lanes,
        dir: impl Fn(usize) -> [f32; 3],
    ) {
        if has_env_map(params) {
            self.escapes.compute(scene, params, escaped, dir);
        }
    }

    /// Takes the environment map's light samples left waiting
    /// (`sample_map_lights`), then computes each kind's lanes (up to `one_by_one` lanes of a
    /// kind of [`SampleLanes`] one after another: [`SampleLanes::compute`]).
    #[inline(always)]
    pub fn compute(&mut self, scene: &CpuScene, params: &GpuRenderParams, one_by_one: usize) {
        self.sample_map_lights(scene, params);
        if self.diffuse.mask() != 0 {
            self.diffuse.compute();
        }
        if self.glass.mask() != 0 {
            self.glass.compute(one_by_one);
        }
        if self.glossy.mask() != 0 {
            self.glossy.compute(one_by_one);
        }
        if self.metal_rough.mask() != 0 {
            self.metal_rough.compute(one_by_one);
        }
    }

    /// Bit `l` set: lane `l` left a light sample here for its kind to evaluate the BSDF
    /// towards (an environment map's, or one its step took on a vertex of a kind of
    /// [`SampleLanes`]).
    #[inline(always)]
    pub fn lights_left(&self) -> Lanes {
        self.map_lights | self.given_lights
    }

    /// Lane `l`'s light sample left here, if it left a valid one, with the BSDF's evaluation
    /// towards it, once [`ShadingLanes::compute`] ran.
    #[inline(always)]
    fn light_left(&self, l: usize) -> Option<LitVertex<'_>> {
        if self.diffuse.mask() >> l & 1 != 0 {
            self.diffuse.given_light(l)
        } else if self.glass.mask() >> l & 1 != 0 {
            self.glass.light(l)
        } else if self.glossy.mask() >> l & 1 != 0 {
            self.glossy.light(l)
        } else {
            self.metal_rough.light(l)
        }
    }

    /// Takes the environment map's light samples left waiting, all lanes side by side
    /// ([`sample_env_maps`]; taken in each lane's step, and then one lane after another,
    /// their chains of loads from the map's megabytes of tables stalled the core), and gives
    /// them to their lanes' kinds to evaluate the BSDF towards.
    #[inline(always)]
    fn sample_map_lights(&mut self, scene: &CpuScene, params: &GpuRenderParams) {
        let (diffuse, glass, glossy) = (&mut self.diffuse, &mut self.glass, &mut self.glossy);
        let metal_rough = &mut self.metal_rough;
        sample_env_maps(scene, params, self.map_lights, &self.map_u, |l, ls| {
            if !ls.valid {
                return;
            }
            if diffuse.mask() >> l & 1 != 0 {
                diffuse.push_light(l, &ls);
            } else if glass.mask() >> l & 1 != 0 {
                glass.push_light(l, &ls);
            } else if glossy.mask() >> l & 1 != 0 {
                glossy.push_light(l, &ls);
            } else {
                metal_rough.push_light(l, &ls);
            }
        });
    }
}

/// A material whose vertices' BSDF samples wait for a kind of [`SampleLanes`], with its
/// parameters.
#[derive(Debug, Clone, Copy)]
enum LaneKind {
    /// Rough glass ([`LobesParams::is_rough_glass`]).
    Glass(LobesParams),
    /// A rough mirror ([`LobesParams::is_rough_mirror`]).
    Glossy(LobesParams),
    /// glTF's opaque rough material ([`MetalRoughParams::is_rough_opaque`]).
    MetalRough(MetalRoughParams),
}

impl LaneKind {
    /// The kind of `material` (not purely diffuse), if it has one, where the lobe choice
    /// draws `u_lobe`: rough glass or a rough mirror of the lobes model alone, whose lobe is
    /// the mixture's only one (`u_lobe` below its weight, 1), or glTF's opaque rough
    /// material.
    #[inline(always)]
    fn of(material: &MaterialPoint, u_lobe: f32) -> Option<Self> {
        if material.model == MODEL_METAL_ROUGH {
            let m = MetalRoughParams::decode(&material.params);
            return m.is_rough_opaque().then_some(Self::MetalRough(m));
        }
        let m = LobesParams::decode(&material.params);
        if u_lobe >= 1.0 {
            None
        } else if m.is_rough_glass() {
            Some(Self::Glass(m))
        } else if m.is_rough_mirror() {
            Some(Self::Glossy(m))
        } else {
            None
        }
    }
}

/// A vertex whose BSDF sample waits for the lanes of its kind, and the light sample left to
/// them with it.
struct WaitingVertex<'a> {
    /// The surface point.
    s: &'a Surface,
    /// The direction the path arrived from.
    wo: Vec3A,
    /// The material's base colour there.
    color: Vec3A,
    /// The dimensions of the lobe and Fresnel choices, of the direction and of Russian
    /// roulette.
    u: (f32, f32, Vec2, f32),
    /// The light sample left to the lanes with it.
    light: LeftLight,
}

impl WaitingVertex<'_> {
    /// Leaves the vertex to `lanes` as lane `lane`, its material's parameters `params` (its
    /// light sample's in `scene`).
    #[inline(always)]
    fn wait_in<M: LaneBsdf>(
        &self,
        lanes: &mut SampleLanes<M>,
        scene: &CpuScene,
        lane: usize,
        params: &M::Params,
    ) {
        let s = self.s;
        lanes.push(
            lane, s.position, s.ns, s.ng, self.wo, self.color, params, self.u,
        );
        match self.light {
            LeftLight::None => {}
            LeftLight::Sample(ls) => lanes.push_light(lane, &ls),
            LeftLight::Sky(radiance, pmf, u_light) => {
                lanes.push_sky_light(lane, radiance, pmf, u_light);
            }
            LeftLight::Quad(object, pmf, u_light) => {
                lanes.push_quad_light(lane, scene, object, pmf, u_light);
            }
        }
    }
}

/// The light sample a vertex whose BSDF sample waits for the lanes of its kind leaves to
/// them, for them to evaluate the BSDF towards.
#[derive(Debug, Clone, Copy)]
enum LeftLight {
    /// None (or one whose BSDF `Path::step` evaluates).
    None,
    /// A valid light sample taken in the step.
    Sample(LightSample),
    /// The constant sky's, of radiance `.0`, chosen with probability `.1`, at `.2`, for the
    /// lanes to take side by side.
    Sky(Vec3A, f32, Vec2),
    /// Quad light `.0`'s, chosen with probability `.1`, at `.2`, for the lanes to take side
    /// by side.
    Quad(u32, f32, Vec2),
}

/// One camera path in progress, between its ray queries: [`Path::ray`] is to be traced and
/// its nearest hit given to [`Path::step`]. It holds what the loop of WGSL `trace_path` keeps in its variables.
#[derive(Debug, Clone)]
pub struct Path {
    /// The next ray to trace.
    pub ray: Ray,
    /// False once the path has ended.
    pub alive: bool,
    /// What it has brought back so far.
    pub sample: PathSample,
    depth: u32,
    throughput: Vec3A,
    /// Density of the BSDF sample that produced `ray`, and whether it came from a delta
    /// lobe (camera rays count as delta: emitters they see get full weight).
    prev_pdf: f32,
    prev_delta: bool,
    prev_position: Vec3A,
    /// Normal (on the side of wo) at the vertex that produced `ray`: environment sampling
    /// there was cosine-weighted about it.
    prev_normal: Vec3A,
    /// Product of the relative IORs crossed: throughput * eta_scale^2 is the throughput
    /// without the 1/eta^2 radiance scaling, which Russian roulette should see.
    eta_scale: f32,
    /// The auxiliary images are still looking for their surface.
    aov_pending: bool,
    /// The weight of the perfect mirrors and glass passed through so far.
    aov_weight: Vec3A,
}

impl Path {
    /// The path starting on camera ray `ray`. Its sample's values come from a [`Sampler`]
    /// kept beside it (each bounce takes it), past the dimensions the ray drew
    /// ([`camera_ray`]'s).
    #[inline(always)]
    pub fn from_camera_ray(params: &GpuRenderParams, ray: Ray) -> Self {
        Self {
            ray,
            alive: params.max_depth > 0,
            sample: PathSample {
                radiance: Vec3A::ZERO,
                albedo: Vec3A::ZERO,
                normal: Vec3A::ZERO,
                rays: 0,
            },
            depth: 0,
            throughput: Vec3A::ONE,
            prev_pdf: 0.0,
            prev_delta: true,
            prev_position: ray.origin.into(),
            prev_normal: Vec3A::ZERO,
            eta_scale: 1.0,
            aov_pending: params.aovs != 0,
            aov_weight: Vec3A::ONE,
        }
    }

    /// Goes on from `hit`, the nearest hit of [`Path::ray`] and the surface there
    /// ([`surface_at`]; `None`: the ray escaped), drawing from the path's
    /// `sampler`: adds what the path sees there, samples a light (returning its shadow ray,
    /// for the caller to trace and [`Path::add_unblocked`]) and the BSDF (the next ray), or
    /// ends the path. On a purely diffuse surface the rest of the bounce (the BSDF sample,
    /// and the light sample of a quad, a constant sky, or a point, spot or sun light without
    /// size) is left to `diffuse` as lane `lane`: once [`DiffuseLanes::compute`] ran,
    /// [`Path::leave_diffuse`] goes on. On rough glass or a rough mirror the BSDF sample is
    /// left to `glass` or `glossy` likewise, on glTF's opaque rough materials to
    /// `metal_rough`, and [`Path::leave_sampled`] goes on. At all such vertices a light
    /// sample of the environment map is left to `lanes` too: [`ShadingLanes::compute`] takes
    /// it and the kind evaluates the BSDF towards it, then [`Path::left_light_test`] gives
    /// its shadow test; at those of the kinds of [`SampleLanes`] so does any other light
    /// sample, taken here (a constant sky's and a quad light's taken by the lanes, side by
    /// side).
    #[inline(always)]
    pub fn step(
        &mut self,
        sampler: &mut Sampler,
        scene: &CpuScene,
        params: &GpuRenderParams,
        hit: Option<(&Hit, &Surface)>,
        lanes: &mut ShadingLanes,
        lane: usize,
    ) -> Option<ShadowTest> {
        let ShadingLanes {
            diffuse,
            glass,
            glossy,
            metal_rough,
            map_lights,
            map_u,
            given_lights,
            escapes,
        } = lanes;
        self.depth += 1;
        self.sample.rays += 1;
        let ray = self.ray;
        let Some((hit, s)) = hit else {
            let (env, pdf) = if has_env_map(params) {
                escapes.get(lane)
            } else {
                env_escape(
                    scene,
                    params,
                    self.prev_normal,
                    ray.dir.into(),
                    !self.prev_delta,
                )
            };
            let w = if self.prev_delta {
                1.0
            } else {
                power_heuristic(self.prev_pdf, pdf)
            };
            self.sample.radiance += self.throughput * env * w;
            if self.aov_pending {
                self.sample.albedo = self.aov_weight * env.clamp(Vec3A::ZERO, Vec3A::ONE);
                self.aov_pending = false;
            }
            self.alive = false;
            return None;
        };
        sampler.prepare();
        let material = &material_at(scene, s);
        let wo = -Vec3A::from(ray.dir);
        if wo.dot(s.ng) < 0.0 {
            // The segment ran inside the object it leaves: Beer-Lambert.
            let absorption = material_absorption(material);
            if absorption.max_element() > 0.0 {
                self.throughput *= (-absorption * hit.t).exp();
            }
        }
        let emission = material.emission;
        if wo.dot(s.ng) > 0.0 && emission.max_element() > 0.0 {
            let object = &scene.objects[hit.object as usize];
            let w = if self.prev_delta || object.light == NO_LIGHT {
                1.0
            } else {
                let pdf_light = light_pdf(
                    scene,
                    params,
                    hit.object,
                    hit.primitive,
                    self.prev_position,
                    s.position,
                    s.ng,
                );
                power_heuristic(self.prev_pdf, pdf_light)
            };
            self.sample.radiance += self.throughput * emission * w;
        }
        let continuous = has_continuous_material_lobe(material);
        if self.aov_pending {
            self.sample.normal = if wo.dot(s.ng) >= 0.0 { s.ns } else { -s.ns };
            if continuous {
                let albedo = material_albedo(material).clamp(Vec3A::ZERO, Vec3A::ONE);
                self.sample.albedo = self.aov_weight * albedo;
                self.aov_pending = false;
            }
        }
        if self.depth == params.max_depth {
            self.end();
            return None;
        }
        // Every bounce draws the same dimensions in the same order.
        let [u_light_select, u_light, u_lobe, u_fresnel, u_bsdf, u_rr] =
            sampler.next_batch(BOUNCE_DRAWS);
        let (u_light_select, u_lobe, u_fresnel, u_rr) =
            (u_light_select.x, u_lobe.x, u_fresnel.x, u_rr.x);
        let n = if wo.dot(s.ng) >= 0.0 { s.ns } else { -s.ns };
        let lambert = is_lambert(material);
        let sampled_lanes = if lambert {
            None
        } else {
            LaneKind::of(material, u_lobe)
        };
        let mut shadow = None;
        // The light sample left to the lanes of `sampled_lanes`, for them to evaluate the
        // BSDF towards (side by side, not a chain of dependent square roots and divisions).
        let mut left = LeftLight::None;
        if continuous {
            let choice = choose_light(scene, params, u_light_select);
            let quad = choice.filter(|(light, _, _)| {
                (lambert || sampled_lanes.is_some())
                    && light.kind == LIGHT_AREA
                    && scene.objects[light.index as usize].kind == KIND_QUAD
            });
            let punctual = choice.filter(|(light, _, _)| lambert && is_delta_light(scene, light));
            let sky = u_light_select < params.env_pmf && !has_env_map(params);
            if let Some((light, pmf, _)) = quad {
                if lambert {
                    let throughput = self.throughput;
                    diffuse.push_quad_light(lane, scene, light.index, pmf, u_light, throughput);
                } else {
                    left = LeftLight::Quad(light.index, pmf, u_light);
                }
            } else if let Some((light, pmf, _)) = punctual {
                diffuse.push_punctual_light(lane, scene, &light, pmf, self.throughput);
            } else if sky && lambert {
                let radiance = Vec3A::from(params.environment);
                diffuse.push_sky_light(lane, radiance, params.env_pmf, u_light, self.throughput);
            } else if sky && sampled_lanes.is_some() {
                let radiance = Vec3A::from(params.environment);
                left = LeftLight::Sky(radiance, params.env_pmf, u_light);
            } else if (lambert || sampled_lanes.is_some())
                && choice.is_none()
                && u_light_select < params.env_pmf
                && has_env_map(params)
            {
                *map_lights |= 1 << lane;
                map_u[lane] = u_light;
            } else {
                let ls = match choice {
                    Some((light, pmf, u_part)) => {
                        sample_table_light(scene, light, pmf, s.position, u_light, u_part)
                    }
                    None => sample_light(scene, params, s.position, n, u_light_select, u_light),
                };
                if ls.valid && sampled_lanes.is_some() {
                    left = LeftLight::Sample(ls);
                } else if ls.valid {
                    let e = eval_material(material, s, wo, ls.wi);
                    shadow = self.shadow_test(scene, params, s.position, s.ng, &ls, &e);
                }
            }
        }
        if lambert {
            let ng = if wo.dot(s.ng) >= 0.0 { s.ng } else { -s.ng };
            let color = material.base_color;
            diffuse.push(lane, s.position, n, ng, wo, color, u_bsdf, u_rr);
            return shadow;
        }
        if let Some(kind) = sampled_lanes {
            let vertex = WaitingVertex {
                s,
                wo,
                color: material.base_color,
                u: (u_lobe, u_fresnel, u_bsdf, u_rr),
                light: left,
            };
            match kind {
                LaneKind::Glass(m) => vertex.wait_in(glass, scene, lane, &m),
                LaneKind::Glossy(m) => vertex.wait_in(glossy, scene, lane, &m),
                LaneKind::MetalRough(m) => vertex.wait_in(metal_rough, scene, lane, &m),
            }
            if !matches!(left, LeftLight::None) {
                *given_lights |= 1 << lane;
            }
            return shadow;
        }
        let bs = sample_material(material, s, wo, u_lobe, u_fresnel, u_bsdf);
        self.bounce(params, &bs, s.position, s.ng, n, u_rr);
        shadow
    }

    /// Goes on from the vertex that lane `lane` of `lanes` holds, once
    /// [`SampleLanes::compute`] ran.
    #[inline(always)]
    pub fn leave_sampled<M: LaneBsdf>(
        &mut self,
        params: &GpuRenderParams,
        lanes: &SampleLanes<M>,
        lane: usize,
    ) {
        let v = lanes.vertex(lane);
        self.bounce(params, &v.sample, v.position, v.ng, v.n, v.u_rr);
    }

    /// The shadow test of the light sample that lane `lane` of `lanes` left there
    /// ([`ShadingLanes::lights_left`]), once [`ShadingLanes::compute`] ran and before the path
    /// leaves the vertex (it reads the throughput that reached the vertex), as
    /// [`Path::step`] returns its own.
    #[inline(always)]
    pub fn left_light_test(
        &mut self,
        scene: &CpuScene,
        params: &GpuRenderParams,
        lanes: &ShadingLanes,
        lane: usize,
    ) -> Option<ShadowTest> {
        let v = lanes.light_left(lane)?;
        self.shadow_test(scene, params, v.position, v.ng, v.light, &v.eval)
    }

    /// The shadow test of the valid light sample `ls` at `position` (geometric normal
    /// `ng`), where the BSDF's evaluation towards it is `e`; none where the BSDF passes
    /// nothing on.
    #[inline(always)]
    fn shadow_test(
        &mut self,
        scene: &CpuScene,
        params: &GpuRenderParams,
        position: Vec3A,
        ng: Vec3A,
        ls: &LightSample,
        e: &BsdfEval,
    ) -> Option<ShadowTest> {
        if e.f.max_element() > 0.0 {
            self.sample.rays += 1;
            let (ray, t_max) = shadow_ray(position, ng, ls);
            let weight = if ls.mis {
                power_heuristic(ls.pdf, e.pdf)
            } else {
                1.0
            };
            let radiance = light_radiance(scene, params, ls);
            let radiance = self.throughput * e.f * radiance * weight / ls.pdf;
            return Some(ShadowTest {
                ray,
                t_max,
                radiance,
            });
        }
        None
    }

    /// Goes on from the diffuse vertex that lane `lane` of `diffuse` holds, once
    /// [`DiffuseLanes::compute`] ran: returns the shadow test of the quad or sky light sample
    /// left to it, as [`Path::step`] returns its own.
    #[inline(always)]
    pub fn leave_diffuse(
        &mut self,
        params: &GpuRenderParams,
        diffuse: &DiffuseLanes,
        lane: usize,
    ) -> Option<ShadowTest> {
        let v = diffuse.vertex(lane);
        if v.shadow.is_some() {
            self.sample.rays += 1;
        }
        self.bounce(params, &v.sample, v.position, v.ng, v.n, v.u_rr);
        v.shadow
    }

    /// Goes on along BSDF sample `bs`, drawn at `position` (geometric normal `ng`, shading
    /// normal `n` on the side of wo), `u_rr` deciding Russian roulette: the next ray, or the
    /// end of the path.
    #[inline(always)]
    fn bounce(
        &mut self,
        params: &GpuRenderParams,
        bs: &BsdfSample,
        position: Vec3A,
        ng: Vec3A,
        n: Vec3A,
        u_rr: f32,
    ) {
        if !bs.valid {
            self.end();
            return;
        }
        if self.aov_pending {
            // A perfect mirror or glass passes on what it reflects or transmits (without
            // refraction's radiance scaling).
            let passed = bs.weight * (bs.eta * bs.eta);
            self.aov_weight *= passed.clamp(Vec3A::ZERO, Vec3A::ONE);
        }
        self.throughput *= bs.weight;
        self.prev_pdf = bs.pdf;
        self.prev_delta = bs.delta;
        self.prev_position = position;
        self.prev_normal = n;
        self.eta_scale *= bs.eta;
        if self.depth >= params.rr_depth {
            let q = (self.throughput.max_element() * self.eta_scale * self.eta_scale).min(0.95);
            if u_rr >= q {
                self.end();
                return;
            }
            self.throughput /= q;
        }
        self.ray = Ray::new(offset_origin(position, ng, bs.wi), bs.wi);
    }

    /// Ends the path on a surface; if the auxiliary images found none but perfect mirrors
    /// and glass, those count as white.
    #[inline(always)]
    fn end(&mut self) {
        self.alive = false;
        if self.aov_pending {
            self.sample.albedo = self.aov_weight;
            self.aov_pending = false;
        }
    }

    /// Adds the radiance of a [`ShadowTest`] whose ray nothing blocked.
    #[inline(always)]
    pub fn add_unblocked(&mut self, radiance: Vec3A) {
        self.sample.radiance += radiance;
    }
}

/// Radiance along the path of sample `sampler` through pixel (x, y) of `scene`, its rays
/// traced one by one by `tracer` (which traces in `scene`). Twin of WGSL `trace_path`.
#[inline(always)]
pub fn trace_path(
    tracer: &mut Tracer,
    scene: &CpuScene,
    params: &GpuRenderParams,
    x: u32,
    y: u32,
    mut sampler: Sampler,
) -> PathSample {
    let ray = camera_ray(params, x, y, &mut sampler);
    let mut path = Path::from_camera_ray(params, ray);
    let mut lanes = ShadingLanes::default();
    while path.alive {
        let hit = tracer.intersect(&path.ray, T_MAX);
        lanes.clear();
        let escaped = Lanes::from(hit.is_none());
        lanes.escape(scene, params, escaped, |_| path.ray.dir.to_array());
        let surface = hit.map(|hit| surface_at(scene, &hit, &path.ray));
        let hit = hit.as_ref().zip(surface.as_ref());
        let mut shadow = path.step(&mut sampler, scene, params, hit, &mut lanes, 0);
        lanes.compute(scene, params, ONE_BY_ONE_WIDE);
        if lanes.lights_left() != 0 {
            shadow = shadow.or(path.left_light_test(scene, params, &lanes, 0));
        }
        if lanes.diffuse.mask() != 0 {
            shadow = shadow.or(path.leave_diffuse(params, &lanes.diffuse, 0));
        }
        if lanes.glass.mask() != 0 {
            path.leave_sampled(params, &lanes.glass, 0);
        }
        if lanes.glossy.mask() != 0 {
            path.leave_sampled(params, &lanes.glossy, 0);
        }
        if lanes.metal_rough.mask() != 0 {
            path.leave_sampled(params, &lanes.metal_rough, 0);
        }
        if let Some(shadow) = shadow
            && !tracer.occluded(&shadow.ray, shadow.t_max)
        {
            path.add_unblocked(shadow.radiance);
        }
    }
    path.sample
}

/// A sample as it is accumulated: non-finite samples count as zero, channels are clamped to
/// [0, SAMPLE_MAX], as WGSL `render` and `add_sample` accumulate it.
#[inline(always)]
pub fn accumulated_value(radiance: Vec3A) -> Vec3A {
    if radiance.is_finite() {
        radiance.clamp(Vec3A::ZERO, Vec3A::splat(SAMPLE_MAX))
    } else {
        Vec3A::ZERO
    }
}

/// `acc += value` in the accumulation's 64-bit fixed point, `value` clamped to
/// [0, SAMPLE_MAX]: the sums are the GPU's bit for bit, whatever order samples arrive in.
/// Twin of WGSL `add_sample`.
#[inline(always)]
pub fn add_sample(acc: &mut GpuAccumPixel, value: Vec3A) {
    let mut sum = FixedSum::default();
    sum.add(value);
    sum.add_to(acc);
}

/// A colour sum in the accumulation's 64-bit fixed point, a `u64` a channel, saturating: the
/// CPU backend adds a row's samples here, then the row's sums to the accumulation
/// ([`FixedSum::add_to`]). The same bits as adding each sample there ([`add_sample`]):
/// saturating sums of numbers that are not negative come out the same in any grouping.
/// (The accumulation keeps each channel's two halves apart, as WGSL has no 64-bit integers;
/// adding to them sample after sample made each add wait on the last one's narrowing
/// stores.)
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct FixedSum(pub [u64; 3]);

impl FixedSum {
    /// `self += value`, `value` clamped to [0, SAMPLE_MAX] as [`add_sample`] does.
    #[inline(always)]
    pub fn add(&mut self, value: Vec3A) {
        // v * 2^32 is exact (a float below 2^24 scaled by a power of two), and its integer
        // part is WGSL's floor(v) * 2^32 + trunc(fract(v) * 2^32): the same fixed-point
        // number, converted once instead of in two halves. At most 2^56, it converts exactly
        // as a signed number too: on AVX2 one instruction, where the unsigned is a dozen.
        // Not a number counts as zero, as `as` converts it.
        let value = Vec3A::select(value.cmpeq(value), value, Vec3A::ZERO);
        let scaled = value.clamp(Vec3A::ZERO, Vec3A::splat(SAMPLE_MAX)) * 4_294_967_296.0;
        for (sum, x) in self.0.iter_mut().zip(scaled.to_array()) {
            // SAFETY: `x` is a number in [0, 2^56], so its integer part is an `i64`. `as`
            // would check for numbers out of range, a branch each; without them AVX-512
            // converts the channels together (+4% on the furnace, whose samples are short).
            let integer = unsafe { x.to_int_unchecked::<i64>() };
            *sum = sum.saturating_add(integer as u64);
        }
    }

    /// `acc += self`, saturating as the accumulation does.
    #[inline(always)]
    pub fn add_to(&self, acc: &mut GpuAccumPixel) {
        for (c, x) in self.0.into_iter().enumerate() {
            acc.add_to_channel(c, x);
        }
    }
}

/// `acc +=` the auxiliary images of `sample`: the albedo, and the normal as `(n + 1) / 2`
/// (an albedo that is not finite counts as zero, such a normal as the zero vector). Twin of
/// WGSL `add_aov_sample`.
#[inline(always)]
pub fn add_aov_sample(acc: &mut GpuAovPixel, sample: &PathSample) {
    let albedo = if sample.albedo.is_finite() {
        sample.albedo
    } else {
        Vec3A::ZERO
    };
    let normal = if sample.normal.is_finite() {
        (sample.normal + 1.0) * 0.5
    } else {
        Vec3A::splat(0.5)
    };
    add_sample(&mut acc.albedo, albedo);
    add_sample(&mut acc.normal, normal);
}

#[cfg(test)]
mod tests {
    use super::*;

    /// WGSL `add_sample`'s arithmetic: the whole and the fractional part converted apart,
    /// added with a carry, saturating to all ones.
    fn add_sample_in_halves(acc: &mut GpuAccumPixel, value: Vec3A) {
        let v = value.clamp(Vec3A::ZERO, Vec3A::splat(SAMPLE_MAX));
        let whole = v.floor();
        let frac = (v - whole) * 4_294_967_296.0;
        acc.accumulate(&GpuAccumPixel {
            hi: [whole.x as u32, whole.y as u32, whole.z as u32, 0],
            lo: [frac.x as u32, frac.y as u32, frac.z as u32, 0],
        });
    }

    /// The one conversion gives WGSL's sums bit for bit: every float exponent from 2^-149 to
    /// past the clamp, values next to whole numbers, negatives, NaN and infinities, and sums
    /// that saturate.
    #[test]
    fn add_sample_is_the_wgsl_sum_bit_for_bit() {
        let mut values = vec![0.0, -0.0, -1.0, f32::NAN, f32::INFINITY, -f32::INFINITY];
        let mut state = 0x2545_f491_u32;
        for exponent in -149..30 {
            let base = 2f32.powi(exponent);
            for _ in 0..64 {
                state ^= state << 13;
                state ^= state >> 17;
                state ^= state << 5;
                let v = base * (1.0 + state as f32 / 4_294_967_296.0);
                values.extend([v, v.floor(), v.next_down(), v.ceil().next_down()]);
            }
        }
        values.extend([SAMPLE_MAX, SAMPLE_MAX.next_down(), SAMPLE_MAX * 2.0]);
        let mut ours = GpuAccumPixel::default();
        let mut theirs = GpuAccumPixel::default();
        for (i, v) in values.iter().enumerate() {
            let sample = Vec3A::new(*v, values[(i * 7) % values.len()], 0.5);
            add_sample(&mut ours, sample);
            add_sample_in_halves(&mut theirs, sample);
            assert_eq!(ours, theirs, "after {sample}");
        }
        // Sums past 2^32 per channel saturate the same way.
        for _ in 0..300 {
            add_sample(&mut ours, Vec3A::splat(SAMPLE_MAX));
            add_sample_in_halves(&mut theirs, Vec3A::splat(SAMPLE_MAX));
        }
        assert_eq!(ours.hi[0], u32::MAX);
        assert_eq!(ours, theirs);
    }

    /// Samples summed in a [`FixedSum`] first, then added to the accumulation, give the
    /// bits of adding each to it: onto an empty accumulation and onto one near saturation,
    /// with sums that saturate in the `FixedSum` itself, and non-finite values.
    #[test]
    fn fixed_sums_add_up_as_samples_one_by_one() {
        let values = [
            0.3,
            1e-30,
            7.25,
            SAMPLE_MAX,
            f32::NAN,
            -2.0,
            0.1,
            f32::INFINITY,
        ];
        let near_full = GpuAccumPixel {
            hi: [u32::MAX - 20_000_000, 5, u32::MAX, 0],
            lo: [7, u32::MAX, 0, 0],
        };
        for start in [GpuAccumPixel::default(), near_full] {
            for count in [1, 9, 300, 2000] {
                let (mut one_by_one, mut at_once) = (start, start);
                let mut sum = FixedSum::default();
                for i in 0..count {
                    let v = Vec3A::new(
                        values[i % values.len()],
                        values[(i * 3 + 1) % values.len()],
                        (i as f32).sqrt(),
                    );
                    add_sample(&mut one_by_one, v);
                    sum.add(v);
                }
                sum.add_to(&mut at_once);
                assert_eq!(at_once, one_by_one, "{count} samples onto {start:?}");
            }
        }
    }
}
