// The seed's material model: a mixture of lobes with the seed's weights, Lambert
// (1 - specular_rate - refract_rate), specular reflection (a smooth mirror or a GGX
// conductor: complex-IOR Fresnel, or Schlick from the specular colour) and transmission (a
// smooth or GGX-rough dielectric). `eval_lobes` returns f * |cos_i| of the non-delta lobes
// and the density of `sample_lobes`, which picks a lobe by weight and, for a continuous
// lobe, returns eval / pdf of the whole mixture (one-sample MIS over the lobes).
// CPU twin: `crates/cpu/src/lobes.rs`.

#import surface
#import sampling
#import microfacet

// The model's parameters: its block in `param_blocks`, laid out by
// `pathlight_core::materials` (`lobes_block`).
// CPU twin: `LobesParams`.
struct LobesParams {
    specular_rate: f32,
    specular_tint: f32,
    specular_roughness: f32,
    refract_rate: f32,
    refract_tint: f32,
    ior: f32,
    refract_roughness: f32,
    // The specular lobe's Fresnel: the conductor of complex IOR eta + i k, else Schlick.
    conductor: bool,
    eta: vec3f,
    k: vec3f,
}

// The parameters in block `p` (a `MaterialPoint`'s `params`).
// CPU twin: `LobesParams::decode`.
fn lobes_params(p: array<vec4f, MODEL_PARAMS>) -> LobesParams {
    return LobesParams(p[0].x, p[0].y, p[0].z, p[0].w, p[1].x, p[1].y, p[1].z, p[1].w != 0.0, p[2].xyz, p[3].xyz);
}

// CPU twin: `specular_reflectance`.
fn specular_reflectance(m: LobesParams, color: vec3f, cos_i: f32) -> vec3f {
    if m.conductor {
        return fresnel_conductor(cos_i, m.eta, m.k);
    }
    let f0 = mix(vec3f(1.0), color, m.specular_tint);
    return f0 + (1.0 - f0) * pow(1.0 - saturate(cos_i), 5.0);
}

// CPU twin: `lobe_weights`.
fn lobe_weights(m: LobesParams) -> vec3f {
    return vec3f(max(0.0, 1.0 - m.specular_rate - m.refract_rate), m.specular_rate, m.refract_rate);
}

// The continuous part: f * |cos_i| of the non-delta lobes and the density of `sample_lobes`
// producing wi.
// CPU twin: `eval_lobes`.
fn eval_lobes(m: LobesParams, color: vec3f, s: Surface, wo: vec3f, wi: vec3f) -> BsdfEval {
    let weights = lobe_weights(m);
    let front = dot(wo, s.ng) >= 0.0;
    let ng = select(-s.ng, s.ng, front);
    let n = select(-s.ns, s.ns, front);
    var out = BsdfEval(vec3f(0.0), 0.0);
    let cos_o = dot(wo, n);
    let cos_i = dot(wi, n);
    if dot(wi, ng) > 0.0 && cos_o > 0.0 && cos_i > 0.0 {
        if weights.x > 0.0 {
            out.f += weights.x * color * (cos_i / PI);
            out.pdf += weights.x * cos_i / PI;
        }
        let alpha = m.specular_roughness * m.specular_roughness;
        if weights.y > 0.0 && alpha >= ALPHA_MIN {
            let frame = frame_around(n);
            let wo_l = to_local(frame, wo);
            let wi_l = to_local(frame, wi);
            let h = normalize(wo_l + wi_l);
            let f = specular_reflectance(m, color, dot(wo_l, h));
            let d = ggx_d(h, alpha);
            let g1o = ggx_g1(wo_l, alpha);
            out.f += weights.y * f * d * g1o * ggx_g1(wi_l, alpha) / (4.0 * wo_l.z);
            out.pdf += weights.y * g1o * d / (4.0 * wo_l.z);
        }
    }
    let alpha_t = m.refract_roughness * m.refract_roughness;
    if weights.z > 0.0 && alpha_t >= ALPHA_MIN {
        let e = eval_rough_dielectric(m.ior, color, m.refract_tint, s, wo, wi, alpha_t);
        out.f += weights.z * e.f;
        out.pdf += weights.z * e.pdf;
    }
    return out;
}

// CPU twin: `lobes_sample`.
fn lobes_sample(m: LobesParams, color: vec3f, s: Surface, wo: vec3f, wi: vec3f) -> BsdfSample {
    return continuous_sample(eval_lobes(m, color, s, wo, wi), s, wo, wi, m.ior);
}

// A lobe chosen by its weight, and a direction from it.
// CPU twin: `sample_lobes`.
fn sample_lobes(m: LobesParams, color: vec3f, s: Surface, wo: vec3f, u_lobe: f32, u_fresnel: f32, u: vec2f) -> BsdfSample {
    let weights = lobe_weights(m);
    let front = dot(wo, s.ng) >= 0.0;
    let ng = select(-s.ng, s.ng, front);
    let n = select(-s.ns, s.ns, front);
    let cos_o = dot(wo, n);
    if u_lobe < weights.y {
        if cos_o <= 0.0 {
            return invalid_sample();
        }
        let alpha = m.specular_roughness * m.specular_roughness;
        if alpha < ALPHA_MIN {
            let wi = 2.0 * cos_o * n - wo;
            if dot(wi, ng) <= 0.0 {
                return invalid_sample();
            }
            return BsdfSample(wi, specular_reflectance(m, color, cos_o), 0.0, true, 1.0, true);
        }
        let frame = frame_around(n);
        let r = ggx_reflection(frame, to_local(frame, wo), alpha, u);
        if !r.valid {
            return invalid_sample();
        }
        return lobes_sample(m, color, s, wo, r.wi);
    }
    if u_lobe < weights.y + weights.z {
        let alpha = m.refract_roughness * m.refract_roughness;
        if alpha < ALPHA_MIN {
            return sample_smooth_dielectric(m.ior, color, m.refract_tint, s, wo, u_fresnel);
        }
        let d = rough_dielectric_direction(m.ior, s, wo, alpha, u_fresnel, u);
        if d.w == 0.0 {
            return invalid_sample();
        }
        return lobes_sample(m, color, s, wo, d.xyz);
    }
    if cos_o <= 0.0 {
        return invalid_sample();
    }
    let wi = frame_around(n) * sample_cosine_hemisphere(u);
    if dot(wi, ng) <= 0.0 {
        return invalid_sample();
    }
    return lobes_sample(m, color, s, wo, wi);
}

// The albedo a denoiser reads (in [0, 1] for colours in [0, 1]): the lobes' weighted colours,
// a conductor's reflectance at normal incidence, Schlick's F0 otherwise.
// CPU twin: `lobes_albedo`.
fn lobes_albedo(m: LobesParams, color: vec3f) -> vec3f {
    let w = lobe_weights(m);
    var specular = mix(vec3f(1.0), color, m.specular_tint);
    if m.conductor {
        specular = fresnel_conductor(1.0, m.eta, m.k);
    }
    return w.x * color + w.y * specular + w.z * mix(vec3f(1.0), color, m.refract_tint);
}

// Whether a lobe is not a delta lobe (next-event estimation is worth doing).
// CPU twin: `has_continuous_lobes`.
fn has_continuous_lobes(m: LobesParams) -> bool {
    let w = lobe_weights(m);
    return w.x > 0.0
        || (w.y > 0.0 && m.specular_roughness * m.specular_roughness >= ALPHA_MIN)
        || (w.z > 0.0 && m.refract_roughness * m.refract_roughness >= ALPHA_MIN);
}
