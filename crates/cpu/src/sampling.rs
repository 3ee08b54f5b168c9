//! Frames and direction sampling. Twin of `sampling.wgsl`.

use std::f32::consts::{PI, TAU};

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
    #[inline(always)]
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
    #[inline(always)]
    pub fn to_world(&self, v: Vec3A) -> Vec3A {
        self.t * v.x + self.b * v.y + self.n * v.z
    }

    /// Local coordinates of world `v`.
    #[inline(always)]
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

/// `atan2(y, x)` in [-pi, pi], to within 2e-7 rad: Abramowitz and Stegun's 4.4.49 on the
/// octant, inline and branch-free (libm's `atan2f` is a call, at the baseline instruction
/// set, and was 10% of an environment-lit render). The WGSL twins call `atan2`.
#[inline(always)]
pub fn atan2(y: f32, x: f32) -> f32 {
    let (ax, ay) = (x.abs(), y.abs());
    let (small, large) = (ax.min(ay), ax.max(ay));
    let t = if large > 0.0 { small / large } else { 0.0 };
    let t2 = t * t;
    let p = estrin(
        t2,
        &[
            0.002_866_225_7,
            -0.016_165_737,
            0.042_909_614,
            -0.075_289_64,
            0.106_562_64,
            -0.142_089,
            0.199_935_51,
            -0.333_331_45,
        ],
    );
    let mut r = t + t * t2 * p;
    if ay > ax {
        r = std::f32::consts::FRAC_PI_2 - r;
    }
    if x < 0.0 {
        r = std::f32::consts::PI - r;
    }
    f32::from_bits(r.to_bits() | (y.to_bits() & 0x8000_0000))
}

/// The polynomial of degree 7 with coefficients `c` (highest power first) at `x`, in
/// Estrin's scheme: pairs, then pairs of pairs, with powers x^2 and x^4, a chain of 4
/// dependent multiply-adds instead of Horner's 7 (the lookups of an environment map wait
/// on it). Never fused, so every level rounds alike.
#[inline(always)]
fn estrin(x: f32, c: &[f32; 8]) -> f32 {
    let x2 = x * x;
    let x4 = x2 * x2;
    let pair = |high: f32, low: f32| low + high * x;
    let low = pair(c[6], c[7]) + x2 * pair(c[4], c[5]);
    let high = pair(c[2], c[3]) + x2 * pair(c[0], c[1]);
    low + x4 * high
}

/// `acos(x)` for `x` in [-1, 1], to within 5e-7 rad: Abramowitz and Stegun's 4.4.46, inline
/// (libm's `acosf` is a call). The WGSL twins call `acos`.
#[inline(always)]
pub fn acos(x: f32) -> f32 {
    let ax = x.abs();
    let p = estrin(
        ax,
        &[
            -0.001_262_491_1,
            0.006_670_09,
            -0.017_088_126,
            0.030_891_88,
            -0.050_174_305,
            0.088_978_99,
            -0.214_598_8,
            std::f32::consts::FRAC_PI_2,
        ],
    );
    let r = (1.0 - ax).max(0.0).sqrt() * p;
    if x < 0.0 { PI - r } else { r }
}

/// The first `i` in `0 .. n` whose `value(i)` exceeds `u`, for non-decreasing values (the
/// last when none does): halving a window of fixed sizes, so that the number of steps and
/// the branches do not depend on the data (a search that branched on each comparison
/// mispredicted half of them). The WGSL twins of its callers (`cdf_search`, `sample_light`)
/// write the same loop out.
#[inline(always)]
pub fn first_above(n: u32, u: f32, value: impl Fn(u32) -> f32) -> u32 {
    let (mut base, mut size) = (0, n);
    while size > 1 {
        let half = size / 2;
        base += half * u32::from(value(base + half - 1) <= u);
        size -= half;
    }
    base
}

/// Cosine-weighted direction about +z. Twin of WGSL `sample_cosine_hemisphere`.
#[inline(always)]
pub fn sample_cosine_hemisphere(u: Vec2) -> Vec3A {
    let r = u.x.sqrt();
    let (sin, cos) = sin_cos_turns(u.y);
    Vec3A::new(r * cos, r * sin, (1.0 - u.x).max(0.0).sqrt())
}

/// Uniform direction on the unit sphere. Twin of WGSL `sample_uniform_sphere`.
#[inline(always)]
pub fn sample_uniform_sphere(u: Vec2) -> Vec3A {
    let z = 1.0 - 2.0 * u.x;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let (sin, cos) = sin_cos_turns(u.y);
    Vec3A::new(r * cos, r * sin, z)
}

/// Uniform direction within the cone about unit `axis` whose half-angle's cosine is
/// `1 - one_minus_cos` (given as `1 - cos`, exact for the small cones of the sun and far
/// spheres); its density is `1 / (2 pi one_minus_cos)`. Twin of WGSL `sample_cone`.
#[inline(always)]
pub fn sample_cone(axis: Vec3A, one_minus_cos: f32, u: Vec2) -> Vec3A {
    let below = u.x * one_minus_cos;
    let sin_theta = (below * (2.0 - below)).max(0.0).sqrt();
    let (sin, cos) = sin_cos_turns(u.y);
    Frame::around(axis).to_world(Vec3A::new(sin_theta * cos, sin_theta * sin, 1.0 - below))
}

/// Uniform point on the unit disk (polar). Twin of WGSL `sample_disk`.
#[inline(always)]
pub fn sample_disk(u: Vec2) -> Vec2 {
    let r = u.x.sqrt();
    let (sin, cos) = sin_cos_turns(u.y);
    Vec2::new(r * cos, r * sin)
}

/// Power heuristic (beta = 2) weight of a strategy with density `a` against one with `b`.
/// Twin of WGSL `power_heuristic`.
#[inline(always)]
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

    /// `atan2` against f64 `atan2` on every direction of a fine circle (2^20 angles) and on
    /// the axes and zeros of both signs: within 4e-7 rad (the stated 2e-7 plus f32 rounding
    /// of the input), and the signs of the axes as libm gives them.
    #[test]
    fn atan2_matches_f64() {
        let mut worst = 0.0f64;
        for i in 0..(1u32 << 20) {
            let (sin, cos) = sin_cos_turns(i as f32 / (1u32 << 20) as f32);
            for scale in [1.0f32, 3.7e-3, 52.0] {
                let (y, x) = (sin * scale, cos * scale);
                let exact = f64::from(y).atan2(f64::from(x));
                worst = worst.max((f64::from(atan2(y, x)) - exact).abs());
            }
        }
        assert!(worst < 4e-7, "largest error {worst:e}");
        for (y, x) in [
            (0.0, 1.0),
            (0.0, -1.0),
            (-0.0, -1.0),
            (1.0, 0.0),
            (-1.0, 0.0),
        ] {
            let exact = f64::from(y).atan2(f64::from(x));
            assert!(
                (f64::from(atan2(y, x)) - exact).abs() < 4e-7,
                "atan2({y}, {x})"
            );
        }
        assert_eq!(atan2(0.0, 0.0), 0.0);
    }

    /// `acos` against f64 `acos` on 2^20 + 1 points of [-1, 1], its ends included: within
    /// 6e-7 rad, and exact at 1.
    #[test]
    fn acos_matches_f64() {
        let mut worst = 0.0f64;
        for i in 0..=(1u32 << 20) {
            let x = (i as f32 / (1u32 << 19) as f32 - 1.0).clamp(-1.0, 1.0);
            worst = worst.max((f64::from(acos(x)) - f64::from(x).acos()).abs());
        }
        assert!(worst < 6e-7, "largest error {worst:e}");
        assert_eq!(acos(1.0), 0.0);
    }

    /// `first_above` against a linear scan, on runs of equal values, every length up to 40
    /// and values of `u` below, between, on and above the entries.
    #[test]
    fn first_above_matches_a_linear_scan() {
        for n in 1..=40u32 {
            let values: Vec<f32> = (0..n).map(|i| (i / 3) as f32).collect();
            for k in -2..=(2 * n as i32) {
                let u = k as f32 * 0.5 - 0.25 * (k % 2) as f32;
                let expected = values.iter().position(|v| *v > u).unwrap_or(n as usize - 1);
                assert_eq!(
                    first_above(n, u, |i| values[i as usize]) as usize,
                    expected,
                    "n {n}, u {u}"
                );
            }
        }
    }
}
