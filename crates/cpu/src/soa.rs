//! Vectors of a packet's lanes stored per axis, for the loops over lanes that the compiler
//! turns into SIMD instructions ([`crate::diffuse`], [`crate::glass`]), and the vector
//! operations of glam and of [`crate::sampling::Frame`] written again on `[f32; 3]` with the
//! same operations in the same order, so that a lane computes what the one-path code computes
//! bit for bit (`Vec3A` is one SSE register per vector, which such loops cannot use). CPU
//! only (on the GPU, threads are lanes already).

use glam::Vec3A;

use crate::packet::PACKET;

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
}
