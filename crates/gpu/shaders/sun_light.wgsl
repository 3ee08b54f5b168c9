// The sun (light-table entries of kind LIGHT_SUN, `index` its parameter block, laid out by
// `pathlight_core::light_table`): light of irradiance E arriving along one direction from
// infinitely far away, or from a disk of the sky of uniform radiance E / (pi sin^2 a) (a its
// angular radius), sampled uniformly in its cone. No ray hits it, so a sample takes no MIS
// weight.
// CPU twin: `crates/cpu/src/sun_light.rs`.

#import scene
#import sampling
#import light_sample

// The light of the sun whose block starts at `block`, chosen with probability `pmf`.
// CPU twin: `sample_sun_light`.
fn sample_sun_light(block: u32, pmf: f32, u: vec2f) -> LightSample {
    let b0 = param_blocks[block];
    let b1 = param_blocks[block + 1u];
    let one_minus_cos = b0.w;
    var wi = b0.xyz;
    var radiance = b1.xyz;
    var pdf = pmf;
    if one_minus_cos > 0.0 {
        wi = sample_cone(b0.xyz, one_minus_cos, u);
        radiance = b1.xyz * b1.w;
        pdf = pmf / (TAU * one_minus_cos);
    }
    return LightSample(wi, vec3f(0.0), false, radiance, pdf, pdf > 0.0 && pdf <= 3.0e38, false);
}
