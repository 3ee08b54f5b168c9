//! Ray-primitive intersection: quads, spheres, cylinders, triangles. Twin of
//! `intersect.wgsl` (same names, same arithmetic, so both backends find the same hits).

use glam::Vec3;

/// Distance returned when there is no hit (WGSL `MISS`).
pub const MISS: f32 = 3.0e38;

/// Growth of a box's far distance that makes the slab test conservative: `1 + 2 gamma(3)`,
/// with `gamma(n) = n eps / (1 - n eps)` for f32's `eps = 2^-24` (Ize, "Robust BVH Ray
/// Traversal", JCGT 2013; pbrt-v4). Without it, a ray that meets a box exactly at its
/// boundary (a triangle's edge at the box's extreme) can be found outside by a rounding of
/// `t_near` past `t_far`, and the triangle it hits is never tested. Twin of WGSL `ROBUST_FAR`.
pub const ROBUST_FAR: f32 = 1.000_000_4;

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
    // (p x ev) . n / nn and (eu x p) . n / nn as dot products with the quad's dual edges,
    // which depend on the quad alone: a packet's test makes them once for all its rays.
    let inv_nn = 1.0 / nn;
    let s = p.dot(ev.cross(n) * inv_nn);
    let r = p.dot(n.cross(eu) * inv_nn);
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

/// A ray in the form the watertight triangle test wants (Woop, Benthin and Wald, "Watertight
/// Ray/Triangle Intersection", JCGT 2013): a point `p` maps to ray space as
/// `(row_x . (p - origin), row_y . (p - origin), row_z . (p - origin))`, where the direction's
/// largest axis becomes z and a shear turns the direction into +z. The rows are the shear's,
/// so that every ray applies them with the same arithmetic. Twin of WGSL `ShearedRay`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShearedRay {
    /// The ray's start.
    pub origin: Vec3,
    /// First row of the shear: unit x' minus the direction's x'/z' times unit z'.
    pub row_x: Vec3,
    /// Second row.
    pub row_y: Vec3,
    /// Third row: unit z' over the direction's z'.
    pub row_z: Vec3,
}

impl ShearedRay {
    /// The ray space of `ray`. Twin of WGSL `sheared_ray`.
    #[inline(always)]
    pub fn new(ray: &Ray) -> Self {
        let d = ray.dir;
        let a = d.abs();
        let kz = if a.x >= a.y && a.x >= a.z {
            0
        } else if a.y >= a.z {
            1
        } else {
            2
        };
        let (kx, ky) = ((kz + 1) % 3, (kz + 2) % 3);
        let (mut row_x, mut row_y, mut row_z) = (Vec3::ZERO, Vec3::ZERO, Vec3::ZERO);
        row_x[kx] = 1.0;
        row_x[kz] = -d[kx] / d[kz];
        row_y[ky] = 1.0;
        row_y[kz] = -d[ky] / d[kz];
        row_z[kz] = 1.0 / d[kz];
        Self {
            origin: ray.origin,
            row_x,
            row_y,
            row_z,
        }
    }

    /// `p` in ray space. Fused multiply-adds in a fixed order: a vertex shared by several
    /// triangles gets the same coordinates in each of their tests.
    #[inline(always)]
    fn in_ray_space(&self, p: Vec3) -> Vec3 {
        let q = p - self.origin;
        let row = |r: Vec3| r.z.mul_add(q.z, r.y.mul_add(q.y, r.x * q.x));
        Vec3::new(row(self.row_x), row(self.row_y), row(self.row_z))
    }
}

/// `a b - c d` with one rounding's error at most (Kahan's algorithm on fused multiply-adds),
/// so its sign is the exact product difference's. Twin of WGSL `difference_of_products`.
#[inline(always)]
pub fn difference_of_products(a: f32, b: f32, c: f32, d: f32) -> f32 {
    let cd = c * d;
    let error = (-c).mul_add(d, cd);
    a.mul_add(b, -cd) + error
}

/// The watertight triangle test: returns `(t, b1, b2)` with the barycentrics of vertices 1
/// and 2, or `t` = [`MISS`]. Each edge function's sign is exact given the vertices' ray-space
/// coordinates, and those are the same in every triangle that shares the vertex, so a ray
/// through an edge shared by two triangles hits one of them (both, when it passes exactly
/// through the edge): no ray leaks through a closed mesh. Twin of WGSL `intersect_triangle`.
#[inline(always)]
pub fn intersect_triangle(
    v0: Vec3,
    v1: Vec3,
    v2: Vec3,
    ray: &ShearedRay,
    t_max: f32,
) -> (f32, f32, f32) {
    // Not `array::map`: its closure may be left out of line (compiled for the baseline).
    let [p0, p1, p2] = [
        ray.in_ray_space(v0),
        ray.in_ray_space(v1),
        ray.in_ray_space(v2),
    ];
    let e0 = difference_of_products(p1.x, p2.y, p1.y, p2.x);
    let e1 = difference_of_products(p2.x, p0.y, p2.y, p0.x);
    let e2 = difference_of_products(p0.x, p1.y, p0.y, p1.x);
    let inside = !((e0 < 0.0 || e1 < 0.0 || e2 < 0.0) && (e0 > 0.0 || e1 > 0.0 || e2 > 0.0));
    let det = e0 + e1 + e2;
    if !inside || det == 0.0 {
        return (MISS, 0.0, 0.0);
    }
    let inv_det = 1.0 / det;
    let t = (e0 * p0.z + e1 * p1.z + e2 * p2.z) * inv_det;
    if !(t > 0.0 && t < t_max) {
        return (MISS, 0.0, 0.0);
    }
    (t, e1 * inv_det, e2 * inv_det)
}

#[cfg(test)]
mod tests {
    use glam::Vec3;
    use rand::rngs::StdRng;
    use rand::{Rng, SeedableRng};

    use super::*;

    /// A random vector with coordinates in [-1, 1).
    fn random_vec(rng: &mut StdRng) -> Vec3 {
        Vec3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        )
    }

    /// On random parallelograms (skewed, of any size from 0.01 to 100), a ray from a random
    /// point towards `origin + s eu + t ev` hits it at that distance with those parameters
    /// (to 1e-4 of the parameters' range), from either side; aimed 1% of an edge outside any
    /// of its four sides, it misses; and it misses beyond `t_max`.
    #[test]
    fn quads_give_the_parameters_of_the_point_hit() {
        let mut rng = StdRng::seed_from_u64(7);
        for _ in 0..20_000 {
            let scale = 10f32.powf(rng.random_range(-2.0..2.0));
            let (origin, eu, ev) = (
                random_vec(&mut rng) * scale,
                random_vec(&mut rng) * scale,
                random_vec(&mut rng) * scale,
            );
            let n = eu.cross(ev);
            // Edges at least a tenth of a radian from parallel: the parameters are well posed.
            if n.length() < 0.1 * eu.length() * ev.length() {
                continue;
            }
            let (s, t) = (rng.random_range(0.01..0.99), rng.random_range(0.01..0.99));
            let target = origin + s * eu + t * ev;
            let from = target + random_vec(&mut rng) * 2.0 * scale;
            let dir = (target - from).normalize();
            // Grazing rays make the hit's distance ill-conditioned.
            if dir.dot(n.normalize()).abs() < 0.1 {
                continue;
            }
            let ray = Ray::new(from, dir);
            let distance = (target - from).length();
            let (hit, hs, ht) = intersect_quad(origin, eu, ev, &ray, f32::INFINITY);
            assert!(
                (hit - distance).abs() <= 1e-4 * distance.max(scale)
                    && (hs - s).abs() <= 1e-4
                    && (ht - t).abs() <= 1e-4,
                "hit ({hit}, {hs}, {ht}), want ({distance}, {s}, {t}): {origin} {eu} {ev} {ray:?}"
            );
            let (before, _, _) = intersect_quad(origin, eu, ev, &ray, 0.99 * distance);
            assert_eq!(before, MISS, "beyond t_max: {origin} {eu} {ev} {ray:?}");
            for outside in [
                origin - 0.01 * eu + t * ev,
                origin + 1.01 * eu + t * ev,
                origin + s * eu - 0.01 * ev,
                origin + s * eu + 1.01 * ev,
            ] {
                let ray = Ray::new(from, (outside - from).normalize());
                let (miss, _, _) = intersect_quad(origin, eu, ev, &ray, f32::INFINITY);
                assert_eq!(miss, MISS, "outside: {outside} {origin} {eu} {ev} {ray:?}");
            }
        }
    }
}
