// The material model (SPEC section 4) as a mixture of lobes chosen by their weights:
// diffuse (1 - specular_rate - refract_rate), specular reflection (specular_rate) and
// transmission (refract_rate). Sampling picks one lobe with probability equal to its
// weight and returns f * cos / pdf of that lobe, an unbiased one-sample estimate of the
// mixture. Lobes implemented here: two-sided Lambert; smooth conductor (complex-IOR
// Fresnel, or Schlick from the specular colour); smooth dielectric with exact Fresnel.

struct BsdfSample {
    wi: vec3f,
    // f * |cos| / pdf.
    weight: vec3f,
    valid: bool,
}

// Unpolarised Fresnel reflectance of a dielectric; eta = n_transmitted / n_incident.
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

// Unpolarised Fresnel reflectance of a conductor with IOR eta + i k (Mitsuba 3's
// `fresnel_conductor`).
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

fn specular_reflectance(material: Material, color: vec3f, cos_i: f32) -> vec3f {
    if material.conductor != 0u {
        return fresnel_conductor(cos_i, material.eta, material.k);
    }
    let f0 = mix(vec3f(1.0), color, material.specular_tint);
    return f0 + (1.0 - f0) * pow(1.0 - saturate(cos_i), 5.0);
}

// Samples the material at `s` for outgoing direction `wo` (unit, pointing away).
fn sample_bsdf(material: Material, color: vec3f, s: Surface, wo: vec3f, u_lobe: f32, u_fresnel: f32, u: vec2f) -> BsdfSample {
    let front = dot(wo, s.ng) >= 0.0;
    let ng = select(-s.ng, s.ng, front);
    let n = select(-s.ns, s.ns, front);
    var out = BsdfSample(vec3f(0.0), vec3f(0.0), false);
    let cos_o = dot(wo, n);
    if cos_o <= 0.0 {
        return out;
    }
    if u_lobe < material.specular_rate {
        out.wi = reflect(-wo, n);
        out.weight = specular_reflectance(material, color, cos_o);
    } else if u_lobe < material.specular_rate + material.refract_rate {
        // Entering when we are on the front (outside) of the surface.
        let eta = select(1.0 / material.ior, material.ior, front);
        let f = fresnel_dielectric(cos_o, eta);
        if u_fresnel < f {
            out.wi = reflect(-wo, n);
            out.weight = vec3f(1.0);
        } else {
            out.wi = refract(-wo, n, 1.0 / eta);
            out.weight = mix(vec3f(1.0), color, material.refract_tint);
            out.valid = dot(out.wi, ng) < 0.0 && dot(out.wi, out.wi) > 0.5;
            return out;
        }
    } else {
        out.wi = frame_around(n) * sample_cosine_hemisphere(u);
        out.weight = color;
    }
    out.valid = dot(out.wi, ng) > 0.0;
    return out;
}
