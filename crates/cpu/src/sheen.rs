//! `KHR_materials_sheen`'s "Charlie" sheen lobe (Estevez and Kulla 2017) and its directional
//! albedo, which scales the layer under it. Twin of `sheen.wgsl`.
//!
//! With perceptual roughness `r` (read as at least [`SHEEN_ROUGHNESS_MIN`]) and
//! `alpha = r^2`: `D(h) = (2 + 1/alpha) sin(theta_h)^(1/alpha) / (2 pi)` and the visibility
//! `1 / ((1 + Lambda(cos_o) + Lambda(cos_i)) 4 cos_o cos_i)`, Lambda the paper's fit, as the
//! extension and Khronos' sample viewer write them. Below roughness 0.2 at grazing angles
//! this lobe alone reflects more than it receives (up to 2.9 times, by the table), so it is
//! divided by `max(1, E(cos_o), E(cos_i))`, E its directional albedo: reciprocal, and never
//! above 1. Elsewhere it is the extension's lobe unchanged.

use std::f32::consts::PI;

use pathlight_core::sheen_table::{SHEEN_ALBEDO, SHEEN_TABLE_SIZE};

/// The smallest sheen roughness read (a smaller one is read as this).
pub const SHEEN_ROUGHNESS_MIN: f32 = 0.07;

/// Cosines below this are read as it (the table's first column).
const COS_MIN: f32 = 1e-4;

/// The table's entry `i`. Twin of WGSL `sheen_table`.
#[inline(always)]
fn table(i: usize) -> f32 {
    SHEEN_ALBEDO[i]
}

/// The directional albedo E of the white sheen lobe at `cos` (with the normal) and
/// perceptual `roughness`, interpolated in the table (columns at `(j / 31)^2`). Twin of WGSL
/// `sheen_albedo`.
#[inline(always)]
pub fn sheen_albedo(cos: f32, roughness: f32) -> f32 {
    let last = (SHEEN_TABLE_SIZE - 1) as f32;
    let x = cos.clamp(0.0, 1.0).sqrt() * last;
    let y = roughness.clamp(0.0, 1.0) * last;
    let x0 = x.floor().min(last - 1.0);
    let y0 = y.floor().min(last - 1.0);
    let (fx, fy) = (x - x0, y - y0);
    let i = y0 as usize * SHEEN_TABLE_SIZE + x0 as usize;
    let low = table(i) + (table(i + 1) - table(i)) * fx;
    let high = table(i + SHEEN_TABLE_SIZE)
        + (table(i + SHEEN_TABLE_SIZE + 1) - table(i + SHEEN_TABLE_SIZE)) * fx;
    low + (high - low) * fy
}

/// The paper's fitted Lambda at `cos` for `alpha`. Twin of WGSL `sheen_lambda`.
#[inline(always)]
fn sheen_lambda(cos: f32, alpha: f32) -> f32 {
    let t = (1.0 - alpha) * (1.0 - alpha);
    let l = |x: f32| {
        let a = 21.5473 + (25.3245 - 21.5473) * t;
        let b = 3.82987 + (3.32435 - 3.82987) * t;
        let c = 0.19823 + (0.16801 - 0.19823) * t;
        let d = -1.97760 + (-1.27393 + 1.97760) * t;
        let e = -4.32054 + (-4.85967 + 4.32054) * t;
        a / (1.0 + b * x.powf(c)) + d * x + e
    };
    if cos < 0.5 {
        l(cos).exp()
    } else {
        (2.0 * l(0.5) - l(1.0 - cos)).exp()
    }
}

/// `f cos_i` of the white sheen lobe (both directions above the surface): `cos_o`, `cos_i`
/// and `cos_h` with the normal. Twin of WGSL `eval_sheen`.
#[inline(always)]
pub fn eval_sheen(roughness: f32, cos_o: f32, cos_i: f32, cos_h: f32) -> f32 {
    let r = roughness.max(SHEEN_ROUGHNESS_MIN);
    let alpha = r * r;
    let (co, ci) = (cos_o.max(COS_MIN), cos_i.max(COS_MIN));
    let sin2 = (1.0 - cos_h * cos_h).max(0.0);
    let d = (2.0 + 1.0 / alpha) * sin2.powf(0.5 / alpha) / (2.0 * PI);
    let f = d / (4.0 * co * (1.0 + sheen_lambda(co, alpha) + sheen_lambda(ci, alpha)));
    f / sheen_albedo(co, r).max(sheen_albedo(ci, r)).max(1.0)
}

/// The albedo of the lobe as [`eval_sheen`] evaluates it, white, at `cos`: at most 1.
/// Twin of WGSL `sheen_reflectance`.
#[inline(always)]
pub fn sheen_reflectance(cos: f32, roughness: f32) -> f32 {
    sheen_albedo(cos.max(COS_MIN), roughness.max(SHEEN_ROUGHNESS_MIN)).min(1.0)
}
