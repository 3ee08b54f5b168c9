//! Random and hand-made scenes for tests of the crates that prepare and trace scenes
//! (feature `test-support`).

use glam::{Vec2, Vec3};
use rand::Rng;
use rand::rngs::StdRng;

use crate::{Camera, Lobes, Material, Object, RenderSettings, Sampler, Scene, Shape, TriangleMesh};

/// A scene of `objects` in one grey diffuse material (index 0), seen from +z by an 8x8
/// camera, with default settings.
pub fn scene_of(objects: Vec<Object>) -> Scene {
    Scene {
        camera: Camera {
            position: Vec3::Z,
            look_at: Vec3::ZERO,
            up: Vec3::Y,
            fov_y_deg: 40.0,
            width: 8,
            height: 8,
        },
        settings: RenderSettings {
            spp: 1,
            max_depth: 8,
            rr_depth: 5,
            seed: 0,
            sampler: Sampler::Sobol,
        },
        environment: Vec3::ZERO,
        materials: vec![Material {
            name: "grey".into(),
            base_color: Vec3::splat(0.5),
            texture: None,
            emission: Vec3::ZERO,
            lobes: Lobes::DIFFUSE,
            conductor: None,
        }],
        textures: Vec::new(),
        objects,
    }
}

/// A uniformly random point of the cube of half-side `extent` about the origin.
pub fn random_point(rng: &mut StdRng, extent: f32) -> Vec3 {
    Vec3::new(
        rng.random_range(-extent..extent),
        rng.random_range(-extent..extent),
        rng.random_range(-extent..extent),
    )
}

/// `triangles` small random triangles (unconnected) within about 1.2 of `center`.
pub fn random_mesh(rng: &mut StdRng, triangles: usize, center: Vec3) -> TriangleMesh {
    let mut mesh = TriangleMesh::default();
    for t in 0..triangles {
        let p = center + random_point(rng, 1.0);
        for _ in 0..3 {
            mesh.positions.push(p + random_point(rng, 0.2));
            mesh.normals.push(Vec3::Y);
            mesh.uvs.push(Vec2::ZERO);
        }
        let i = 3 * t as u32;
        mesh.indices.push([i, i + 1, i + 2]);
    }
    mesh
}

/// `count` random objects within about 4 of the origin, in material 0: quads, spheres,
/// cylinders (capped or not) and meshes of up to 300 triangles in turn.
pub fn random_objects(rng: &mut StdRng, count: usize) -> Vec<Object> {
    (0..count)
        .map(|i| {
            let c = random_point(rng, 3.0);
            let shape = match i % 4 {
                0 => Shape::Quad {
                    origin: c,
                    edge_u: random_point(rng, 1.0),
                    edge_v: random_point(rng, 1.0),
                },
                1 => Shape::Sphere {
                    center: c,
                    radius: rng.random_range(0.05..0.6),
                    texture_rotation: 0.0,
                },
                2 => Shape::Cylinder {
                    p0: c,
                    p1: c + random_point(rng, 1.0),
                    radius: rng.random_range(0.05..0.4),
                    caps: rng.random_bool(0.5),
                },
                _ => {
                    let triangles = rng.random_range(1..300);
                    Shape::Mesh(random_mesh(rng, triangles, c))
                }
            };
            Object {
                name: format!("o{i}"),
                material: 0,
                shape,
            }
        })
        .collect()
}

/// A mesh of the given triangles (corner positions), each with its own three vertices and
/// the normal +z.
pub fn mesh_of(triangles: &[[Vec3; 3]]) -> TriangleMesh {
    let mut mesh = TriangleMesh::default();
    for (t, corners) in triangles.iter().enumerate() {
        mesh.positions.extend(corners);
        mesh.normals.extend([Vec3::Z; 3]);
        mesh.uvs.extend([Vec2::ZERO; 3]);
        let i = 3 * t as u32;
        mesh.indices.push([i, i + 1, i + 2]);
    }
    mesh
}

/// An object named `name` in material 0.
pub fn object(name: &str, shape: Shape) -> Object {
    Object {
        name: name.into(),
        material: 0,
        shape,
    }
}

/// A mesh of degenerate triangles (zero area: collinear corners, a repeated corner) and one
/// proper triangle in the plane z = 0 (corners (-1, -1), (1, -1), (0, 1)), and a flat quad
/// covering [-1, 1]^2 at z = -2: boxes of no thickness, hit by rays along the axes.
pub fn degenerate_objects() -> Vec<Object> {
    let mesh = mesh_of(&[
        [Vec3::ZERO, Vec3::X, Vec3::X * 2.0],
        [Vec3::Y, Vec3::Y, Vec3::Z],
        [
            Vec3::new(-1.0, -1.0, 0.0),
            Vec3::new(1.0, -1.0, 0.0),
            Vec3::Y,
        ],
    ]);
    let flat = Shape::Quad {
        origin: Vec3::new(-1.0, -1.0, -2.0),
        edge_u: Vec3::X * 2.0,
        edge_v: Vec3::Y * 2.0,
    };
    vec![object("mesh", Shape::Mesh(mesh)), object("flat quad", flat)]
}

/// `copies` copies of one triangle (corners (-1, -1, 0), (1, 0, 0), (0, 1, 0)): no centroid
/// split separates them, whatever depth a build makes.
pub fn coincident_triangles(copies: usize) -> Vec<Object> {
    let triangle = [Vec3::new(-1.0, -1.0, 0.0), Vec3::X, Vec3::Y];
    vec![object(
        "stack",
        Shape::Mesh(mesh_of(&vec![triangle; copies])),
    )]
}
