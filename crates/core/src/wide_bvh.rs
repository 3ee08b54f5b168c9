//! The acceleration structure both backends walk: [`GpuScene`]'s binary BVH collapsed into a
//! 4-wide one, whose four child boxes are tested at once (in SIMD lanes on the CPU, glam's
//! `Vec4`; as `vec4f`s by WGSL `trace_scene` in `bvh.wgsl`, which reads [`GpuWideNode`]s).
//!
//! A ray visits about half as many nodes as in the binary tree and tests their children in
//! one go. The primitive tests are [`crate::trace`]'s, the WGSL twins, so hits are the same;
//! only the order of the walk differs (which can change the answer between two primitives at
//! exactly the same distance).

use bytemuck::Zeroable;
use glam::Vec4;
use obvhs::aabb::Aabb;

use crate::accel::GpuScene;
use crate::gpu::{GpuBvhNode, GpuWideNode, NO_TRIANGLE, SHAPE_LEAF};
use crate::packet::Lanes;
use crate::trace::{Hit, Ray, safe_inverse};

/// Four child boxes in structure-of-arrays form, and what each child is.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Node4 {
    /// Per axis x, y, z: the children's minimum coordinates. An unused lane holds an
    /// inverted box (+inf to -inf) that no ray enters.
    pub lo: [Vec4; 3],
    /// Per axis: the children's maximum coordinates.
    pub hi: [Vec4; 3],
    /// Per child: the index of an inner node, or a leaf's first primitive.
    pub first: [u32; 4],
    /// Per child: the number of primitives of a leaf; 0 for an inner node or an unused lane.
    pub count: [u32; 4],
}

/// A 4-wide BVH over a [`GpuScene`]'s primitives.
#[derive(Debug, Clone, Default)]
pub struct WideBvh {
    /// The nodes, root at 0; empty when the scene has no primitives.
    pub(crate) nodes: Vec<Node4>,
    /// Per leaf primitive: whether it is a whole shape rather than a triangle.
    pub(crate) is_shape: Vec<bool>,
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
    /// test, with the min/max of each pair chosen by the direction's sign.
    #[inline(always)]
    fn enter(&self, node: &Node4, t_max: f32) -> (Vec4, u32) {
        let mut t_near = Vec4::ZERO;
        let mut t_far = Vec4::splat(t_max);
        for axis in 0..3 {
            let (near, far) = if self.backwards[axis] {
                (node.hi[axis], node.lo[axis])
            } else {
                (node.lo[axis], node.hi[axis])
            };
            let (o, inv) = (self.origin[axis], self.inv_dir[axis]);
            t_near = t_near.max((near - o) * inv);
            t_far = t_far.min((far - o) * inv);
        }
        (t_near, t_near.cmple(t_far).bitmask())
    }
}

impl WideBvh {
    /// Collapses the binary tree of `scene`.
    pub fn build(scene: &GpuScene) -> Self {
        let mut bvh = Self {
            is_shape: scene
                .primitives
                .iter()
                .map(|p| p.triangle == NO_TRIANGLE)
                .collect(),
            ..Self::default()
        };
        if !scene.primitives.is_empty() {
            bvh.collapse(&scene.nodes, 0);
        }
        bvh
    }

    /// Whether the leaf of `count` primitives from `first` holds a shape.
    fn holds_shape(&self, first: u32, count: u32) -> bool {
        self.is_shape[first as usize..(first + count) as usize]
            .iter()
            .any(|&s| s)
    }

    /// The nodes in the layout the GPU reads, leaves holding shapes marked [`SHAPE_LEAF`].
    /// Never empty: without primitives, one node of four unused children, which no ray
    /// enters.
    pub fn gpu_nodes(&self) -> Vec<GpuWideNode> {
        if self.nodes.is_empty() {
            return vec![GpuWideNode {
                lo_x: [f32::INFINITY; 4],
                lo_y: [f32::INFINITY; 4],
                lo_z: [f32::INFINITY; 4],
                hi_x: [f32::NEG_INFINITY; 4],
                hi_y: [f32::NEG_INFINITY; 4],
                hi_z: [f32::NEG_INFINITY; 4],
                ..GpuWideNode::zeroed()
            }];
        }
        self.nodes
            .iter()
            .map(|n| GpuWideNode {
                lo_x: n.lo[0].to_array(),
                lo_y: n.lo[1].to_array(),
                lo_z: n.lo[2].to_array(),
                hi_x: n.hi[0].to_array(),
                hi_y: n.hi[1].to_array(),
                hi_z: n.hi[2].to_array(),
                first: n.first,
                count: [0, 1, 2, 3].map(|lane| {
                    let (first, count) = (n.first[lane], n.count[lane]);
                    if count > 0 && self.holds_shape(first, count) {
                        count | SHAPE_LEAF
                    } else {
                        count
                    }
                }),
            })
            .collect()
    }

    /// Most entries the traversal stack of WGSL `trace_scene` can hold at once. At each node
    /// the walk tests the entered leaves that hold shapes at once and pushes the other
    /// entered children but the nearest, and the stack holds only the pending entries of
    /// the current node and its ancestors (an entry is popped before its node is visited).
    /// The integrator's stack is sized from it.
    pub fn stack_bound(&self) -> u32 {
        if self.nodes.is_empty() {
            return 1;
        }
        // At least one entry: WGSL has no empty arrays.
        self.path_pushes(0).max(1)
    }

    /// Most entries pushed along one path down from `node`.
    fn path_pushes(&self, node: u32) -> u32 {
        let n = &self.nodes[node as usize];
        let used = (0..4).filter(|&lane| n.lo[0][lane] <= n.hi[0][lane]);
        let pushed = used
            .filter(|&lane| n.count[lane] == 0 || !self.holds_shape(n.first[lane], n.count[lane]))
            .count() as u32;
        let below = (0..4)
            .filter(|&lane| n.lo[0][lane] <= n.hi[0][lane] && n.count[lane] == 0)
            .map(|lane| self.path_pushes(n.first[lane]))
            .max()
            .unwrap_or(0);
        pushed.saturating_sub(1) + below
    }

    /// Appends the 4-wide form of the binary subtree at `root`; returns its node index.
    /// Each wide node takes the binary node's children and keeps opening its largest inner
    /// child (by surface area) until it has four.
    fn collapse(&mut self, nodes: &[GpuBvhNode], root: u32) -> u32 {
        let index = self.nodes.len() as u32;
        self.nodes.push(Node4 {
            lo: [Vec4::INFINITY; 3],
            hi: [Vec4::NEG_INFINITY; 3],
            first: [0; 4],
            count: [0; 4],
        });
        let node = &nodes[root as usize];
        let mut children: Vec<u32> = if node.prim_count > 0 {
            vec![root]
        } else {
            vec![node.first_index, node.first_index + 1]
        };
        while children.len() < 4 {
            let widest = children
                .iter()
                .enumerate()
                .filter(|(_, c)| nodes[**c as usize].prim_count == 0)
                .max_by(|(_, a), (_, b)| {
                    half_area(&nodes[**a as usize]).total_cmp(&half_area(&nodes[**b as usize]))
                })
                .map(|(i, _)| i);
            let Some(i) = widest else { break };
            let opened = children.swap_remove(i);
            let first = nodes[opened as usize].first_index;
            children.extend([first, first + 1]);
        }
        for (lane, &child) in children.iter().enumerate() {
            let c = &nodes[child as usize];
            let (first, count) = if c.prim_count > 0 {
                (c.first_index, c.prim_count)
            } else {
                (self.collapse(nodes, child), 0)
            };
            let n = &mut self.nodes[index as usize];
            for axis in 0..3 {
                n.lo[axis][lane] = c.aabb_min[axis];
                n.hi[axis][lane] = c.aabb_max[axis];
            }
            n.first[lane] = first;
            n.count[lane] = count;
        }
        index
    }
}

/// Ray queries from one thread against a scene and its [`WideBvh`], one ray at a time or in
/// packets ([`crate::packet`]). It keeps the traversal stacks that every query reuses, so
/// that queries allocate nothing once they have grown to the tree's needs, and so that the
/// whole walk inlines into the caller (compiled for its instruction set).
#[derive(Debug, Clone)]
pub struct Tracer<'a> {
    /// The scene.
    pub scene: &'a GpuScene,
    /// Its tree.
    pub bvh: &'a WideBvh,
    /// The single-ray walk's stack.
    pub(crate) stack: Vec<Entry>,
    /// The packet walk's stack: nodes and the rays that entered them.
    pub(crate) packet_stack: Vec<(u32, Lanes)>,
}

impl<'a> Tracer<'a> {
    /// Queries against `scene` in `bvh`, which must have been built from it.
    pub fn new(scene: &'a GpuScene, bvh: &'a WideBvh) -> Self {
        Self {
            scene,
            bvh,
            stack: Vec::new(),
            packet_stack: Vec::new(),
        }
    }

    /// Nearest hit in `(0, t_max)`.
    #[inline(always)]
    pub fn intersect(&mut self, ray: &Ray, t_max: f32) -> Option<Hit> {
        let hit = self.trace(ray, t_max, false);
        (hit.object != u32::MAX).then_some(hit)
    }

    /// Whether anything lies on the ray in `(0, t_max)`.
    #[inline(always)]
    pub fn occluded(&mut self, ray: &Ray, t_max: f32) -> bool {
        self.trace(ray, t_max, true).object != u32::MAX
    }

    #[inline(always)]
    fn trace(&mut self, ray: &Ray, t_max: f32, any_hit: bool) -> Hit {
        let mut hit = Hit::none(t_max);
        if !self.bvh.nodes.is_empty() {
            let lanes = RayLanes::new(ray);
            self.stack.clear();
            let walk = Walk {
                bvh: self.bvh,
                scene: self.scene,
                ray,
                lanes: &lanes,
                any_hit,
            };
            walk.tree(&mut self.stack, 0, &mut hit);
        }
        hit
    }
}

/// Half the surface area of a binary node's box.
fn half_area(node: &GpuBvhNode) -> f32 {
    Aabb::new(node.aabb_min.into(), node.aabb_max.into()).half_area()
}

/// One ray query in progress.
pub(crate) struct Walk<'a> {
    pub bvh: &'a WideBvh,
    pub scene: &'a GpuScene,
    pub ray: &'a Ray,
    pub lanes: &'a RayLanes,
    pub any_hit: bool,
}

impl Walk<'_> {
    /// Walks the subtree at `root`, nearest boxes first, using `stack` above its
    /// current length. A node's entered leaves are tested as it is visited (nearest first);
    /// inner nodes are pushed. An any-hit query stops at its first hit.
    #[inline(always)]
    pub(crate) fn tree(&self, stack: &mut Vec<Entry>, root: u32, hit: &mut Hit) {
        let base = stack.len();
        let mut node = root;
        loop {
            let n = &self.bvh.nodes[node as usize];
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
                if n.count[lane] > 0 && t < hit.t {
                    for i in n.first[lane]..n.first[lane] + n.count[lane] {
                        self.scene.intersect_primitive(i, self.ray, hit);
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
