//! Vectors of a packet's lanes stored per axis, for the loops over lanes that the compiler
//! turns into SIMD instructions ([`crate::diffuse`], [`crate::bsdf_lanes`]), and the vector
//! operations of glam, of [`crate::sampling::Frame`] and of the GGX distribution
//! ([`crate::microfacet`]) written again on `[f32; 3]` with the same operations in the same
//! order, so that a lane computes what the one-path code computes bit for bit (`Vec3A` is
//! one SSE register per vector, which such loops cannot use). CPU only (on the GPU, threads
//! are lanes already).

use std::f32::consts::PI;

use glam::Vec3A;

use crate::packet::PACKET;
use crate::sampling::sin_cos_turns;

/// A vector per lane, stored per axis.
pub(crate) type Lanes3 = [[f32; PACKET]; 3];

/// Lane `l` of `a` as a vector.
#[inline(always)]
pub(crate) fn lane(a: &Lanes3, l: usize) -> Vec3A {
    Vec3A::new(a[0][l], a[1][l], a[2][l])
}

/// Lane `l` of `a` as an array.
#[inline(always)]
pub(crate) fn at(a: &Lanes3, l: usize) -> [f32; 3] {
    [a[0][l], a[1][l], a[2][l]]
}

/// Writes `v` to lane `l` of `a`.
#[inline(always)]
pub(crate) fn set_lane(a: &mut Lanes3, l: usize, v: Vec3A) {
    for (axis, row) in a.iter_mut().enumerate() {
        row[l] = v[axis];
    }
}

/// `a . b` as glam computes it: `(x + y) + z`.
#[inline(always)]
pub(crate) fn dot(a: [f32; 3], b: [f32; 3]) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// `a.cross(b)` as glam computes it.
#[inline(always)]
pub(crate) fn cross(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [
        a[1] * b[2] - b[1] * a[2],
        a[2] * b[0] - b[2] * a[0],
        a[0] * b[1] - b[0] * a[1],
    ]
}

/// `v.normalize()` as glam computes it: each component divided by the length.
#[inline(always)]
pub(crate) fn normalize(v: [f32; 3]) -> [f32; 3] {
    let length = dot(v, v).sqrt();
    v.map(|c| c / length)
}

/// `s * v`.
#[inline(always)]
pub(crate) fn scale(s: f32, v: [f32; 3]) -> [f32; 3] {
    v.map(|c| s * c)
}

/// `a + b`.
#[inline(always)]
pub(crate) fn add(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    std::array::from_fn(|i| a[i] + b[i])
}

/// `_mm_max_ps(x, floor)`, as glam's `Vec3A::max` computes it (`floor` where `x` is NaN).
#[inline(always)]
pub(crate) fn max_ps(x: f32, floor: f32) -> f32 {
    if x > floor { x } else { floor }
}

/// `sample_cosine_hemisphere([ux, uy])`.
#[inline(always)]
pub(crate) fn cosine_hemisphere(ux: f32, uy: f32) -> [f32; 3] {
    let r = ux.sqrt();
    let (sin, cos) = sin_cos_turns(uy);
    [r * cos, r * sin, (1.0 - ux).max(0.0).sqrt()]
}

/// `Frame::around(n)`: tangent, bitangent, normal.
#[inline(always)]
pub(crate) fn frame_around(n: [f32; 3]) -> [[f32; 3]; 3] {
    let s = if n[2] >= 0.0 { 1.0 } else { -1.0 };
    let a = -1.0 / (s + n[2]);
    let b = n[0] * n[1] * a;
    [
        [1.0 + s * n[0] * n[0] * a, s * b, -s * n[0]],
        [b, s + n[1] * n[1] * a, -n[1]],
        n,
    ]
}

/// `Frame::to_world`.
#[inline(always)]
pub(crate) fn to_world(frame: &[[f32; 3]; 3], v: [f32; 3]) -> [f32; 3] {
    let [t, b, n] = frame;
    std::array::from_fn(|i| t[i] * v[0] + b[i] * v[1] + n[i] * v[2])
}

/// `Frame::to_local`.
#[inline(always)]
pub(crate) fn to_local(frame: &[[f32; 3]; 3], v: [f32; 3]) -> [f32; 3] {
    frame.map(|axis| dot(v, axis))
}

/// `ggx_d`.
#[inline(always)]
pub(crate) fn ggx_d(m: [f32; 3], alpha: f32) -> f32 {
    let a2 = alpha * alpha;
    let t = (m[0] * m[0] + m[1] * m[1]) / a2 + m[2] * m[2];
    1.0 / (PI * a2 * t * t)
}

/// `ggx_g1` (its early return a select).
#[inline(always)]
pub(crate) fn ggx_g1(w: [f32; 3], alpha: f32) -> f32 {
    let z2 = w[2] * w[2];
    let tan2 = (w[0] * w[0] + w[1] * w[1]) / z2;
    let g1 = 2.0 / (1.0 + (1.0 + alpha * alpha * tan2).sqrt());
    if z2 <= 0.0 { 0.0 } else { g1 }
}

/// `ggx_sample_visible`.
#[inline(always)]
pub(crate) fn ggx_sample_visible(wo: [f32; 3], alpha: f32, u: [f32; 2]) -> [f32; 3] {
    let w = if wo[2] < 0.0 { wo.map(|c| -c) } else { wo };
    let vh = normalize([alpha * w[0], alpha * w[1], w[2]]);
    let len2 = vh[0] * vh[0] + vh[1] * vh[1];
    let length = len2.sqrt();
    let t1 = if len2 > 0.0 {
        [-vh[1] / length, vh[0] / length, 0.0 / length]
    } else {
        [1.0, 0.0, 0.0]
    };
    let t2 = cross(vh, t1);
    let r = u[0].sqrt();
    let (sin, cos) = sin_cos_turns(u[1]);
    let p1 = r * cos;
    let s = 0.5 * (1.0 + vh[2]);
    let p2 = (1.0 - s) * (1.0 - p1 * p1).max(0.0).sqrt() + s * r * sin;
    let k = (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt();
    let nh = add(add(scale(p1, t1), scale(p2, t2)), scale(k, vh));
    normalize([alpha * nh[0], alpha * nh[1], nh[2].max(1e-7)])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Frame;

    /// Each operation is glam's (or `Frame`'s) bit for bit on random vectors of mixed
    /// magnitudes and signs, normals next to -z included (the frame's other branch). Fails
    /// with any operation reordered (the cross product's terms grouped otherwise, a
    /// normalisation by the reciprocal of the length).
    #[test]
    fn operations_are_glams_bit_for_bit() {
        let mut state = 0x2545_f491_u32;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            (state as f32 / 4_294_967_296.0) * 2.0 - 1.0
        };
        let bits = |v: [f32; 3]| v.map(f32::to_bits);
        let glam_bits = |v: Vec3A| v.to_array().map(f32::to_bits);
        for i in 0..20_000 {
            let magnitude = [1.0, 1e-3, 37.0][i % 3];
            let a = [next(), next(), next()].map(|c| c * magnitude);
            let b = [next(), next(), next()];
            let (va, vb) = (Vec3A::from(a), Vec3A::from(b));
            assert_eq!(dot(a, b).to_bits(), va.dot(vb).to_bits());
            assert_eq!(bits(cross(a, b)), glam_bits(va.cross(vb)));
            assert_eq!(bits(normalize(a)), glam_bits(va.normalize()));
            let n = if i % 7 == 0 {
                normalize([0.01 * b[0], 0.01 * b[1], -1.0])
            } else {
                normalize(b)
            };
            let frame = Frame::around(Vec3A::from(n));
            let ours = frame_around(n);
            assert_eq!(bits(ours[0]), glam_bits(frame.t));
            assert_eq!(bits(ours[1]), glam_bits(frame.b));
            assert_eq!(bits(to_world(&ours, a)), glam_bits(frame.to_world(va)));
            assert_eq!(bits(to_local(&ours, a)), glam_bits(frame.to_local(va)));
        }
    }

    /// The GGX functions are `microfacet`'s bit for bit: directions in both hemispheres and
    /// on the horizon, roughnesses from 0.03 to 1, draws at 0 and next to 1. Fails with any
    /// operation reordered.
    #[test]
    fn ggx_is_microfacets_bit_for_bit() {
        use glam::Vec2;

        use crate::microfacet;

        let mut state = 0x6b43_a9b5_u32;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            state as f32 / 4_294_967_296.0
        };
        let bits = |v: [f32; 3]| v.map(f32::to_bits);
        let glam_bits = |v: Vec3A| v.to_array().map(f32::to_bits);
        for i in 0..20_000 {
            let mut w = normalize([next() * 2.0 - 1.0, next() * 2.0 - 1.0, next() * 2.0 - 1.0]);
            if i % 11 == 0 {
                w[2] = 0.0;
            }
            let alpha = [0.03, 0.3, 1.0, next()][i % 4].max(0.03);
            let u = if i % 13 == 0 {
                [
                    [0.0, 1.0f32.next_down()][i % 2],
                    [0.0, 0.999_999_9][(i / 2) % 2],
                ]
            } else {
                [next(), next()]
            };
            let vw = Vec3A::from(w);
            assert_eq!(
                ggx_g1(w, alpha).to_bits(),
                microfacet::ggx_g1(vw, alpha).to_bits()
            );
            let h = ggx_sample_visible(w, alpha, u);
            let theirs = microfacet::ggx_sample_visible(vw, alpha, Vec2::from(u));
            assert_eq!(bits(h), glam_bits(theirs), "{w:?} {alpha} {u:?}");
            assert_eq!(
                ggx_d(h, alpha).to_bits(),
                microfacet::ggx_d(theirs, alpha).to_bits()
            );
        }
    }
}
