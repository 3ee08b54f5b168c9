//! The acceleration structure both backends walk: an obvhs BVH2 over every primitive of the
//! scene (PLOC build, reinsertion, SAH-driven leaf collapse) collapsed into a 4-wide tree
//! whose four child boxes a ray tests at once (in SIMD lanes on the CPU, as `vec4f`s in
//! `bvh.wgsl`). A ray visits about half as many nodes as in the binary tree.

use std::time::Duration;

use obvhs::BvhBuildParams;
use obvhs::aabb::Aabb;
use obvhs::bvh2::builder::build_bvh2;
use obvhs::bvh2::node::Bvh2Node;
use rayon::slice::ParallelSliceMut;

use crate::gpu_types::{GpuPrimitive, GpuWideNode, INSTANCE, SHAPE_LEAF};

/// A binary tree over primitive boxes, and the order in which its leaves hold them.
pub(crate) struct BinaryTree {
    /// The nodes, root at 0: an inner node's children are `first_index` and
    /// `first_index + 1`; a leaf holds `first_index .. first_index + prim_count` of the
    /// reordered primitives.
    pub nodes: Vec<Bvh2Node>,
    /// Per leaf slot, the index of the primitive box it holds.
    pub primitive_indices: Vec<u32>,
}

/// Above this many primitives the tree is built with obvhs' fast preset (a narrower
/// nearest-neighbour search, fewer reinsertions), below with its medium one. On a 4M-triangle
/// mesh the fast build saved 0.4-1.2 s of a 7 s render at the same CPU samples/s
/// (BENCHMARKS.md); scenes this small build in a fraction of a second either way.
const FAST_BUILD_ABOVE: usize = 500_000;

/// obvhs' build preset for `count` primitives.
fn preset(count: usize) -> BvhBuildParams {
    if count > FAST_BUILD_ABOVE {
        BvhBuildParams::fast_build()
    } else {
        BvhBuildParams::medium_build()
    }
}

/// Builds the binary tree over `bounds` (not empty) with obvhs' medium preset
/// (SAH-quality PLOC with reinsertion; its fast one for large inputs), on every core.
/// Primitives with the very same box share one leaf: PLOC pairs nearest neighbours and
/// breaks ties one way, so n identical boxes made a chain n/3 deep in O(n^2) (20,000
/// coincident triangles: 11 s).
pub(crate) fn build_binary(bounds: &[Aabb]) -> BinaryTree {
    let groups = IdenticalBoxes::of(bounds);
    let mut build_time = Duration::ZERO;
    if groups.count() == bounds.len() {
        let tree = build_bvh2(bounds, preset(bounds.len()), &mut build_time);
        return BinaryTree {
            nodes: tree.nodes,
            primitive_indices: tree.primitive_indices,
        };
    }
    let unique: Vec<Aabb> = (0..groups.count())
        .map(|g| bounds[groups.members_of(g as u32)[0] as usize])
        .collect();
    let tree = build_bvh2(&unique, preset(unique.len()), &mut build_time);
    // Each leaf slot of the tree over unique boxes becomes the slots of its group.
    let mut slot_starts = Vec::with_capacity(tree.primitive_indices.len() + 1);
    let mut primitive_indices = Vec::with_capacity(bounds.len());
    for &group in &tree.primitive_indices {
        slot_starts.push(primitive_indices.len() as u32);
        primitive_indices.extend_from_slice(groups.members_of(group));
    }
    slot_starts.push(primitive_indices.len() as u32);
    let mut nodes = tree.nodes;
    for node in nodes.iter_mut().filter(|n| n.prim_count > 0) {
        let first = slot_starts[node.first_index as usize];
        node.prim_count = slot_starts[(node.first_index + node.prim_count) as usize] - first;
        node.first_index = first;
    }
    BinaryTree {
        nodes,
        primitive_indices,
    }
}

/// Primitives grouped by box, bit for bit: group `g` is
/// `members[starts[g] .. starts[g + 1]]`.
struct IdenticalBoxes {
    members: Vec<u32>,
    starts: Vec<u32>,
}

impl IdenticalBoxes {
    fn of(bounds: &[Aabb]) -> Self {
        let key = |i: u32| {
            let b = &bounds[i as usize];
            [b.min.x, b.min.y, b.min.z, b.max.x, b.max.y, b.max.z].map(f32::to_bits)
        };
        let mut members: Vec<u32> = (0..bounds.len() as u32).collect();
        members.par_sort_unstable_by_key(|&i| key(i));
        let mut starts: Vec<u32> = (0..members.len())
            .filter(|&i| i == 0 || key(members[i]) != key(members[i - 1]))
            .map(|i| i as u32)
            .collect();
        starts.push(members.len() as u32);
        Self { members, starts }
    }

    fn count(&self) -> usize {
        self.starts.len() - 1
    }

    fn members_of(&self, group: u32) -> &[u32] {
        let g = group as usize;
        &self.members[self.starts[g] as usize..self.starts[g + 1] as usize]
    }
}

/// The one node of a tree without primitives: four unused children, which no ray enters.
pub(crate) fn empty_tree() -> Vec<GpuWideNode> {
    vec![GpuWideNode {
        lo_x: [f32::INFINITY; 4],
        lo_y: [f32::INFINITY; 4],
        lo_z: [f32::INFINITY; 4],
        hi_x: [f32::NEG_INFINITY; 4],
        hi_y: [f32::NEG_INFINITY; 4],
        hi_z: [f32::NEG_INFINITY; 4],
        first: [0; 4],
        count: [0; 4],
    }]
}

/// Appends the 4-wide form of `tree` to `out` in pre-order and returns its root's index.
/// Each wide node takes the binary node's children and keeps opening its largest inner child
/// (by surface area) until it has four. A leaf's primitives are the tree's leaf slots plus
/// `primitive_base`; a leaf child holding a whole shape (`is_shape` of its first primitive
/// slot ..) is marked [`SHAPE_LEAF`]; an unused child has an inverted box.
pub(crate) fn collapse(
    tree: &BinaryTree,
    is_shape: &[bool],
    primitive_base: u32,
    out: &mut Vec<GpuWideNode>,
) -> u32 {
    collapse_node(&tree.nodes, is_shape, primitive_base, 0, out)
}

/// Appends the 4-wide form of the binary subtree at `root`; returns its node index.
fn collapse_node(
    nodes: &[Bvh2Node],
    is_shape: &[bool],
    primitive_base: u32,
    root: u32,
    out: &mut Vec<GpuWideNode>,
) -> u32 {
    let index = out.len() as u32;
    out.extend(empty_tree());
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
                let area = |i: u32| nodes[i as usize].aabb.half_area();
                area(**a).total_cmp(&area(**b))
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
            let slots = c.first_index as usize..(c.first_index + c.prim_count) as usize;
            let shape = is_shape[slots].iter().any(|&s| s);
            let mark = if shape { SHAPE_LEAF } else { 0 };
            (primitive_base + c.first_index, c.prim_count | mark)
        } else {
            (
                collapse_node(nodes, is_shape, primitive_base, child, out),
                0,
            )
        };
        let n = &mut out[index as usize];
        let (lo, hi) = (c.aabb.min, c.aabb.max);
        n.lo_x[lane] = lo.x;
        n.lo_y[lane] = lo.y;
        n.lo_z[lane] = lo.z;
        n.hi_x[lane] = hi.x;
        n.hi_y[lane] = hi.y;
        n.hi_z[lane] = hi.z;
        n.first[lane] = first;
        n.count[lane] = count;
    }
    index
}

/// Whether child `lane` of `node` is used (an unused one has an inverted box).
pub fn lane_used(node: &GpuWideNode, lane: usize) -> bool {
    node.lo_x[lane] <= node.hi_x[lane]
}

/// Per node of `nodes` (in pre-order, as [`collapse`] lays them out), its parent's index
/// times 4 plus its lane there; [`NO_PARENT`] for the root. The GPU walk climbs it when its
/// traversal stack is full (`trace_stackless` in `bvh.wgsl`).
pub fn parents(nodes: &[GpuWideNode]) -> Vec<u32> {
    let mut parents = vec![NO_PARENT; nodes.len()];
    for (index, node) in nodes.iter().enumerate() {
        for lane in (0..4).filter(|&lane| lane_used(node, lane) && node.count[lane] == 0) {
            parents[node.first[lane] as usize] = (index as u32) << 2 | lane as u32;
        }
    }
    parents
}

/// The root's entry in [`parents`].
pub const NO_PARENT: u32 = u32::MAX;

/// Most entries the traversal stack of WGSL `trace_scene` needs in the trees of `nodes`
/// (in pre-order: the top level's at 0, each shared mesh's after it, leaves indexing
/// `primitives`) to finish every walk with it. At each node the walk tests the entered
/// leaves that hold shapes at once (walking the meshes of the placements among them) and
/// pushes the other entered children but the nearest; the stack holds only the pending
/// entries of the current node and its ancestors (an entry is popped before its node is
/// visited). A placement's mesh is walked above the top level's entries (`trace_mesh`), so
/// the bound is the top level's plus the deepest mesh tree's. At least 1: WGSL has no empty
/// arrays.
pub fn stack_bound(nodes: &[GpuWideNode], primitives: &[GpuPrimitive]) -> u32 {
    // Most entries pushed along one path down from each node; children come after their
    // parent in pre-order, so a reverse sweep sees them first (no recursion on deep trees).
    let mut below = vec![0u32; nodes.len()];
    let mut mesh_roots = Vec::new();
    for (index, n) in nodes.iter().enumerate().rev() {
        let used = (0..4).filter(|&lane| lane_used(n, lane));
        let pushed = used
            .clone()
            .filter(|&lane| n.count[lane] & SHAPE_LEAF == 0)
            .count() as u32;
        for lane in used.clone().filter(|&lane| n.count[lane] & SHAPE_LEAF != 0) {
            let first = n.first[lane] as usize;
            let count = (n.count[lane] & !SHAPE_LEAF) as usize;
            mesh_roots.extend(
                primitives[first..first + count]
                    .iter()
                    .filter(|p| p.triangle == INSTANCE)
                    .map(|p| p.root),
            );
        }
        let deepest = used
            .filter(|&lane| n.count[lane] == 0)
            .map(|lane| below[n.first[lane] as usize])
            .max()
            .unwrap_or(0);
        below[index] = pushed.saturating_sub(1) + deepest;
    }
    let mesh = mesh_roots
        .iter()
        .map(|&root| below[root as usize])
        .max()
        .unwrap_or(0);
    (below[0] + mesh).max(1)
}
