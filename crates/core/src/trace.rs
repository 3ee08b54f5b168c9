//! Ray queries on a [`GpuScene`] on the CPU: the twin of `intersect.wgsl` and of the
//! primitive tests of `bvh.wgsl` (same names, same arithmetic), and a walk of the binary
//! tree, used for picking and as the reference the 4-wide walks are checked against.

use glam::{Vec3, Vec3A};

use crate::accel::GpuScene;
use crate::gpu::{FLAG_CAPS, GpuBvhNode, KIND_QUAD, KIND_SPHERE, NO_TRIANGLE};

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

/// The nearest hit of a ray (WGSL `Hit`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hit {
    /// Distance along the ray.
    pub t: f32,
    /// Index into [`GpuScene::objects`] (the scene's order).
    pub object: u32,
    /// Mesh: triangle index; other shapes: 0.
    pub primitive: u32,
    /// Triangle: barycentric of vertex 1; quad: s.
    pub b1: f32,
    /// Triangle: barycentric of vertex 2; quad: t.
    pub b2: f32,
}

impl Hit {
    /// No hit yet: a search up to `t_max` (`object` is `u32::MAX` until something is hit).
    pub fn none(t_max: f32) -> Self {
        Self {
            t: t_max,
            object: u32::MAX,
            primitive: 0,
            b1: 0.0,
            b2: 0.0,
        }
    }
}

/// Slab test on a binary node's box; twin of WGSL `intersect_aabb`. Returns the entry distance or [`MISS`].
///
/// In SIMD lanes (`Vec3A`): its min and max skip the NaN handling of `f32::min`, which cost a
/// fifth of the traversal; no NaN can arise (`inv_dir` is finite, see [`safe_inverse`]), and
/// min and max are exact, so the result is the WGSL twin's bit for bit.
pub fn intersect_aabb(node: &GpuBvhNode, origin: Vec3, inv_dir: Vec3, t_max: f32) -> f32 {
    let (origin, inv_dir) = (Vec3A::from(origin), Vec3A::from(inv_dir));
    let t0 = (Vec3A::from(node.aabb_min) - origin) * inv_dir;
    let t1 = (Vec3A::from(node.aabb_max) - origin) * inv_dir;
    let t_near = t0.min(t1).max_element().max(0.0);
    let t_far = t0.max(t1).min_element().min(t_max);
    if t_near <= t_far { t_near } else { MISS }
}

/// `1 / d` without infinities; twin of WGSL `safe_inverse`.
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

/// Parallelogram; twin of WGSL `intersect_quad`. Returns `(t, s, t_param)`.
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

/// Sphere; twin of WGSL `intersect_sphere`.
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

/// Cylinder; twin of WGSL `intersect_cylinder`.
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

/// Moller-Trumbore. Returns `(t, b1, b2)`.
pub fn intersect_triangle(v0: Vec3, v1: Vec3, v2: Vec3, ray: &Ray, t_max: f32) -> (f32, f32, f32) {
    intersect_triangle_edges(v0, v1 - v0, v2 - v0, ray, t_max)
}

/// [`intersect_triangle`] given the edges `e1 = v1 - v0` and `e2 = v2 - v0`; twin of WGSL
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

impl GpuScene {
    /// Triangle `i`'s corner positions.
    #[inline(always)]
    pub fn triangle(&self, i: u32) -> [Vec3; 3] {
        let i = 3 * i as usize;
        [0, 1, 2].map(|k| Vec3::from(self.vertices[i + k].position))
    }

    /// Nearest hit on quad, sphere or cylinder object `i`, updating `hit`; twin of WGSL
    /// `intersect_shape`.
    #[inline(always)]
    pub fn intersect_shape(&self, i: u32, ray: &Ray, hit: &mut Hit) {
        let o = &self.objects[i as usize];
        let a = Vec3::from_slice(&o.a);
        let (t, b1, b2) = match o.kind {
            KIND_QUAD => intersect_quad(
                a,
                Vec3::from_slice(&o.b),
                Vec3::from_slice(&o.c),
                ray,
                hit.t,
            ),
            KIND_SPHERE => (intersect_sphere(a, o.a[3], ray, hit.t), 0.0, 0.0),
            _ => {
                let caps = o.flags & FLAG_CAPS != 0;
                let t = intersect_cylinder(a, Vec3::from_slice(&o.b), o.a[3], caps, ray, hit.t);
                (t, 0.0, 0.0)
            }
        };
        if t < hit.t {
            *hit = Hit {
                t,
                object: i,
                primitive: 0,
                b1,
                b2,
            };
        }
    }

    /// Nearest hit on primitive `i` (a shape or a triangle), updating `hit`; twin of WGSL
    /// `intersect_primitive`.
    #[inline(always)]
    pub fn intersect_primitive(&self, i: u32, ray: &Ray, hit: &mut Hit) {
        let p = &self.primitives[i as usize];
        if p.triangle == NO_TRIANGLE {
            self.intersect_shape(p.object, ray, hit);
            return;
        }
        let [v0, e1, e2] = [p.v0, p.e1, p.e2].map(Vec3::from);
        let (t, b1, b2) = intersect_triangle_edges(v0, e1, e2, ray, hit.t);
        if t < hit.t {
            *hit = Hit {
                t,
                object: p.object,
                primitive: p.triangle,
                b1,
                b2,
            };
        }
    }

    /// Nearest hit in `(0, t_max)`, or with `any_hit` the first one found: an ordered stack
    /// walk of the binary tree.
    fn trace(&self, ray: &Ray, t_max: f32, any_hit: bool) -> Hit {
        let mut hit = Hit::none(t_max);
        let nodes = &self.nodes;
        let inv_dir = safe_inverse(ray.dir);
        if self.primitives.is_empty()
            || intersect_aabb(&nodes[0], ray.origin, inv_dir, hit.t) == MISS
        {
            return hit;
        }
        // Nodes still to visit, with the distances at which the ray enters their boxes.
        let mut stack: Vec<(u32, f32)> = Vec::with_capacity(64);
        let mut index = 0u32;
        loop {
            let node = &nodes[index as usize];
            if node.prim_count > 0 {
                for i in node.first_index..node.first_index + node.prim_count {
                    self.intersect_primitive(i, ray, &mut hit);
                }
                if any_hit && hit.object != u32::MAX {
                    break;
                }
            } else {
                let a = node.first_index;
                let ta = intersect_aabb(&nodes[a as usize], ray.origin, inv_dir, hit.t);
                let tb = intersect_aabb(&nodes[a as usize + 1], ray.origin, inv_dir, hit.t);
                if ta != MISS && tb != MISS {
                    let (near, far) = if ta <= tb { (a, a + 1) } else { (a + 1, a) };
                    index = near;
                    stack.push((far, ta.max(tb)));
                    continue;
                } else if ta != MISS || tb != MISS {
                    index = if ta != MISS { a } else { a + 1 };
                    continue;
                }
            }
            let next = std::iter::from_fn(|| stack.pop()).find(|&(_, t)| t < hit.t);
            let Some((node, _)) = next else { break };
            index = node;
        }
        hit
    }

    /// Nearest hit in `(0, t_max)`; twin of WGSL `trace_scene` without `any_hit`.
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<Hit> {
        let hit = self.trace(ray, t_max, false);
        (hit.object != u32::MAX).then_some(hit)
    }

    /// Whether anything lies on the ray in `(0, t_max)`; twin of WGSL `trace_scene` with `any_hit`.
    pub fn occluded(&self, ray: &Ray, t_max: f32) -> bool {
        self.trace(ray, t_max, true).object != u32::MAX
    }
}
