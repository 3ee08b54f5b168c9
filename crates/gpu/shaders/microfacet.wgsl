// What every material model shares: the result types of a BSDF, Fresnel reflectance, the
// GGX microfacet distribution (separable Smith G1(wo) G1(wi) as in Mitsuba 3, alpha =
// roughness^2, visible-normal sampling after Heitz 2018), smooth and rough dielectric
// interfaces (Walter et al. 2007 in pbrt-v4's form, exact Fresnel), and the sample of a
// continuous mixture. CPU twin: `crates/cpu/src/microfacet.rs`.

#import scene
#import surface
#import sampling

const ALPHA_MIN: f32 = 1e-3;

// CPU twin: `BsdfEval`.
struct BsdfEval {
    f: vec3f,
    pdf: f32,
}

// CPU twin: `BsdfSample`.
struct BsdfSample {
    wi: vec3f,
    // f * |cos| / pdf (for a delta lobe: its reflectance or transmittance).
    weight: vec3f,
    // Density of the whole mixture at wi; 0 for a delta lobe.
    pdf: f32,
    delta: bool,
    // Relative IOR crossed by a refraction, else 1.
    eta: f32,
    valid: bool,
}

fn invalid_sample() -> BsdfSample {
    return BsdfSample(vec3f(0.0), vec3f(0.0), 0.0, false, 1.0, false);
}

fn to_local(frame: mat3x3f, v: vec3f) -> vec3f {
    return vec3f(dot(v, frame[0]), dot(v, frame[1]), dot(v, frame[2]));
}

// eta = n_transmitted / n_incident, cos_i >= 0.
// CPU twin: `fresnel_dielectric`.
fn fresnel_dielectric(cos_i: f32, eta: f32) -> f32 {
    let sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = sqrt(1.0 - sin2_t);
    let rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    let rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    return 0.5 * (rs * rs + rp * rp);
}

// Mitsuba 3's `fresnel_conductor`.
// CPU twin: `fresnel_conductor`.
fn fresnel_conductor(cos_i: f32, eta: vec3f, k: vec3f) -> vec3f {
    let cos2 = cos_i * cos_i;
    let sin2 = 1.0 - cos2;
    let eta2 = eta * eta;
    let k2 = k * k;
    let t0 = eta2 - k2 - sin2;
    let a2pb2 = sqrt(max(t0 * t0 + 4.0 * eta2 * k2, vec3f(0.0)));
    let a = sqrt(max(0.5 * (a2pb2 + t0), vec3f(0.0)));
    let t1 = a2pb2 + cos2;
    let t2 = 2.0 * cos_i * a;
    let rs = (t1 - t2) / max(t1 + t2, vec3f(1e-20));
    let t3 = cos2 * a2pb2 + sin2 * sin2;
    let t4 = t2 * sin2;
    let rp = rs * (t3 - t4) / max(t3 + t4, vec3f(1e-20));
    return 0.5 * (rp + rs);
}

// CPU twin: `ggx_d`.
fn ggx_d(m: vec3f, alpha: f32) -> f32 {
    let a2 = alpha * alpha;
    let t = (m.x * m.x + m.y * m.y) / a2 + m.z * m.z;
    return 1.0 / (PI * a2 * t * t);
}

// CPU twin: `ggx_g1`.
fn ggx_g1(w: vec3f, alpha: f32) -> f32 {
    let z2 = w.z * w.z;
    if z2 <= 0.0 {
        return 0.0;
    }
    let tan2 = (w.x * w.x + w.y * w.y) / z2;
    return 2.0 / (1.0 + sqrt(1.0 + alpha * alpha * tan2));
}

// What `ggx_reflection` returns (the CPU's returns an Option).
struct GgxReflection {
    wi: vec3f,
    valid: bool,
}

// The reflection of `wo_l` (local to `frame`) about a GGX normal of `alpha` visible from
// it, in world space; not valid when it points below the surface.
// CPU twin: `ggx_reflection`.
fn ggx_reflection(frame: mat3x3f, wo_l: vec3f, alpha: f32, u: vec2f) -> GgxReflection {
    let h = ggx_sample_visible(wo_l, alpha, u);
    let wi_l = 2.0 * dot(wo_l, h) * h - wo_l;
    return GgxReflection(frame * wi_l, wi_l.z > 0.0);
}

// CPU twin: `ggx_sample_visible`.
fn ggx_sample_visible(wo: vec3f, alpha: f32, u: vec2f) -> vec3f {
    let w = select(wo, -wo, wo.z < 0.0);
    let vh = normalize(vec3f(alpha * w.x, alpha * w.y, w.z));
    let len2 = vh.x * vh.x + vh.y * vh.y;
    let t1 = select(vec3f(1.0, 0.0, 0.0), vec3f(-vh.y, vh.x, 0.0) / sqrt(len2), len2 > 0.0);
    let t2 = cross(vh, t1);
    let r = sqrt(u.x);
    let phi = TAU * u.y;
    let p1 = r * cos(phi);
    let s = 0.5 * (1.0 + vh.z);
    let p2 = (1.0 - s) * sqrt(max(0.0, 1.0 - p1 * p1)) + s * r * sin(phi);
    let nh = p1 * t1 + p2 * t2 + sqrt(max(0.0, 1.0 - p1 * p1 - p2 * p2)) * vh;
    return normalize(vec3f(alpha * nh.x, alpha * nh.y, max(nh.z, 1e-7)));
}

// CPU twin: `ggx_pdf_visible`.
fn ggx_pdf_visible(wo: vec3f, m: vec3f, alpha: f32) -> f32 {
    return ggx_g1(wo, alpha) * abs(dot(wo, m)) * ggx_d(m, alpha) / abs(wo.z);
}

// CPU twin: `fresnel_dielectric_local`.
fn fresnel_dielectric_local(cos_om: f32, ior: f32) -> f32 {
    if cos_om >= 0.0 {
        return fresnel_dielectric(cos_om, ior);
    }
    return fresnel_dielectric(-cos_om, 1.0 / ior);
}

// A rough dielectric interface of inside index `ior` about `s.ns`: f * |cos_i| and the
// density of `rough_dielectric_direction`; the transmission is tinted by
// mix(1, color, tint).
// CPU twin: `eval_rough_dielectric`.
fn eval_rough_dielectric(ior: f32, color: vec3f, tint_amount: f32, s: Surface, wo: vec3f, wi: vec3f, alpha: f32) -> BsdfEval {
    let none = BsdfEval(vec3f(0.0), 0.0);
    let frame = frame_around(s.ns);
    let wo_l = to_local(frame, wo);
    let wi_l = to_local(frame, wi);
    let cos_o = wo_l.z;
    let cos_i = wi_l.z;
    let geo_reflect = (dot(wo, s.ng) >= 0.0) == (dot(wi, s.ng) >= 0.0);
    let reflect = cos_o * cos_i > 0.0;
    if cos_o == 0.0 || cos_i == 0.0 || reflect != geo_reflect {
        return none;
    }
    var etap = 1.0;
    if !reflect {
        etap = select(1.0 / ior, ior, cos_o > 0.0);
    }
    var h = wi_l * etap + wo_l;
    if dot(h, h) == 0.0 {
        return none;
    }
    h = normalize(h);
    if h.z < 0.0 {
        h = -h;
    }
    if dot(h, wi_l) * cos_i < 0.0 || dot(h, wo_l) * cos_o < 0.0 {
        return none;
    }
    let fr = fresnel_dielectric_local(dot(wo_l, h), ior);
    let d = ggx_d(h, alpha);
    let g = ggx_g1(wo_l, alpha) * ggx_g1(wi_l, alpha);
    let pdf_h = ggx_pdf_visible(wo_l, h, alpha);
    if reflect {
        return BsdfEval(vec3f(d * g * fr / (4.0 * abs(cos_o))), pdf_h / (4.0 * abs(dot(wo_l, h))) * fr);
    }
    let x = dot(wi_l, h) + dot(wo_l, h) / etap;
    let denom = x * x;
    let tint = mix(vec3f(1.0), color, tint_amount);
    let ft = (1.0 - fr) * d * g * abs(dot(wi_l, h) * dot(wo_l, h)) / (abs(cos_o) * denom) / (etap * etap);
    return BsdfEval(tint * ft, pdf_h * abs(dot(wi_l, h)) / denom * (1.0 - fr));
}

// A smooth dielectric interface of inside index `ior`: reflection with probability F, else
// refraction tinted by mix(1, color, tint), radiance scaled by 1/eta^2.
// CPU twin: `sample_smooth_dielectric`.
fn sample_smooth_dielectric(ior: f32, color: vec3f, tint_amount: f32, s: Surface, wo: vec3f, u_fresnel: f32) -> BsdfSample {
    let front = dot(wo, s.ng) >= 0.0;
    let ng = select(-s.ng, s.ng, front);
    let n = select(-s.ns, s.ns, front);
    let cos_o = dot(wo, n);
    if cos_o <= 0.0 {
        return invalid_sample();
    }
    let eta = select(1.0 / ior, ior, front);
    let f = fresnel_dielectric(cos_o, eta);
    if u_fresnel < f {
        let wi = 2.0 * cos_o * n - wo;
        return BsdfSample(wi, vec3f(1.0), 0.0, true, 1.0, dot(wi, ng) > 0.0);
    }
    let sin2_t = (1.0 - cos_o * cos_o) / (eta * eta);
    let cos_t = sqrt(max(0.0, 1.0 - sin2_t));
    let wi = -wo / eta + (cos_o / eta - cos_t) * n;
    let weight = mix(vec3f(1.0), color, tint_amount) / (eta * eta);
    return BsdfSample(wi, weight, 0.0, true, eta, dot(wi, ng) < 0.0);
}

// A direction sampled from a rough dielectric wall of relative index `ior` about
// `s.ns`: reflection or refraction of a visible GGX normal, chosen by its Fresnel
// reflectance; w = 0 when there is none.
// CPU twin: `rough_dielectric_direction`.
fn rough_dielectric_direction(ior: f32, s: Surface, wo: vec3f, alpha: f32, u_fresnel: f32, u: vec2f) -> vec4f {
    let frame = frame_around(s.ns);
    let wo_l = to_local(frame, wo);
    if wo_l.z == 0.0 {
        return vec4f(0.0);
    }
    let h = ggx_sample_visible(wo_l, alpha, u);
    let cos_oh = dot(wo_l, h);
    let fr = fresnel_dielectric_local(cos_oh, ior);
    var wi_l: vec3f;
    let reflect = u_fresnel < fr;
    if reflect {
        wi_l = 2.0 * cos_oh * h - wo_l;
    } else {
        let outside = cos_oh >= 0.0;
        let eta = select(1.0 / ior, ior, outside);
        let hf = select(-h, h, outside);
        let c = abs(cos_oh);
        let sin2_t = (1.0 - c * c) / (eta * eta);
        if sin2_t >= 1.0 {
            return vec4f(0.0);
        }
        wi_l = -wo_l / eta + (c / eta - sqrt(1.0 - sin2_t)) * hf;
    }
    // A reflection below the surface or a refraction above it belongs to the other
    // lobe, whose density does not count this way of reaching it: discarded.
    if (wi_l.z * wo_l.z > 0.0) != reflect {
        return vec4f(0.0);
    }
    return vec4f(frame * wi_l, 1.0);
}

// The sample of a mixture's continuous lobe in direction wi: eval / pdf of the whole
// mixture (`e`, evaluated at wi), and the relative IOR crossed when wi lies across the
// geometric surface from wo (an interface of inside index `ior`; 1 for a thin wall).
// CPU twin: `continuous_sample`.
fn continuous_sample(e: BsdfEval, s: Surface, wo: vec3f, wi: vec3f, ior: f32) -> BsdfSample {
    if !(e.pdf > 0.0 && e.pdf <= 3.0e38) {
        return invalid_sample();
    }
    let front_o = dot(wo, s.ng) >= 0.0;
    var eta = 1.0;
    if front_o != (dot(wi, s.ng) >= 0.0) {
        eta = select(1.0 / ior, ior, front_o);
    }
    return BsdfSample(wi, e.f / e.pdf, e.pdf, false, eta, true);
}
