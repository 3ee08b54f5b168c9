//! Frames and direction sampling. Twin of `sampling.wgsl`.

use std::f32::consts::TAU;

use glam::{Vec2, Vec3};

/// An orthonormal basis. Twin of WGSL `frame_around` (a `mat3x3f` there).
#[derive(Debug, Clone, Copy)]
pub struct Frame {
    /// Tangent.
    pub t: Vec3,
    /// Bitangent.
    pub b: Vec3,
    /// Normal.
    pub n: Vec3,
}

impl Frame {
    /// Basis around unit `n` (Duff et al., JCGT 2017). Twin of WGSL `frame_around`.
    pub fn around(n: Vec3) -> Self {
        let s = if n.z >= 0.0 { 1.0 } else { -1.0 };
        let a = -1.0 / (s + n.z);
        let b = n.x * n.y * a;
        Self {
            t: Vec3::new(1.0 + s * n.x * n.x * a, s * b, -s * n.x),
            b: Vec3::new(b, s + n.y * n.y * a, -n.y),
            n,
        }
    }

    /// World direction of local `v`.
    pub fn to_world(&self, v: Vec3) -> Vec3 {
        self.t * v.x + self.b * v.y + self.n * v.z
    }

    /// Local coordinates of world `v`.
    pub fn to_local(&self, v: Vec3) -> Vec3 {
        Vec3::new(v.dot(self.t), v.dot(self.b), v.dot(self.n))
    }
}

/// Cosine-weighted direction about +z. Twin of WGSL `sample_cosine_hemisphere`.
pub fn sample_cosine_hemisphere(u: Vec2) -> Vec3 {
    let r = u.x.sqrt();
    let phi = TAU * u.y;
    Vec3::new(r * phi.cos(), r * phi.sin(), (1.0 - u.x).max(0.0).sqrt())
}

/// Uniform direction on the unit sphere. Twin of WGSL `sample_uniform_sphere`.
pub fn sample_uniform_sphere(u: Vec2) -> Vec3 {
    let z = 1.0 - 2.0 * u.x;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = TAU * u.y;
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// Uniform point on the unit disk (polar). Twin of WGSL `sample_disk`.
pub fn sample_disk(u: Vec2) -> Vec2 {
    let r = u.x.sqrt();
    let phi = TAU * u.y;
    Vec2::new(r * phi.cos(), r * phi.sin())
}

/// Power heuristic (beta = 2) weight of a strategy with density `a` against one with `b`.
/// Twin of WGSL `power_heuristic`.
pub fn power_heuristic(a: f32, b: f32) -> f32 {
    let a2 = a * a;
    let b2 = b * b;
    if a2 + b2 > 0.0 && a2.is_finite() {
        a2 / (a2 + b2)
    } else if a2.is_infinite() {
        1.0
    } else {
        0.0
    }
}
