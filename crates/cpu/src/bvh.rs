//! The BVH walk of one ray: an ordered depth-first walk of the 4-wide tree with one
//! explicit stack; a ray that enters a placed instance walks its mesh's tree in the mesh's
//! space, on the same stack, before it goes on. Twin of `bvh.wgsl` (its primitive tests are the same functions, so the
//! hits are the same; only the order of the walk differs, which can change the answer
//! between two primitives at exactly the same distance). [`crate::packet`] walks packets
//! of rays through the same tree; [`crate::tracer`] holds both walks' stacks for a thread.

use glam::{Vec3, Vec4};
use pathlight_core::gpu_types::{
    FLAG_ALPHA, FLAG_CAPS, GpuPrimitive, GpuWideNode, INSTANCE, KIND_QUAD, KIND_SPHERE,
    NO_TRIANGLE, SHAPE_LEAF,
};

use crate::cpu_scene::CpuScene;
use crate::intersect::{
    ROBUST_FAR, Ray, ShearedRay, intersect_cylinder, intersect_quad, intersect_sphere,
    intersect_triangle, safe_inverse,
};
use crate::textures::alpha_stops;

/// The nearest hit of a ray. Twin of WGSL `Hit`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hit {
    /// Distance along the ray.
    pub t: f32,
    /// Index into the objects (the scene's order).
    pub object: u32,
    /// Mesh: triangle index; other shapes: 0.
    pub primitive: u32,
    /// Triangle: barycentric of vertex 1; quad: s.
    pub b1: f32,
    /// Triangle: barycentric of vertex 2; quad: t.
    pub b2: f32,
}

impl Hit {
    /// No hit yet: a search up to `t_max` (`object` is `u32::MAX` until something is hit).
    pub fn none(t_max: f32) -> Self {
        Self {
            t: t_max,
            object: u32::MAX,
            primitive: 0,
            b1: 0.0,
            b2: 0.0,
        }
    }
}

/// A node still to visit, and the distance at which the ray enters its box.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Entry {
    node: u32,
    t: f32,
}

/// The ray in the form the box tests want: its origin and inverse direction splatted across
/// lanes, and per axis whether it runs backwards (so the maximum planes are the near ones).
pub(crate) struct RayLanes {
    origin: [Vec4; 3],
    inv_dir: [Vec4; 3],
    backwards: [bool; 3],
}

impl RayLanes {
    #[inline(always)]
    pub(crate) fn new(ray: &Ray) -> Self {
        let inv = safe_inverse(ray.dir);
        Self {
            origin: [
                Vec4::splat(ray.origin.x),
                Vec4::splat(ray.origin.y),
                Vec4::splat(ray.origin.z),
            ],
            inv_dir: [Vec4::splat(inv.x), Vec4::splat(inv.y), Vec4::splat(inv.z)],
            backwards: [inv.x < 0.0, inv.y < 0.0, inv.z < 0.0],
        }
    }

    /// Entry distances of the four child boxes of `node` (clamped at 0) and the bit mask of
    /// those the ray enters before `t_max`. Per lane the same products as the WGSL slab
    /// test, with the min/max of each pair chosen by the direction's sign. Twin of WGSL
    /// `enter_children`.
    #[inline(always)]
    fn enter(&self, node: &GpuWideNode, t_max: f32) -> (Vec4, u32) {
        let lo = [node.lo_x, node.lo_y, node.lo_z].map(Vec4::from_array);
        let hi = [node.hi_x, node.hi_y, node.hi_z].map(Vec4::from_array);
        let mut t_near = Vec4::ZERO;
        let mut t_far = Vec4::splat(t_max);
        for axis in 0..3 {
            let (near, far) = if self.backwards[axis] {
                (hi[axis], lo[axis])
            } else {
                (lo[axis], hi[axis])
            };
            let (o, inv) = (self.origin[axis], self.inv_dir[axis]);
            t_near = t_near.max((near - o) * inv);
            t_far = t_far.min((far - o) * inv);
        }
        (t_near, t_near.cmple(t_far * ROBUST_FAR).bitmask())
    }

    /// Whether the ray enters the box from `lo` to `hi` before `t_max`: the slab test of
    /// [`Self::enter`] on one box. Twin of WGSL `enters_box`.
    #[inline(always)]
    fn enters_box(&self, lo: Vec3, hi: Vec3, t_max: f32) -> bool {
        let mut t_near = 0.0f32;
        let mut t_far = t_max;
        for axis in 0..3 {
            let (near, far) = if self.backwards[axis] {
                (hi[axis], lo[axis])
            } else {
                (lo[axis], hi[axis])
            };
            let (o, inv) = (self.origin[axis].x, self.inv_dir[axis].x);
            t_near = t_near.max((near - o) * inv);
            t_far = t_far.min((far - o) * inv);
        }
        t_near <= t_far * ROBUST_FAR
    }
}

impl CpuScene<'_> {
    /// Nearest hit on quad, sphere or cylinder object `i`, updating `hit`. Twin of WGSL
    /// `intersect_shape`.
    #[inline(always)]
    pub fn intersect_shape(&self, i: u32, ray: &Ray, hit: &mut Hit) {
        let o = &self.objects[i as usize];
        let a = Vec3::from_slice(&o.a);
        let (t, b1, b2) = match o.kind {
            KIND_QUAD => intersect_quad(
                a,
                Vec3::from_slice(&o.b),
                Vec3::from_slice(&o.c),
                ray,
                hit.t,
            ),
            KIND_SPHERE => (intersect_sphere(a, o.a[3], ray, hit.t), 0.0, 0.0),
            _ => {
                let caps = o.flags & FLAG_CAPS != 0;
                let t = intersect_cylinder(a, Vec3::from_slice(&o.b), o.a[3], caps, ray, hit.t);
                (t, 0.0, 0.0)
            }
        };
        if t < hit.t {
            *hit = Hit {
                t,
                object: i,
                primitive: 0,
                b1,
                b2,
            };
        }
    }

    /// Nearest hit on primitive `i` (a shape or a triangle, not an instance), updating
    /// `hit`; `sheared` is `ray` in ray space. Twin of WGSL `intersect_primitive`.
    #[inline(always)]
    pub fn intersect_primitive(&self, i: u32, ray: &Ray, sheared: &ShearedRay, hit: &mut Hit) {
        let p = &self.primitives[i as usize];
        if p.triangle == NO_TRIANGLE {
            self.intersect_shape(p.object, ray, hit);
            return;
        }
        self.hit_triangle(p.object, p, sheared, hit);
    }

    /// Hit on triangle primitive `p` as part of mesh object `object` (the primitive's own,
    /// or an instance's that places it), if nearer than `hit`; a triangle of a mesh with
    /// alpha holes counts only where its texel stops the ray. Twin of WGSL `hit_triangle`.
    #[inline(always)]
    pub fn hit_triangle(&self, object: u32, p: &GpuPrimitive, sheared: &ShearedRay, hit: &mut Hit) {
        let [v0, v1, v2] = [p.v0, p.v1, p.v2].map(Vec3::from);
        let (t, b1, b2) = intersect_triangle(v0, v1, v2, sheared, hit.t);
        if t < hit.t
            && (self.objects[object as usize].flags & FLAG_ALPHA == 0
                || alpha_stops(self, object, p.triangle, b1, b2, t))
        {
            *hit = Hit {
                t,
                object,
                primitive: p.triangle,
                b1,
                b2,
            };
        }
    }
}

/// [`Walk::object`] of a walk of the top-level tree.
pub(crate) const TOP_LEVEL: u32 = u32::MAX;

/// Nearest hit of `ray` in `(0, t_max)` in `scene`, or with `any_hit` the first one found,
/// walking with `stack` (emptied first). Twin of WGSL `trace_scene`.
#[inline(always)]
pub(crate) fn trace_scene(
    scene: &CpuScene,
    stack: &mut Vec<Entry>,
    ray: &Ray,
    t_max: f32,
    any_hit: bool,
) -> Hit {
    let mut hit = Hit::none(t_max);
    if !scene.primitives.is_empty() {
        let lanes = RayLanes::new(ray);
        stack.clear();
        let walk = Walk {
            scene,
            ray,
            sheared: ShearedRay::new(ray),
            lanes: &lanes,
            any_hit,
            object: TOP_LEVEL,
        };
        walk.tree::<true>(stack, 0, &mut hit);
    }
    hit
}

/// One ray query in progress.
pub(crate) struct Walk<'a> {
    pub scene: &'a CpuScene<'a>,
    pub ray: &'a Ray,
    /// The ray in ray space, for the triangle tests.
    pub sheared: ShearedRay,
    pub lanes: &'a RayLanes,
    pub any_hit: bool,
    /// In a shared mesh's tree, the instance object being walked (its hits are that
    /// object's); [`TOP_LEVEL`] in the top-level tree.
    pub object: u32,
}

impl Walk<'_> {
    /// Tests primitive `i` of a leaf: a shape or a triangle, or in the top level (`TOP`) an
    /// instance, whose mesh's tree the ray then walks (on `stack`, above its entries).
    #[inline(always)]
    fn primitive<const TOP: bool>(&self, stack: &mut Vec<Entry>, i: u32, hit: &mut Hit) {
        let p = &self.scene.primitives[i as usize];
        if !TOP {
            self.scene.hit_triangle(self.object, p, &self.sheared, hit);
        } else if p.triangle == INSTANCE {
            self.instance(stack, p, hit);
        } else {
            self.scene
                .intersect_primitive(i, self.ray, &self.sheared, hit);
        }
    }

    /// The ray walks the tree of the instance `p` places, in its mesh's space (the same
    /// distances: the direction is not renormalised). Inlined like the rest of the walk, so
    /// that it is compiled for the row renderer's instruction set. Twin of WGSL
    /// `trace_instance`.
    #[inline(always)]
    pub(crate) fn instance(&self, stack: &mut Vec<Entry>, p: &GpuPrimitive, hit: &mut Hit) {
        let object = &self.scene.objects[p.object as usize];
        // Its world box first: a leaf may hold several placements.
        let (lo, hi) = (Vec3::from_slice(&object.a), Vec3::from_slice(&object.b));
        if !self.lanes.enters_box(lo, hi, hit.t) {
            return;
        }
        let instance = &self.scene.instances[object.instance as usize];
        let ray = Ray::new(
            instance.to_object_point(self.ray.origin.into()),
            instance.to_object_vector(self.ray.dir.into()),
        );
        let lanes = RayLanes::new(&ray);
        let walk = Walk {
            scene: self.scene,
            ray: &ray,
            sheared: ShearedRay::new(&ray),
            lanes: &lanes,
            any_hit: self.any_hit,
            object: p.object,
        };
        walk.tree::<false>(stack, p.root, hit);
    }

    /// Walks the subtree at `root`, nearest boxes first, using `stack` above its
    /// current length: of the top-level tree with `TOP`, else of a shared mesh's (whose
    /// leaves hold triangles alone). A node's entered leaves are tested as it is visited
    /// (nearest first); inner nodes are pushed. An any-hit query stops at its first hit.
    #[inline(always)]
    pub(crate) fn tree<const TOP: bool>(&self, stack: &mut Vec<Entry>, root: u32, hit: &mut Hit) {
        let base = stack.len();
        let mut node = root;
        loop {
            let n = &self.scene.nodes[node as usize];
            let (t_near, mut mask) = self.lanes.enter(n, hit.t);
            // The entered children, nearest first.
            let mut order = [(0.0f32, 0usize); 4];
            let mut entered = 0;
            while mask != 0 {
                let lane = mask.trailing_zeros() as usize;
                mask &= mask - 1;
                let t = t_near[lane];
                let mut k = entered;
                while k > 0 && order[k - 1].0 > t {
                    order[k] = order[k - 1];
                    k -= 1;
                }
                order[k] = (t, lane);
                entered += 1;
            }
            for &(t, lane) in &order[..entered] {
                let count = n.count[lane] & !SHAPE_LEAF;
                if count > 0 && t < hit.t {
                    for i in n.first[lane]..n.first[lane] + count {
                        self.primitive::<TOP>(stack, i, hit);
                    }
                    if self.any_hit && hit.object != u32::MAX {
                        return;
                    }
                }
            }
            for &(t, lane) in order[..entered].iter().rev() {
                if n.count[lane] == 0 {
                    stack.push(Entry {
                        node: n.first[lane],
                        t,
                    });
                }
            }
            loop {
                if stack.len() == base {
                    return;
                }
                let Some(entry) = stack.pop() else {
                    return;
                };
                if entry.t < hit.t {
                    node = entry.node;
                    break;
                }
            }
        }
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use glam::Vec3;
    use pathlight_core::PreparedScene;
    use pathlight_core::bvh::lane_used;
    use pathlight_core::gpu_types::KIND_MESH;
    use pathlight_scene::testing::{
        coincident_triangles, degenerate_objects, flattened, icosphere, instances_of, object,
        random_mesh, random_objects, random_placements, random_point, scene_of,
    };
    use pathlight_scene::{Object, Shape};
    use rand::rngs::StdRng;
    use rand::{Rng, SeedableRng};

    use super::Hit;
    use crate::cpu_scene::CpuScene;
    use crate::intersect::{Ray, ShearedRay, intersect_triangle};
    use crate::tracer::Tracer;

    /// The scene of `objects`, prepared.
    pub(crate) fn prepare(objects: Vec<Object>) -> PreparedScene {
        PreparedScene::new(&scene_of(objects)).unwrap()
    }

    /// The nearest hit over every object and every triangle, without the BVH.
    pub(crate) fn brute_force(scene: &CpuScene, ray: &Ray, t_max: f32) -> Option<Hit> {
        brute_force_among(scene, ray, t_max, &|_| true)
    }

    /// [`brute_force`] among the objects `among` keeps.
    fn brute_force_among(
        scene: &CpuScene,
        ray: &Ray,
        t_max: f32,
        among: &dyn Fn(u32) -> bool,
    ) -> Option<Hit> {
        let mut hit = Hit::none(t_max);
        for (i, o) in scene.objects.iter().enumerate() {
            if !among(i as u32) {
                continue;
            }
            if o.kind != KIND_MESH {
                // (A scene without objects holds a placeholder quad of no area.)
                scene.intersect_shape(i as u32, ray, &mut hit);
                continue;
            }
            for tri in o.first_triangle..o.first_triangle + o.triangle_count {
                let [v0, v1, v2] = scene.triangle(tri);
                let (t, b1, b2) = intersect_triangle(v0, v1, v2, &ShearedRay::new(ray), hit.t);
                if t < hit.t {
                    hit = Hit {
                        t,
                        object: i as u32,
                        primitive: tri,
                        b1,
                        b2,
                    };
                }
            }
        }
        (hit.object != u32::MAX).then_some(hit)
    }

    /// A ray from anywhere in a 10-unit cube towards a point within `target` of the origin.
    pub(crate) fn random_ray(rng: &mut StdRng, target: f32) -> Ray {
        let origin = random_point(rng, 5.0);
        Ray::new(
            origin,
            (random_point(rng, target) - origin).normalize_or(Vec3::X),
        )
    }

    /// A ray towards a random point of the box around the scene's primitives.
    pub(crate) fn ray_into_scene(rng: &mut StdRng, scene: &CpuScene) -> Ray {
        let n = &scene.nodes[0];
        let (min, max) = (0..4).filter(|&lane| lane_used(n, lane)).fold(
            (Vec3::MAX, Vec3::MIN),
            |(min, max), l| {
                let lo = Vec3::new(n.lo_x[l], n.lo_y[l], n.lo_z[l]);
                (
                    min.min(lo),
                    max.max(Vec3::new(n.hi_x[l], n.hi_y[l], n.hi_z[l])),
                )
            },
        );
        let target = min + (max - min) * Vec3::new(rng.random(), rng.random(), rng.random());
        let origin = random_point(rng, 5.0);
        Ray::new(origin, (target - origin).normalize_or(Vec3::X))
    }

    /// Checks a traversal (its nearest-hit and shadow queries) against brute force on
    /// `rays`; returns how many rays hit something. The distances agree to a relative 1e-5,
    /// or `tolerance` where brute force looks at the same surfaces placed otherwise (an
    /// instanced scene flattened rounds differently: grazing hits moved up to 1.6e-5 in
    /// 2,000 rays); the objects agree unless brute force finds the walk's object as near.
    pub(crate) fn assert_like_brute_force(
        scene: &CpuScene,
        tolerance: f32,
        rays: &[Ray],
        name: &str,
        intersect: &mut dyn FnMut(&Ray, f32) -> Option<Hit>,
        occluded: &mut dyn FnMut(&Ray, f32) -> bool,
    ) -> usize {
        let mut hits = 0;
        for ray in rays {
            let slow = brute_force(scene, ray, 1e30);
            hits += usize::from(slow.is_some());
            // The shadow query: blocked exactly when the nearest hit lies before t_max.
            for t_max in [0.5, 2.0, 1e30] {
                let blocked = slow.is_some_and(|h| h.t < t_max);
                assert_eq!(
                    occluded(ray, t_max),
                    blocked,
                    "{name}: ray {ray:?}, t_max {t_max}"
                );
            }
            match (intersect(ray, 1e30), slow) {
                (None, None) => {}
                (Some(a), Some(b)) => {
                    assert!(
                        (a.t - b.t).abs() <= tolerance * b.t.max(1.0),
                        "{name}: ray {ray:?}: bvh t {} vs brute force {}",
                        a.t,
                        b.t
                    );
                    if a.object != b.object {
                        // Near-equal distances on two objects: either answer is right.
                        let own = brute_force_among(scene, ray, 1e30, &|i| i == a.object);
                        assert!(
                            own.is_some_and(|h| (h.t - a.t).abs() <= tolerance * a.t.max(1.0)),
                            "{name}: ray {ray:?}: bvh object {} vs brute force {}",
                            a.object,
                            b.object
                        );
                    }
                }
                (a, b) => panic!("{name}: ray {ray:?}: bvh {a:?} vs brute force {b:?}"),
            }
        }
        hits
    }

    /// The single-ray walk against brute force in `truth` (`scene` itself, or the same
    /// scene with its instances flattened).
    fn assert_walk(scene: &CpuScene, truth: &CpuScene, rays: &[Ray]) -> usize {
        let tracer = std::cell::RefCell::new(Tracer::new(scene));
        let tolerance = if std::ptr::eq(scene, truth) {
            1e-5
        } else {
            1e-4
        };
        assert_like_brute_force(
            truth,
            tolerance,
            rays,
            "walk",
            &mut |r, t| tracer.borrow_mut().intersect(r, t),
            &mut |r, t| tracer.borrow_mut().occluded(r, t),
        )
    }

    #[test]
    fn the_walk_matches_brute_force_on_random_scenes() {
        let mut rng = StdRng::seed_from_u64(7);
        for count in [1, 2, 5, 40] {
            let prepared = prepare(random_objects(&mut rng, count));
            let scene = CpuScene::new(&prepared);
            let rays: Vec<Ray> = (0..2000)
                .map(|_| ray_into_scene(&mut rng, &scene))
                .collect();
            let hits = assert_walk(&scene, &scene, &rays);
            assert!(hits > 20, "{count} objects: only {hits} of 2000 rays hit");
        }
        let prepared = prepare(vec![object(
            "big",
            Shape::Mesh(random_mesh(&mut rng, 20_000, Vec3::ZERO)),
        )]);
        let scene = CpuScene::new(&prepared);
        let rays: Vec<Ray> = (0..300).map(|_| random_ray(&mut rng, 1.0)).collect();
        assert!(assert_walk(&scene, &scene, &rays) > 50);
    }

    /// Random shapes and two shared meshes placed 30 and 12 times (rotated, scaled unevenly,
    /// a third of them mirrored), one placement of each with no other.
    pub(crate) fn instanced_objects(rng: &mut StdRng) -> Vec<Object> {
        let mut objects = random_objects(rng, 12);
        let rocks = random_placements(rng, 30);
        objects.extend(instances_of(
            "rocks",
            random_mesh(rng, 200, Vec3::ZERO),
            &rocks,
        ));
        let balls = random_placements(rng, 12);
        objects.extend(instances_of("balls", icosphere(2), &balls));
        objects
    }

    #[test]
    fn the_walk_through_instances_finds_what_the_flattened_scene_holds() {
        let mut rng = StdRng::seed_from_u64(19);
        let objects = instanced_objects(&mut rng);
        let (prepared, flat) = (prepare(objects.clone()), prepare(flattened(&objects)));
        let (scene, truth) = (CpuScene::new(&prepared), CpuScene::new(&flat));
        let rays: Vec<Ray> = (0..3000)
            .map(|_| ray_into_scene(&mut rng, &scene))
            .collect();
        let hits = assert_walk(&scene, &truth, &rays);
        assert!(hits > 300, "only {hits} of 3000 rays hit");
        // The instances' triangles are kept once: 200 + 320 (the icosphere's), not 30 x 200 +
        // 12 x 320.
        let world: usize = objects
            .iter()
            .map(|o| match &o.shape {
                Shape::Mesh(mesh) => mesh.indices.len(),
                _ => 0,
            })
            .sum();
        assert_eq!(prepared.geometry.triangle_count(), world + 200 + 320);
        assert_eq!(
            prepared.geometry.placed_triangle_count(),
            flat.geometry.triangle_count()
        );
    }

    #[test]
    fn an_empty_scene_has_no_hits() {
        let prepared = prepare(Vec::new());
        let scene = CpuScene::new(&prepared);
        let mut tracer = Tracer::new(&scene);
        let mut rng = StdRng::seed_from_u64(1);
        for _ in 0..100 {
            let ray = random_ray(&mut rng, 3.0);
            assert_eq!(tracer.intersect(&ray, 1e30), None);
            assert!(!tracer.occluded(&ray, 1e30));
        }
    }

    #[test]
    fn degenerate_triangles_coincident_triangles_and_axis_rays() {
        let prepared = prepare(degenerate_objects());
        let scene = CpuScene::new(&prepared);
        // Rays along the axes (zero direction components) through the flat boxes.
        let mut rays = vec![
            Ray::new(Vec3::new(0.0, 0.0, 5.0), -Vec3::Z),
            Ray::new(Vec3::new(0.5, -0.5, 5.0), -Vec3::Z),
            Ray::new(Vec3::new(5.0, 0.0, 0.0), -Vec3::X),
            Ray::new(Vec3::new(0.0, 5.0, -2.0), -Vec3::Y),
        ];
        let mut rng = StdRng::seed_from_u64(3);
        rays.extend((0..500).map(|_| random_ray(&mut rng, 1.0)));
        assert!(assert_walk(&scene, &scene, &rays) >= 2);
        let mut tracer = Tracer::new(&scene);
        let hit = tracer
            .intersect(&rays[0], 1e30)
            .expect("the proper triangle is hit");
        assert!((hit.t - 5.0).abs() < 1e-5);
        assert_eq!(
            tracer.intersect(&rays[0], 4.0),
            None,
            "t_max bounds the search"
        );
        let prepared = prepare(coincident_triangles(5000));
        let scene = CpuScene::new(&prepared);
        let rays: Vec<Ray> = (0..200).map(|_| random_ray(&mut rng, 0.5)).collect();
        assert!(assert_walk(&scene, &scene, &rays) > 20);
    }
}
