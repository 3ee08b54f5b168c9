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
use crate::sampling::Frame;
use crate::textures::{has_texture, material_texture, triangle_color};

/// The surface at a hit. Twin of WGSL `Surface`.
#[derive(Debug, Clone, Copy)]
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

/// Twin of WGSL `surface_at`, except that sphere and cylinder texture coordinates (`atan2`,
/// `acos`) are computed only for materials with a texture, the only ones that read them
/// (zero otherwise).
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
                let phi = n.x.atan2(n.z) + o.b[0];
                let u = 0.5 + phi / TAU;
                s.uv = Vec2::new(u - u.floor(), n.y.clamp(-1.0, 1.0).acos() / PI);
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
                let frame = Frame::around(axis);
                let phi = radial.dot(frame.b).atan2(radial.dot(frame.t));
                let u = phi / TAU;
                u - u.floor()
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
