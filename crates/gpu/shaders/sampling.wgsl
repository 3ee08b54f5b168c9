// Direction sampling, local frames and MIS weights. CPU twin: `crates/cpu/src/sampling.rs`.

const PI: f32 = 3.14159265358979;
const TAU: f32 = 6.28318530717959;

// Orthonormal basis around unit `n` (Duff et al., "Building an Orthonormal Basis,
// Revisited", JCGT 2017). Columns: tangent, bitangent, n.
// CPU twin: `Frame::around`.
fn frame_around(n: vec3f) -> mat3x3f {
    let s = select(-1.0, 1.0, n.z >= 0.0);
    let a = -1.0 / (s + n.z);
    let b = n.x * n.y * a;
    let t = vec3f(1.0 + s * n.x * n.x * a, s * b, -s * n.x);
    let bt = vec3f(b, s + n.y * n.y * a, -n.y);
    return mat3x3f(t, bt, n);
}

// Cosine-weighted direction about +z; pdf = cos(theta) / pi.
// CPU twin: `sample_cosine_hemisphere`.
fn sample_cosine_hemisphere(u: vec2f) -> vec3f {
    let r = sqrt(u.x);
    let phi = TAU * u.y;
    return vec3f(r * cos(phi), r * sin(phi), sqrt(max(0.0, 1.0 - u.x)));
}

// Uniform direction on the unit sphere; pdf = 1 / (4 pi).
// CPU twin: `sample_uniform_sphere`.
fn sample_uniform_sphere(u: vec2f) -> vec3f {
    let z = 1.0 - 2.0 * u.x;
    let r = sqrt(max(0.0, 1.0 - z * z));
    let phi = TAU * u.y;
    return vec3f(r * cos(phi), r * sin(phi), z);
}

// Uniform direction within the cone about unit `axis` whose half-angle's cosine is
// 1 - one_minus_cos (given as 1 - cos, exact for small cones); density
// 1 / (2 pi one_minus_cos).
// CPU twin: `sample_cone`.
fn sample_cone(axis: vec3f, one_minus_cos: f32, u: vec2f) -> vec3f {
    let below = u.x * one_minus_cos;
    let sin_theta = sqrt(max(0.0, below * (2.0 - below)));
    let phi = TAU * u.y;
    return frame_around(axis) * vec3f(sin_theta * cos(phi), sin_theta * sin(phi), 1.0 - below);
}

// Uniform point on the unit disk (polar).
// CPU twin: `sample_disk`.
fn sample_disk(u: vec2f) -> vec2f {
    let r = sqrt(u.x);
    let phi = TAU * u.y;
    return vec2f(r * cos(phi), r * sin(phi));
}

// Power heuristic (beta = 2) weight of a strategy with density `a` against one with `b`.
// CPU twin: `power_heuristic`.
fn power_heuristic(a: f32, b: f32) -> f32 {
    let a2 = a * a;
    let b2 = b * b;
    if a2 + b2 > 0.0 && a2 <= 3.0e38 {
        return a2 / (a2 + b2);
    }
    return select(0.0, 1.0, a2 > 3.0e38);
}
