//! The BVH: structure validated after every build, and both traversals (the WGSL twin in
//! `trace` and the CPU's 4-wide `WideBvh`) compared with brute force on random rays, for
//! random, empty and degenerate scenes; and the build independent of the thread count.

use glam::{Vec2, Vec3};
use pathlight_core::gpu::{GpuBvhNode, KIND_MESH, NO_TRIANGLE};
use pathlight_core::packet::{Lanes, PACKET, RayPacket};
use pathlight_core::scene::{Camera, Lobes, Material, RenderSettings, TriangleMesh};
use pathlight_core::trace::{Hit, Ray, intersect_triangle};
use std::cell::RefCell;

use pathlight_core::{GpuScene, Object, Scene, Shape, Tracer, WideBvh};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};

fn scene_of(objects: Vec<Object>) -> Scene {
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
            sampler: 0,
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

fn random_point(rng: &mut StdRng, extent: f32) -> Vec3 {
    Vec3::new(
        rng.random_range(-extent..extent),
        rng.random_range(-extent..extent),
        rng.random_range(-extent..extent),
    )
}

fn random_mesh(rng: &mut StdRng, triangles: usize, center: Vec3) -> TriangleMesh {
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

fn random_objects(rng: &mut StdRng, count: usize) -> Vec<Object> {
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

/// Every node's box holds its children or primitives; every primitive is in exactly one
/// leaf; every shape and every mesh triangle is exactly one primitive, a triangle one with
/// the vertex buffer's corners and its mesh's triangle range.
fn validate(gpu: &GpuScene) {
    fn contains(outer: &GpuBvhNode, min: Vec3, max: Vec3) -> bool {
        Vec3::from(outer.aabb_min).cmple(min + 1e-4).all()
            && Vec3::from(outer.aabb_max).cmpge(max - 1e-4).all()
    }
    fn walk(gpu: &GpuScene, index: u32, leaf: &mut dyn FnMut(&GpuBvhNode, u32)) {
        let node = gpu.nodes[index as usize];
        if node.prim_count == 0 {
            for child in [node.first_index, node.first_index + 1] {
                let c = gpu.nodes[child as usize];
                assert!(
                    contains(&node, c.aabb_min.into(), c.aabb_max.into()),
                    "child {child} escapes node {index}"
                );
                walk(gpu, child, leaf);
            }
        } else {
            for p in node.first_index..node.first_index + node.prim_count {
                leaf(&node, p);
            }
        }
    }
    let mut seen = Vec::new();
    if !gpu.primitives.is_empty() {
        walk(gpu, 0, &mut |node, p| {
            let prim = gpu.primitives[p as usize];
            let owner = gpu.objects[prim.object as usize];
            if prim.triangle == NO_TRIANGLE {
                assert_ne!(owner.kind, KIND_MESH, "primitive {p}: a mesh as a shape");
            } else {
                let tri = prim.triangle;
                assert!(
                    owner.kind == KIND_MESH
                        && (owner.first_triangle..owner.first_triangle + owner.triangle_count)
                            .contains(&tri),
                    "primitive {p}: triangle {tri} outside its mesh's range"
                );
                let [v0, v1, v2] = gpu.triangle(tri);
                assert_eq!(
                    [prim.v0, prim.e1, prim.e2],
                    [v0, v1 - v0, v2 - v0].map(|v| v.to_array()),
                    "primitive {p}: not triangle {tri}'s corner and edges"
                );
                for v in [v0, v1, v2] {
                    assert!(contains(node, v, v), "triangle {tri} escapes its leaf");
                }
            }
            seen.push(p);
        });
    }
    seen.sort_unstable();
    assert_eq!(seen, (0..gpu.primitives.len() as u32).collect::<Vec<_>>());
    let mut shapes: Vec<u32> = gpu
        .primitives
        .iter()
        .filter(|p| p.triangle == NO_TRIANGLE)
        .map(|p| p.object)
        .collect();
    shapes.sort_unstable();
    let expected: Vec<u32> = (0..gpu.object_count)
        .filter(|&i| gpu.objects[i as usize].kind != KIND_MESH)
        .collect();
    assert_eq!(shapes, expected, "every shape is one primitive");
    let mut triangles: Vec<u32> = gpu
        .primitives
        .iter()
        .filter(|p| p.triangle != NO_TRIANGLE)
        .map(|p| p.triangle)
        .collect();
    triangles.sort_unstable();
    let triangle_count = gpu.objects[..gpu.object_count as usize]
        .iter()
        .filter(|o| o.kind == KIND_MESH)
        .map(|o| o.triangle_count)
        .sum::<u32>();
    assert_eq!(
        triangles,
        (0..triangle_count).collect::<Vec<_>>(),
        "every triangle is one primitive"
    );
}

/// The nearest hit over every object and every triangle, without the BVH.
fn brute_force(gpu: &GpuScene, ray: &Ray, t_max: f32) -> Option<Hit> {
    let mut hit = Hit::none(t_max);
    for (i, o) in gpu
        .objects
        .iter()
        .enumerate()
        .take(gpu.object_count as usize)
    {
        if o.kind == KIND_MESH {
            continue;
        }
        gpu.intersect_shape(i as u32, ray, &mut hit);
    }
    for tri in 0..(gpu.vertices.len() / 3) as u32 {
        let [v0, v1, v2] = gpu.triangle(tri);
        let (t, b1, b2) = intersect_triangle(v0, v1, v2, ray, hit.t);
        if t < hit.t {
            let object = owner_of(gpu, tri);
            hit = Hit {
                t,
                object,
                primitive: tri,
                b1,
                b2,
            };
        }
    }
    (hit.object != u32::MAX).then_some(hit)
}

/// The mesh object whose triangle range holds triangle `tri`.
fn owner_of(gpu: &GpuScene, tri: u32) -> u32 {
    let owners: Vec<u32> = (0..gpu.object_count)
        .filter(|&i| {
            let o = &gpu.objects[i as usize];
            o.kind == KIND_MESH
                && (o.first_triangle..o.first_triangle + o.triangle_count).contains(&tri)
        })
        .collect();
    assert_eq!(
        owners.len(),
        1,
        "triangle {tri} belongs to exactly one mesh"
    );
    owners[0]
}

/// A ray from anywhere in a 10-unit cube towards a point within `target` of the origin.
fn random_ray(rng: &mut StdRng, target: f32) -> Ray {
    let origin = random_point(rng, 5.0);
    Ray {
        origin,
        dir: (random_point(rng, target) - origin).normalize_or(Vec3::X),
    }
}

/// A traversal's name, nearest-hit query and shadow query.
type Traversal<'a> = (
    &'a str,
    &'a dyn Fn(&Ray, f32) -> Option<Hit>,
    &'a dyn Fn(&Ray, f32) -> bool,
);

/// Checks the traversals (the twin, the wide BVH alone and in packets) against brute force on `rays`; returns how many rays hit.
fn assert_same(gpu: &GpuScene, rays: &[Ray]) -> usize {
    let wide = WideBvh::build(gpu);
    let tracer = RefCell::new(Tracer::new(gpu, &wide));
    // The ray in a packet with others of `rays`, at a lane that depends on the ray.
    let packet_of = |ray: &Ray, t_max: f32| {
        let start = ray.origin.x.to_bits() as usize % rays.len();
        let lane = start % PACKET;
        // Every other packet holds this ray alone (it walks alone from the root), the others
        // most lanes; a bit beyond the packet's lanes is set too and must be ignored.
        let beyond = Lanes::from(1u8).checked_shl(PACKET as u32).unwrap_or(0);
        let others = if start.is_multiple_of(2) {
            !0x0040_4040
        } else {
            0
        };
        let mut packet = RayPacket {
            t_max: [t_max; PACKET],
            active: others | beyond | (1 << lane),
            ..RayPacket::default()
        };
        for (l, r) in packet.rays.iter_mut().enumerate() {
            *r = if l == lane {
                *ray
            } else {
                rays[(start + l) % rays.len()]
            };
        }
        (packet, lane)
    };
    let traversals: [Traversal; 3] = [
        ("twin", &|r, t| gpu.intersect(r, t), &|r, t| {
            gpu.occluded(r, t)
        }),
        (
            "wide",
            &|r, t| tracer.borrow_mut().intersect(r, t),
            &|r, t| tracer.borrow_mut().occluded(r, t),
        ),
        (
            "packet",
            &|r, t| {
                let (packet, lane) = packet_of(r, t);
                tracer.borrow_mut().intersect_packet(&packet).hit(lane)
            },
            &|r, t| {
                let (packet, lane) = packet_of(r, t);
                tracer.borrow_mut().occluded_packet(&packet) >> lane & 1 != 0
            },
        ),
    ];
    let mut hits = 0;
    for ray in rays {
        let slow = brute_force(gpu, ray, 1e30);
        hits += usize::from(slow.is_some());
        for (name, intersect, occluded) in &traversals {
            let fast = intersect(ray, 1e30);
            // The shadow-ray query: blocked exactly when the nearest hit lies before t_max.
            for t_max in [0.5, 2.0, 1e30] {
                let blocked = slow.is_some_and(|h| h.t < t_max);
                assert_eq!(
                    occluded(ray, t_max),
                    blocked,
                    "{name}: ray {ray:?}, t_max {t_max}"
                );
            }
            match (fast, slow) {
                (None, None) => {}
                (Some(a), Some(b)) => {
                    assert!(
                        (a.t - b.t).abs() <= 1e-5 * b.t.max(1.0),
                        "{name}: ray {ray:?}: bvh t {} vs brute force {}",
                        a.t,
                        b.t
                    );
                    if (a.t - b.t).abs() > 1e-7 * b.t {
                        continue; // equal distances on two primitives: either answer is right
                    }
                    assert_eq!(a.object, b.object, "{name}: ray {ray:?}");
                }
                (a, b) => panic!("{name}: ray {ray:?}: bvh {a:?} vs brute force {b:?}"),
            }
        }
    }
    hits
}

/// A ray towards a random point of the root's box.
fn ray_into_root_box(rng: &mut StdRng, gpu: &GpuScene) -> Ray {
    let root = gpu.nodes[0];
    let (min, max) = (Vec3::from(root.aabb_min), Vec3::from(root.aabb_max));
    let target = min + (max - min) * Vec3::new(rng.random(), rng.random(), rng.random());
    let origin = random_point(rng, 5.0);
    Ray {
        origin,
        dir: (target - origin).normalize_or(Vec3::X),
    }
}

#[test]
fn traversal_matches_brute_force_on_random_scenes() {
    let mut rng = StdRng::seed_from_u64(7);
    for count in [1, 2, 5, 40] {
        let gpu = GpuScene::build(&scene_of(random_objects(&mut rng, count)));
        validate(&gpu);
        let rays: Vec<Ray> = (0..2000)
            .map(|_| ray_into_root_box(&mut rng, &gpu))
            .collect();
        let hits = assert_same(&gpu, &rays);
        assert!(
            hits > 20,
            "{count} objects: only {hits} of 2000 rays hit; the test would prove little"
        );
    }
}

#[test]
fn empty_scene_has_no_hits() {
    let gpu = GpuScene::build(&scene_of(Vec::new()));
    assert_eq!(gpu.object_count, 0);
    let mut rng = StdRng::seed_from_u64(1);
    let wide = WideBvh::build(&gpu);
    let mut tracer = Tracer::new(&gpu, &wide);
    for _ in 0..100 {
        let ray = random_ray(&mut rng, 3.0);
        assert_eq!(gpu.intersect(&ray, 1e30), None);
        assert_eq!(tracer.intersect(&ray, 1e30), None);
        assert!(!tracer.occluded(&ray, 1e30));
    }
}

#[test]
fn degenerate_triangles_and_axis_rays() {
    let mut mesh = TriangleMesh::default();
    let pts = [
        // Zero area (collinear), a repeated point, and one proper triangle.
        [Vec3::ZERO, Vec3::X, Vec3::X * 2.0],
        [Vec3::Y, Vec3::Y, Vec3::Z],
        [
            Vec3::new(-1.0, -1.0, 0.0),
            Vec3::new(1.0, -1.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        ],
    ];
    for (t, tri) in pts.iter().enumerate() {
        mesh.positions.extend(tri);
        mesh.normals.extend([Vec3::Z; 3]);
        mesh.uvs.extend([Vec2::ZERO; 3]);
        let i = 3 * t as u32;
        mesh.indices.push([i, i + 1, i + 2]);
    }
    let objects = vec![
        Object {
            name: "mesh".into(),
            material: 0,
            shape: Shape::Mesh(mesh),
        },
        Object {
            name: "flat quad".into(),
            material: 0,
            shape: Shape::Quad {
                origin: Vec3::new(-1.0, -1.0, -2.0),
                edge_u: Vec3::X * 2.0,
                edge_v: Vec3::Y * 2.0,
            },
        },
    ];
    let gpu = GpuScene::build(&scene_of(objects));
    validate(&gpu);
    // Rays along the axes (zero direction components) through the flat boxes.
    let mut rays = vec![
        Ray {
            origin: Vec3::new(0.0, 0.0, 5.0),
            dir: -Vec3::Z,
        },
        Ray {
            origin: Vec3::new(0.5, -0.5, 5.0),
            dir: -Vec3::Z,
        },
        Ray {
            origin: Vec3::new(5.0, 0.0, 0.0),
            dir: -Vec3::X,
        },
        Ray {
            origin: Vec3::new(0.0, 5.0, -2.0),
            dir: -Vec3::Y,
        },
    ];
    let mut rng = StdRng::seed_from_u64(3);
    rays.extend((0..500).map(|_| random_ray(&mut rng, 1.0)));
    assert!(assert_same(&gpu, &rays) >= 2);
    let hit = gpu
        .intersect(&rays[0], 1e30)
        .expect("the proper triangle is hit");
    assert!((hit.t - 5.0).abs() < 1e-5);
    assert_eq!(
        gpu.intersect(&rays[0], 4.0),
        None,
        "t_max must bound the search"
    );
}

#[test]
fn large_mesh_bvh_is_valid_and_exact() {
    let mut rng = StdRng::seed_from_u64(11);
    let objects = vec![Object {
        name: "big".into(),
        material: 0,
        shape: Shape::Mesh(random_mesh(&mut rng, 20_000, Vec3::ZERO)),
    }];
    let gpu = GpuScene::build(&scene_of(objects));
    validate(&gpu);
    let rays: Vec<Ray> = (0..300).map(|_| random_ray(&mut rng, 1.0)).collect();
    assert!(assert_same(&gpu, &rays) > 50);
}

#[test]
fn coincident_triangles_build_and_trace() {
    // 5,000 copies of one triangle: no centroid splits them, whatever depth the build makes.
    let mut mesh = TriangleMesh::default();
    for t in 0..5000u32 {
        mesh.positions
            .extend([Vec3::new(-1.0, -1.0, 0.0), Vec3::X, Vec3::Y]);
        mesh.normals.extend([Vec3::Z; 3]);
        mesh.uvs.extend([Vec2::ZERO; 3]);
        mesh.indices.push([3 * t, 3 * t + 1, 3 * t + 2]);
    }
    let objects = vec![Object {
        name: "stack".into(),
        material: 0,
        shape: Shape::Mesh(mesh),
    }];
    let gpu = GpuScene::build(&scene_of(objects));
    validate(&gpu);
    let mut rng = StdRng::seed_from_u64(5);
    let rays: Vec<Ray> = (0..200).map(|_| random_ray(&mut rng, 0.5)).collect();
    assert!(assert_same(&gpu, &rays) > 20);
}

#[test]
fn the_build_does_not_depend_on_the_thread_count() {
    // obvhs' build and the buffer fill run on rayon: one thread and four give the same tree
    // and buffers, so a seeded render is the same image on any machine.
    let mut rng = StdRng::seed_from_u64(13);
    let mut objects = random_objects(&mut rng, 40);
    objects.push(Object {
        name: "big".into(),
        material: 0,
        shape: Shape::Mesh(random_mesh(&mut rng, 30_000, Vec3::ZERO)),
    });
    let scene = scene_of(objects);
    let build_on = |threads| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("a thread pool")
            .install(|| GpuScene::build(&scene))
    };
    let (one, four) = (build_on(1), build_on(4));
    validate(&four);
    assert!(same_bytes(&one.nodes, &four.nodes), "nodes differ");
    assert!(
        same_bytes(&one.primitives, &four.primitives),
        "primitives differ"
    );
    assert!(same_bytes(&one.vertices, &four.vertices), "vertices differ");
    assert!(same_bytes(&one.objects, &four.objects), "objects differ");
}

/// Whether two buffers hold the same bytes.
fn same_bytes<T: bytemuck::Pod>(a: &[T], b: &[T]) -> bool {
    bytemuck::cast_slice::<T, u8>(a) == bytemuck::cast_slice::<T, u8>(b)
}
