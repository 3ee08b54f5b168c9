// What every light type's sampling returns: a direction towards the light, the point it
// reaches (for a finite light), the radiance arriving, the density of having sampled it and
// whether BSDF sampling could have found it too.
// CPU twin: `crates/cpu/src/light_sample.rs`.

// CPU twin: `LightSample`.
struct LightSample {
    wi: vec3f,
    // The point on the light (unused for the environment).
    point: vec3f,
    // False for the environment.
    finite: bool,
    radiance: vec3f,
    // Solid-angle density including the choice of the light.
    pdf: f32,
    valid: bool,
    // Whether a ray can hit the light too (weighted against BSDF sampling by MIS); false
    // for point and sun lights.
    mis: bool,
}

// CPU twin: `INVALID`.
fn invalid_light_sample() -> LightSample {
    return LightSample(vec3f(0.0), vec3f(0.0), false, vec3f(0.0), 0.0, false, true);
}
