#import scene
#import surface
#import sampling
#import bsdf

// glTF's metal-rough model, and the choice between it and the lobe model of bsdf.wgsl. CPU
// twin: `crates/cpu/src/metal_rough.rs`, whose header states the model: a mixture of a GGX specular lobe with Schlick Fresnel, a diffuse base coupled
// to it and a dielectric wall (transmission), weighted by metallic and transmission.

// The model's lobe weights. CPU twin: `Lobes`.
struct MetalRoughLobes {
    // Schlick reflectance of the specular lobe at normal and grazing incidence.
    spec_f0: vec3f,
    spec_f90: f32,
    // Weight of the diffuse base: (1 - metallic)(1 - transmission).
    diffuse: f32,
    // Weight of the dielectric wall: (1 - metallic) transmission.
    wall: f32,
    // Schlick F0 of the dielectric: ((ior - 1) / (ior + 1))^2.
    f0_d: f32,
}

// CPU twin: `lobes`.
fn mr_lobes(m: Material) -> MetalRoughLobes {
    let r = (m.ior - 1.0) / (m.ior + 1.0);
    let f0_d = r * r;
    let dielectric = 1.0 - m.metallic;
    let base = dielectric * (1.0 - m.transmission);
    return MetalRoughLobes(m.metallic * m.base_color + base * f0_d, m.metallic + base, base, dielectric * m.transmission, f0_d);
}

// CPU twin: `schlick`.
fn schlick(f0: vec3f, f90: f32, cos_i: f32) -> vec3f {
    return f0 + (vec3f(f90) - f0) * pow(1.0 - saturate(cos_i), 5.0);
}

// Probabilities of sampling the specular lobe, the diffuse base and the wall.
// CPU twin: `probabilities`.
fn mr_probabilities(m: Material, l: MetalRoughLobes, cos_o: f32) -> vec3f {
    let lum = vec3f(0.2126, 0.7152, 0.0722);
    let spec = dot(schlick(l.spec_f0, l.spec_f90, cos_o), lum);
    let diffuse = l.diffuse * dot(m.base_color, lum) * (1.0 - schlick(vec3f(l.f0_d), 1.0, cos_o).x);
    let total = spec + diffuse + l.wall;
    if !(total > 0.0) {
        return vec3f(0.0);
    }
    return vec3f(spec, diffuse, l.wall) / total;
}

// CPU twin: `eval`.
fn eval_metal_rough(m: Material, s: Surface, wo: vec3f, wi: vec3f) -> BsdfEval {
    let front = dot(wo, s.ng) >= 0.0;
    let ng = select(-s.ng, s.ng, front);
    let n = select(-s.ns, s.ns, front);
    let l = mr_lobes(m);
    let cos_o = dot(wo, n);
    let cos_i = dot(wi, n);
    let probs = mr_probabilities(m, l, cos_o);
    let alpha = m.roughness * m.roughness;
    let thin = (m.flags & MATERIAL_THIN) != 0u;
    var out = BsdfEval(vec3f(0.0), 0.0);
    if cos_o <= 0.0 {
        return out;
    }
    let frame = frame_around(n);
    let wo_l = to_local(frame, wo);
    if dot(wi, ng) > 0.0 && cos_i > 0.0 {
        if l.diffuse > 0.0 {
            let coupling = (1.0 - schlick(vec3f(l.f0_d), 1.0, cos_o).x) * (1.0 - schlick(vec3f(l.f0_d), 1.0, cos_i).x);
            out.f += l.diffuse * coupling * m.base_color * (cos_i / PI);
            out.pdf += probs.y * cos_i / PI;
        }
        if alpha >= ALPHA_MIN {
            let wi_l = to_local(frame, wi);
            let h = normalize(wo_l + wi_l);
            let d = ggx_d(h, alpha);
            let g1o = ggx_g1(wo_l, alpha);
            let spec = d * g1o * ggx_g1(wi_l, alpha) / (4.0 * wo_l.z);
            let pdf_r = g1o * d / (4.0 * wo_l.z);
            out.f += schlick(l.spec_f0, l.spec_f90, dot(wo_l, h)) * spec;
            out.pdf += probs.x * pdf_r;
            if thin && l.wall > 0.0 {
                let fr = fresnel_dielectric(dot(wo_l, h), m.ior);
                out.f += vec3f(l.wall * fr * spec);
                out.pdf += probs.z * fr * pdf_r;
            }
        }
    }
    if l.wall > 0.0 && alpha >= ALPHA_MIN {
        if thin {
            if dot(wi, ng) < 0.0 && cos_i < 0.0 {
                // Through a thin wall: the reflection of the mirrored direction, tinted.
                let wm_l = to_local(frame, wi - 2.0 * cos_i * n);
                let h = normalize(wo_l + wm_l);
                let d = ggx_d(h, alpha);
                let g1o = ggx_g1(wo_l, alpha);
                let spec = d * g1o * ggx_g1(wm_l, alpha) / (4.0 * wo_l.z);
                let ft = 1.0 - fresnel_dielectric(dot(wo_l, h), m.ior);
                out.f += l.wall * ft * spec * m.base_color;
                out.pdf += probs.z * ft * g1o * d / (4.0 * wo_l.z);
            }
        } else {
            var glass = m;
            glass.refract_tint = 1.0;
            let e = eval_rough_dielectric(glass, m.base_color, s, wo, wi, alpha);
            out.f += l.wall * e.f;
            out.pdf += probs.z * e.pdf;
        }
    }
    return out;
}

// `eval_metal_rough / pdf` of a continuous sample. CPU twin: `mixture_sample`.
fn mr_mixture_sample(m: Material, s: Surface, wo: vec3f, wi: vec3f) -> BsdfSample {
    let e = eval_metal_rough(m, s, wo, wi);
    if !(e.pdf > 0.0 && e.pdf <= 3.0e38) {
        return invalid_sample();
    }
    let front_o = dot(wo, s.ng) >= 0.0;
    var eta = 1.0;
    if front_o != (dot(wi, s.ng) >= 0.0) && (m.flags & MATERIAL_THIN) == 0u {
        eta = select(1.0 / m.ior, m.ior, front_o);
    }
    return BsdfSample(wi, e.f / e.pdf, e.pdf, false, eta, true);
}

// CPU twin: `sample`.
fn sample_metal_rough(m: Material, s: Surface, wo: vec3f, u_lobe: f32, u_fresnel: f32, u: vec2f) -> BsdfSample {
    let front = dot(wo, s.ng) >= 0.0;
    let ng = select(-s.ng, s.ng, front);
    let n = select(-s.ns, s.ns, front);
    let cos_o = dot(wo, n);
    if cos_o <= 0.0 {
        return invalid_sample();
    }
    let l = mr_lobes(m);
    let probs = mr_probabilities(m, l, cos_o);
    let alpha = m.roughness * m.roughness;
    let frame = frame_around(n);
    let wo_l = to_local(frame, wo);
    if u_lobe < probs.x {
        if alpha < ALPHA_MIN {
            let wi = 2.0 * cos_o * n - wo;
            if dot(wi, ng) <= 0.0 {
                return invalid_sample();
            }
            return BsdfSample(wi, schlick(l.spec_f0, l.spec_f90, cos_o) / probs.x, 0.0, true, 1.0, true);
        }
        let h = ggx_sample_visible(wo_l, alpha, u);
        let wi_l = 2.0 * dot(wo_l, h) * h - wo_l;
        if wi_l.z <= 0.0 {
            return invalid_sample();
        }
        return mr_mixture_sample(m, s, wo, frame * wi_l);
    }
    if u_lobe < probs.x + probs.z {
        if (m.flags & MATERIAL_THIN) != 0u {
            if alpha < ALPHA_MIN {
                let fr = fresnel_dielectric(cos_o, m.ior);
                if u_fresnel < fr {
                    let wi = 2.0 * cos_o * n - wo;
                    return BsdfSample(wi, vec3f(l.wall / probs.z), 0.0, true, 1.0, dot(wi, ng) > 0.0);
                }
                return BsdfSample(-wo, l.wall / probs.z * m.base_color, 0.0, true, 1.0, true);
            }
            let h = ggx_sample_visible(wo_l, alpha, u);
            let wr_l = 2.0 * dot(wo_l, h) * h - wo_l;
            if wr_l.z <= 0.0 {
                return invalid_sample();
            }
            let fr = fresnel_dielectric(dot(wo_l, h), m.ior);
            let wi_l = select(vec3f(wr_l.x, wr_l.y, -wr_l.z), wr_l, u_fresnel < fr);
            return mr_mixture_sample(m, s, wo, frame * wi_l);
        }
        if alpha < ALPHA_MIN {
            var glass = m;
            glass.refract_tint = 1.0;
            var bs = sample_smooth_dielectric(glass, m.base_color, s, wo, u_fresnel);
            bs.weight *= l.wall / probs.z;
            return bs;
        }
        let d = rough_dielectric_direction(m.ior, s, wo, alpha, u_fresnel, u);
        if d.w == 0.0 {
            return invalid_sample();
        }
        return mr_mixture_sample(m, s, wo, d.xyz);
    }
    let wi = frame * sample_cosine_hemisphere(u);
    if dot(wi, ng) <= 0.0 {
        return invalid_sample();
    }
    return mr_mixture_sample(m, s, wo, wi);
}

// The BSDF of either model. CPU twin: `eval_material`.
fn eval_material(m: Material, s: Surface, wo: vec3f, wi: vec3f) -> BsdfEval {
    if m.model == MODEL_METAL_ROUGH {
        return eval_metal_rough(m, s, wo, wi);
    }
    return eval_bsdf(m, m.base_color, s, wo, wi);
}

// A direction sampled from either model. CPU twin: `sample_material`.
fn sample_material(m: Material, s: Surface, wo: vec3f, u_lobe: f32, u_fresnel: f32, u: vec2f) -> BsdfSample {
    if m.model == MODEL_METAL_ROUGH {
        return sample_metal_rough(m, s, wo, u_lobe, u_fresnel, u);
    }
    return sample_bsdf(m, m.base_color, s, wo, u_lobe, u_fresnel, u);
}

// Whether either model has a non-delta lobe. CPU twin: `has_continuous_material_lobe`.
fn has_continuous_material_lobe(m: Material) -> bool {
    if m.model == MODEL_METAL_ROUGH {
        return mr_lobes(m).diffuse > 0.0 || m.roughness * m.roughness >= ALPHA_MIN;
    }
    return has_continuous_lobe(m);
}
