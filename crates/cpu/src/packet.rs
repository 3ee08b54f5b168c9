//! Ray queries for packets of up to [`PACKET`] rays: the CPU backend traces its paths side
//! by side, and their rays walk the 4-wide BVH together, each child box and each shape
//! tested for all of them at once (a shape for the groups of eight lanes that hold one of
//! the rays entering its leaf). The per-ray arithmetic is written as loops over the
//! lanes, which the compiler turns into SIMD instructions of the caller's instruction set
//! (32 lanes: two AVX-512 registers, four AVX2 ones; 32 measured faster than 16 and 8).
//! Where a packet has spread so that few of its rays still enter a node, each of those goes
//! on alone with the single-ray walk.
//!
//! The shape tests are [`crate::intersect`]'s, so each ray gets the same hit as alone (only the
//! order of the walk differs, which can change the answer between two primitives at exactly
//! the same distance).

use std::ops::Range;

use glam::Vec3;

use pathlight_core::gpu_types::{
    FLAG_ALPHA, FLAG_CAPS, GpuPrimitive, GpuWideNode, INSTANCE, KIND_QUAD, KIND_SPHERE,
    NO_TRIANGLE, SHAPE_LEAF,
};

use crate::bvh::{Entry, Hit, RayLanes, TOP_LEVEL, Walk};
use crate::cpu_scene::CpuScene;
use crate::intersect::{
    MISS, ROBUST_FAR, Ray, ShearedRay, intersect_cylinder, intersect_quad, intersect_sphere,
    intersect_triangle,
};
use crate::slots::GROUP;
use crate::textures::alpha_stops;

/// Rays per packet.
pub const PACKET: usize = 32;

/// Lanes a shape test computes at once: one register of `f32`s, sixteen where the level
/// has AVX-512 (`wide`: 3-5% faster there than eight on an Intel Xeon), [`GROUP`] (AVX2's)
/// otherwise.
const fn test_group(wide: bool) -> usize {
    if wide { 16 } else { GROUP }
}

/// Below this many rays entering a node, the packet's rays go on alone.
const MIN_SHARED_RAYS: u32 = 5;

/// A bit mask of a packet's lanes (bit `l` is lane `l`).
pub type Lanes = u32;
const _: () = assert!(PACKET <= Lanes::BITS as usize);

/// Up to [`PACKET`] rays to trace together.
#[derive(Debug, Clone, Copy)]
pub struct RayPacket {
    /// The rays; only those in `active` are traced.
    pub rays: [Ray; PACKET],
    /// Per ray: the end of the searched interval `(0, t_max)`.
    pub t_max: [f32; PACKET],
    /// Bit `l` set: ray `l` is traced (bits from [`PACKET`] up are ignored).
    pub active: Lanes,
}

impl Default for RayPacket {
    fn default() -> Self {
        Self {
            rays: [Ray {
                origin: Vec3::ZERO,
                dir: Vec3::Z,
            }; PACKET],
            t_max: [0.0; PACKET],
            active: 0,
        }
    }
}

/// A packet's rays in structure-of-arrays form, per axis.
#[derive(Debug, Clone)]
pub(crate) struct PacketRays {
    origin: [[f32; PACKET]; 3],
    dir: [[f32; PACKET]; 3],
    inv_dir: [[f32; PACKET]; 3],
    /// The rows of each ray's shear into ray space ([`ShearedRay`]), per row and axis; for
    /// the triangle tests alone, so zeros in a scene without triangles.
    shear: [[[f32; PACKET]; 3]; 3],
}

impl Default for PacketRays {
    fn default() -> Self {
        Self {
            origin: [[0.0; PACKET]; 3],
            dir: [[1.0; PACKET]; 3],
            inv_dir: [[1.0; PACKET]; 3],
            shear: [[[0.0; PACKET]; 3]; 3],
        }
    }
}

impl PacketRays {
    /// Sets these to the rays of `packet`, their inverse directions and (`with_shears`: for
    /// a scene with triangles) their shears computed lane by lane side by side (the values of
    /// [`crate::intersect::safe_inverse`] and [`ShearedRay::new`] bit for bit: the same
    /// operations, the axis choices made with masks instead of indices). The shears cost three
    /// divisions a ray; a scene of shapes alone never reads them.
    #[inline(always)]
    pub(crate) fn set(&mut self, packet: &RayPacket, with_shears: bool) {
        let rays = self;
        for (l, ray) in packet.rays.iter().enumerate() {
            for axis in 0..3 {
                rays.origin[axis][l] = ray.origin[axis];
                rays.dir[axis][l] = ray.dir[axis];
            }
        }
        let tiny = 1e-20_f32;
        for axis in 0..3 {
            for l in 0..PACKET {
                let c = rays.dir[axis][l];
                let fixed = if c.abs() < tiny {
                    if c >= 0.0 { tiny } else { -tiny }
                } else {
                    c
                };
                rays.inv_dir[axis][l] = 1.0 / fixed;
            }
        }
        if !with_shears {
            return;
        }
        for l in 0..PACKET {
            let [dx, dy, dz] = [rays.dir[0][l], rays.dir[1][l], rays.dir[2][l]];
            let (ax, ay, az) = (dx.abs(), dy.abs(), dz.abs());
            // kz: the largest axis (ties to the first, as `ShearedRay::new`); kx, ky the next.
            let z_is = {
                let x = ax >= ay && ax >= az;
                let y = !x && ay >= az;
                [x, y, !x && !y]
            };
            let pick = |k: [bool; 3]| {
                if k[0] {
                    dx
                } else if k[1] {
                    dy
                } else {
                    dz
                }
            };
            let x_is = [z_is[2], z_is[0], z_is[1]];
            let y_is = [z_is[1], z_is[2], z_is[0]];
            let (d_kx, d_ky, d_kz) = (pick(x_is), pick(y_is), pick(z_is));
            let (shear_x, shear_y, scale_z) = (-d_kx / d_kz, -d_ky / d_kz, 1.0 / d_kz);
            for axis in 0..3 {
                let on_z = |value: f32| if z_is[axis] { value } else { 0.0 };
                rays.shear[0][axis][l] = if x_is[axis] { 1.0 } else { on_z(shear_x) };
                rays.shear[1][axis][l] = if y_is[axis] { 1.0 } else { on_z(shear_y) };
                rays.shear[2][axis][l] = on_z(scale_z);
            }
        }
    }

    /// Ray `l` in ray space.
    #[inline(always)]
    fn sheared(&self, l: usize) -> ShearedRay {
        let row = |r: usize| {
            Vec3::new(
                self.shear[r][0][l],
                self.shear[r][1][l],
                self.shear[r][2][l],
            )
        };
        ShearedRay {
            origin: Vec3::new(self.origin[0][l], self.origin[1][l], self.origin[2][l]),
            row_x: row(0),
            row_y: row(1),
            row_z: row(2),
        }
    }

    #[inline(always)]
    fn ray(&self, l: usize) -> Ray {
        Ray {
            origin: Vec3::new(self.origin[0][l], self.origin[1][l], self.origin[2][l]),
            dir: Vec3::new(self.dir[0][l], self.dir[1][l], self.dir[2][l]),
        }
    }
}

/// The nearest hits of a packet's rays (found so far, during its walk).
#[derive(Debug, Clone, Default)]
pub struct PacketHits {
    t: [f32; PACKET],
    object: [u32; PACKET],
    primitive: [u32; PACKET],
    b1: [f32; PACKET],
    b2: [f32; PACKET],
    /// Lanes still searching: all active ones for nearest hits; an any-hit query drops a
    /// lane once it has found something.
    searching: Lanes,
}

impl PacketHits {
    /// No hit yet for the rays of `packet`, the `active` ones searching: the distances back
    /// to the rays' ends and no object (a hit's other fields are read only where it found
    /// one, which writes them all).
    #[inline(always)]
    pub(crate) fn reset(&mut self, packet: &RayPacket, active: Lanes) {
        self.t = packet.t_max;
        self.object = [u32::MAX; PACKET];
        self.searching = active;
    }

    /// The hit of ray `l`, which hit something ([`PacketHits::found`] has its bit).
    #[inline(always)]
    pub fn nearest(&self, l: usize) -> Hit {
        Hit {
            t: self.t[l],
            object: self.object[l],
            primitive: self.primitive[l],
            b1: self.b1[l],
            b2: self.b2[l],
        }
    }

    #[inline(always)]
    fn set(&mut self, l: usize, hit: Hit) {
        self.t[l] = hit.t;
        self.object[l] = hit.object;
        self.primitive[l] = hit.primitive;
        self.b1[l] = hit.b1;
        self.b2[l] = hit.b2;
    }

    /// Keeps, in the lanes of `lanes`, the hits on `shape` (`object`'s `primitive`) nearer
    /// than the current ones.
    #[inline(always)]
    fn test<const WIDE: bool>(
        &mut self,
        rays: &PacketRays,
        lanes: Lanes,
        object: u32,
        primitive: u32,
        shape: &impl ShapeTest,
    ) {
        // Every lane is written, blended by a bit mask the compiler cannot see is all ones
        // or all zeros: a select of the lane's own value would become masked stores, which
        // AMD CPUs run slowly under AVX2 (the x86-64-v3 level).
        let opaque = std::hint::black_box(0u32);
        let blend = |new: u32, old: u32, take: bool| {
            let m = u32::from(take).wrapping_neg() ^ opaque;
            (new & m) | (old & !m)
        };
        let blend_f = |new: f32, old: f32, take: bool| {
            f32::from_bits(blend(new.to_bits(), old.to_bits(), take))
        };
        // Only the groups of lanes with a ray in `lanes` (a leaf's rays are some 5-14 of 32
        // on the reference scenes, in 2.8-3.2 of the four groups of eight).
        let size = test_group(WIDE);
        let group_lanes: Lanes = (1 << size) - 1;
        for group in 0..PACKET / size {
            if (lanes >> (group * size)) & group_lanes == 0 {
                continue;
            }
            for l in group * size..(group + 1) * size {
                let (t, b1, b2) = shape.intersect(rays, l, self.t[l]);
                let take = (lanes >> l) & 1 != 0 && t < self.t[l];
                self.t[l] = blend_f(t, self.t[l], take);
                self.b1[l] = blend_f(b1, self.b1[l], take);
                self.b2[l] = blend_f(b2, self.b2[l], take);
                self.object[l] = blend(object, self.object[l], take);
                self.primitive[l] = blend(primitive, self.primitive[l], take);
            }
        }
    }

    /// Lanes that have hit something.
    #[inline(always)]
    pub fn found(&self) -> Lanes {
        let mut found = 0;
        for l in 0..PACKET {
            found |= Lanes::from(self.object[l] != u32::MAX) << l;
        }
        found
    }
}

/// A shape a packet's rays are tested against, one by one ([`crate::intersect`]'s tests).
trait ShapeTest {
    /// The hit `(t, b1, b2)` of ray `l` of `rays` in `(0, t_max)`, `t` =
    /// [`crate::intersect::MISS`] for none.
    fn intersect(&self, rays: &PacketRays, l: usize, t_max: f32) -> (f32, f32, f32);
}

/// A quad: corner and edges.
struct Quad(Vec3, Vec3, Vec3);

/// A sphere: centre and radius.
struct Sphere(Vec3, f32);

/// A cylinder: axis ends, radius, whether capped.
struct Cylinder(Vec3, Vec3, f32, bool);

/// A triangle: its corners.
struct Triangle([Vec3; 3]);

impl ShapeTest for Quad {
    #[inline(always)]
    fn intersect(&self, rays: &PacketRays, l: usize, t_max: f32) -> (f32, f32, f32) {
        intersect_quad(self.0, self.1, self.2, &rays.ray(l), t_max)
    }
}

impl ShapeTest for Sphere {
    #[inline(always)]
    fn intersect(&self, rays: &PacketRays, l: usize, t_max: f32) -> (f32, f32, f32) {
        (
            intersect_sphere(self.0, self.1, &rays.ray(l), t_max),
            0.0,
            0.0,
        )
    }
}

impl ShapeTest for Cylinder {
    #[inline(always)]
    fn intersect(&self, rays: &PacketRays, l: usize, t_max: f32) -> (f32, f32, f32) {
        let t = intersect_cylinder(self.0, self.1, self.2, self.3, &rays.ray(l), t_max);
        (t, 0.0, 0.0)
    }
}

impl ShapeTest for Triangle {
    #[inline(always)]
    fn intersect(&self, rays: &PacketRays, l: usize, t_max: f32) -> (f32, f32, f32) {
        let [v0, v1, v2] = self.0;
        intersect_triangle(v0, v1, v2, &rays.sheared(l), t_max)
    }
}

/// A triangle of a mesh with alpha holes: a hit counts only where its texel stops the ray.
struct CutOutTriangle<'a> {
    corners: [Vec3; 3],
    scene: &'a CpuScene<'a>,
    object: u32,
    triangle: u32,
}

impl ShapeTest for CutOutTriangle<'_> {
    #[inline(always)]
    fn intersect(&self, rays: &PacketRays, l: usize, t_max: f32) -> (f32, f32, f32) {
        let [v0, v1, v2] = self.corners;
        let (t, b1, b2) = intersect_triangle(v0, v1, v2, &rays.sheared(l), t_max);
        if t < t_max && !alpha_stops(self.scene, self.object, self.triangle, b1, b2, t) {
            return (MISS, 0.0, 0.0);
        }
        (t, b1, b2)
    }
}

/// Smaller of two numbers that are not NaN (one instruction, unlike `f32::min`).
#[inline(always)]
fn min(a: f32, b: f32) -> f32 {
    if a < b { a } else { b }
}

/// Larger of two numbers that are not NaN.
#[inline(always)]
fn max(a: f32, b: f32) -> f32 {
    if a > b { a } else { b }
}

/// The two traversal stacks: nodes a packet still has to visit (with the lanes that
/// entered them), and the single-ray walk's.
pub(crate) struct Stacks<'a> {
    pub packet: &'a mut Vec<(u32, Lanes)>,
    pub single: &'a mut Vec<Entry>,
}

/// One packet query in progress; `WIDE`: the level has AVX-512 ([`test_group`]).
pub(crate) struct PacketWalk<'a, const WIDE: bool> {
    pub scene: &'a CpuScene<'a>,
    pub rays: &'a PacketRays,
    pub any_hit: bool,
}

impl<const WIDE: bool> PacketWalk<'_, WIDE> {
    /// Walks the tree at `root` with the rays `lanes`, nearest boxes first (as seen by the
    /// rays entering them). Leaves are tested as their node is visited; where fewer than
    /// [`MIN_SHARED_RAYS`] rays enter a node, each goes on alone from there.
    #[inline(always)]
    pub(crate) fn tree(&self, stacks: &mut Stacks, root: u32, lanes: Lanes, hits: &mut PacketHits) {
        let base = stacks.packet.len();
        stacks.packet.push((root, lanes));
        while stacks.packet.len() > base {
            let Some((node, lanes)) = stacks.packet.pop() else {
                break;
            };
            let mut lanes = lanes & hits.searching;
            if lanes.count_ones() < MIN_SHARED_RAYS {
                while lanes != 0 {
                    let l = lanes.trailing_zeros() as usize;
                    lanes &= lanes - 1;
                    self.alone(stacks, l, node, hits);
                }
                continue;
            }
            let n = &self.scene.nodes[node as usize];
            // The entered children, nearest first by their nearest ray's entry distance.
            let mut order = [(0.0f32, 0 as Lanes, 0usize); 4];
            let mut entered = 0;
            for child in 0..4 {
                if n.lo_x[child] > n.hi_x[child] {
                    continue; // An unused lane.
                }
                let (t, child_lanes) = self.enter(n, child, lanes, &hits.t);
                if child_lanes == 0 {
                    continue;
                }
                let mut k = entered;
                while k > 0 && order[k - 1].0 > t {
                    order[k] = order[k - 1];
                    k -= 1;
                }
                order[k] = (t, child_lanes, child);
                entered += 1;
            }
            for &(_, child_lanes, child) in &order[..entered] {
                let child_lanes = child_lanes & hits.searching;
                let count = n.count[child] & !SHAPE_LEAF;
                if count > 0 && child_lanes != 0 {
                    let first = n.first[child];
                    self.primitives(stacks, first..first + count, child_lanes, hits);
                }
            }
            for &(_, child_lanes, child) in order[..entered].iter().rev() {
                if n.count[child] == 0 {
                    stacks.packet.push((n.first[child], child_lanes));
                }
            }
        }
    }

    /// The rays of `lanes` that enter child `child` of `n` before their current nearest
    /// hit `t`, and the smallest of their entry distances. Per ray the slab test of
    /// [`RayLanes`].
    #[inline(always)]
    fn enter(
        &self,
        n: &GpuWideNode,
        child: usize,
        lanes: Lanes,
        t: &[f32; PACKET],
    ) -> (f32, Lanes) {
        let lo = [n.lo_x[child], n.lo_y[child], n.lo_z[child]];
        let hi = [n.hi_x[child], n.hi_y[child], n.hi_z[child]];
        let r = self.rays;
        let mut near = [f32::INFINITY; PACKET];
        let mut entered = 0;
        for l in 0..PACKET {
            let mut t_near = 0.0f32;
            let mut t_far = t[l];
            for axis in 0..3 {
                let t0 = (lo[axis] - r.origin[axis][l]) * r.inv_dir[axis][l];
                let t1 = (hi[axis] - r.origin[axis][l]) * r.inv_dir[axis][l];
                t_near = max(t_near, min(t0, t1));
                t_far = min(t_far, max(t0, t1));
            }
            let inside = (lanes >> l) & 1 != 0 && t_near <= t_far * ROBUST_FAR;
            entered |= Lanes::from(inside) << l;
            near[l] = if inside { t_near } else { f32::INFINITY };
        }
        if self.any_hit {
            return (0.0, entered); // Any hit will do: no order needed.
        }
        let mut width = PACKET / 2;
        while width > 0 {
            for l in 0..width {
                near[l] = min(near[l], near[l + width]);
            }
            width /= 2;
        }
        (near[0], entered)
    }

    /// Tests the primitives `range` with the rays `lanes` (an instance with each ray alone,
    /// on the single-ray stack).
    #[inline(always)]
    fn primitives(
        &self,
        stacks: &mut Stacks,
        range: Range<u32>,
        lanes: Lanes,
        hits: &mut PacketHits,
    ) {
        let rays = self.rays;
        for i in range {
            let lanes = lanes & hits.searching;
            let p = &self.scene.primitives[i as usize];
            if p.triangle == INSTANCE {
                self.instance(stacks, p, lanes, hits);
                continue;
            }
            if p.triangle != NO_TRIANGLE {
                let corners = [p.v0, p.v1, p.v2].map(Vec3::from);
                if self.scene.objects[p.object as usize].flags & FLAG_ALPHA != 0 {
                    let triangle = CutOutTriangle {
                        corners,
                        scene: self.scene,
                        object: p.object,
                        triangle: p.triangle,
                    };
                    hits.test::<WIDE>(rays, lanes, p.object, p.triangle, &triangle);
                } else {
                    hits.test::<WIDE>(rays, lanes, p.object, p.triangle, &Triangle(corners));
                }
                continue;
            }
            let o = &self.scene.objects[p.object as usize];
            let a = Vec3::from_slice(&o.a);
            match o.kind {
                KIND_QUAD => {
                    let quad = Quad(a, Vec3::from_slice(&o.b), Vec3::from_slice(&o.c));
                    hits.test::<WIDE>(rays, lanes, p.object, 0, &quad);
                }
                KIND_SPHERE => hits.test::<WIDE>(rays, lanes, p.object, 0, &Sphere(a, o.a[3])),
                _ => {
                    let caps = o.flags & FLAG_CAPS != 0;
                    let cylinder = Cylinder(a, Vec3::from_slice(&o.b), o.a[3], caps);
                    hits.test::<WIDE>(rays, lanes, p.object, 0, &cylinder);
                }
            }
        }
        self.stop_found(hits);
    }

    /// An any-hit query stops searching with the rays that found something.
    #[inline(always)]
    fn stop_found(&self, hits: &mut PacketHits) {
        if self.any_hit {
            hits.searching &= !hits.found();
        }
    }

    /// Ray `lane` walks the subtree at `node` alone.
    #[inline(always)]
    fn alone(&self, stacks: &mut Stacks, lane: usize, node: u32, hits: &mut PacketHits) {
        self.each_alone(stacks, 1 << lane, hits, Alone::Subtree(node));
    }

    /// The rays `lanes` walk the tree of the instance `p` places, one by one.
    #[inline(always)]
    fn instance(&self, stacks: &mut Stacks, p: &GpuPrimitive, lanes: Lanes, hits: &mut PacketHits) {
        self.each_alone(stacks, lanes, hits, Alone::Instance(p));
    }

    /// Each ray of `lanes` in turn, with its current hit, walks `what` as a single ray (the
    /// single-ray stack emptied first).
    #[inline(always)]
    fn each_alone(
        &self,
        stacks: &mut Stacks,
        mut lanes: Lanes,
        hits: &mut PacketHits,
        what: Alone,
    ) {
        while lanes != 0 {
            let lane = lanes.trailing_zeros() as usize;
            lanes &= lanes - 1;
            let ray = self.rays.ray(lane);
            let ray_lanes = RayLanes::new(&ray);
            let single = Walk {
                scene: self.scene,
                ray: &ray,
                sheared: self.rays.sheared(lane),
                lanes: &ray_lanes,
                any_hit: self.any_hit,
                object: TOP_LEVEL,
            };
            let mut hit = hits.nearest(lane);
            stacks.single.clear();
            match what {
                Alone::Subtree(node) => single.tree::<true>(stacks.single, node, &mut hit),
                Alone::Instance(p) => single.instance(stacks.single, p, &mut hit),
            }
            hits.set(lane, hit);
            if self.any_hit && hit.object != u32::MAX {
                hits.searching &= !(1 << lane);
            }
        }
    }
}

/// What a ray of a packet walks alone: a subtree of the top level, or a placed instance.
#[derive(Clone, Copy)]
enum Alone<'a> {
    Subtree(u32),
    Instance(&'a GpuPrimitive),
}

#[cfg(test)]
mod tests {
    use std::cell::RefCell;

    use glam::Vec3;
    use pathlight_scene::Shape;
    use pathlight_scene::testing::{object, random_mesh, random_objects};
    use rand::SeedableRng;
    use rand::rngs::StdRng;

    use super::{Lanes, PACKET, PacketHits, RayPacket};
    use crate::bvh::tests::{
        assert_like_brute_force, instanced_objects, prepare, random_ray, ray_into_scene,
    };
    use crate::cpu_scene::CpuScene;
    use crate::intersect::Ray;
    use crate::tracer::Tracer;
    use pathlight_scene::testing::flattened;

    /// A packet's lane-wise inverse directions and shears are those of `safe_inverse` and
    /// `ShearedRay::new` ray by ray, bit for bit: directions with ties between their largest
    /// axes, zero and tiny components of both signs, and random ones.
    #[test]
    fn packet_rays_are_the_single_rays_bit_for_bit() {
        use crate::intersect::{ShearedRay, safe_inverse};
        let mut rng = StdRng::seed_from_u64(7);
        let mut dirs = vec![
            Vec3::new(1.0, 1.0, 1.0),
            Vec3::new(-1.0, 1.0, 0.0),
            Vec3::new(0.0, -2.0, 2.0),
            Vec3::new(0.0, 0.0, -1.0),
            Vec3::new(-0.0, 1e-30, -1.0),
            Vec3::new(3.0, -3.0, -3.0),
            Vec3::new(1e-21, -1e-21, 0.5),
        ];
        while dirs.len() < 3 * PACKET {
            dirs.push(random_ray(&mut rng, 2.0).dir);
        }
        let bits = |v: Vec3| v.to_array().map(f32::to_bits);
        for chunk in dirs.chunks(PACKET) {
            let mut packet = RayPacket::default();
            for (l, dir) in chunk.iter().enumerate() {
                packet.rays[l] = Ray {
                    origin: Vec3::new(l as f32, -1.0, 2.0),
                    dir: *dir,
                };
            }
            let mut lanes = super::PacketRays::default();
            lanes.set(&packet, true);
            for (l, ray) in packet.rays.iter().enumerate() {
                let inv = Vec3::new(
                    lanes.inv_dir[0][l],
                    lanes.inv_dir[1][l],
                    lanes.inv_dir[2][l],
                );
                assert_eq!(bits(inv), bits(safe_inverse(ray.dir)), "lane {l}: {ray:?}");
                let (packed, alone) = (lanes.sheared(l), ShearedRay::new(ray));
                for (a, b) in [
                    (packed.row_x, alone.row_x),
                    (packed.row_y, alone.row_y),
                    (packed.row_z, alone.row_z),
                    (packed.origin, alone.origin),
                ] {
                    assert_eq!(bits(a), bits(b), "lane {l}: {ray:?}");
                }
            }
        }
    }

    /// Each ray traced in a packet with others of `rays`, at a lane that depends on the ray,
    /// gets brute force's answer. A third of the packets hold the ray alone (it walks alone
    /// from the root), a third most lanes, a third the ray and the last lane of each group
    /// of eight (enough to walk as a packet, each group's only ray in its top lane, for
    /// the shape tests that skip the groups without one); a bit beyond the packet's lanes is
    /// set too and must be ignored. Shape tests by groups of eight lanes and of sixteen (the
    /// AVX-512 level's) find the same. Brute force looks in `truth`: `scene` itself, or the same scene with its
    /// instances flattened.
    fn assert_packets(scene: &CpuScene, truth: &CpuScene, rays: &[Ray]) -> usize {
        let tracer = RefCell::new(Tracer::new(scene));
        let packet_of = |ray: &Ray, t_max: f32| {
            let start = ray.origin.x.to_bits() as usize % rays.len();
            let lane = start % PACKET;
            let beyond = Lanes::from(1u8).checked_shl(PACKET as u32).unwrap_or(0);
            let others = match start % 3 {
                0 => !0x0040_4040,
                1 => 0x8080_8080,
                _ => 0,
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
        let tolerance = if std::ptr::eq(scene, truth) {
            1e-5
        } else {
            1e-4
        };
        assert_like_brute_force(
            truth,
            tolerance,
            rays,
            "packet",
            &mut |r, t| {
                let (packet, lane) = packet_of(r, t);
                let (mut narrow, mut wide) = (PacketHits::default(), PacketHits::default());
                tracer
                    .borrow_mut()
                    .intersect_packet::<false>(&packet, &mut narrow);
                tracer
                    .borrow_mut()
                    .intersect_packet::<true>(&packet, &mut wide);
                let hit = |h: &PacketHits| (h.found() >> lane & 1 != 0).then(|| h.nearest(lane));
                assert_eq!(
                    hit(&narrow),
                    hit(&wide),
                    "shape tests by 8 and 16 lanes: {r:?}"
                );
                hit(&narrow)
            },
            &mut |r, t| {
                let (packet, lane) = packet_of(r, t);
                let narrow = tracer.borrow_mut().occluded_packet::<false>(&packet);
                let wide = tracer.borrow_mut().occluded_packet::<true>(&packet);
                assert_eq!(narrow, wide, "shape tests by 8 and 16 lanes: {r:?}");
                narrow >> lane & 1 != 0
            },
        )
    }

    #[test]
    fn packets_match_brute_force() {
        let mut rng = StdRng::seed_from_u64(17);
        for count in [1, 5, 40] {
            let prepared = prepare(random_objects(&mut rng, count));
            let scene = CpuScene::new(&prepared);
            let rays: Vec<Ray> = (0..2000)
                .map(|_| ray_into_scene(&mut rng, &scene))
                .collect();
            assert!(assert_packets(&scene, &scene, &rays) > 20);
        }
        let prepared = prepare(vec![object(
            "big",
            Shape::Mesh(random_mesh(&mut rng, 20_000, Vec3::ZERO)),
        )]);
        let scene = CpuScene::new(&prepared);
        let rays: Vec<Ray> = (0..300).map(|_| random_ray(&mut rng, 1.0)).collect();
        assert!(assert_packets(&scene, &scene, &rays) > 50);
    }

    #[test]
    fn packets_through_instances_find_what_the_flattened_scene_holds() {
        let mut rng = StdRng::seed_from_u64(23);
        let objects = instanced_objects(&mut rng);
        let (prepared, flat) = (prepare(objects.clone()), prepare(flattened(&objects)));
        let (scene, truth) = (CpuScene::new(&prepared), CpuScene::new(&flat));
        let rays: Vec<Ray> = (0..2000)
            .map(|_| ray_into_scene(&mut rng, &scene))
            .collect();
        assert!(assert_packets(&scene, &truth, &rays) > 200);
    }
}
