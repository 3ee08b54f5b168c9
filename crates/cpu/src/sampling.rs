//! Frames and direction sampling. Twin of `sampling.wgsl`.

use std::f32::consts::TAU;

use glam::{Vec2, Vec3A};

/// An orthonormal basis (a `mat3x3f` in WGSL, see [`Frame::around`]).
#[derive(Debug, Clone, Copy)]
pub struct Frame {
    /// Tangent.
    pub t: Vec3A,
    /// Bitangent.
    pub b: Vec3A,
    /// Normal.
    pub n: Vec3A,
}

impl Frame {
    /// Basis around unit `n` (Duff et al., JCGT 2017). Twin of WGSL `frame_around`.
    pub fn around(n: Vec3A) -> Self {
        let s = if n.z >= 0.0 { 1.0 } else { -1.0 };
        let a = -1.0 / (s + n.z);
        let b = n.x * n.y * a;
        Self {
            t: Vec3A::new(1.0 + s * n.x * n.x * a, s * b, -s * n.x),
            b: Vec3A::new(b, s + n.y * n.y * a, -n.y),
            n,
        }
    }

    /// World direction of local `v`.
    pub fn to_world(&self, v: Vec3A) -> Vec3A {
        self.t * v.x + self.b * v.y + self.n * v.z
    }

    /// Local coordinates of world `v`.
    pub fn to_local(&self, v: Vec3A) -> Vec3A {
        Vec3A::new(v.dot(self.t), v.dot(self.b), v.dot(self.n))
    }
}

/// `(sin, cos)` of the angle `2 pi turns`, for `turns` in [0, 1], to within 1e-7 (a few
/// ulp). Inline and branch-free, unlike libm's `sincosf`: a call there makes the caller
/// save every live vector register, and it runs at the baseline instruction set. The WGSL
/// twins call `sin` and `cos` of `2 pi turns`.
#[inline(always)]
pub fn sin_cos_turns(turns: f32) -> (f32, f32) {
    // The nearest quarter turn q (exact), and the rest: an angle in [-pi/4, pi/4].
    let q = (4.0 * turns + 0.5) as i32;
    let x = (turns - q as f32 * 0.25) * TAU;
    let x2 = x * x;
    let x4 = x2 * x2;
    // Taylor series to x^9 and x^8 (truncation errors below 2e-9 and 3e-8), evaluated in
    // Estrin's scheme: a shorter chain of dependent operations than Horner's.
    let sin = x
        * ((1.0 - x2 * (1.0 / 6.0))
            + x4 * ((1.0 / 120.0 - x2 * (1.0 / 5040.0)) + x4 * (1.0 / 362_880.0)));
    let cos = (1.0 - x2 * 0.5) + x4 * ((1.0 / 24.0 - x2 * (1.0 / 720.0)) + x4 * (1.0 / 40_320.0));
    // Rotate by q quarter turns: odd q swaps sine and cosine, then the signs.
    let (s, c) = if q & 1 != 0 { (cos, sin) } else { (sin, cos) };
    let sin_sign = ((q as u32 >> 1) & 1) << 31;
    let cos_sign = ((q as u32 ^ (q as u32 >> 1)) & 1) << 31;
    (
        f32::from_bits(s.to_bits() ^ sin_sign),
        f32::from_bits(c.to_bits() ^ cos_sign),
    )
}

/// Cosine-weighted direction about +z. Twin of WGSL `sample_cosine_hemisphere`.
#[inline(always)]
pub fn sample_cosine_hemisphere(u: Vec2) -> Vec3A {
    let r = u.x.sqrt();
    let (sin, cos) = sin_cos_turns(u.y);
    Vec3A::new(r * cos, r * sin, (1.0 - u.x).max(0.0).sqrt())
}

/// Uniform direction on the unit sphere. Twin of WGSL `sample_uniform_sphere`.
pub fn sample_uniform_sphere(u: Vec2) -> Vec3A {
    let z = 1.0 - 2.0 * u.x;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let (sin, cos) = sin_cos_turns(u.y);
    Vec3A::new(r * cos, r * sin, z)
}

/// Uniform point on the unit disk (polar). Twin of WGSL `sample_disk`.
pub fn sample_disk(u: Vec2) -> Vec2 {
    let r = u.x.sqrt();
    let (sin, cos) = sin_cos_turns(u.y);
    Vec2::new(r * cos, r * sin)
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

#[cfg(test)]
mod tests {
    use super::*;

    /// `sin_cos_turns` against f64 `sin_cos` on a fine grid of [0, 1] (every 2^-20 turn, the
    /// quarter-turn boundaries included): within 1.5e-7, and exactly (0, 1) at a whole turn.
    #[test]
    fn sin_cos_turns_matches_f64() {
        let mut worst = 0.0f64;
        for i in 0..=(1u32 << 20) {
            let turns = i as f32 / (1u32 << 20) as f32;
            let (sin, cos) = sin_cos_turns(turns);
            let (s, c) = (f64::from(turns) * std::f64::consts::TAU).sin_cos();
            worst = worst
                .max((f64::from(sin) - s).abs())
                .max((f64::from(cos) - c).abs());
        }
        assert!(worst < 1.5e-7, "largest error {worst:e}");
        assert_eq!(sin_cos_turns(1.0), (0.0, 1.0));
        assert_eq!(sin_cos_turns(0.0), (0.0, 1.0));
    }
}
