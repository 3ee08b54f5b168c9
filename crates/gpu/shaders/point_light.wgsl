// Point and spot lights (light-table entries of kind LIGHT_POINT, `index` their parameter
// block, laid out by `pathlight_core::light_table`): a point, or a small sphere seen by light
// samples alone, shining with radiant intensity I in every direction or within a cone,
// glTF's smooth falloff t^2 between its inner and outer angle. No ray hits one, so a sample
// takes no MIS weight.
// CPU twin: `crates/cpu/src/point_light.rs`.

#import scene
#import sampling
#import light_sample
#import area_light

// The light of the point or spot light whose block starts at `block`, chosen with
// probability `pmf`, as seen from `p`: from its centre (radiance I falloff / d^2 over a
// density of pmf), or from a direction towards its sphere (radiance I falloff / (pi r^2),
// uniform in the cone the sphere subtends).
// CPU twin: `sample_point_light`.
fn sample_point_light(block: u32, pmf: f32, p: vec3f, u: vec2f) -> LightSample {
    let b0 = param_blocks[block];
    let b1 = param_blocks[block + 1u];
    let b2 = param_blocks[block + 2u];
    let center = b0.xyz;
    let radius = b0.w;
    let to_center = center - p;
    let d2 = dot(to_center, to_center);
    if d2 <= 0.0 {
        return invalid_light_sample();
    }
    let towards = to_center / sqrt(d2);
    let t = clamp((dot(-towards, b2.xyz) - b2.w) * b1.w, 0.0, 1.0);
    let falloff = t * t;
    var wi = towards;
    var point = center;
    var radiance = b1.xyz * (falloff / d2);
    var pdf = pmf;
    if radius > 0.0 {
        let one_minus_cos = sphere_cone(center, radius, p);
        if one_minus_cos <= 0.0 {
            return invalid_light_sample();
        }
        wi = sample_cone(towards, one_minus_cos, u);
        // The near side of the sphere along wi.
        let along = dot(to_center, wi);
        point = p + (along - sqrt(max(0.0, radius * radius - (d2 - along * along)))) * wi;
        radiance = b1.xyz * (falloff / (PI * radius * radius));
        pdf = pmf / (TAU * one_minus_cos);
    }
    let finite = all(abs(radiance) <= vec3f(3.0e38));
    return LightSample(wi, point, true, radiance, pdf, falloff > 0.0 && pdf > 0.0 && pdf <= 3.0e38 && finite, false);
}
