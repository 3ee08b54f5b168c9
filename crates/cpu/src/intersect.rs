//! Ray-primitive intersection: quads, spheres, cylinders, triangles. Twin of
//! `intersect.wgsl` (same names, same arithmetic, so both backends find the same hits).

use glam::Vec3;

/// Distance returned when there is no hit (WGSL `MISS`).
pub const MISS: f32 = 3.0e38;

/// A ray with a unit direction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ray {
    /// Start point.
    pub origin: Vec3,
    /// Unit direction.
    pub dir: Vec3,
}

impl Ray {
    /// The ray from `origin` along `dir`, from any glam 3-vector (the CPU backend shades in
    /// `Vec3A`).
    #[inline(always)]
    pub fn new(origin: impl Into<Vec3>, dir: impl Into<Vec3>) -> Self {
        Self {
            origin: origin.into(),
            dir: dir.into(),
        }
    }
}

/// `1 / d` without infinities. Twin of WGSL `safe_inverse`.
#[inline(always)]
pub fn safe_inverse(d: Vec3) -> Vec3 {
    let tiny = 1e-20_f32;
    let fix = |c: f32| {
        if c.abs() < tiny {
            if c >= 0.0 { tiny } else { -tiny }
        } else {
            c
        }
    };
    Vec3::ONE / Vec3::new(fix(d.x), fix(d.y), fix(d.z))
}

/// Parallelogram. Twin of WGSL `intersect_quad`. Returns `(t, s, t_param)`.
#[inline(always)]
pub fn intersect_quad(origin: Vec3, eu: Vec3, ev: Vec3, ray: &Ray, t_max: f32) -> (f32, f32, f32) {
    let n = eu.cross(ev);
    let denom = n.dot(ray.dir);
    let nn = n.dot(n);
    if denom.abs() <= 1e-12 * nn.sqrt() || nn <= 0.0 {
        return (MISS, 0.0, 0.0);
    }
    let t = n.dot(origin - ray.origin) / denom;
    if !(t > 0.0 && t < t_max) {
        return (MISS, 0.0, 0.0);
    }
    let p = ray.origin + t * ray.dir - origin;
    let s = p.cross(ev).dot(n) / nn;
    let r = eu.cross(p).dot(n) / nn;
    if !(0.0..=1.0).contains(&s) || !(0.0..=1.0).contains(&r) {
        return (MISS, 0.0, 0.0);
    }
    (t, s, r)
}

/// Sphere. Twin of WGSL `intersect_sphere`.
#[inline(always)]
pub fn intersect_sphere(center: Vec3, radius: f32, ray: &Ray, t_max: f32) -> f32 {
    let oc = ray.origin - center;
    let b = -oc.dot(ray.dir);
    let closest = oc + b * ray.dir;
    let disc = radius * radius - closest.dot(closest);
    if disc < 0.0 {
        return MISS;
    }
    let h = disc.sqrt();
    let t_near = b - h;
    if t_near > 0.0 && t_near < t_max {
        return t_near;
    }
    let t_far = b + h;
    if t_far > 0.0 && t_far < t_max {
        return t_far;
    }
    MISS
}

/// Cylinder. Twin of WGSL `intersect_cylinder`.
#[inline(always)]
pub fn intersect_cylinder(
    p0: Vec3,
    p1: Vec3,
    radius: f32,
    caps: bool,
    ray: &Ray,
    t_max: f32,
) -> f32 {
    let axis_full = p1 - p0;
    let height = axis_full.length();
    let axis = axis_full / height;
    let oc = ray.origin - p0;
    let d_perp = ray.dir - ray.dir.dot(axis) * axis;
    let o_perp = oc - oc.dot(axis) * axis;
    let mut t_best = MISS;
    let a = d_perp.dot(d_perp);
    if a > 1e-12 {
        let b = d_perp.dot(o_perp);
        let c = o_perp.dot(o_perp) - radius * radius;
        let disc = b * b - a * c;
        if disc >= 0.0 {
            let h = disc.sqrt();
            for t in [(-b - h) / a, (-b + h) / a] {
                let y = (oc + t * ray.dir).dot(axis);
                if t > 0.0 && t < t_max.min(t_best) && y >= 0.0 && y <= height {
                    t_best = t;
                }
            }
        }
    }
    if caps {
        let d_axis = ray.dir.dot(axis);
        if d_axis.abs() > 1e-12 {
            for cap_height in [0.0, height] {
                let t = (cap_height - oc.dot(axis)) / d_axis;
                let q = o_perp + t * d_perp;
                if t > 0.0 && t < t_max.min(t_best) && q.dot(q) <= radius * radius {
                    t_best = t;
                }
            }
        }
    }
    t_best
}

/// Moller-Trumbore on corner `v0` and the edges `e1 = v1 - v0`, `e2 = v2 - v0`; returns
/// `(t, b1, b2)` with the barycentrics of vertices 1 and 2. Twin of WGSL
/// `intersect_triangle_edges`.
#[inline(always)]
pub fn intersect_triangle_edges(
    v0: Vec3,
    e1: Vec3,
    e2: Vec3,
    ray: &Ray,
    t_max: f32,
) -> (f32, f32, f32) {
    let p = ray.dir.cross(e2);
    let det = e1.dot(p);
    if det.abs() < 1e-20 {
        return (MISS, 0.0, 0.0);
    }
    let inv_det = 1.0 / det;
    let s = ray.origin - v0;
    let b1 = s.dot(p) * inv_det;
    if !(0.0..=1.0).contains(&b1) {
        return (MISS, 0.0, 0.0);
    }
    let q = s.cross(e1);
    let b2 = ray.dir.dot(q) * inv_det;
    if b2 < 0.0 || b1 + b2 > 1.0 {
        return (MISS, 0.0, 0.0);
    }
    let t = e2.dot(q) * inv_det;
    if !(t > 0.0 && t < t_max) {
        return (MISS, 0.0, 0.0);
    }
    (t, b1, b2)
}
