// Direction sampling and local frames.

const PI: f32 = 3.14159265358979;
const TAU: f32 = 6.28318530717959;

// Orthonormal basis around unit `n` (Duff et al., "Building an Orthonormal Basis,
// Revisited", JCGT 2017). Columns: tangent, bitangent, n.
fn frame_around(n: vec3f) -> mat3x3f {
    let s = select(-1.0, 1.0, n.z >= 0.0);
    let a = -1.0 / (s + n.z);
    let b = n.x * n.y * a;
    let t = vec3f(1.0 + s * n.x * n.x * a, s * b, -s * n.x);
    let bt = vec3f(b, s + n.y * n.y * a, -n.y);
    return mat3x3f(t, bt, n);
}

// Cosine-weighted direction about +z; pdf = cos(theta) / pi.
fn sample_cosine_hemisphere(u: vec2f) -> vec3f {
    let r = sqrt(u.x);
    let phi = TAU * u.y;
    return vec3f(r * cos(phi), r * sin(phi), sqrt(max(0.0, 1.0 - u.x)));
}
