//! From a hit to the local surface: position, normals (normal maps applied), texture
//! coordinates, material. Twin of `surface.wgsl`.

use std::f32::consts::{PI, TAU};

use glam::{Vec2, Vec3A};
use pathlight_core::gpu_types::{
    FLAG_CAPS, FLAG_FLAT, FLAG_INSTANCE, FLAG_MIRRORED, GpuMaterial, KIND_CYLINDER, KIND_QUAD,
    KIND_SPHERE, TEXTURE_COAT_NORMAL, TEXTURE_NORMAL,
};
use pathlight_core::octahedral::{self, tangent_sign};

use crate::bvh::Hit;
use crate::cpu_scene::CpuScene;
use crate::intersect::Ray;
use crate::sampling::{Frame, acos, atan2};
use crate::textures::{has_texture, material_texture, triangle_color};

/// The surface at a hit. Twin of WGSL `Surface`.
#[derive(Debug, Clone, Copy, Default)]
pub struct Surface {
    /// World position.
    pub position: Vec3A,
    /// Geometric normal on the shape's front side.
    pub ng: Vec3A,
    /// Shading normal, in the hemisphere of `ng`.
    pub ns: Vec3A,
    /// The shading normal of the material's coat: its own normal map
    /// ([`TEXTURE_COAT_NORMAL`]) applied, else `ns`; in the hemisphere of `ng`.
    pub nc: Vec3A,
    /// Texture coordinates.
    pub uv: Vec2,
    /// Material index.
    pub material: u32,
    /// The vertex colour (white but on meshes with `COLOR_0`), multiplying the base colour.
    pub color: Vec3A,
}

/// The shading normal bent by the material's normal map `which` ([`TEXTURE_NORMAL`] or
/// [`TEXTURE_COAT_NORMAL`], its x and y scaled by `scale`). Twin of WGSL `normal_mapped`.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn normal_mapped(
    scene: &CpuScene,
    m: &GpuMaterial,
    which: u32,
    scale: f32,
    uv: Vec2,
    ns: Vec3A,
    tangent: Vec3A,
    sign: f32,
) -> Vec3A {
    let t = tangent - tangent.dot(ns) * ns;
    if t.dot(t) < 1e-12 {
        return ns;
    }
    let tn = t.normalize();
    let b = ns.cross(tn) * sign;
    let c = Vec3A::from(material_texture(scene, m, which, uv).truncate()) * 2.0 - 1.0;
    let n = tn * (c.x * scale) + b * (c.y * scale) + ns * c.z;
    if n.dot(n) < 1e-12 {
        return ns;
    }
    n.normalize()
}

/// `n` turned towards `ng` (both on the side of the unit `wo`) just enough that the mirror
/// reflection of `wo` about it leaves the surface at least as steeply as min(0.9 wo.ng,
/// 0.01): a normal map's normal that would reflect into the surface otherwise leaves black
/// rims. Cycles' `ensure_valid_specular_reflection`: the new normal stays in the plane of
/// `n` and `ng`, its height over the surface the one root of the quartic that lifts the
/// reflection to the threshold. Twin of WGSL `valid_reflection_normal`.
#[inline(always)]
fn valid_reflection_normal(ng: Vec3A, wo: Vec3A, n: Vec3A) -> Vec3A {
    let iz = wo.dot(ng);
    let threshold = (0.9 * iz).min(0.01);
    if (2.0 * n.dot(wo) * n - wo).dot(ng) >= threshold || iz <= 0.0 {
        return n;
    }
    let x = (n - n.dot(ng) * ng).normalize_or_zero();
    let ix = wo.dot(x);
    let a = ix * ix + iz * iz;
    let b = 2.0 * (a + iz * threshold);
    let c = (threshold + iz) * (threshold + iz);
    let root = (b * b - 4.0 * a * c).max(0.0).sqrt();
    let nz2 = 0.25 * (if ix < 0.0 { b + root } else { b - root }) / a;
    (1.0 - nz2).max(0.0).sqrt() * x + nz2.max(0.0).sqrt() * ng
}

/// Texture coordinates on a sphere at unit normal `n`, its texture turned by `rotation`
/// radians about the axis: longitude (from +z towards +x) and colatitude (from +y), each in
/// [0, 1]. The polynomial `atan2` and `acos` of [`crate::sampling`] (within 3e-7 rad of the
/// WGSL built-ins, inline rather than libm calls at the baseline instruction set).
#[inline(always)]
fn sphere_uv(n: Vec3A, rotation: f32) -> Vec2 {
    let u = 0.5 + (atan2(n.x, n.z) + rotation) / TAU;
    Vec2::new(u - u.floor(), acos(n.y.clamp(-1.0, 1.0)) / PI)
}

/// The texture's u on a cylinder at `radial` (the point less its axis component): the angle
/// about the axis in `frame` (around the axis), from its tangent towards its bitangent, in
/// [0, 1] (1 only where rounding lifts an angle just below 0).
#[inline(always)]
fn cylinder_u(frame: Frame, radial: Vec3A) -> f32 {
    let u = atan2(radial.dot(frame.b), radial.dot(frame.t)) / TAU;
    u - u.floor()
}

/// Twin of WGSL `surface_at`, except that sphere and cylinder texture coordinates are
/// computed only for materials with a texture, the only ones that read them (zero
/// otherwise), with polynomial `atan2` and `acos` (`sphere_uv`, `cylinder_u`).
#[inline(always)]
pub fn surface_at(cpu_scene: &CpuScene, hit: &Hit, ray: &Ray) -> Surface {
    let scene = cpu_scene;
    let o = &scene.objects[hit.object as usize];
    let textured = scene.materials[o.material as usize].texture_mask != 0;
    let [a, b] = [o.a, o.b].map(|v| Vec3A::from_slice(&v));
    let p = Vec3A::from(ray.origin) + hit.t * Vec3A::from(ray.dir);
    let mut s = Surface {
        position: p,
        ng: Vec3A::Y,
        ns: Vec3A::Y,
        nc: Vec3A::Y,
        uv: Vec2::ZERO,
        material: o.material,
        color: Vec3A::ONE,
    };
    match o.kind {
        KIND_QUAD => {
            s.ng = cpu_scene.quad_normal(hit.object);
            s.ns = s.ng;
            s.uv = Vec2::new(hit.b1, 1.0 - hit.b2);
        }
        KIND_SPHERE => {
            let n = (p - a).normalize();
            s.ng = n;
            s.ns = n;
            if textured {
                s.uv = sphere_uv(n, o.b[0]);
            }
        }
        KIND_CYLINDER => {
            let axis_full = b - a;
            let height = axis_full.length();
            let axis = axis_full / height;
            let local = p - a;
            let y = local.dot(axis);
            let radial = local - y * axis;
            let radius = o.a[3];
            let u = if textured {
                cylinder_u(Frame::around(axis), radial)
            } else {
                0.0
            };
            if o.flags & FLAG_CAPS != 0 && radial.dot(radial) < radius * radius * 0.999 {
                s.ng = if y < 0.5 * height { -axis } else { axis };
                s.uv = Vec2::new(u, radial.length() / radius);
            } else {
                s.ng = radial.normalize();
                s.uv = Vec2::new(u, 1.0 - y / height);
            }
            s.ns = s.ng;
        }
        _ => {
            let [v0, v1, v2] = scene.corners(hit.primitive);
            let b0 = 1.0 - hit.b1 - hit.b2;
            let [p0, p1, p2] = [v0, v1, v2].map(|v| Vec3A::from(v.position));
            let instance =
                (o.flags & FLAG_INSTANCE != 0).then(|| &scene.instances[o.instance as usize]);
            let ng = (p1 - p0).cross(p2 - p0);
            s.ng = instance.map_or(ng, |i| i.to_world_normal(ng)).normalize();
            // An instance's corner normals and tangents are placed one by one, as a glTF
            // viewer's vertex shader places them (and as the mesh flattened holds them).
            let decode = |code: u32| Vec3A::from(octahedral::decode(code));
            let normal = |code: u32| match instance {
                Some(i) => i.to_world_normal(decode(code)).normalize_or_zero(),
                None => decode(code),
            };
            let n =
                b0 * normal(v0.normal) + hit.b1 * normal(v1.normal) + hit.b2 * normal(v2.normal);
            s.uv = b0 * Vec2::from(v0.uv) + hit.b1 * Vec2::from(v1.uv) + hit.b2 * Vec2::from(v2.uv);
            s.color = triangle_color(scene, hit.primitive, hit.b1, hit.b2)
                .truncate()
                .into();
            if o.flags & FLAG_FLAT != 0 || n.dot(n) < 1e-12 {
                s.ns = s.ng;
            } else {
                s.ns = n.normalize();
            }
            let m = &scene.materials[o.material as usize];
            let interpolated = s.ns;
            let wo = -Vec3A::from(ray.dir);
            let side = if wo.dot(s.ng) >= 0.0 { 1.0 } else { -1.0 };
            let tangent =
                if m.texture_mask & ((1 << TEXTURE_NORMAL) | (1 << TEXTURE_COAT_NORMAL)) != 0 {
                    let tangent = |code: u32| match instance {
                        Some(i) => i.to_world_vector(decode(code)).normalize_or_zero(),
                        None => decode(code),
                    };
                    b0 * tangent(v0.tangent)
                        + hit.b1 * tangent(v1.tangent)
                        + hit.b2 * tangent(v2.tangent)
                } else {
                    Vec3A::ZERO
                };
            let mirrored = o.flags & FLAG_MIRRORED != 0;
            let sign = tangent_sign(v0.tangent) * if mirrored { -1.0 } else { 1.0 };
            if has_texture(m, TEXTURE_NORMAL) {
                s.ns = normal_mapped(
                    scene,
                    m,
                    TEXTURE_NORMAL,
                    m.normal_scale,
                    s.uv,
                    s.ns,
                    tangent,
                    sign,
                );
                s.ns = side * valid_reflection_normal(side * s.ng, wo, side * s.ns);
            }
            if s.ns.dot(s.ng) < 0.0 {
                s.ns = -s.ns;
            }
            s.nc = s.ns;
            if has_texture(m, TEXTURE_COAT_NORMAL) {
                s.nc = normal_mapped(
                    scene,
                    m,
                    TEXTURE_COAT_NORMAL,
                    m.coat_normal_scale,
                    s.uv,
                    interpolated,
                    tangent,
                    sign,
                );
                s.nc = side * valid_reflection_normal(side * s.ng, wo, side * s.nc);
                if s.nc.dot(s.ng) < 0.0 {
                    s.nc = -s.nc;
                }
            }
            return s;
        }
    }
    s.nc = s.ns;
    s
}

#[cfg(test)]
mod tests {
    use std::f64::consts::{PI, TAU};

    use super::*;

    /// Distance between two coordinates that wrap at 1.
    fn wrapped_distance(a: f64, b: f64) -> f64 {
        let d = (a - b).rem_euclid(1.0);
        d.min(1.0 - d)
    }

    /// Unit vectors spread over the sphere, with the seam's and the poles' directions.
    fn directions() -> Vec<Vec3A> {
        let mut state = 0x9e37_79b9_u32;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            state as f32 / 4_294_967_296.0 * 2.0 - 1.0
        };
        let mut out: Vec<Vec3A> = (0..100_000)
            .map(|_| Vec3A::new(next(), next(), next()).normalize_or_zero())
            .filter(|v| *v != Vec3A::ZERO)
            .collect();
        for x in [0.0, -0.0, 1e-7, -1e-7] {
            out.extend([
                Vec3A::new(x, 0.0, -1.0),
                Vec3A::new(x, 0.3, -0.9).normalize(),
            ]);
        }
        out.extend([Vec3A::Y, -Vec3A::Y, Vec3A::X, -Vec3A::X, Vec3A::Z]);
        out
    }

    #[test]
    fn sphere_uvs_are_longitude_and_colatitude() {
        for rotation in [0.0f32, 0.35, -2.0] {
            for n in directions() {
                let uv = sphere_uv(n, rotation);
                let (x, y, z) = (f64::from(n.x), f64::from(n.y), f64::from(n.z));
                let u = 0.5 + (x.atan2(z) + f64::from(rotation)) / TAU;
                let v = y.clamp(-1.0, 1.0).acos() / PI;
                assert!(
                    (0.0..=1.0).contains(&uv.x) && (0.0..=1.0).contains(&uv.y),
                    "{n}: {uv}"
                );
                // The polynomials' error (atan2 3e-7 rad, a 5e-8 turn; acos 5e-7 rad, a 1.6e-7
                // half turn) and the floats' own rounding.
                // (At a pole, where x = z = 0, every longitude is the same point.)
                let pole = n.x == 0.0 && n.z == 0.0;
                let near = wrapped_distance(f64::from(uv.x), u) < 2e-7;
                assert!(pole || near, "{n}: u {} for {u}", uv.x);
                assert!(
                    (f64::from(uv.y) - v).abs() < 2e-7,
                    "{n}: v {} for {v}",
                    uv.y
                );
            }
        }
    }

    #[test]
    fn cylinder_u_is_the_angle_about_the_axis() {
        for axis in [Vec3A::Y, Vec3A::new(0.3, -0.5, 0.8).normalize()] {
            let frame = Frame::around(axis);
            for d in directions() {
                let radial = d - d.dot(axis) * axis;
                let u = cylinder_u(frame, radial);
                let (b, t) = (radial.dot(frame.b), radial.dot(frame.t));
                let exact = (f64::from(b).atan2(f64::from(t)) / TAU).rem_euclid(1.0);
                assert!((0.0..=1.0).contains(&u), "{d}: {u}");
                assert!(
                    wrapped_distance(f64::from(u), exact) < 2e-7,
                    "{d}: {u} for {exact}"
                );
            }
        }
    }
}
