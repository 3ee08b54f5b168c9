//! The light table: one entry per emissive quad, sphere and cylinder, one per triangle of
//! an emissive mesh, and one per point, spot and sun light, each chosen with probability
//! proportional to its power. Each emissive object points at its first entry, so that a
//! path that hits it by BSDF sampling can compute the density of having sampled it (MIS).
//! A point or sun light's parameters are a block of `vec4`s in the parameter-block buffer
//! (after the materials'), which its entry's `index` points at.

use bytemuck::Zeroable;
use glam::Vec3;
use pathlight_scene::{Light, LightKind};

use crate::geometry::Geometry;
use crate::gpu_types::{
    FLAG_CAPS, GpuInstance, GpuLight, GpuObject, GpuVertex, KIND_CYLINDER, KIND_MESH, KIND_QUAD,
    KIND_SPHERE, LIGHT_AREA, LIGHT_POINT, LIGHT_SUN, NO_LIGHT,
};
use crate::instance::world_triangle;

/// Luminance of linear RGB (Rec. 709 weights): what emitters and environment-map cells are
/// chosen by.
pub fn luminance(rgb: Vec3) -> f32 {
    rgb.dot(Vec3::new(0.2126, 0.7152, 0.0722))
}

/// Surface area of light-table entry `(object, primitive)`: the whole shape, or triangle
/// `primitive` (in `triangles`, corners in `vertices`) of a mesh (placed, for an instance, by its transform in
/// `instances`). The CPU backend's twin of WGSL `emitter_area` calls it, inlined into its
/// row renderer (a call would make it save its vector registers).
#[inline(always)]
pub fn emitter_area(
    object: &GpuObject,
    vertices: &[GpuVertex],
    triangles: &[[u32; 3]],
    instances: &[GpuInstance],
    primitive: u32,
) -> f32 {
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
            let [v0, v1, v2] = world_triangle(object, vertices, triangles, instances, primitive);
            0.5 * (v1 - v0).cross(v2 - v0).length()
        }
    }
}

/// The weight an emitter of `rgb` is chosen by: its luminance, or a thousandth of its
/// largest channel when that is more (so a light of a colour with no luminance is chosen).
fn weight(rgb: Vec3) -> f32 {
    luminance(rgb).max(rgb.max_element() * 1e-3)
}

/// The light table of `objects` (with their materials set) in `geometry` and of `lights`,
/// never empty (a placeholder when nothing emits), and the number of real entries;
/// `emission` is each material's mean emitted radiance. Sets each object's `light` to its
/// first entry, or [`NO_LIGHT`], and appends the lights' parameter blocks to `blocks`.
///
/// Entries are chosen in groups: all emissive surfaces are one group, each point, spot and
/// sun light another; half the choices go by the groups' power, half evenly to each group
/// (a spot light's power is small beside a sun's, yet it is all the light where it points),
/// and an entry within its group by power. An entry's power, divided by pi: an area
/// light's area times its radiance (its luminance); a point light's 4 pi I / pi; a spot
/// light's 2 pi I (1 - (cos_inner + cos_outer) / 2) / pi (its cone's, as pbrt estimates
/// it); a sun's irradiance times the area of the disk the scene's bounding sphere shows it.
pub fn build(
    objects: &mut [GpuObject],
    emission: &[Vec3],
    geometry: &Geometry,
    lights: &[Light],
    blocks: &mut Vec<[f32; 4]>,
) -> (Vec<GpuLight>, u32) {
    let mut table = Vec::new();
    let mut powers = Vec::new();
    for (i, object) in objects.iter_mut().enumerate() {
        object.light = NO_LIGHT;
        let luminance = weight(emission[object.material as usize]);
        if luminance <= 0.0 {
            continue;
        }
        let primitives = if object.kind == KIND_MESH {
            object.first_triangle..object.first_triangle + object.triangle_count
        } else {
            0..1
        };
        object.light = table.len() as u32;
        for primitive in primitives {
            powers.push(
                emitter_area(
                    object,
                    &geometry.vertices,
                    &geometry.triangles,
                    &geometry.instances,
                    primitive,
                ) * luminance,
            );
            table.push(GpuLight {
                kind: LIGHT_AREA,
                index: i as u32,
                primitive,
                cdf: 0.0,
                pmf: 0.0,
            });
        }
    }
    // Groups: every emissive surface together (group 0, when there are any), then each
    // point and sun light alone.
    let surfaces = table.len();
    let scene_radius = geometry.bounding_radius();
    for light in lights.iter().filter(|l| !l.is_dark()) {
        let (kind, power, block) = punctual(light, scene_radius);
        powers.push(power);
        table.push(GpuLight {
            kind,
            index: blocks.len() as u32,
            primitive: 0,
            cdf: 0.0,
            pmf: 0.0,
        });
        blocks.extend(block);
    }
    let group = |entry: usize| {
        if entry < surfaces {
            0
        } else {
            entry - surfaces + usize::from(surfaces > 0)
        }
    };
    let groups = table.len() - surfaces + usize::from(surfaces > 0);
    let mut group_power = vec![0.0f64; groups];
    for (entry, &power) in powers.iter().enumerate() {
        group_power[group(entry)] += f64::from(power);
    }
    let total: f64 = group_power.iter().sum();
    if total <= 0.0 || !total.is_finite() {
        // Only zero-area emitters: nothing can be sampled (or hit).
        table.clear();
        objects.iter_mut().for_each(|o| o.light = NO_LIGHT);
    }
    let share = |g: usize| {
        if groups == 1 {
            1.0
        } else {
            0.5 * group_power[g] / total + 0.5 / groups as f64
        }
    };
    let mut running = 0.0f64;
    for (entry, (light, power)) in table.iter_mut().zip(&powers).enumerate() {
        let g = group(entry);
        let pmf = if group_power[g] > 0.0 {
            share(g) * f64::from(*power) / group_power[g]
        } else {
            0.0
        };
        running += pmf;
        light.pmf = pmf as f32;
        light.cdf = running as f32;
    }
    if let Some(last) = table.last_mut() {
        last.cdf = 1.0;
    }
    let count = table.len() as u32;
    if table.is_empty() {
        table.push(GpuLight::zeroed());
    }
    (table, count)
}

/// A point or sun light's `LIGHT_*`, power (over pi) and parameter block. A point or spot
/// light: `[position, radius]`, `[intensity, the spot's falloff scale]`, `[axis, cos of the
/// outer angle]` (a point light's cone takes in every direction); a sun: `[unit direction
/// towards it, 1 - cos of its disk's half-angle]`, `[irradiance, its disk's radiance over
/// its irradiance]` (both 0 for a true directional light).
fn punctual(light: &Light, scene_radius: f32) -> (u32, f32, Vec<[f32; 4]>) {
    let i = light.intensity;
    match light.kind {
        LightKind::Point {
            position,
            radius,
            cone,
        } => {
            let (axis, cos_inner, cos_outer, power) = match cone {
                None => (Vec3::Z, -2.0, -2.0, 4.0 * weight(i)),
                Some(c) => {
                    let (cos_inner, cos_outer) = (
                        c.inner_deg.to_radians().cos(),
                        c.outer_deg.to_radians().cos(),
                    );
                    let power = 2.0 * weight(i) * (1.0 - 0.5 * (cos_inner + cos_outer));
                    (c.axis, cos_inner, cos_outer, power)
                }
            };
            let block = vec![
                position.extend(radius).to_array(),
                i.extend(spot_scale(cos_inner, cos_outer)).to_array(),
                axis.extend(cos_outer).to_array(),
            ];
            (LIGHT_POINT, power, block)
        }
        LightKind::Sun {
            direction,
            angular_diameter_deg,
        } => {
            let half = 0.5 * angular_diameter_deg.to_radians();
            let sin2 = half.sin() * half.sin();
            let per_irradiance = if sin2 > 0.0 {
                1.0 / (std::f32::consts::PI * sin2)
            } else {
                0.0
            };
            let block = vec![
                // 1 - cos(half), exact for the real sun's 0.27 degrees.
                (-direction)
                    .extend(2.0 * (0.5 * half).sin().powi(2))
                    .to_array(),
                i.extend(per_irradiance).to_array(),
            ];
            (LIGHT_SUN, weight(i) * scene_radius * scene_radius, block)
        }
    }
}

/// The factor of a spot light's linear step from `cos_outer` to `cos_inner`
/// (`1 / (cos_inner - cos_outer)`), or a huge finite one for a hard edge (equal angles),
/// so that the step takes no branch.
fn spot_scale(cos_inner: f32, cos_outer: f32) -> f32 {
    let width = cos_inner - cos_outer;
    if width > 1e-20 { 1.0 / width } else { 1e30 }
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

    #[test]
    fn point_and_sun_lights_are_groups_of_their_own_with_their_blocks() {
        use pathlight_scene::{Cone, Light, LightKind};

        use crate::gpu_types::{GpuLight, LIGHT_POINT, LIGHT_SUN};

        let mut scene = lit(Vec3::splat(2.0));
        let light = |kind| Light {
            name: "l".into(),
            intensity: Vec3::splat(1.0),
            kind,
        };
        scene.lights = vec![
            light(LightKind::Point {
                position: Vec3::new(1.0, 2.0, 3.0),
                radius: 0.5,
                cone: None,
            }),
            light(LightKind::Point {
                position: Vec3::ZERO,
                radius: 0.0,
                cone: Some(Cone {
                    axis: Vec3::NEG_Y,
                    inner_deg: 20.0,
                    outer_deg: 30.0,
                }),
            }),
            light(LightKind::Sun {
                direction: Vec3::NEG_Y,
                angular_diameter_deg: 0.53,
            }),
            // A dark light takes no entry.
            Light {
                intensity: Vec3::ZERO,
                ..light(LightKind::Sun {
                    direction: Vec3::NEG_Y,
                    angular_diameter_deg: 0.0,
                })
            },
        ];
        let geometry = Geometry::build(&scene.objects).unwrap();
        let shading = Shading::build(&scene, &geometry, &Textures::build(&[]));
        assert_eq!(shading.light_count, 4 + 3);
        let table = &shading.lights[..7];
        assert_eq!(table.last().unwrap().cdf, 1.0);
        let total: f32 = table.iter().map(|l| l.pmf).sum();
        assert!((total - 1.0).abs() < 1e-6);
        // Four groups (the surfaces, then each light), half chosen evenly: each at least 1/8.
        let surfaces: f32 = table[..4].iter().map(|l| l.pmf).sum();
        for group in [surfaces, table[4].pmf, table[5].pmf, table[6].pmf] {
            assert!(group >= 0.125 - 1e-6, "{table:?}");
        }
        // Powers over pi: the surfaces 2 x (2 + pi + 0.5 + 2), the point light 4, the spot
        // 2 (1 - (cos 20 + cos 30) / 2), the sun its irradiance x the bounding radius^2.
        let (cos_inner, cos_outer) = (20f32.to_radians().cos(), 30f32.to_radians().cos());
        let powers = [
            2.0 * (4.5 + std::f32::consts::PI),
            4.0,
            2.0 * (1.0 - 0.5 * (cos_inner + cos_outer)),
            geometry.bounding_radius().powi(2),
        ];
        let sum: f32 = powers.iter().sum();
        let want = powers.map(|p| 0.5 * p / sum + 0.125);
        let got = [surfaces, table[4].pmf, table[5].pmf, table[6].pmf];
        for (g, w) in got.iter().zip(want) {
            assert!((g - w).abs() < 1e-5, "{got:?} against {want:?}");
        }
        let blocks = |l: &GpuLight, n: usize| {
            assert!(shading.param_blocks.len() >= l.index as usize + n);
            &shading.param_blocks[l.index as usize..l.index as usize + n]
        };
        assert_eq!(table[4].kind, LIGHT_POINT);
        assert_eq!(
            blocks(&table[4], 3),
            [
                [1.0, 2.0, 3.0, 0.5],
                [1.0, 1.0, 1.0, 1e30],
                [0.0, 0.0, 1.0, -2.0]
            ]
        );
        assert_eq!(table[5].kind, LIGHT_POINT);
        let spot = blocks(&table[5], 3);
        assert!((spot[1][3] * (cos_inner - cos_outer) - 1.0).abs() < 1e-5);
        assert_eq!(spot[2], [0.0, -1.0, 0.0, cos_outer]);
        assert_eq!(table[6].kind, LIGHT_SUN);
        let sun = blocks(&table[6], 2);
        assert_eq!(sun[0][..3], [0.0, 1.0, 0.0]);
        // 1 - cos of the half-angle, to f32 precision although it is 1e-5.
        let half = 0.5 * 0.53f64.to_radians();
        assert!(((f64::from(sun[0][3]) / (1.0 - half.cos())) - 1.0).abs() < 1e-5);
        let radiance = 1.0 / (std::f64::consts::PI * half.sin().powi(2));
        assert!((f64::from(sun[1][3]) / radiance - 1.0).abs() < 1e-5);
    }
}
