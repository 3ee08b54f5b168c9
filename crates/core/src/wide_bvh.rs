//! The acceleration structure both backends walk: [`GpuScene`]'s binary BVHs collapsed into
//! 4-wide ones, whose four child boxes are tested at once (in SIMD lanes on the CPU, glam's
//! `Vec4`; as `vec4f`s by WGSL `trace_scene` in `bvh.wgsl`, which reads [`GpuWideNode`]s).
//!
//! A ray visits about half as many nodes as in the binary tree and tests their children in
//! one go. The primitive tests are [`crate::trace`]'s, the WGSL twins, so hits are the same;
//! only the order of the walk differs (which can change the answer between two primitives at
//! exactly the same distance).

use std::ops::Range;

use bytemuck::Zeroable;
use glam::{Vec3, Vec4};
use obvhs::aabb::Aabb;

use crate::accel::GpuScene;
use crate::gpu::{GpuBvhNode, GpuObject, GpuTriangle, GpuWideNode, KIND_MESH};
use crate::packet::Lanes;
use crate::trace::{Hit, Ray, intersect_triangle_edges, safe_inverse};

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

/// A 4-wide BVH over a [`GpuScene`]: one tree over the objects and one per mesh.
#[derive(Debug, Clone, Default)]
pub struct WideBvh {
    /// Every tree's nodes; the top level's root is node 0 (when there are objects).
    pub(crate) nodes: Vec<Node4>,
    /// Per object of the scene: the root of its mesh's tree (unused for other shapes).
    pub(crate) mesh_roots: Vec<u32>,
    /// Per triangle: its first corner and the two edges from it (`intersect_triangle`'s
    /// subtractions done once, with the same results).
    pub(crate) triangles: Vec<[Vec3; 3]>,
    /// Whether the scene has any object.
    pub(crate) has_objects: bool,
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
    /// Collapses the binary trees of `scene` (its top level and every mesh's BLAS).
    pub fn build(scene: &GpuScene) -> Self {
        let mut bvh = Self {
            has_objects: scene.object_count > 0,
            ..Self::default()
        };
        if bvh.has_objects {
            bvh.collapse(&scene.nodes, 0);
        }
        bvh.mesh_roots = scene
            .objects
            .iter()
            .map(|o| {
                if o.kind == KIND_MESH {
                    bvh.collapse(&scene.nodes, o.blas_root)
                } else {
                    0
                }
            })
            .collect();
        bvh.triangles = (0..(scene.vertices.len() / 3) as u32)
            .map(|i| {
                let [v0, v1, v2] = scene.triangle(i);
                [v0, v1 - v0, v2 - v0]
            })
            .collect();
        bvh
    }

    /// The nodes in the layout the GPU reads. Never empty (a placeholder when there are no
    /// objects).
    pub fn gpu_nodes(&self) -> Vec<GpuWideNode> {
        if self.nodes.is_empty() {
            return vec![GpuWideNode::zeroed()];
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
                count: n.count,
            })
            .collect()
    }

    /// The triangles as the GPU reads them. Never empty (a placeholder when there are none).
    pub fn gpu_triangles(&self) -> Vec<GpuTriangle> {
        if self.triangles.is_empty() {
            return vec![GpuTriangle::zeroed()];
        }
        self.triangles
            .iter()
            .map(|[v0, e1, e2]| GpuTriangle {
                v0: v0.to_array(),
                e1: e1.to_array(),
                e2: e2.to_array(),
                ..GpuTriangle::zeroed()
            })
            .collect()
    }

    /// `scene`'s objects as the GPU reads them: a mesh's `blas_root` is the root of its tree
    /// here instead of in the binary nodes.
    pub fn gpu_objects(&self, scene: &GpuScene) -> Vec<GpuObject> {
        scene
            .objects
            .iter()
            .zip(&self.mesh_roots)
            .map(|(o, &root)| GpuObject {
                blas_root: if o.kind == KIND_MESH { root } else { 0 },
                ..*o
            })
            .collect()
    }

    /// Most entries the traversal stack of WGSL `trace_scene` can hold at once for `scene`
    /// (from which this tree was built). At each node the walk pushes the entered children
    /// still to visit but the nearest (inner ones in the top level, whose leaves it tests at
    /// once, pushing their meshes; leaves too in a mesh's tree), and the stack holds only the
    /// pending entries of the current node and its ancestors; a mesh's tree is walked above
    /// the marker that replaces its entry. The integrator's stack is sized from it.
    pub fn stack_bound(&self, scene: &GpuScene) -> u32 {
        if !self.has_objects {
            return 1;
        }
        let meshes_in = |first: u32, count: u32| {
            (first..first + count)
                .filter(|&i| scene.objects[i as usize].kind == KIND_MESH)
                .count() as u32
        };
        let top = self.path_pushes(0, Some(&meshes_in));
        let mesh = scene.objects[..scene.object_count as usize]
            .iter()
            .zip(&self.mesh_roots)
            .filter(|(o, _)| o.kind == KIND_MESH)
            .map(|(_, &root)| self.path_pushes(root, None))
            .max()
            .unwrap_or(0);
        top + mesh + 1
    }

    /// Most entries pushed along one path down from `node`. With `tested_leaves` a node's
    /// leaves are tested when it is visited, a leaf of `count` primitives from `first`
    /// pushing `tested_leaves(first, count)` entries; without, leaves are pushed like inner
    /// children.
    fn path_pushes(&self, node: u32, tested_leaves: Option<&dyn Fn(u32, u32) -> u32>) -> u32 {
        let n = &self.nodes[node as usize];
        let used = (0..4).filter(|&lane| n.lo[0][lane] <= n.hi[0][lane]);
        let (inner, leaves): (Vec<usize>, Vec<usize>) = used.partition(|&lane| n.count[lane] == 0);
        let at_node = match tested_leaves {
            Some(pushes) => {
                leaves
                    .iter()
                    .map(|&lane| pushes(n.first[lane], n.count[lane]))
                    .sum::<u32>()
                    + (inner.len() as u32).saturating_sub(1)
            }
            None => (inner.len() + leaves.len()).saturating_sub(1) as u32,
        };
        let below = inner
            .iter()
            .map(|&lane| self.path_pushes(n.first[lane], tested_leaves))
            .max()
            .unwrap_or(0);
        at_node + below
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
        if self.bvh.has_objects {
            let lanes = RayLanes::new(ray);
            self.stack.clear();
            let walk = Walk {
                bvh: self.bvh,
                scene: self.scene,
                ray,
                lanes: &lanes,
                any_hit,
            };
            walk.tree(&mut self.stack, 0, &mut hit, |stack, range, hit| {
                walk.objects(stack, range, hit)
            });
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
    /// Walks the tree at `root`, nearest boxes first, using `stack` above its current
    /// length. Leaves go to `leaf` as their node is visited (nearest first); inner nodes are
    /// pushed. Returns false as soon as `leaf` does (an any-hit query has its answer).
    #[inline(always)]
    pub(crate) fn tree(
        &self,
        stack: &mut Vec<Entry>,
        root: u32,
        hit: &mut Hit,
        mut leaf: impl FnMut(&mut Vec<Entry>, Range<u32>, &mut Hit) -> bool,
    ) -> bool {
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
                    let (first, count) = (n.first[lane], n.count[lane]);
                    if !leaf(stack, first..first + count, hit) {
                        return false;
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
                    return true;
                }
                let Some(entry) = stack.pop() else {
                    return true;
                };
                if entry.t < hit.t {
                    node = entry.node;
                    break;
                }
            }
        }
    }

    /// Tests the top-level objects `range`, walking the tree of each mesh among them.
    /// Returns false once an any-hit query has its answer.
    #[inline(always)]
    pub(crate) fn objects(&self, stack: &mut Vec<Entry>, range: Range<u32>, hit: &mut Hit) -> bool {
        for i in range {
            if self.scene.objects[i as usize].kind == KIND_MESH {
                let root = self.bvh.mesh_roots[i as usize];
                let found = !self.tree(stack, root, hit, |_, triangles, hit| {
                    self.triangles(i, triangles, hit)
                });
                if found {
                    return false;
                }
            } else {
                self.scene.intersect_shape(i, self.ray, hit);
            }
        }
        !(self.any_hit && hit.object != u32::MAX)
    }

    /// Tests the triangles `range` of mesh object `object`. Returns false once an any-hit
    /// query has its answer.
    #[inline(always)]
    pub(crate) fn triangles(&self, object: u32, range: Range<u32>, hit: &mut Hit) -> bool {
        for tri in range {
            let [v0, e1, e2] = self.bvh.triangles[tri as usize];
            let (t, b1, b2) = intersect_triangle_edges(v0, e1, e2, self.ray, hit.t);
            if t < hit.t {
                *hit = Hit {
                    t,
                    object,
                    primitive: tri,
                    b1,
                    b2,
                };
            }
        }
        !(self.any_hit && hit.object != u32::MAX)
    }
}
