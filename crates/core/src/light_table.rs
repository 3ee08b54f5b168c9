//! The light table: one entry per emissive quad, sphere and cylinder and one per triangle
//! of an emissive mesh, each chosen with probability proportional to its power (area x
//! luminance). Each emissive object points at its first entry, so that a path that hits it
//! by BSDF sampling can compute the density of having sampled it (MIS).

use bytemuck::Zeroable;
use glam::Vec3;

use crate::geometry::Geometry;
use crate::gpu_types::{
    FLAG_CAPS, GpuLight, GpuObject, GpuVertex, KIND_CYLINDER, KIND_MESH, KIND_QUAD, KIND_SPHERE,
    LIGHT_AREA, NO_LIGHT,
};

/// Luminance of linear RGB (Rec. 709 weights): what emitters and environment-map cells are
/// chosen by.
pub fn luminance(rgb: Vec3) -> f32 {
    rgb.dot(Vec3::new(0.2126, 0.7152, 0.0722))
}

/// Surface area of light-table entry `(object, primitive)`: the whole shape, or triangle
/// `primitive` (in `vertices`) of a mesh. The CPU backend's twin of WGSL `emitter_area`
/// calls it, inlined into its row renderer (a call would make it save its vector registers).
#[inline(always)]
pub fn emitter_area(object: &GpuObject, vertices: &[GpuVertex], primitive: u32) -> f32 {
    let [a, b, c] = [object.a, object.b, object.c].map(|v| Vec3::from_slice(&v));
    match object.kind {
        KIND_QUAD => b.cross(c).length(),
        KIND_SPHERE => 4.0 * std::f32::consts::PI * object.a[3] * object.a[3],
        KIND_CYLINDER => {
            let r = object.a[3];
            let caps = if object.flags & FLAG_CAPS != 0 {
                2.0
            } else {
                0.0
            };
            std::f32::consts::TAU * r * (b - a).length() + caps * std::f32::consts::PI * r * r
        }
        _ => {
            let i = 3 * primitive as usize;
            let [v0, v1, v2] = [0, 1, 2].map(|k| Vec3::from(vertices[i + k].position));
            0.5 * (v1 - v0).cross(v2 - v0).length()
        }
    }
}

/// The light table of `objects` (with their materials set) in `geometry`, never empty (a
/// placeholder when nothing emits), and the number of real entries; `emission` is each
/// material's mean emitted radiance. Sets each object's `light` to its first entry, or
/// [`NO_LIGHT`].
pub fn build(
    objects: &mut [GpuObject],
    emission: &[Vec3],
    geometry: &Geometry,
) -> (Vec<GpuLight>, u32) {
    let mut lights = Vec::new();
    let mut powers = Vec::new();
    for (i, object) in objects.iter_mut().enumerate() {
        object.light = NO_LIGHT;
        let e = emission[object.material as usize];
        let luminance = luminance(e).max(e.max_element() * 1e-3);
        if luminance <= 0.0 {
            continue;
        }
        let primitives = if object.kind == KIND_MESH {
            object.first_triangle..object.first_triangle + object.triangle_count
        } else {
            0..1
        };
        object.light = lights.len() as u32;
        for primitive in primitives {
            powers.push(emitter_area(object, &geometry.vertices, primitive) * luminance);
            lights.push(GpuLight {
                kind: LIGHT_AREA,
                index: i as u32,
                primitive,
                cdf: 0.0,
                pmf: 0.0,
            });
        }
    }
    let total: f64 = powers.iter().map(|&p| f64::from(p)).sum();
    if total <= 0.0 || !total.is_finite() {
        // Only zero-area emitters: nothing can be sampled (or hit).
        lights.clear();
        objects.iter_mut().for_each(|o| o.light = NO_LIGHT);
    }
    let mut running = 0.0f64;
    for (light, power) in lights.iter_mut().zip(&powers) {
        running += f64::from(*power);
        light.pmf = (f64::from(*power) / total) as f32;
        light.cdf = (running / total) as f32;
    }
    if let Some(last) = lights.last_mut() {
        last.cdf = 1.0;
    }
    let count = lights.len() as u32;
    if lights.is_empty() {
        lights.push(GpuLight::zeroed());
    }
    (lights, count)
}

#[cfg(test)]
mod tests {
    use glam::Vec3;
    use pathlight_scene::testing::{mesh_of, object, scene_of};
    use pathlight_scene::{Material, Scene, Shape};

    use crate::gpu_types::{LIGHT_AREA, NO_LIGHT};
    use crate::{Geometry, Shading, Textures};

    /// A scene whose material 1 emits `emission`, with a 2x1 quad, a sphere of radius 0.5
    /// and a mesh of two triangles (areas 0.5 and 2) in it, and a grey sphere.
    fn lit(emission: Vec3) -> Scene {
        let mut scene = scene_of(vec![
            object(
                "quad",
                Shape::Quad {
                    origin: Vec3::ZERO,
                    edge_u: Vec3::X * 2.0,
                    edge_v: Vec3::Y,
                },
            ),
            object(
                "ball",
                Shape::Sphere {
                    center: Vec3::Z,
                    radius: 0.5,
                    texture_rotation: 0.0,
                },
            ),
            object(
                "mesh",
                Shape::Mesh(mesh_of(&[
                    [Vec3::ZERO, Vec3::X, Vec3::Y],
                    [Vec3::ZERO, Vec3::X * 2.0, Vec3::Y * 2.0],
                ])),
            ),
            object(
                "grey",
                Shape::Sphere {
                    center: -Vec3::Z,
                    radius: 1.0,
                    texture_rotation: 0.0,
                },
            ),
        ]);
        scene.materials.push(Material {
            name: "light".into(),
            emission,
            ..scene.materials[0].clone()
        });
        for o in &mut scene.objects[..3] {
            o.material = 1;
        }
        scene
    }

    #[test]
    fn entries_are_chosen_by_power_and_objects_point_at_them() {
        let scene = lit(Vec3::splat(2.0));
        let geometry = Geometry::build(&scene.objects).unwrap();
        let shading = Shading::build(&scene, &geometry, &Textures::build(&[]));
        // One entry per shape, one per mesh triangle; the grey sphere has none.
        assert_eq!(shading.light_count, 4);
        let areas = [2.0, std::f32::consts::PI, 0.5, 2.0];
        let total: f32 = areas.iter().sum();
        let lights = &shading.lights[..4];
        let mut areas_found: Vec<f32> = lights.iter().map(|l| l.pmf * total).collect();
        areas_found.sort_by(f32::total_cmp);
        let mut expected = areas.to_vec();
        expected.sort_by(f32::total_cmp);
        for (a, b) in areas_found.iter().zip(&expected) {
            assert!((a - b).abs() < 1e-5, "{areas_found:?} vs {expected:?}");
        }
        let mut running = 0.0;
        for l in lights {
            running += l.pmf;
            assert!((l.cdf - running).abs() < 1e-6);
        }
        assert_eq!(lights[3].cdf, 1.0);
        for (i, o) in shading.objects[..3].iter().enumerate() {
            assert_eq!(shading.lights[o.light as usize].index, i as u32);
        }
        assert_eq!(shading.objects[3].light, NO_LIGHT);
        // A mesh's entries follow its triangles in the vertex buffer.
        let mesh = shading.objects[2];
        for t in 0..mesh.triangle_count {
            let entry = shading.lights[(mesh.light + t) as usize];
            assert_eq!(
                (entry.kind, entry.index, entry.primitive),
                (LIGHT_AREA, 2, mesh.first_triangle + t)
            );
        }
    }

    #[test]
    fn without_emission_or_area_the_table_is_a_placeholder() {
        let dark = lit(Vec3::ZERO);
        let geometry = Geometry::build(&dark.objects).unwrap();
        let shading = Shading::build(&dark, &geometry, &Textures::build(&[]));
        assert_eq!((shading.light_count, shading.lights.len()), (0, 1));
        assert!(shading.objects.iter().all(|o| o.light == NO_LIGHT));
        // Emitters of zero area cannot be sampled (or hit): no entries either.
        let mut flat = lit(Vec3::ONE);
        flat.objects.truncate(1);
        flat.objects[0].shape = Shape::Quad {
            origin: Vec3::ZERO,
            edge_u: Vec3::X,
            edge_v: Vec3::X,
        };
        let geometry = Geometry::build(&flat.objects).unwrap();
        assert_eq!(
            Shading::build(&flat, &geometry, &Textures::build(&[])).light_count,
            0
        );
    }
}
