//! The acceleration structure both backends walk: an obvhs BVH2 over every primitive of the
//! scene (PLOC build, reinsertion, SAH-driven leaf collapse) collapsed into a 4-wide tree
//! whose four child boxes a ray tests at once (in SIMD lanes on the CPU, as `vec4f`s in
//! `bvh.wgsl`). A ray visits about half as many nodes as in the binary tree.

use std::ops::Range;
use std::time::Duration;

use glam::Vec3A;
use obvhs::BvhBuildParams;
use obvhs::aabb::Aabb;
use obvhs::bvh2::builder::build_bvh2;
use obvhs::bvh2::node::Bvh2Node;
use obvhs::ploc::morton::morton_encode_u32;
use rayon::prelude::*;

use crate::gpu_types::{GpuPrimitive, GpuWideNode, INSTANCE, SHAPE_LEAF};

/// A binary tree over primitive boxes, and the order in which its leaves hold them.
struct BinaryTree {
    /// The nodes, root at 0: an inner node's children are `first_index` and
    /// `first_index + 1`; a leaf holds `first_index .. first_index + prim_count` of the
    /// reordered primitives.
    nodes: Vec<Bvh2Node>,
    /// Per leaf slot, the index of the primitive box it holds.
    primitive_indices: Vec<u32>,
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

/// When a tree is built in spatial chunks: with more than `above` primitives, in chunks of
/// at most `size` (obvhs' builder keeps about 224 bytes of scratch a primitive it builds at
/// once, more than the scene itself; a few chunks at a time bound it).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Chunks {
    /// Most primitives built in one piece.
    pub above: usize,
    /// Most primitives in one chunk.
    pub size: usize,
}

impl Chunks {
    /// Scenes up to the fast preset's threshold (every reference scene) are built whole;
    /// larger ones in chunks of 131,072 primitives (about 29 MB of builder scratch). Larger
    /// chunks build slower: a 16.8M-triangle mesh in chunks of 1,048,576 took 12.3 s to its
    /// first frame against 7.2-7.4 s (BENCHMARKS.md).
    pub const DEFAULT: Self = Self {
        above: FAST_BUILD_ABOVE,
        size: 1 << 17,
    };
}

/// Builds the 4-wide tree over `count` primitives (boxes by `bound_of`, `count` > 0) and
/// appends it to `out` in pre-order; returns its root and the leaf order (per leaf slot,
/// the primitive it holds). A leaf's slots are numbered from `primitive_base`; a leaf
/// holding a primitive for which `is_shape` holds is marked [`SHAPE_LEAF`].
///
/// Up to `chunks.above` primitives one obvhs build covers them all. Above, the primitives
/// are sorted along a Morton curve and split at its cells into chunks of at most
/// `chunks.size`; a tree over the chunks' boxes (one chunk a leaf) is the top, and
/// the chunks' own trees are built (a few at a time) and collapsed under it, so the
/// builder's scratch is a few chunks'. The result does not depend on the thread count.
pub(crate) fn build(
    count: usize,
    bound_of: &(dyn Fn(u32) -> Aabb + Sync),
    is_shape: &(dyn Fn(u32) -> bool + Sync),
    primitive_base: u32,
    chunks: Chunks,
    out: &mut Vec<GpuWideNode>,
) -> (u32, Vec<u32>) {
    let params = preset(count);
    if count <= chunks.above {
        let bounds: Vec<Aabb> = (0..count as u32).into_par_iter().map(bound_of).collect();
        let tree = build_binary(&bounds, params);
        drop(bounds);
        let order = tree.primitive_indices;
        let root = collapse_node(
            &tree.nodes,
            &|leaf| leaf_lane(leaf, &order, is_shape, primitive_base),
            0,
            out,
        );
        return (root, order);
    }
    let curve = morton_order(count, bound_of);
    let mut ranges = Vec::new();
    let size = chunks.size;
    split_cells(&curve, size, 0, &mut ranges);
    let boxes: Vec<Aabb> = ranges
        .par_iter()
        .map(|r| {
            curve[r.clone()]
                .iter()
                .fold(Aabb::empty(), |b, &(_, p)| b.union(&bound_of(p)))
        })
        .collect();
    // The top: one chunk a leaf, each leaf lane a link to be set once its chunk is built.
    let top_params = BvhBuildParams {
        max_prims_per_leaf: 1,
        ..BvhBuildParams::medium_build()
    };
    let top = build_bvh2(&boxes, top_params, &mut Duration::default());
    let top_start = out.len();
    let root = collapse_node(
        &top.nodes,
        &|leaf| (top.primitive_indices[leaf.first_index as usize], CHUNK_LINK),
        0,
        out,
    );
    let top_end = out.len();
    // Up to as many chunks at a time as there are threads (obvhs' own build keeps two cores
    // half idle on a chunk) while their scratch stays under 28 bytes a primitive of the
    // scene (an eighth of them built at once), each collapsed on its own and moved in after
    // the last.
    let mut order = Vec::with_capacity(count);
    let mut chunk_roots = Vec::with_capacity(ranges.len());
    let at_once = (count / (8 * size)).clamp(1, rayon::current_num_threads().max(1));
    for batch in ranges.chunks(at_once) {
        let built: Vec<(Vec<GpuWideNode>, Vec<u32>)> = batch
            .par_iter()
            .map(|range| {
                let members = &curve[range.clone()];
                let bounds: Vec<Aabb> = members.iter().map(|&(_, p)| bound_of(p)).collect();
                let tree = build_binary(&bounds, params);
                drop(bounds);
                let chunk_order: Vec<u32> = tree
                    .primitive_indices
                    .iter()
                    .map(|&i| members[i as usize].1)
                    .collect();
                let mut nodes = Vec::new();
                collapse_node(
                    &tree.nodes,
                    &|leaf| leaf_lane(leaf, &chunk_order, is_shape, 0),
                    0,
                    &mut nodes,
                );
                (nodes, chunk_order)
            })
            .collect();
        for (nodes, chunk_order) in built {
            let node_base = out.len() as u32;
            let slot_base = primitive_base + order.len() as u32;
            chunk_roots.push(node_base);
            out.extend(nodes.into_iter().map(|mut n| {
                for lane in 0..4 {
                    if !lane_used(&n, lane) {
                        continue;
                    }
                    n.first[lane] += if n.count[lane] == 0 {
                        node_base
                    } else {
                        slot_base
                    };
                }
                n
            }));
            order.extend(chunk_order);
        }
    }
    for node in &mut out[top_start..top_end] {
        for lane in 0..4 {
            if lane_used(node, lane) && node.count[lane] == CHUNK_LINK {
                node.first[lane] = chunk_roots[node.first[lane] as usize];
                node.count[lane] = 0;
            }
        }
    }
    (root, order)
}

/// [`GpuWideNode::count`] of a top lane whose chunk is not built yet (its `first` names the
/// chunk); [`build`] links it to the chunk's root.
const CHUNK_LINK: u32 = u32::MAX;

/// A wide node's `first` and `count` for binary leaf `leaf` of a tree whose leaf slots
/// hold `order`, numbered from `base`.
fn leaf_lane(
    leaf: &Bvh2Node,
    order: &[u32],
    is_shape: &dyn Fn(u32) -> bool,
    base: u32,
) -> (u32, u32) {
    let slots = leaf.first_index as usize..(leaf.first_index + leaf.prim_count) as usize;
    let shape = order[slots].iter().any(|&p| is_shape(p));
    let mark = if shape { SHAPE_LEAF } else { 0 };
    (base + leaf.first_index, leaf.prim_count | mark)
}

/// The `count` primitives as `(Morton code of the box centre, primitive)`, sorted: 10 bits
/// an axis of the centres' box, enough to cut chunks (each chunk's build sorts finer).
fn morton_order(count: usize, bound_of: &(dyn Fn(u32) -> Aabb + Sync)) -> Vec<(u32, u32)> {
    let centres = (0..count as u32)
        .into_par_iter()
        .map(|p| Aabb::from_point(bound_of(p).center()))
        .reduce(Aabb::empty, |a, b| a.union(&b));
    let extent = centres.diagonal();
    let scale = Vec3A::select(extent.cmpgt(Vec3A::ZERO), 1023.0 / extent, Vec3A::ZERO);
    let mut curve: Vec<(u32, u32)> = (0..count as u32)
        .into_par_iter()
        .map(|p| {
            let cell = ((bound_of(p).center() - centres.min) * scale)
                .clamp(Vec3A::ZERO, Vec3A::splat(1023.0));
            (
                morton_encode_u32(cell.x as u16, cell.y as u16, cell.z as u16),
                p,
            )
        })
        .collect();
    curve.par_sort_unstable();
    curve
}

/// Splits sorted `curve` (its first entry at `start` of the whole) at the highest bit in
/// which its codes differ until every piece holds at most `size`, appending the pieces'
/// ranges in curve order; a run of one code longer than `size` is halved.
fn split_cells(curve: &[(u32, u32)], size: usize, start: usize, out: &mut Vec<Range<usize>>) {
    if curve.len() <= size {
        out.push(start..start + curve.len());
        return;
    }
    let (first, last) = (curve[0].0, curve[curve.len() - 1].0);
    let mid = if first == last {
        curve.len() / 2
    } else {
        let bit = 1 << (31 - (first ^ last).leading_zeros());
        curve.partition_point(|&(code, _)| code & bit == 0)
    };
    split_cells(&curve[..mid], size, start, out);
    split_cells(&curve[mid..], size, start + mid, out);
}

/// Builds the binary tree over `bounds` (not empty) with preset `params`, on every core.
/// Primitives with the very same box share one leaf: PLOC pairs nearest neighbours and
/// breaks ties one way, so n identical boxes made a chain n/3 deep in O(n^2) (20,000
/// coincident triangles: 11 s).
fn build_binary(bounds: &[Aabb], params: BvhBuildParams) -> BinaryTree {
    let mut build_time = Duration::ZERO;
    let Some(groups) = IdenticalBoxes::of(bounds) else {
        let tree = build_bvh2(bounds, params, &mut build_time);
        return BinaryTree {
            nodes: tree.nodes,
            primitive_indices: tree.primitive_indices,
        };
    };
    let unique: Vec<Aabb> = (0..groups.count())
        .map(|g| bounds[groups.members_of(g as u32)[0] as usize])
        .collect();
    let tree = build_bvh2(&unique, params, &mut build_time);
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
    /// The groups of `bounds`, `None` when every box is distinct. Sorting one 64-bit hash a
    /// box shows most inputs distinct for less than sorting the boxes' bits (which took 0.8 s
    /// of a 16.8M-triangle mesh's first frame); when two hashes are equal, the boxes are
    /// sorted by their bits.
    fn of(bounds: &[Aabb]) -> Option<Self> {
        let key = |i: u32| {
            let b = &bounds[i as usize];
            [b.min.x, b.min.y, b.min.z, b.max.x, b.max.y, b.max.z].map(f32::to_bits)
        };
        let mut hashes: Vec<u64> = (0..bounds.len() as u32)
            .into_par_iter()
            .map(|i| {
                key(i).iter().fold(0u64, |h, &x| {
                    (h.rotate_left(5) ^ u64::from(x)).wrapping_mul(0x517c_c1b7_2722_0a95)
                })
            })
            .collect();
        hashes.par_sort_unstable();
        if hashes.windows(2).all(|w| w[0] != w[1]) {
            return None;
        }
        drop(hashes);
        let mut members: Vec<u32> = (0..bounds.len() as u32).collect();
        members.par_sort_unstable_by_key(|&i| key(i));
        let mut starts: Vec<u32> = (0..members.len())
            .filter(|&i| i == 0 || key(members[i]) != key(members[i - 1]))
            .map(|i| i as u32)
            .collect();
        starts.push(members.len() as u32);
        (starts.len() - 1 < bounds.len()).then_some(Self { members, starts })
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

/// Appends the 4-wide form of the binary subtree of `nodes` at `root` to `out` in pre-order
/// and returns its index. Each wide node takes the binary node's children and keeps opening
/// its largest inner child (by surface area) until it has four; a leaf child's `first` and
/// `count` are `leaf`'s; an unused child has an inverted box.
fn collapse_node(
    nodes: &[Bvh2Node],
    leaf: &dyn Fn(&Bvh2Node) -> (u32, u32),
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
            leaf(c)
        } else {
            (collapse_node(nodes, leaf, child, out), 0)
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

/// Per node of `nodes` (in pre-order, as the build lays them out), its parent's index
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
