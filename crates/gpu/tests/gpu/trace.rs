//! The WGSL traversal (`intersect.wgsl`, `bvh.wgsl`) against its CPU twin on random rays
//! through the default scene (quads, spheres, capped cylinders and a 6k-triangle mesh). The
//! twin itself is checked against brute force in `crates/cpu/src/bvh.rs`.

use crate::common::context;
use glam::{Vec2, Vec3, Vec3A};
use pathlight_core::PreparedScene;
use pathlight_core::gpu_types::{FLAG_INSTANCE, KIND_MESH, NO_TRIANGLE, SHAPE_LEAF};
use pathlight_cpu::bvh::Hit;
use pathlight_cpu::intersect::{MISS, Ray, ShearedRay, intersect_triangle};
use pathlight_cpu::{CpuScene, Tracer};
use pathlight_gpu::Accel;
use pathlight_gpu::gpu_renderer::MAX_STACK;
use pathlight_gpu::pipeline::{create_compute_pipeline, storage_entry};
use pathlight_gpu::scene_buffers::SceneBuffers;
use pathlight_gpu::wgsl;
use pathlight_scene::testing::{
    icosphere, instances_of, object, random_mesh, random_placements, rays_at_shared_edges,
    scene_of, watertight_meshes,
};
use pathlight_scene::{Object, Shape, TriangleMesh, default_scene};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use wgpu::util::DeviceExt;

/// A test-only pass: one ray per invocation, nearest hit written back.
const KERNEL: &str = r#"
#import bvh

struct TraceRay { origin: vec3f, t_max: f32, dir: vec3f, pad: f32 }
struct TraceHit { t: f32, object: u32, primitive: u32, blocked: u32 }
@group(1) @binding(0) var<storage, read> rays: array<TraceRay>;
@group(1) @binding(1) var<storage, read_write> hits: array<TraceHit>;

@compute @workgroup_size(64)
fn trace(@builtin(global_invocation_id) gid: vec3u) {
    let i = gid.x;
    if i >= arrayLength(&rays) {
        return;
    }
    let r = rays[i];
    let hit = trace_scene(Ray(r.origin, r.dir), r.t_max, OBJECT_COUNT, false);
    let blocked = trace_scene(Ray(r.origin, r.dir), r.t_max, OBJECT_COUNT, true).object != NO_HIT;
    hits[i] = TraceHit(hit.t, hit.object, hit.primitive, select(0u, 1u, blocked));
}
"#;

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct TraceRay {
    origin: [f32; 3],
    t_max: f32,
    dir: [f32; 3],
    pad: f32,
}

#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct TraceHit {
    t: f32,
    object: u32,
    primitive: u32,
    /// The shadow-ray query's answer (1: something lies before t_max).
    blocked: u32,
}

/// The traversal stack the integrator compiles for `prepared`.
fn integrator_stack(prepared: &PreparedScene) -> u32 {
    prepared
        .geometry
        .stack_bound
        .next_multiple_of(8)
        .min(MAX_STACK)
}

/// `rays` traced on the GPU with the scheme `accel` and a traversal stack of `stack` entries.
fn trace_on_gpu(
    prepared: &PreparedScene,
    rays: &[TraceRay],
    accel: Accel,
    stack: u32,
) -> Vec<TraceHit> {
    let ctx = context();
    let device = &ctx.device;
    let scene = SceneBuffers::upload(device, prepared).unwrap();
    let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("trace test"),
        entries: &[storage_entry(0, true), storage_entry(1, false)],
    });
    let source = wgsl::assemble_source(
        &format!(
            "const OBJECT_COUNT: u32 = {}u;\n{KERNEL}",
            prepared.shading.object_count
        ),
        &[("STACK_SIZE", stack)],
    )
    .unwrap();
    let pipeline = create_compute_pipeline(
        device,
        "trace test",
        &source,
        "trace",
        &[&scene.layout, &layout],
        &accel.pipeline_constants(),
    )
    .unwrap();
    // In chunks of 2^20 rays (32 MiB), within every adapter's binding limit.
    let mut hits = Vec::with_capacity(rays.len());
    for chunk in rays.chunks(1 << 20) {
        hits.extend(trace_chunk(
            device, &ctx.queue, &pipeline, &scene, &layout, chunk,
        ));
    }
    hits
}

/// One dispatch of `trace_on_gpu`.
fn trace_chunk(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    pipeline: &wgpu::ComputePipeline,
    scene: &SceneBuffers,
    layout: &wgpu::BindGroupLayout,
    rays: &[TraceRay],
) -> Vec<TraceHit> {
    let ray_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("rays"),
        contents: bytemuck::cast_slice(rays),
        usage: wgpu::BufferUsages::STORAGE,
    });
    let size = (rays.len() * size_of::<TraceHit>()) as u64;
    let hit_buffer = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("hits"),
        size,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    let readback = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("hits readback"),
        size,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("trace test"),
        layout,
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: ray_buffer.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: hit_buffer.as_entire_binding(),
            },
        ],
    });
    let mut encoder = device.create_command_encoder(&Default::default());
    {
        let mut pass = encoder.begin_compute_pass(&Default::default());
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, &scene.bind_group, &[]);
        pass.set_bind_group(1, &bind_group, &[]);
        pass.dispatch_workgroups((rays.len() as u32).div_ceil(64), 1, 1);
    }
    encoder.copy_buffer_to_buffer(&hit_buffer, 0, &readback, 0, size);
    queue.submit([encoder.finish()]);
    readback
        .slice(..)
        .map_async(wgpu::MapMode::Read, |r| r.unwrap());
    device.poll(wgpu::PollType::wait_indefinitely()).unwrap();
    let view = readback.slice(..).get_mapped_range().unwrap();
    bytemuck::cast_slice(&view).to_vec()
}

/// No ray passes between the triangles of a closed mesh in the WGSL walk either: the rays
/// of `crates/cpu/tests/watertight.rs` (aimed at shared edges and vertices of a torus, an
/// icosphere and the vase, 10^7 in all) hit no farther than the point aimed at.
#[test]
fn no_ray_passes_between_the_triangles_of_a_closed_mesh() {
    let mut total = 0;
    for (seed, (name, mesh)) in watertight_meshes().into_iter().enumerate() {
        let prepared =
            PreparedScene::new(&scene_of(vec![object(name, Shape::Mesh(mesh.clone()))])).unwrap();
        let mut rng = StdRng::seed_from_u64(100 + seed as u64);
        let aimed = rays_at_shared_edges(&mut rng, &mesh, 3_400_000);
        let rays: Vec<TraceRay> = aimed
            .iter()
            .map(|(origin, dir, _)| TraceRay {
                origin: origin.to_array(),
                t_max: 1e30,
                dir: dir.to_array(),
                pad: 0.0,
            })
            .collect();
        let hits = trace_on_gpu(&prepared, &rays, Accel::Bvh, integrator_stack(&prepared));
        let leaks = aimed
            .iter()
            .zip(&hits)
            .filter(|((_, _, distance), hit)| {
                !(hit.object != u32::MAX && hit.t <= distance * (1.0 + 1e-4) + 1e-5)
            })
            .count();
        assert_eq!(
            leaks,
            0,
            "{name}: {leaks} of {} rays passed through the surface",
            rays.len()
        );
        total += rays.len();
    }
    assert!(total >= 10_000_000);
}

/// Rays from inside the room and in front of it, directions uniform on the sphere, every
/// tenth with a short t_max.
fn room_rays(seed: u64, count: usize) -> Vec<TraceRay> {
    let mut rng = StdRng::seed_from_u64(seed);
    (0..count)
        .map(|i| {
            let origin = Vec3::new(
                rng.random_range(-1.9..1.9),
                rng.random_range(0.01..2.3),
                rng.random_range(-2.9..2.0),
            );
            let dir = loop {
                let d = Vec3::new(
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                );
                if (0.01..1.0).contains(&d.length_squared()) {
                    break d.normalize();
                }
            };
            let t_max = if i % 10 == 0 { 0.5 } else { 1e30 };
            TraceRay {
                origin: origin.to_array(),
                t_max,
                dir: dir.to_array(),
                pad: 0.0,
            }
        })
        .collect()
}

/// Every acceleration scheme finds what the CPU twin finds; so does the BVH walk with a
/// one-entry stack, which mostly walks without it (`trace_stackless`).
#[test]
fn wgsl_traversal_matches_cpu_twin() {
    let prepared = PreparedScene::new(&default_scene::load().unwrap()).unwrap();
    check_every_scheme(&prepared, &room_rays(5, 20_000));
}

/// `rays` traced on the GPU with every scheme, and with the BVH walk on a one-entry stack,
/// find what the CPU twin finds.
fn check_every_scheme(prepared: &PreparedScene, rays: &[TraceRay]) {
    for accel in Accel::ALL {
        check_hits(
            prepared,
            rays,
            &trace_on_gpu(prepared, rays, accel, integrator_stack(prepared)),
            accel,
        );
    }
    check_hits(
        prepared,
        rays,
        &trace_on_gpu(prepared, rays, Accel::Bvh, 1),
        Accel::Bvh,
    );
}

/// Leaves that hold shapes and triangles together (tested at once on the GPU, like leaves of
/// shapes alone) find what the CPU twin finds: the default scene with small spheres strewn
/// among the triangles of a cloud of small ones.
#[test]
fn wgsl_traversal_matches_cpu_twin_in_mixed_leaves() {
    let mut scene = default_scene::load().unwrap();
    let mut rng = StdRng::seed_from_u64(9);
    let point = |rng: &mut StdRng| {
        Vec3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(0.3..1.5),
            rng.random_range(-1.0..0.5),
        )
    };
    let mut cloud = TriangleMesh::default();
    for t in 0..400u32 {
        let p = point(&mut rng);
        for _ in 0..3 {
            let corner = p + 0.05 * (point(&mut rng) - Vec3::new(0.0, 0.9, -0.25));
            cloud.positions.push(corner);
            cloud.normals.push(Vec3::Y);
            cloud.uvs.push(Vec2::ZERO);
        }
        cloud.indices.push([3 * t, 3 * t + 1, 3 * t + 2]);
    }
    let material = scene.objects[0].material;
    for i in 0..100 {
        scene.objects.push(Object {
            name: format!("bead {i}"),
            material,
            shape: Shape::Sphere {
                center: point(&mut rng),
                radius: 0.02,
                texture_rotation: 0.0,
            },
        });
    }
    scene.objects.push(Object {
        name: "cloud".into(),
        material,
        shape: Shape::Mesh(cloud),
    });
    let prepared = PreparedScene::new(&scene).unwrap();
    let g = &prepared.geometry;
    let mixed = g
        .nodes
        .iter()
        .flat_map(|n| (0..4).map(|lane| (n.first[lane], n.count[lane])))
        .filter(|&(first, count)| {
            let count = count & !SHAPE_LEAF;
            count != 0
                && g.primitives[first as usize..(first + count) as usize]
                    .iter()
                    .any(|p| p.triangle != NO_TRIANGLE)
                && g.primitives[first as usize..(first + count) as usize]
                    .iter()
                    .any(|p| p.triangle == NO_TRIANGLE)
        })
        .count();
    assert!(
        mixed >= 5,
        "only {mixed} leaves hold both kinds; the test would prove little"
    );
    let rays = room_rays(6, 20_000);
    for stack in [integrator_stack(&prepared), 1] {
        check_hits(
            &prepared,
            &rays,
            &trace_on_gpu(&prepared, &rays, Accel::Bvh, stack),
            Accel::Bvh,
        );
    }
}

/// Instances (a mesh of 300 random triangles placed 40 times and an icosphere 15 times,
/// rotated, scaled unevenly, a third mirrored) among the default scene's shapes: every scheme
/// finds what the CPU twin finds, and so does the walk with a one-entry stack (whose mesh
/// walks go without a stack too, `trace_mesh_stackless`).
#[test]
fn wgsl_traversal_matches_cpu_twin_through_instances() {
    let mut scene = default_scene::load().unwrap();
    let mut rng = StdRng::seed_from_u64(12);
    let mut in_room = |count: usize, size: f32| {
        random_placements(&mut rng, count)
            .into_iter()
            .map(|mut p| {
                p.matrix3 *= size;
                p.translation = Vec3A::new(
                    p.translation.x * 0.5,
                    0.8 + p.translation.y * 0.25,
                    -0.5 + p.translation.z * 0.4,
                );
                p
            })
            .collect::<Vec<_>>()
    };
    let (rocks, balls) = (in_room(40, 0.25), in_room(15, 0.15));
    let mesh = random_mesh(&mut StdRng::seed_from_u64(13), 300, Vec3::ZERO);
    let material = scene.objects[0].material;
    for o in instances_of("rock", mesh, &rocks)
        .into_iter()
        .chain(instances_of("ball", icosphere(2), &balls))
    {
        scene.objects.push(Object { material, ..o });
    }
    let prepared = PreparedScene::new(&scene).unwrap();
    check_every_scheme(&prepared, &room_rays(7, 20_000));
}

/// A scene whose only object is a mesh without triangles has no primitive: nothing is hit,
/// on the GPU (whose tree is then one node no ray enters) and on the CPU.
#[test]
fn a_scene_without_primitives_hits_nothing() {
    let mut scene = default_scene::load().unwrap();
    let material = scene.objects[0].material;
    scene.objects = vec![Object {
        name: "empty".into(),
        material,
        shape: Shape::Mesh(TriangleMesh::default()),
    }];
    let prepared = PreparedScene::new(&scene).unwrap();
    assert!(prepared.geometry.primitives.is_empty());
    // The GPU's placeholder: four unused children (inverted boxes), so that no ray enters
    // it and loops (an empty box at the origin would be entered by rays through the origin).
    let nodes = &prepared.geometry.nodes;
    assert_eq!(nodes.len(), 1);
    let n = nodes[0];
    for lane in 0..4 {
        assert!(
            n.lo_x[lane] > n.hi_x[lane]
                && n.lo_y[lane] > n.hi_y[lane]
                && n.lo_z[lane] > n.hi_z[lane],
            "placeholder child {lane} can be entered"
        );
    }
    let rays = room_rays(7, 256);
    for accel in Accel::ALL {
        let hits = trace_on_gpu(&prepared, &rays, accel, integrator_stack(&prepared));
        assert!(
            hits.iter().all(|h| h.object == u32::MAX && h.blocked == 0),
            "{accel:?}: a hit in an empty scene"
        );
    }
    let view = CpuScene::new(&prepared);
    let mut tracer = Tracer::new(&view);
    for ray in &rays {
        assert_eq!(tracer.intersect(&ray_of(ray), ray.t_max), None);
    }
}

fn check_hits(prepared: &PreparedScene, rays: &[TraceRay], hits: &[TraceHit], accel: Accel) {
    let view = CpuScene::new(prepared);
    let mut tracer = Tracer::new(&view);
    let (mut hit_count, mut mesh_hits, mut ties) = (0, 0, 0);
    for (ray, gpu) in rays.iter().zip(hits) {
        let cpu = tracer.intersect(&ray_of(ray), ray.t_max);
        assert_eq!(
            gpu.blocked == 1,
            cpu.is_some(),
            "{accel:?}: any-hit query disagrees with the nearest hit {cpu:?}"
        );
        match cpu {
            None => assert_eq!(
                gpu.object,
                u32::MAX,
                "{accel:?}: GPU hit {gpu:?} where the CPU twin misses"
            ),
            Some(cpu) => {
                hit_count += 1;
                assert!(
                    (gpu.t - cpu.t).abs() <= 1e-4 * cpu.t.max(1.0),
                    "{accel:?}: t: GPU {gpu:?}, CPU {cpu:?}"
                );
                if (gpu.object, gpu.primitive) != (cpu.object, cpu.primitive) {
                    // A tie: a ray through a shared edge, or onto two coincident surfaces
                    // (the vase's base on the floor), may report either primitive, but the
                    // GPU's must lie at the same distance.
                    let t = distance_to(&view, &ray_of(ray), gpu.object, gpu.primitive);
                    assert!(
                        (t - cpu.t).abs() <= 1e-5 * cpu.t.max(1.0),
                        "{accel:?}: GPU {gpu:?} (at {t}) where the CPU twin hits {cpu:?}"
                    );
                    ties += 1;
                }
                mesh_hits += usize::from(view.objects[gpu.object as usize].kind == KIND_MESH);
            }
        }
    }
    assert!(
        hit_count > 10_000 && mesh_hits > 200,
        "{accel:?}: {hit_count} hits, {mesh_hits} on the vase"
    );
    assert!(
        ties <= hit_count / 500,
        "{accel:?}: {ties} of {hit_count} hits are ties; too many to be chance"
    );
}

fn ray_of(ray: &TraceRay) -> Ray {
    Ray::new(Vec3::from(ray.origin), Vec3::from(ray.dir))
}

/// Where `ray` meets primitive `primitive` of object `object` (a hit's pair), or MISS.
fn distance_to(scene: &CpuScene, ray: &Ray, object: u32, primitive: u32) -> f32 {
    let o = &scene.objects[object as usize];
    if o.kind == KIND_MESH {
        let [v0, v1, v2] = scene.triangle(primitive);
        let ray = if o.flags & FLAG_INSTANCE != 0 {
            let m = &scene.instances[o.instance as usize];
            Ray::new(
                m.to_object_point(ray.origin.into()),
                m.to_object_vector(ray.dir.into()),
            )
        } else {
            *ray
        };
        intersect_triangle(v0, v1, v2, &ShearedRay::new(&ray), MISS).0
    } else {
        let mut hit = Hit::none(MISS);
        scene.intersect_shape(object, ray, &mut hit);
        hit.t
    }
}

/// Rays that fill the traversal stack: a row of 200 spheres along -z whose boxes every ray
/// enters near a corner without touching a sphere, and small targets in the first gaps of
/// the row, each on the line of one ray. The walk pushes the farther children of every node
/// on its way to the first sphere and finds its target only in one of those entries, so a
/// stack smaller than the scene's bound must not drop entries (it did: a third of the bound
/// lost targets) but walk again without a stack; every target is found with any stack.
#[test]
fn a_walk_deeper_than_its_stack_finds_every_target() {
    const SPHERES: usize = 200;
    // Ray lines through the corner region of the spheres' boxes (radius 0.1): outside every
    // sphere (0.0778 * sqrt(2) > 0.1), at least 0.01 apart.
    let lines: Vec<(f32, f32)> = [0.078f32, 0.09]
        .iter()
        .flat_map(|&x| [0.078f32, 0.09].map(|y| (x, y)))
        .flat_map(|(x, y)| [(x, y), (-x, y), (x, -y), (-x, -y)])
        .collect();
    let mut text = String::from(
        "[camera]\nposition = [0, 0, 1]\nlook_at = [0, 0, 0]\nfov_y = 40\n\
         resolution = [8, 8]\n[materials.white]\ncolor = [0.5, 0.5, 0.5]\n",
    );
    let sphere = |text: &mut String, center: Vec3, radius: f32| {
        text.push_str(&format!(
            "[[sphere]]\nmaterial = \"white\"\ncenter = [{}, {}, {}]\nradius = {radius}\n",
            center.x, center.y, center.z
        ));
    };
    for i in 0..SPHERES {
        sphere(&mut text, Vec3::new(0.0, 0.0, -0.3 * i as f32), 0.1);
    }
    // Target j (scene object SPHERES + j) lies on line j, in the gap after sphere j.
    for (j, &(x, y)) in lines.iter().enumerate() {
        sphere(&mut text, Vec3::new(x, y, -0.3 * j as f32 - 0.15), 0.004);
    }
    let scene = pathlight_scene::load_scene(&pathlight_scene::SceneSource {
        name: "sphere row".into(),
        text: &text,
        base_dir: Default::default(),
        embedded: &[],
    })
    .unwrap();
    let prepared = PreparedScene::new(&scene).unwrap();
    let rays: Vec<TraceRay> = lines
        .iter()
        .map(|&(x, y)| TraceRay {
            origin: [x, y, 1.0],
            t_max: 1e30,
            dir: [0.0, 0.0, -1.0],
            pad: 0.0,
        })
        .collect();
    let bound = prepared.geometry.stack_bound;
    assert!(
        bound >= 9,
        "a stack bound of {bound}: the rays cannot fill a third of it"
    );
    for stack in [integrator_stack(&prepared), bound, bound / 3, 1] {
        let hits = trace_on_gpu(&prepared, &rays, Accel::Bvh, stack);
        let found = hits
            .iter()
            .enumerate()
            .filter(|(j, hit)| hit.object != u32::MAX && hit.object as usize == SPHERES + j)
            .count();
        assert_eq!(
            found,
            lines.len(),
            "a stack of {stack} entries (bound {bound}) lost targets"
        );
    }
}
