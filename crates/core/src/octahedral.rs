//! Octahedral encoding of unit vectors in 32 bits (two 16-bit snorm numbers), as the
//! vertex buffer stores normals and tangents (Cigolle et al. 2014, "A Survey of Efficient
//! Representations for Independent Unit Vectors"). WGSL twin: `decode_unit` in
//! `surface.wgsl`.

use glam::{Vec2, Vec3};

/// The code of the zero vector (both halves -32768, which no unit vector encodes to).
pub const ZERO: u32 = 0x8000_8000;

/// The code of `v` (normalised first); [`ZERO`] for a zero or non-finite vector.
pub fn encode(v: Vec3) -> u32 {
    let l1 = v.x.abs() + v.y.abs() + v.z.abs();
    if !(l1 > 0.0 && l1.is_finite()) {
        return ZERO;
    }
    let p = Vec2::new(v.x, v.y) / l1;
    let p = if v.z < 0.0 {
        (Vec2::ONE - Vec2::new(p.y, p.x).abs()) * p.signum()
    } else {
        p
    };
    let snorm = |x: f32| ((x.clamp(-1.0, 1.0) * 32767.0).round() as i16) as u16;
    u32::from(snorm(p.x)) | (u32::from(snorm(p.y)) << 16)
}

/// The bit of a tangent's code that holds the sign of its bitangent (the lowest of its second
/// half: the vector moves by at most 1/32767 in one coordinate, which no shading shows).
pub const SIGN_BIT: u32 = 1 << 16;

/// The code of tangent `t` (normalised first) with the bitangent's sign `w` in
/// [`SIGN_BIT`] (set for a negative sign); [`ZERO`] for a zero tangent, whatever `w`.
pub fn encode_tangent(t: Vec3, w: f32) -> u32 {
    let code = encode(t);
    if code == ZERO {
        return ZERO;
    }
    if w < 0.0 {
        code | SIGN_BIT
    } else {
        code & !SIGN_BIT
    }
}

/// The bitangent's sign in tangent code `code`: -1 or 1. Twin of WGSL `tangent_sign`.
#[inline(always)]
pub fn tangent_sign(code: u32) -> f32 {
    if code & SIGN_BIT != 0 { -1.0 } else { 1.0 }
}

/// The unit vector of `code` (WGSL `unpack2x16snorm` then the octahedron unfolded); zero
/// for [`ZERO`].
#[inline(always)]
pub fn decode(code: u32) -> Vec3 {
    if code == ZERO {
        return Vec3::ZERO;
    }
    let snorm = |h: u32| (f32::from(h as u16 as i16) / 32767.0).max(-1.0);
    let (x, y) = (snorm(code & 0xffff), snorm(code >> 16));
    let z = 1.0 - x.abs() - y.abs();
    let t = (-z).max(0.0);
    let x = x + if x >= 0.0 { -t } else { t };
    let y = y + if y >= 0.0 { -t } else { t };
    Vec3::new(x, y, z).normalize()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unit_vectors_survive_within_a_twentieth_of_a_degree() {
        let mut worst = 0.0f32;
        for i in 0..2000 {
            // A Fibonacci sphere covers every octant and both poles.
            let z = 1.0 - (i as f32 + 0.5) / 1000.0;
            let r = (1.0 - z * z).max(0.0).sqrt();
            let phi = i as f32 * 2.399_963;
            let v = Vec3::new(r * phi.cos(), r * phi.sin(), z);
            let back = decode(encode(v));
            // The angle by its sine, in f64: acos near 1 in f32 alone errs by 0.02 degrees.
            let sine = f64::from(v.cross(back).length());
            worst = worst.max(sine.asin().to_degrees() as f32);
        }
        for v in [
            Vec3::X,
            Vec3::NEG_X,
            Vec3::Y,
            Vec3::NEG_Y,
            Vec3::Z,
            Vec3::NEG_Z,
        ] {
            assert_eq!(decode(encode(v)), v);
        }
        assert!(worst < 0.05, "worst error {worst} degrees");
    }

    #[test]
    fn a_tangent_keeps_its_sign_and_its_direction_within_a_twentieth_of_a_degree() {
        for i in 0..500 {
            let z = 1.0 - (i as f32 + 0.5) / 250.0;
            let r = (1.0 - z * z).max(0.0).sqrt();
            let phi = i as f32 * 2.399_963;
            let t = Vec3::new(r * phi.cos(), r * phi.sin(), z);
            for w in [1.0, -1.0] {
                let code = encode_tangent(t, w);
                assert_eq!(tangent_sign(code), w);
                let sine = f64::from(t.cross(decode(code)).length());
                assert!(sine.asin().to_degrees() < 0.05, "{t} {w}");
            }
        }
        assert_eq!(encode_tangent(Vec3::ZERO, -1.0), ZERO);
    }

    #[test]
    fn the_zero_vector_has_its_own_code() {
        assert_eq!(encode(Vec3::ZERO), ZERO);
        assert_eq!(encode(Vec3::NAN), ZERO);
        assert_eq!(decode(ZERO), Vec3::ZERO);
    }
}
