//! Random and hand-made scenes for tests of the crates that prepare and trace scenes
//! (feature `test-support`).

use std::sync::Arc;

use glam::{Affine3A, Quat, Vec2, Vec3};
use rand::Rng;
use rand::rngs::StdRng;

use crate::{
    Camera, Environment, Instance, Lobes, Material, Model, Object, RenderSettings, Sampler, Scene,
    Shape, TriangleMesh,
};

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
            aperture_radius: 0.0,
            focus_distance: 1.0,
        },
        settings: RenderSettings {
            spp: 1,
            max_depth: 8,
            rr_depth: 5,
            seed: 0,
            sampler: Sampler::Sobol,
            aovs: false,
        },
        environment: Environment::default(),
        materials: vec![Material::new(
            "grey",
            Vec3::splat(0.5),
            Model::Lobes(Lobes::DIFFUSE),
        )],
        textures: Vec::new(),
        objects,
        lights: Vec::new(),
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

/// `mesh` placed by each of `placements`, as instances sharing one copy of it named
/// `name#k`, in material 0.
pub fn instances_of(name: &str, mesh: TriangleMesh, placements: &[Affine3A]) -> Vec<Object> {
    let mesh = Arc::new(mesh);
    placements
        .iter()
        .enumerate()
        .map(|(k, &to_world)| {
            object(
                &format!("{name}#{k}"),
                Shape::Instance(Instance {
                    mesh: mesh.clone(),
                    to_world,
                }),
            )
        })
        .collect()
}

/// `count` random placements within about 3 of the origin: rotated, scaled unevenly (0.3 to
/// 1.5 per axis), every third one mirrored.
pub fn random_placements(rng: &mut StdRng, count: usize) -> Vec<Affine3A> {
    (0..count)
        .map(|k| {
            let axis = random_point(rng, 1.0).normalize_or(Vec3::Y);
            let rotation = Quat::from_axis_angle(axis, rng.random_range(0.0..6.0));
            let mut scale = Vec3::new(
                rng.random_range(0.3..1.5),
                rng.random_range(0.3..1.5),
                rng.random_range(0.3..1.5),
            );
            if k % 3 == 2 {
                scale.x = -scale.x;
            }
            Affine3A::from_scale_rotation_translation(scale, rotation, random_point(rng, 3.0))
        })
        .collect()
}

/// `objects` with every instance's mesh copied into the world ([`Instance::flattened`]):
/// what the instances look like.
pub fn flattened(objects: &[Object]) -> Vec<Object> {
    objects
        .iter()
        .map(|o| match &o.shape {
            Shape::Instance(instance) => Object {
                shape: Shape::Mesh(instance.flattened()),
                ..o.clone()
            },
            _ => o.clone(),
        })
        .collect()
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

/// A closed torus about the y axis (radii `major` and `minor`), `segments` x `rings`
/// quads of two triangles, every vertex shared by its six triangles.
pub fn torus(major: f32, minor: f32, segments: u32, rings: u32) -> TriangleMesh {
    let mut mesh = TriangleMesh::default();
    for i in 0..segments {
        let (sin_u, cos_u) = (std::f32::consts::TAU * i as f32 / segments as f32).sin_cos();
        for j in 0..rings {
            let (sin_v, cos_v) = (std::f32::consts::TAU * j as f32 / rings as f32).sin_cos();
            let r = major + minor * cos_v;
            mesh.positions
                .push(Vec3::new(r * cos_u, minor * sin_v, r * sin_u));
            mesh.normals
                .push(Vec3::new(cos_v * cos_u, sin_v, cos_v * sin_u));
            mesh.uvs.push(Vec2::ZERO);
        }
    }
    let index = |i: u32, j: u32| (i % segments) * rings + j % rings;
    for i in 0..segments {
        for j in 0..rings {
            let [a, b, c, d] = [
                index(i, j),
                index(i + 1, j),
                index(i, j + 1),
                index(i + 1, j + 1),
            ];
            mesh.indices.push([a, b, d]);
            mesh.indices.push([a, d, c]);
        }
    }
    mesh
}

/// A closed unit icosphere: an icosahedron whose faces are split in four `subdivisions`
/// times, the new vertices pushed onto the sphere, every vertex shared.
pub fn icosphere(subdivisions: u32) -> TriangleMesh {
    let t = (1.0 + 5f32.sqrt()) / 2.0;
    let mut positions: Vec<Vec3> = [
        [-1.0, t, 0.0],
        [1.0, t, 0.0],
        [-1.0, -t, 0.0],
        [1.0, -t, 0.0],
        [0.0, -1.0, t],
        [0.0, 1.0, t],
        [0.0, -1.0, -t],
        [0.0, 1.0, -t],
        [t, 0.0, -1.0],
        [t, 0.0, 1.0],
        [-t, 0.0, -1.0],
        [-t, 0.0, 1.0],
    ]
    .iter()
    .map(|&p| Vec3::from(p).normalize())
    .collect();
    let mut faces: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..subdivisions {
        let mut midpoints = std::collections::HashMap::new();
        let mut midpoint = |a: u32, b: u32, positions: &mut Vec<Vec3>| {
            *midpoints.entry((a.min(b), a.max(b))).or_insert_with(|| {
                let p = (positions[a as usize] + positions[b as usize]).normalize();
                positions.push(p);
                positions.len() as u32 - 1
            })
        };
        faces = faces
            .iter()
            .flat_map(|&[a, b, c]| {
                let ab = midpoint(a, b, &mut positions);
                let bc = midpoint(b, c, &mut positions);
                let ca = midpoint(c, a, &mut positions);
                [[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]
            })
            .collect();
    }
    TriangleMesh {
        normals: positions.clone(),
        uvs: vec![Vec2::ZERO; positions.len()],
        positions,
        indices: faces,
        tangents: Vec::new(),
        colors: Vec::new(),
        flat: false,
    }
}

/// `count` rays aimed at the edges and vertices that `mesh`'s triangles share: each ray
/// `(origin, unit direction, distance to the aimed-at point)` starts 0.5 to 3 away from a
/// point of an edge (every tenth ray: a vertex) that does not touch the boundary of an open
/// mesh. Its direction makes an angle of more than
/// about 6 degrees with the planes of all the triangles around that point, all of which it
/// meets from the same side: the triangles then cover the point's neighbourhood as the ray
/// sees it, so the ray must hit the mesh no farther than the point, and one that does not
/// passed between two triangles. (Where they face both ways the point is on the
/// silhouette, and a ray a rounding error outside it rightly misses.)
pub fn rays_at_shared_edges(
    rng: &mut StdRng,
    mesh: &TriangleMesh,
    count: usize,
) -> Vec<(Vec3, Vec3, f32)> {
    use std::collections::HashMap;
    let key = |p: Vec3| p.to_array().map(f32::to_bits);
    let normals: Vec<Vec3> = mesh
        .indices
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
            (b - a).cross(c - a).normalize_or_zero()
        })
        .collect();
    let mut at_vertex: HashMap<[u32; 3], Vec<usize>> = HashMap::new();
    let mut at_edge: HashMap<[[u32; 3]; 2], Vec<usize>> = HashMap::new();
    for (f, t) in mesh.indices.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (
                key(mesh.positions[t[k] as usize]),
                key(mesh.positions[t[(k + 1) % 3] as usize]),
            );
            at_vertex.entry(a).or_default().push(f);
            at_edge.entry([a.min(b), a.max(b)]).or_default().push(f);
        }
    }
    // An open mesh's boundary (edges of one triangle, and their ends) has nothing beyond it.
    let boundary: std::collections::HashSet<[u32; 3]> = at_edge
        .iter()
        .filter(|(_, faces)| faces.len() < 2)
        .flat_map(|(edge, _)| *edge)
        .collect();
    let mut rays = Vec::with_capacity(count);
    while rays.len() < count {
        let tri = mesh.indices[rng.random_range(0..mesh.indices.len())];
        let k = rng.random_range(0..3);
        let (a, b) = (
            mesh.positions[tri[k] as usize],
            mesh.positions[tri[(k + 1) % 3] as usize],
        );
        let (target, faces) = if rays.len() % 10 == 0 {
            (a, &at_vertex[&key(a)])
        } else {
            let (ka, kb) = (key(a), key(b));
            (a.lerp(b, rng.random()), &at_edge[&[ka.min(kb), ka.max(kb)]])
        };
        let on_boundary =
            faces.len() < 2 || boundary.contains(&key(a)) || boundary.contains(&key(b));
        if on_boundary || faces.iter().any(|&f| normals[f] == Vec3::ZERO) {
            continue;
        }
        for _ in 0..64 {
            let d = random_point(rng, 1.0);
            if !(0.01..1.0).contains(&d.length_squared()) {
                continue;
            }
            let dir = d.normalize();
            let facing = |f: &usize| dir.dot(normals[*f]);
            let same_side =
                faces.iter().all(|f| facing(f) > 0.1) || faces.iter().all(|f| facing(f) < -0.1);
            if same_side {
                let distance = rng.random_range(0.5..3.0);
                let origin = target - dir * distance;
                let to_target = target - origin;
                rays.push((origin, to_target.normalize(), to_target.length()));
                break;
            }
        }
    }
    rays
}

/// The meshes the watertightness tests aim at: a closed torus, a closed icosphere, and the
/// default scene's vase (a surface of revolution, open at its top).
pub fn watertight_meshes() -> Vec<(&'static str, TriangleMesh)> {
    let scene = crate::default_scene::load().expect("the default scene loads");
    let vase = scene
        .objects
        .into_iter()
        .find(|o| o.name == "vase")
        .expect("the default scene has a vase");
    let Shape::Mesh(vase) = vase.shape else {
        panic!("the vase is a mesh")
    };
    vec![
        ("torus", torus(1.0, 0.35, 96, 48)),
        ("icosphere", icosphere(5)),
        ("vase", vase),
    ]
}
