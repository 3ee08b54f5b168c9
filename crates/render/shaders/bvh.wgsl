// Two-level 4-wide BVH traversal: the top level over objects, a tree per mesh, all in
// `nodes` (`WideNode`s collapsed from obvhs BVH2s: `crates/core/src/wide_bvh.rs`). Ordered
// depth-first with one explicit stack for both levels. At each node the four child boxes are
// tested at once. In the top level the entered leaves' shapes are tested at once and a
// leaf's mesh is pushed as an ENTER_MESH entry; popping it pushes a LEAVE_MESH marker and
// walks the mesh's tree, whose entries all lie above the marker. The nearest entered child
// still to visit (inner, or in a mesh's tree a leaf too) is taken next and the others are
// pushed with their entry distances, nearest on top, to be skipped on pop if a closer hit
// was found meanwhile. Shadow rays stop at the first hit. CPU twin: `Walk::tree` in
// `crates/core/src/wide_bvh.rs` (which tests a node's leaves as it visits the node; the hits
// are the same).
//
// `ACCEL` (a pipeline constant) selects the seed's slower schemes for benchmarks: every object
// in turn, a mesh's triangles tested only when the ray hits the mesh's bounding box
// (ACCEL_BOUNDING_VOLUME) or always (ACCEL_BRUTE_FORCE). Each finds the same nearest hit.

const ACCEL_BVH: u32 = 0u;
const ACCEL_BOUNDING_VOLUME: u32 = 1u;
const ACCEL_BRUTE_FORCE: u32 = 2u;
override ACCEL: u32 = 0u;

const STACK_SIZE: u32 = 64u;
const NO_HIT: u32 = 0xffffffffu;
// Stack entry tags (an untagged entry is an inner node): an object whose tree is still to be
// walked (its index in the low bits), a leaf child (node << 2 | lane in the low bits: the
// host refuses trees of 2^28 nodes or more), and
// the end of the mesh tree being walked.
const ENTER_MESH: u32 = 0x80000000u;
const LEAF: u32 = 0x40000000u;
const ENTRY_TAG: u32 = 0xc0000000u;
const LEAVE_MESH: u32 = 0xffffffffu;
// No node left to visit.
const NO_NODE: u32 = 0xffffffffu;

struct Hit {
    t: f32,
    // Index into `objects` (top-level order), or NO_HIT.
    object: u32,
    // Mesh: triangle index; other shapes: 0.
    primitive: u32,
    // Triangle: barycentrics of vertices 1 and 2; quad: (s, t).
    b1: f32,
    b2: f32,
}

// Nearest hit on quad, sphere or cylinder `i` (top-level order), updating `hit`.
fn intersect_shape(i: u32, o: Object, ray: Ray, hit: ptr<function, Hit>) {
    switch o.kind {
        case KIND_QUAD: {
            let r = intersect_quad(o.a.xyz, o.b.xyz, o.c.xyz, ray, (*hit).t);
            if r.x < (*hit).t {
                *hit = Hit(r.x, i, 0u, r.y, r.z);
            }
        }
        case KIND_SPHERE: {
            let t = intersect_sphere(o.a.xyz, o.a.w, ray, (*hit).t);
            if t < (*hit).t {
                *hit = Hit(t, i, 0u, 0.0, 0.0);
            }
        }
        default: {
            let t = intersect_cylinder(o.a.xyz, o.b.xyz, o.a.w, (o.flags & FLAG_CAPS) != 0u, ray, (*hit).t);
            if t < (*hit).t {
                *hit = Hit(t, i, 0u, 0.0, 0.0);
            }
        }
    }
}

// Nearest hit among triangles `first .. first + count` of mesh object `object`.
fn intersect_triangles(object: u32, first: u32, count: u32, ray: Ray, hit: ptr<function, Hit>) {
    for (var i = first; i < first + count; i++) {
        let tri = triangles[i];
        let r = intersect_triangle_edges(tri.v0, tri.e1, tri.e2, ray, (*hit).t);
        if r.x < (*hit).t {
            *hit = Hit(r.x, object, i, r.y, r.z);
        }
    }
}

// The slower `ACCEL` schemes: every object in turn.
fn intersect_linear(ray: Ray, inv_dir: vec3f, object_count: u32, any_hit: bool, hit: ptr<function, Hit>) {
    for (var i = 0u; i < object_count; i++) {
        let o = objects[i];
        if o.kind != KIND_MESH {
            intersect_shape(i, o, ray, hit);
        } else if ACCEL == ACCEL_BRUTE_FORCE
            || intersect_aabb(tree_bounds(nodes[o.blas_root]), ray.origin, inv_dir, (*hit).t) != MISS {
            intersect_triangles(i, o.first_triangle, o.triangle_count, ray, hit);
        }
        if any_hit && (*hit).object != NO_HIT {
            return;
        }
    }
}

// Box around the four children of `n` (the bounds of the tree it is the root of).
fn tree_bounds(n: WideNode) -> Aabb {
    let lo = vec3f(
        min(min(n.lo_x.x, n.lo_x.y), min(n.lo_x.z, n.lo_x.w)),
        min(min(n.lo_y.x, n.lo_y.y), min(n.lo_y.z, n.lo_y.w)),
        min(min(n.lo_z.x, n.lo_z.y), min(n.lo_z.z, n.lo_z.w)),
    );
    let hi = vec3f(
        max(max(n.hi_x.x, n.hi_x.y), max(n.hi_x.z, n.hi_x.w)),
        max(max(n.hi_y.x, n.hi_y.y), max(n.hi_y.z, n.hi_y.w)),
        max(max(n.hi_z.x, n.hi_z.y), max(n.hi_z.z, n.hi_z.w)),
    );
    return Aabb(lo, hi);
}

// Entry distances (clamped at 0) of the four child boxes of `n`, MISS for those the ray does
// not enter before t_max. Per axis the near plane is the minimum one unless the ray runs
// backwards (`backwards`), so an unused child's inverted box is never entered. Twin of
// `RayLanes::enter`.
fn enter_children(n: WideNode, origin: vec3f, inv_dir: vec3f, backwards: vec3<bool>, t_max: f32) -> vec4f {
    let near_x = (select(n.lo_x, n.hi_x, backwards.x) - origin.x) * inv_dir.x;
    let far_x = (select(n.hi_x, n.lo_x, backwards.x) - origin.x) * inv_dir.x;
    let near_y = (select(n.lo_y, n.hi_y, backwards.y) - origin.y) * inv_dir.y;
    let far_y = (select(n.hi_y, n.lo_y, backwards.y) - origin.y) * inv_dir.y;
    let near_z = (select(n.lo_z, n.hi_z, backwards.z) - origin.z) * inv_dir.z;
    let far_z = (select(n.hi_z, n.lo_z, backwards.z) - origin.z) * inv_dir.z;
    let t_near = max(max(near_x, near_y), max(near_z, vec4f(0.0)));
    let t_far = min(min(far_x, far_y), min(far_z, vec4f(t_max)));
    return select(vec4f(MISS), t_near, t_near <= t_far);
}

// Orders the pairs (a, b) by key: afterwards *ka <= *kb.
fn order_pair(ka: ptr<function, f32>, ca: ptr<function, u32>, kb: ptr<function, f32>, cb: ptr<function, u32>) {
    let swap = *kb < *ka;
    let k = *ka;
    let c = *ca;
    *ka = select(k, *kb, swap);
    *ca = select(c, *cb, swap);
    *kb = select(*kb, k, swap);
    *cb = select(*cb, c, swap);
}

// Nearest hit in (0, t_max) over the whole scene, or with `any_hit` the first one found;
// `object_count` 0 means an empty scene.
fn trace_scene(ray: Ray, t_max: f32, object_count: u32, any_hit: bool) -> Hit {
    var hit = Hit(t_max, NO_HIT, 0u, 0.0, 0.0);
    if object_count == 0u {
        return hit;
    }
    let inv_dir = safe_inverse(ray.dir);
    if ACCEL != ACCEL_BVH {
        intersect_linear(ray, inv_dir, object_count, any_hit, &hit);
        return hit;
    }
    let backwards = inv_dir < vec3f(0.0);
    // Entries (node or tagged entry, bits of the entry distance), one 8-byte store each.
    var stack: array<vec2u, STACK_SIZE>;
    var sp = 0u;
    var index = 0u;
    // The mesh whose tree is being walked, or NO_HIT in the top level.
    var mesh = NO_HIT;
    loop {
        let n = nodes[index];
        let t = enter_children(n, ray.origin, inv_dir, backwards, hit.t);
        if mesh == NO_HIT {
            // Top level: the entered leaves' shapes are tested now (cheaper than pushing
            // them), a mesh is pushed as an ENTER_MESH entry.
            for (var lane = 0u; lane < 4u; lane++) {
                let count = n.count[lane];
                if count == 0u || t[lane] >= hit.t {
                    continue;
                }
                let first = n.first[lane];
                for (var i = first; i < first + count; i++) {
                    let o = objects[i];
                    if o.kind != KIND_MESH {
                        intersect_shape(i, o, ray, &hit);
                    } else if sp < STACK_SIZE {
                        stack[sp] = vec2u(ENTER_MESH | i, bitcast<u32>(t[lane]));
                        sp++;
                    }
                }
            }
            if any_hit && hit.object != NO_HIT {
                return hit;
            }
        }
        // The children still to visit (in the top level its inner ones, in a mesh's tree
        // leaves too, as LEAF entries) sorted by entry distance: a sorting network on four
        // keys, MISS for those not entered before the current hit. The nearest is taken
        // next, the others are pushed, farthest first.
        let leaves = vec4u(LEAF | (index << 2u)) | vec4u(0u, 1u, 2u, 3u);
        let entries = select(n.first, leaves, n.count != vec4u(0u));
        let take = t < vec4f(hit.t) & (n.count == vec4u(0u) | vec4<bool>(mesh != NO_HIT));
        var k0 = select(MISS, t.x, take.x);
        var k1 = select(MISS, t.y, take.y);
        var k2 = select(MISS, t.z, take.z);
        var k3 = select(MISS, t.w, take.w);
        var c0 = entries.x;
        var c1 = entries.y;
        var c2 = entries.z;
        var c3 = entries.w;
        order_pair(&k0, &c0, &k1, &c1);
        order_pair(&k2, &c2, &k3, &c3);
        order_pair(&k0, &c0, &k2, &c2);
        order_pair(&k1, &c1, &k3, &c3);
        order_pair(&k1, &c1, &k2, &c2);
        if k3 != MISS && sp < STACK_SIZE {
            stack[sp] = vec2u(c3, bitcast<u32>(k3));
            sp++;
        }
        if k2 != MISS && sp < STACK_SIZE {
            stack[sp] = vec2u(c2, bitcast<u32>(k2));
            sp++;
        }
        if k1 != MISS && sp < STACK_SIZE {
            stack[sp] = vec2u(c1, bitcast<u32>(k1));
            sp++;
        }
        var next = c0;
        if k0 == MISS {
            next = pop_entry(&stack, &sp, &mesh, hit.t);
        }
        // A mesh's leaves, nearest first, until the next inner node ("while-while", Aila and
        // Laine: a warp's lanes intersect triangles together, then walk nodes together).
        loop {
            if next == NO_NODE {
                return hit;
            }
            if (next & ENTRY_TAG) != LEAF {
                break;
            }
            let node = (next & ~LEAF) >> 2u;
            let lane = next & 3u;
            intersect_triangles(mesh, nodes[node].first[lane], nodes[node].count[lane], ray, &hit);
            if any_hit && hit.object != NO_HIT {
                return hit;
            }
            next = pop_entry(&stack, &sp, &mesh, hit.t);
        }
        index = next;
    }
    return hit;
}

// Pops the next entry whose subtree may hold a hit nearer than `t` and returns it (an inner
// node or a LEAF entry), or NO_NODE when none is left; entering or leaving a mesh's tree on
// the way updates `mesh`.
fn pop_entry(
    stack: ptr<function, array<vec2u, STACK_SIZE>>,
    sp: ptr<function, u32>,
    mesh: ptr<function, u32>,
    t: f32,
) -> u32 {
    while *sp > 0u {
        *sp -= 1u;
        let top = (*stack)[*sp];
        let entry = top.x;
        if entry == LEAVE_MESH {
            *mesh = NO_HIT;
            continue;
        }
        if bitcast<f32>(top.y) >= t {
            continue;
        }
        if (entry & ENTER_MESH) != 0u {
            *mesh = entry & ~ENTER_MESH;
            // The slot just freed holds the marker below the BLAS entries.
            (*stack)[*sp].x = LEAVE_MESH;
            *sp += 1u;
            return objects[*mesh].blas_root;
        }
        return entry;
    }
    return NO_NODE;
}
