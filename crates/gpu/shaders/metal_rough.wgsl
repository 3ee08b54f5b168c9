// glTF 2.0's metallic-roughness material model. CPU twin: `crates/cpu/src/metal_rough.rs`,
// whose header states the model: a mixture of a GGX specular lobe with Schlick Fresnel, a
// diffuse base under it weighted as glTF's `fresnel_mix` and a dielectric wall
// (transmission), weighted by metallic and transmission, under a sheen, under a clear coat.

#import scene
#import textures
#import surface
#import sampling
#import microfacet
#import sheen

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
    // Colour of the sheen (KHR_materials_sheen; black: none).
    sheen_color: vec3f,
    // The sheen's perceptual roughness.
    sheen_roughness: f32,
}

// The parameters in block `p` (a `MaterialPoint`'s `params`).
// CPU twin: `MetalRoughParams::decode`.
fn metal_rough_params(p: array<vec4f, MODEL_PARAMS>) -> MetalRoughParams {
    return MetalRoughParams(p[0].x, p[0].y, p[0].z, p[0].w, p[1].x != 0.0, p[1].y, p[2].xyz, p[1].z, p[1].w, p[3].xyz, p[4].xyz, p[4].w);
}

// The model's texture step on block `p`: metallic times the blue and roughness times the
// green channel of its texture (slot TEXTURE_MODEL, linear) at `uv`, then the extensions'
// textures on their factors (glTF's channels; colours sRGB).
// CPU twin: `metal_rough_textured`.
fn metal_rough_textured(p: ptr<function, array<vec4f, MODEL_PARAMS>>, m: Material, uv: vec2f) {
    if has_texture(m, TEXTURE_MODEL) {
        let t = material_texture(m, TEXTURE_MODEL, uv);
        (*p)[0].y *= t.g;
        (*p)[0].x *= t.b;
    }
    if (m.texture_mask >> TEXTURE_TRANSMISSION) == 0u {
        return;
    }
    if has_texture(m, TEXTURE_TRANSMISSION) {
        (*p)[0].z *= material_texture(m, TEXTURE_TRANSMISSION, uv).r;
    }
    if has_texture(m, TEXTURE_SPECULAR) {
        (*p)[1].y *= material_texture(m, TEXTURE_SPECULAR, uv).a;
    }
    if has_texture(m, TEXTURE_SPECULAR_COLOR) {
        (*p)[2] *= vec4f(material_color(m, TEXTURE_SPECULAR_COLOR, uv).rgb, 1.0);
    }
    if has_texture(m, TEXTURE_CLEARCOAT) {
        (*p)[1].z *= material_texture(m, TEXTURE_CLEARCOAT, uv).r;
    }
    if has_texture(m, TEXTURE_CLEARCOAT_ROUGHNESS) {
        (*p)[1].w *= material_texture(m, TEXTURE_CLEARCOAT_ROUGHNESS, uv).g;
    }
    if has_texture(m, TEXTURE_SHEEN_COLOR) {
        (*p)[4] *= vec4f(material_color(m, TEXTURE_SHEEN_COLOR, uv).rgb, 1.0);
    }
    if has_texture(m, TEXTURE_SHEEN_ROUGHNESS) {
        (*p)[4].w *= material_texture(m, TEXTURE_SHEEN_ROUGHNESS, uv).a;
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

// Estimated albedos of the specular lobe, the diffuse base and the wall at cos_o.
// CPU twin: `lobe_albedos`.
fn mr_lobe_albedos(color: vec3f, l: MetalRoughLobes, cos_o: f32) -> vec3f {
    let lum = vec3f(0.2126, 0.7152, 0.0722);
    let spec = dot(schlick(l.spec_f0, l.spec_f90, cos_o), lum);
    let diffuse = l.diffuse * dot(color, lum) * mr_coupling(l, cos_o);
    return vec3f(spec, diffuse, l.wall);
}

// Probabilities of sampling the specular lobe, the diffuse base and the wall.
// CPU twin: `probabilities`.
fn mr_probabilities(color: vec3f, l: MetalRoughLobes, cos_o: f32) -> vec3f {
    let albedos = mr_lobe_albedos(color, l, cos_o);
    let total = albedos.x + albedos.y + albedos.z;
    if !(total > 0.0) {
        return vec3f(0.0);
    }
    return albedos / total;
}

// The continuous part of the BSDF: the coat over the sheen over the rest.
// CPU twin: `eval`.
fn eval_metal_rough(m: MetalRoughParams, color: vec3f, s: Surface, wo: vec3f, wi: vec3f) -> BsdfEval {
    var base = eval_metal_rough_base(m, color, s, wo, wi);
    if max3(m.sheen_color) > 0.0 {
        base = mr_sheen_over(m, color, s, wo, wi, base);
    }
    if m.clearcoat <= 0.0 {
        return base;
    }
    let front = dot(wo, s.ng) >= 0.0;
    let ng = select(-s.ng, s.ng, front);
    // The coat's own shading normal.
    let n = select(-s.nc, s.nc, front);
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

// The largest of v's components (glam's `max_element` on the CPU).
fn max3(v: vec3f) -> f32 {
    return max(max(v.x, v.y), v.z);
}

// The probability of sampling the sheen rather than the layer under it: its estimated
// albedo over that plus the layer's, scaled (1 without a layer to sample).
// CPU twin: `sheen_probability`.
fn mr_sheen_probability(m: MetalRoughParams, color: vec3f, cos_o: f32) -> f32 {
    let sheen = max3(m.sheen_color) * sheen_reflectance(cos_o, m.sheen_roughness);
    let a = mr_lobe_albedos(color, mr_lobes(m, color), cos_o);
    let under = (1.0 - sheen) * (a.x + a.y + a.z);
    if under > 0.0 {
        return sheen / (sheen + under);
    }
    return 1.0;
}

// What the sheen lets through to the layer under it at cos_o: the extension's albedo
// scaling in its VdotN form.
// CPU twin: `sheen_scaling`.
fn mr_sheen_scaling(m: MetalRoughParams, cos_o: f32) -> f32 {
    return 1.0 - max3(m.sheen_color) * sheen_reflectance(cos_o, m.sheen_roughness);
}

// The sheen over `under` (the layer below it, evaluated).
// CPU twin: `sheen_over`.
fn mr_sheen_over(m: MetalRoughParams, color: vec3f, s: Surface, wo: vec3f, wi: vec3f, under: BsdfEval) -> BsdfEval {
    let front = dot(wo, s.ng) >= 0.0;
    let ng = select(-s.ng, s.ng, front);
    let n = select(-s.ns, s.ns, front);
    let cos_o = dot(wo, n);
    let cos_i = dot(wi, n);
    let q = mr_sheen_probability(m, color, cos_o);
    var out = BsdfEval(under.f * mr_sheen_scaling(m, cos_o), under.pdf * (1.0 - q));
    if cos_o > 0.0 && cos_i > 0.0 && dot(wi, ng) > 0.0 {
        let cos_h = dot(normalize(wo + wi), n);
        out.f += m.sheen_color * eval_sheen(m.sheen_roughness, cos_o, cos_i, cos_h);
        out.pdf += q / (2.0 * PI);
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
    // The coat, about its own shading normal.
    let nc = select(-s.nc, s.nc, front);
    let cos_c = dot(wo, nc);
    var coat = 0.0;
    if m.clearcoat > 0.0 {
        coat = mr_coat_weight(m, cos_c);
    }
    if u_lobe < coat {
        let alpha_c = m.clearcoat_roughness * m.clearcoat_roughness;
        if alpha_c < ALPHA_MIN {
            // A mirror coat: its weight over its probability is 1.
            let wi = 2.0 * cos_c * nc - wo;
            return BsdfSample(wi, vec3f(1.0), 0.0, true, 1.0, dot(wi, ng) > 0.0);
        }
        let frame_c = frame_around(nc);
        let r = ggx_reflection(frame_c, to_local(frame_c, wo), alpha_c, u);
        if !r.valid {
            return invalid_sample();
        }
        return mr_mixture_sample(m, color, s, wo, r.wi);
    }
    // The material under the coat, from what is left of u_lobe: the sheen, or under it.
    let u_rest = (u_lobe - coat) / (1.0 - coat);
    if max3(m.sheen_color) <= 0.0 {
        return sample_metal_rough_base(m, color, s, wo, u_rest, u_fresnel, u);
    }
    let q = mr_sheen_probability(m, color, cos_o);
    if u_rest < q {
        let wi = sample_cone(n, 1.0, u);
        if dot(wi, ng) <= 0.0 {
            return invalid_sample();
        }
        return mr_mixture_sample(m, color, s, wo, wi);
    }
    var bs = sample_metal_rough_base(m, color, s, wo, (u_rest - q) / (1.0 - q), u_fresnel, u);
    if bs.delta {
        bs.weight *= mr_sheen_scaling(m, cos_o) / (1.0 - q);
    }
    return bs;
}

// Samples the material under the coat and the sheen.
// CPU twin: `sample_base`.
fn sample_metal_rough_base(m: MetalRoughParams, color: vec3f, s: Surface, wo: vec3f, u_base: f32, u_fresnel: f32, u: vec2f) -> BsdfSample {
    let front = dot(wo, s.ng) >= 0.0;
    let ng = select(-s.ng, s.ng, front);
    let n = select(-s.ns, s.ns, front);
    let cos_o = dot(wo, n);
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
// specular layer lets through at normal incidence, and the tinted wall, under the sheen's
// albedo at normal incidence.
// CPU twin: `metal_rough_albedo`.
fn metal_rough_albedo(m: MetalRoughParams, color: vec3f) -> vec3f {
    let l = mr_lobes(m, color);
    let under = l.spec_f0 + (l.diffuse * mr_coupling(l, 1.0)) * color + l.wall * color;
    let sheen = sheen_reflectance(1.0, m.sheen_roughness);
    let base = under * (1.0 - max3(m.sheen_color) * sheen) + m.sheen_color * sheen;
    let coat = mr_coat_weight(m, 1.0);
    return base * (1.0 - coat) + vec3f(coat);
}

// Whether the model has a non-delta lobe.
// CPU twin: `has_continuous_metal_rough`.
fn has_continuous_metal_rough(m: MetalRoughParams, color: vec3f) -> bool {
    return mr_lobes(m, color).diffuse > 0.0 || m.roughness * m.roughness >= ALPHA_MIN
        || (m.clearcoat > 0.0 && m.clearcoat_roughness * m.clearcoat_roughness >= ALPHA_MIN)
        || max3(m.sheen_color) > 0.0;
}
