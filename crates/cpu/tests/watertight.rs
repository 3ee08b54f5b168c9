//! No ray passes between the triangles of a closed mesh: rays aimed at the edges and
//! vertices that triangles share (where a test that rounds each triangle on its own lets a
//! ray slip through) hit the mesh no farther than the point aimed at. A torus, an
//! icosphere and the default scene's vase, from every direction; 10^7 rays in all, through
//! the CPU's single-ray walk. (The GPU's walk: `crates/gpu/tests/gpu/trace.rs`.)

use pathlight_core::PreparedScene;
use pathlight_cpu::intersect::Ray;
use pathlight_cpu::{CpuScene, Tracer};
use pathlight_scene::Shape;
use pathlight_scene::testing::{object, rays_at_shared_edges, scene_of, watertight_meshes};
use rand::SeedableRng;
use rand::rngs::StdRng;
use rayon::prelude::*;

/// Rays per mesh: three meshes, 10^7 rays or more in all.
const RAYS_PER_MESH: usize = 3_400_000;

#[test]
fn no_ray_passes_between_the_triangles_of_a_closed_mesh() {
    let mut total = 0;
    for (seed, (name, mesh)) in watertight_meshes().into_iter().enumerate() {
        let prepared =
            PreparedScene::new(&scene_of(vec![object(name, Shape::Mesh(mesh.clone()))])).unwrap();
        let view = CpuScene::new(&prepared);
        let mut rng = StdRng::seed_from_u64(seed as u64);
        let rays = rays_at_shared_edges(&mut rng, &mesh, RAYS_PER_MESH);
        let leaks: Vec<_> = rays
            .par_chunks(4096)
            .flat_map_iter(|chunk| {
                let mut tracer = Tracer::new(&view);
                chunk
                    .iter()
                    .filter(move |(origin, dir, distance)| {
                        let hit = tracer.intersect(&Ray::new(*origin, *dir), 1e30);
                        !hit.is_some_and(|h| h.t <= distance * (1.0 + 1e-4) + 1e-5)
                    })
                    .copied()
                    .collect::<Vec<_>>()
            })
            .collect();
        assert!(
            leaks.is_empty(),
            "{name}: {} of {} rays passed through the surface, e.g. {:?}",
            leaks.len(),
            rays.len(),
            &leaks[..leaks.len().min(3)]
        );
        total += rays.len();
    }
    assert!(total >= 10_000_000);
}
