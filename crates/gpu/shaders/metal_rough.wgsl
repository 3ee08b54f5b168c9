// glTF 2.0's metallic-roughness material model. CPU twin: `crates/cpu/src/metal_rough.rs`,
// whose header states the model: a mixture of a GGX specular lobe with Schlick Fresnel, a
// diffuse base under it weighted as glTF's `fresnel_mix` and a dielectric wall
// (transmission), weighted by metallic and transmission, under a clear coat.

#import scene
#import textures
#import surface
#import sampling
#import microfacet

// The model's parameters: its block in `param_blocks`, laid out by
// `pathlight_core::materials` (`metal_rough_block`), with its texture applied.
// CPU twin: `MetalRoughParams`.
struct MetalRoughParams {
    // 0 dielectric, 1 metal.
    metallic: f32,
    // Perceptual roughness; GGX alpha is its square.
    roughness: f32,
    // Fraction of the dielectric base that transmits.
    transmission: f32,
    ior: f32,
    // Transmission through a thin wall rather than into a volume.
    thin: bool,
    // Strength of the dielectric's specular reflection (KHR_materials_specular).
    specular: f32,
    // Colour multiplying the dielectric's F0.
    specular_color: vec3f,
    // Strength of the clear coat (KHR_materials_clearcoat).
    clearcoat: f32,
    // The coat's perceptual roughness.
    clearcoat_roughness: f32,
    // Absorption coefficient per unit length inside a solid material.
    attenuation: vec3f,
}

// The parameters in block `p` (a `MaterialPoint`'s `params`).
// CPU twin: `MetalRoughParams::decode`.
fn metal_rough_params(p: array<vec4f, MODEL_PARAMS>) -> MetalRoughParams {
    return MetalRoughParams(p[0].x, p[0].y, p[0].z, p[0].w, p[1].x != 0.0, p[1].y, p[2].xyz, p[1].z, p[1].w, p[3].xyz);
}

// The model's texture step on block `p`: metallic times the blue and roughness times the
// green channel of its texture (slot TEXTURE_MODEL, linear) at `uv`.
// CPU twin: `metal_rough_textured`.
fn metal_rough_textured(p: ptr<function, array<vec4f, MODEL_PARAMS>>, m: Material, uv: vec2f) {
    if has_texture(m, TEXTURE_MODEL) {
        let t = material_texture(m, TEXTURE_MODEL, uv);
        (*p)[0].y *= t.g;
        (*p)[0].x *= t.b;
    }
}

// The model's lobe weights. CPU twin: `Lobes`.
struct MetalRoughLobes {
    // Schlick reflectance of the specular lobe at normal and grazing incidence.
    spec_f0: vec3f,
    spec_f90: f32,
    // Weight of the diffuse base: (1 - metallic)(1 - transmission).
    diffuse: f32,
    // Weight of the dielectric wall: (1 - metallic) transmission.
    wall: f32,
    // Schlick F0 of the dielectric's specular reflection, coloured (at most 1).
    f0_d: vec3f,
    // Its strength (KHR_materials_specular's weight).
    specular: f32,
}

// CPU twin: `lobes`.
fn mr_lobes(m: MetalRoughParams, color: vec3f) -> MetalRoughLobes {
    let r = (m.ior - 1.0) / (m.ior + 1.0);
    let f0_d = min(r * r * m.specular_color, vec3f(1.0));
    let dielectric = 1.0 - m.metallic;
    let base = dielectric * (1.0 - m.transmission);
    let layer = base * m.specular;
    return MetalRoughLobes(m.metallic * color + layer * f0_d, m.metallic + layer, base, dielectric * m.transmission, f0_d, m.specular);
}

// CPU twin: `schlick`.
fn schlick(f0: vec3f, f90: f32, cos_i: f32) -> vec3f {
    return f0 + (vec3f(f90) - f0) * pow(1.0 - saturate(cos_i), 5.0);
}

// What the dielectric's specular layer passes to the diffuse base at `cos_i` (the cosine
// with the half vector): glTF's fresnel_mix, 1 - specular max(F).
// CPU twin: `coupling`.
fn mr_coupling(l: MetalRoughLobes, cos_i: f32) -> f32 {
    let f = schlick(l.f0_d, 1.0, cos_i);
    return 1.0 - l.specular * max(max(f.x, f.y), f.z);
}

// Probabilities of sampling the specular lobe, the diffuse base and the wall.
// CPU twin: `probabilities`.
fn mr_probabilities(color: vec3f, l: MetalRoughLobes, cos_o: f32) -> vec3f {
    let lum = vec3f(0.2126, 0.7152, 0.0722);
    let spec = dot(schlick(l.spec_f0, l.spec_f90, cos_o), lum);
    let diffuse = l.diffuse * dot(color, lum) * mr_coupling(l, cos_o);
    let total = spec + diffuse + l.wall;
    if !(total > 0.0) {
        return vec3f(0.0);
    }
    return vec3f(spec, diffuse, l.wall) / total;
}

// The continuous part of the BSDF: the coat over the rest.
// CPU twin: `eval`.
fn eval_metal_rough(m: MetalRoughParams, color: vec3f, s: Surface, wo: vec3f, wi: vec3f) -> BsdfEval {
    let base = eval_metal_rough_base(m, color, s, wo, wi);
    if m.clearcoat <= 0.0 {
        return base;
    }
    let front = dot(wo, s.ng) >= 0.0;
    let ng = select(-s.ng, s.ng, front);
    let n = select(-s.ns, s.ns, front);
    let weight = mr_coat_weight(m, dot(wo, n));
    var out = BsdfEval(base.f * (1.0 - weight), base.pdf * (1.0 - weight));
    let alpha = m.clearcoat_roughness * m.clearcoat_roughness;
    if alpha >= ALPHA_MIN && dot(wi, ng) > 0.0 && dot(wi, n) > 0.0 && dot(wo, n) > 0.0 {
        let frame = frame_around(n);
        let wo_l = to_local(frame, wo);
        let wi_l = to_local(frame, wi);
        let h = normalize(wo_l + wi_l);
        let d = ggx_d(h, alpha);
        let g1o = ggx_g1(wo_l, alpha);
        out.f += vec3f(weight * d * g1o * ggx_g1(wi_l, alpha) / (4.0 * wo_l.z));
        out.pdf += weight * g1o * d / (4.0 * wo_l.z);
    }
    return out;
}

// The coat's weight at cos_o: its strength times Schlick's Fresnel from 0.04, which is also
// its sampling probability.
// CPU twin: `coat_weight`.
fn mr_coat_weight(m: MetalRoughParams, cos_o: f32) -> f32 {
    return m.clearcoat * schlick(vec3f(0.04), 1.0, cos_o).x;
}

// The continuous part of the BSDF under the coat.
// CPU twin: `eval_base`.
fn eval_metal_rough_base(m: MetalRoughParams, color: vec3f, s: Surface, wo: vec3f, wi: vec3f) -> BsdfEval {
    let front = dot(wo, s.ng) >= 0.0;
    let ng = select(-s.ng, s.ng, front);
    let n = select(-s.ns, s.ns, front);
    let l = mr_lobes(m, color);
    let cos_o = dot(wo, n);
    let cos_i = dot(wi, n);
    let probs = mr_probabilities(color, l, cos_o);
    let alpha = m.roughness * m.roughness;
    let thin = m.thin;
    var out = BsdfEval(vec3f(0.0), 0.0);
    if cos_o <= 0.0 {
        return out;
    }
    let frame = frame_around(n);
    let wo_l = to_local(frame, wo);
    if dot(wi, ng) > 0.0 && cos_i > 0.0 {
        if l.diffuse > 0.0 {
            // glTF's fresnel_mix: what the specular layer's Fresnel at the half vector passes.
            let passed = mr_coupling(l, dot(wo, normalize(wo + wi)));
            out.f += l.diffuse * passed * color * (cos_i / PI);
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
                out.f += l.wall * ft * spec * color;
                out.pdf += probs.z * ft * g1o * d / (4.0 * wo_l.z);
            }
        } else {
            let e = eval_rough_dielectric(m.ior, color, 1.0, s, wo, wi, alpha);
            out.f += l.wall * e.f;
            out.pdf += probs.z * e.pdf;
        }
    }
    return out;
}

// `eval_metal_rough / pdf` of a continuous sample; a thin wall refracts nothing.
// CPU twin: `mixture_sample`.
fn mr_mixture_sample(m: MetalRoughParams, color: vec3f, s: Surface, wo: vec3f, wi: vec3f) -> BsdfSample {
    return continuous_sample(eval_metal_rough(m, color, s, wo, wi), s, wo, wi, select(m.ior, 1.0, m.thin));
}

// CPU twin: `sample`.
fn sample_metal_rough(m: MetalRoughParams, color: vec3f, s: Surface, wo: vec3f, u_lobe: f32, u_fresnel: f32, u: vec2f) -> BsdfSample {
    let front = dot(wo, s.ng) >= 0.0;
    let ng = select(-s.ng, s.ng, front);
    let n = select(-s.ns, s.ns, front);
    let cos_o = dot(wo, n);
    if cos_o <= 0.0 {
        return invalid_sample();
    }
    var coat = 0.0;
    if m.clearcoat > 0.0 {
        coat = mr_coat_weight(m, cos_o);
    }
    if u_lobe < coat {
        let alpha_c = m.clearcoat_roughness * m.clearcoat_roughness;
        if alpha_c < ALPHA_MIN {
            // A mirror coat: its weight over its probability is 1.
            let wi = 2.0 * cos_o * n - wo;
            return BsdfSample(wi, vec3f(1.0), 0.0, true, 1.0, dot(wi, ng) > 0.0);
        }
        let frame_c = frame_around(n);
        let r = ggx_reflection(frame_c, to_local(frame_c, wo), alpha_c, u);
        if !r.valid {
            return invalid_sample();
        }
        return mr_mixture_sample(m, color, s, wo, r.wi);
    }
    // The material under the coat, from what is left of u_lobe.
    let u_base = (u_lobe - coat) / (1.0 - coat);
    let l = mr_lobes(m, color);
    let probs = mr_probabilities(color, l, cos_o);
    let alpha = m.roughness * m.roughness;
    let frame = frame_around(n);
    let wo_l = to_local(frame, wo);
    if u_base < probs.x {
        if alpha < ALPHA_MIN {
            let wi = 2.0 * cos_o * n - wo;
            if dot(wi, ng) <= 0.0 {
                return invalid_sample();
            }
            return BsdfSample(wi, schlick(l.spec_f0, l.spec_f90, cos_o) / probs.x, 0.0, true, 1.0, true);
        }
        let r = ggx_reflection(frame, wo_l, alpha, u);
        if !r.valid {
            return invalid_sample();
        }
        return mr_mixture_sample(m, color, s, wo, r.wi);
    }
    if u_base < probs.x + probs.z {
        if m.thin {
            if alpha < ALPHA_MIN {
                let fr = fresnel_dielectric(cos_o, m.ior);
                if u_fresnel < fr {
                    let wi = 2.0 * cos_o * n - wo;
                    return BsdfSample(wi, vec3f(l.wall / probs.z), 0.0, true, 1.0, dot(wi, ng) > 0.0);
                }
                return BsdfSample(-wo, l.wall / probs.z * color, 0.0, true, 1.0, true);
            }
            let h = ggx_sample_visible(wo_l, alpha, u);
            let wr_l = 2.0 * dot(wo_l, h) * h - wo_l;
            if wr_l.z <= 0.0 {
                return invalid_sample();
            }
            let fr = fresnel_dielectric(dot(wo_l, h), m.ior);
            let wi_l = select(vec3f(wr_l.x, wr_l.y, -wr_l.z), wr_l, u_fresnel < fr);
            return mr_mixture_sample(m, color, s, wo, frame * wi_l);
        }
        if alpha < ALPHA_MIN {
            var bs = sample_smooth_dielectric(m.ior, color, 1.0, s, wo, u_fresnel);
            bs.weight *= l.wall / probs.z;
            return bs;
        }
        let d = rough_dielectric_direction(m.ior, s, wo, alpha, u_fresnel, u);
        if d.w == 0.0 {
            return invalid_sample();
        }
        return mr_mixture_sample(m, color, s, wo, d.xyz);
    }
    let wi = frame * sample_cosine_hemisphere(u);
    if dot(wi, ng) <= 0.0 {
        return invalid_sample();
    }
    return mr_mixture_sample(m, color, s, wo, wi);
}

// The albedo a denoiser reads: the specular F0, the diffuse base's colour under what the
// specular layer lets through at normal incidence, and the tinted wall.
// CPU twin: `metal_rough_albedo`.
fn metal_rough_albedo(m: MetalRoughParams, color: vec3f) -> vec3f {
    let l = mr_lobes(m, color);
    let base = l.spec_f0 + (l.diffuse * mr_coupling(l, 1.0)) * color + l.wall * color;
    let coat = mr_coat_weight(m, 1.0);
    return base * (1.0 - coat) + vec3f(coat);
}

// Whether the model has a non-delta lobe.
// CPU twin: `has_continuous_metal_rough`.
fn has_continuous_metal_rough(m: MetalRoughParams, color: vec3f) -> bool {
    return mr_lobes(m, color).diffuse > 0.0 || m.roughness * m.roughness >= ALPHA_MIN
        || (m.clearcoat > 0.0 && m.clearcoat_roughness * m.clearcoat_roughness >= ALPHA_MIN);
}
