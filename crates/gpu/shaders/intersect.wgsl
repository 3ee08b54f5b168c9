// Ray-primitive intersection: boxes, quads, spheres, cylinders, triangles.
// CPU twin: `crates/cpu/src/intersect.rs` (same names, same arithmetic).
// Each function returns the hit distance, or MISS when there is none in (0, t_max).

const MISS: f32 = 3.0e38;

// Growth of a box's far distance that makes the slab test conservative: 1 + 2 gamma(3) for
// f32 (Ize, "Robust BVH Ray Traversal", JCGT 2013), so a ray touching a box's boundary enters.
// CPU twin: `ROBUST_FAR`.
const ROBUST_FAR: f32 = 1.0000004;

struct Ray {
    origin: vec3f,
    dir: vec3f,
}

// An axis-aligned box.
struct Aabb {
    min: vec3f,
    max: vec3f,
}

// Slab test; `inv_dir` has no infinities (see `safe_inverse`). Returns the entry distance.
fn intersect_aabb(b: Aabb, origin: vec3f, inv_dir: vec3f, t_max: f32) -> f32 {
    let t0 = (b.min - origin) * inv_dir;
    let t1 = (b.max - origin) * inv_dir;
    let t_near = max(max(min(t0.x, t1.x), min(t0.y, t1.y)), max(min(t0.z, t1.z), 0.0));
    let t_far = min(min(max(t0.x, t1.x), max(t0.y, t1.y)), min(max(t0.z, t1.z), t_max));
    return select(MISS, t_near, t_near <= t_far * ROBUST_FAR);
}

// 1 / d with zero components replaced by a tiny value of the same sign.
// CPU twin: `safe_inverse`.
fn safe_inverse(d: vec3f) -> vec3f {
    let tiny = 1e-20;
    let x = select(d.x, select(-tiny, tiny, d.x >= 0.0), abs(d.x) < tiny);
    let y = select(d.y, select(-tiny, tiny, d.y >= 0.0), abs(d.y) < tiny);
    let z = select(d.z, select(-tiny, tiny, d.z >= 0.0), abs(d.z) < tiny);
    return 1.0 / vec3f(x, y, z);
}

// Parallelogram origin + s eu + t ev; returns (t, s, t_param).
// CPU twin: `intersect_quad`.
fn intersect_quad(origin: vec3f, eu: vec3f, ev: vec3f, ray: Ray, t_max: f32) -> vec3f {
    let n = cross(eu, ev);
    let denom = dot(n, ray.dir);
    let nn = dot(n, n);
    if abs(denom) <= 1e-12 * sqrt(nn) || nn <= 0.0 {
        return vec3f(MISS, 0.0, 0.0);
    }
    let t = dot(n, origin - ray.origin) / denom;
    if !(t > 0.0 && t < t_max) {
        return vec3f(MISS, 0.0, 0.0);
    }
    let p = ray.origin + t * ray.dir - origin;
    // (p x ev) . n / nn and (eu x p) . n / nn as dot products with the quad's dual edges.
    let inv_nn = 1.0 / nn;
    let s = dot(p, cross(ev, n) * inv_nn);
    let r = dot(p, cross(n, eu) * inv_nn);
    if s < 0.0 || s > 1.0 || r < 0.0 || r > 1.0 {
        return vec3f(MISS, 0.0, 0.0);
    }
    return vec3f(t, s, r);
}

// Sphere; `ray.dir` is unit. The discriminant uses the closest-approach form
// (Haines et al., Ray Tracing Gems ch. 7) to stay accurate far from the sphere.
// CPU twin: `intersect_sphere`.
fn intersect_sphere(center: vec3f, radius: f32, ray: Ray, t_max: f32) -> f32 {
    let oc = ray.origin - center;
    let b = -dot(oc, ray.dir);
    let closest = oc + b * ray.dir;
    let disc = radius * radius - dot(closest, closest);
    if disc < 0.0 {
        return MISS;
    }
    let h = sqrt(disc);
    let t_near = b - h;
    if t_near > 0.0 && t_near < t_max {
        return t_near;
    }
    let t_far = b + h;
    if t_far > 0.0 && t_far < t_max {
        return t_far;
    }
    return MISS;
}

// Cylinder from p0 to p1 (side, and the end disks when `caps`).
// CPU twin: `intersect_cylinder`.
fn intersect_cylinder(p0: vec3f, p1: vec3f, radius: f32, caps: bool, ray: Ray, t_max: f32) -> f32 {
    let axis_full = p1 - p0;
    let height = length(axis_full);
    let axis = axis_full / height;
    let oc = ray.origin - p0;
    let d_perp = ray.dir - dot(ray.dir, axis) * axis;
    let o_perp = oc - dot(oc, axis) * axis;
    var t_best = MISS;
    let a = dot(d_perp, d_perp);
    if a > 1e-12 {
        let b = dot(d_perp, o_perp);
        let c = dot(o_perp, o_perp) - radius * radius;
        let disc = b * b - a * c;
        if disc >= 0.0 {
            let h = sqrt(disc);
            let roots = array<f32, 2>((-b - h) / a, (-b + h) / a);
            for (var i = 0; i < 2; i++) {
                let t = roots[i];
                let y = dot(oc + t * ray.dir, axis);
                if t > 0.0 && t < min(t_max, t_best) && y >= 0.0 && y <= height {
                    t_best = t;
                }
            }
        }
    }
    if caps {
        let d_axis = dot(ray.dir, axis);
        if abs(d_axis) > 1e-12 {
            let heights = array<f32, 2>(0.0, height);
            for (var i = 0; i < 2; i++) {
                let t = (heights[i] - dot(oc, axis)) / d_axis;
                let q = o_perp + t * d_perp;
                if t > 0.0 && t < min(t_max, t_best) && dot(q, q) <= radius * radius {
                    t_best = t;
                }
            }
        }
    }
    return t_best;
}

// A ray in the form the watertight triangle test wants (Woop, Benthin and Wald, "Watertight
// Ray/Triangle Intersection", JCGT 2013): a point p maps to ray space as the dot products of
// p - origin with the three rows, which make the direction's largest axis z and shear the
// direction onto +z.
// CPU twin: `ShearedRay`.
struct ShearedRay {
    origin: vec3f,
    row_x: vec3f,
    row_y: vec3f,
    row_z: vec3f,
}

// CPU twin: `ShearedRay::new`.
fn sheared_ray(ray: Ray) -> ShearedRay {
    let d = ray.dir;
    let a = abs(d);
    var kz = 2u;
    if a.x >= a.y && a.x >= a.z {
        kz = 0u;
    } else if a.y >= a.z {
        kz = 1u;
    }
    let kx = (kz + 1u) % 3u;
    let ky = (kz + 2u) % 3u;
    var row_x = vec3f(0.0);
    var row_y = vec3f(0.0);
    var row_z = vec3f(0.0);
    row_x[kx] = 1.0;
    row_x[kz] = -d[kx] / d[kz];
    row_y[ky] = 1.0;
    row_y[kz] = -d[ky] / d[kz];
    row_z[kz] = 1.0 / d[kz];
    return ShearedRay(ray.origin, row_x, row_y, row_z);
}

// `p` in ray space, with fused multiply-adds in a fixed order so that a vertex shared by
// several triangles gets the same coordinates in each of their tests.
fn to_ray_space(ray: ShearedRay, p: vec3f) -> vec3f {
    let q = p - ray.origin;
    return vec3f(
        fma(ray.row_x.z, q.z, fma(ray.row_x.y, q.y, ray.row_x.x * q.x)),
        fma(ray.row_y.z, q.z, fma(ray.row_y.y, q.y, ray.row_y.x * q.x)),
        fma(ray.row_z.z, q.z, fma(ray.row_z.y, q.y, ray.row_z.x * q.x)),
    );
}

// a b - c d with one rounding's error at most (Kahan's algorithm), so its sign is exact.
// CPU twin: `difference_of_products`.
fn difference_of_products(a: f32, b: f32, c: f32, d: f32) -> f32 {
    let cd = c * d;
    let error = fma(-c, d, cd);
    return fma(a, b, -cd) + error;
}

// The watertight triangle test; returns (t, b1, b2) with the barycentrics of vertices 1 and
// 2. Edge function signs are exact given the ray-space corners, which are the same in every
// triangle sharing a corner, so no ray passes between two triangles of a mesh.
// CPU twin: `intersect_triangle`.
fn intersect_triangle(v0: vec3f, v1: vec3f, v2: vec3f, ray: ShearedRay, t_max: f32) -> vec3f {
    let p0 = to_ray_space(ray, v0);
    let p1 = to_ray_space(ray, v1);
    let p2 = to_ray_space(ray, v2);
    let e0 = difference_of_products(p1.x, p2.y, p1.y, p2.x);
    let e1 = difference_of_products(p2.x, p0.y, p2.y, p0.x);
    let e2 = difference_of_products(p0.x, p1.y, p0.y, p1.x);
    let inside = !((e0 < 0.0 || e1 < 0.0 || e2 < 0.0) && (e0 > 0.0 || e1 > 0.0 || e2 > 0.0));
    let det = e0 + e1 + e2;
    if !inside || det == 0.0 {
        return vec3f(MISS, 0.0, 0.0);
    }
    let inv_det = 1.0 / det;
    let t = (e0 * p0.z + e1 * p1.z + e2 * p2.z) * inv_det;
    if !(t > 0.0 && t < t_max) {
        return vec3f(MISS, 0.0, 0.0);
    }
    return vec3f(t, e1 * inv_det, e2 * inv_det);
}
