// 4-wide BVH traversal over every primitive of the scene (`nodes`: `WideNode`s collapsed
// from an obvhs BVH2, `crates/core/src/bvh.rs`; leaves index `primitives`: shapes and
// the triangles of every mesh). Ordered depth-first with one explicit stack. At each node the
// four child boxes are tested at once. The entered leaves that hold shapes (SHAPE_LEAF) are
// tested at once; the other entered children (inner nodes, leaves of triangles as LEAF
// entries) are sorted, the nearest is taken next and the others are pushed with their entry
// distances, nearest on top, to be skipped on pop if a closer hit was found meanwhile. A walk
// that would overflow the stack (the host caps it) starts again without one.
// Leaves of triangles are tested in a loop of their own. Shadow rays stop at the first hit.
// A placed instance is a primitive of a shape leaf: the ray, moved into its mesh's space,
// walks the mesh's tree (`trace_mesh`, the same walk without shapes, on a stack of its own).
// CPU twin: `crates/cpu/src/bvh.rs` (whose walk tests a node's leaves as it visits the node;
// the hits are the same).
//
// `ACCEL` (a pipeline constant) selects the seed's slower schemes for benchmarks: every object
// in turn, a mesh's triangles tested only when the ray hits the mesh's bounding box
// (ACCEL_BOUNDING_VOLUME) or always (ACCEL_BRUTE_FORCE). Each finds the same nearest hit.

#import scene
#import intersect
#import instance
#import textures

const ACCEL_BVH: u32 = 0u;
const ACCEL_BOUNDING_VOLUME: u32 = 1u;
const ACCEL_BRUTE_FORCE: u32 = 2u;
override ACCEL: u32 = 0u;

// Entries of the traversal stack: the host sizes it to the scene's tree
// (`pathlight_core::bvh::stack_bound`, rounded up to 8, at most `MAX_STACK` in
// `gpu_renderer.rs`) when it assembles the module.
#const STACK_SIZE: u32
const NO_HIT: u32 = 0xffffffffu;
// Stack entry tag (an untagged entry is an inner node): a leaf child, node << 2 | lane in
// the low bits (the host refuses trees of 2^28 nodes or more).
const LEAF: u32 = 0x80000000u;
// No node left to visit.
const NO_NODE: u32 = 0xffffffffu;

// CPU twin: `Hit`.
struct Hit {
    t: f32,
    // Index into `objects`, or NO_HIT.
    object: u32,
    // Mesh: triangle index in `vertices`; other shapes: 0.
    primitive: u32,
    // Triangle: barycentrics of vertices 1 and 2; quad: (s, t).
    b1: f32,
    b2: f32,
}

// Nearest hit on quad, sphere or cylinder object `i`, updating `hit`.
// CPU twin: `CpuScene::intersect_shape`.
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

// Hit on triangle `triangle` (its corners) of mesh object `object`, if nearer than `hit`.
// A triangle of a mesh with alpha holes counts only where its texel stops the ray.
// CPU twin: `CpuScene::hit_triangle`.
fn hit_triangle(object: u32, triangle: u32, v0: vec3f, v1: vec3f, v2: vec3f, ray: ShearedRay, hit: ptr<function, Hit>) {
    let r = intersect_triangle(v0, v1, v2, ray, (*hit).t);
    if r.x < (*hit).t
        && (!ALPHA || (objects[object].flags & FLAG_ALPHA) == 0u || alpha_stops(object, triangle, r.y, r.z, r.x)) {
        *hit = Hit(r.x, object, triangle, r.y, r.z);
    }
}

// Nearest hit on primitive `i`, a shape or a triangle, updating `hit`; `sheared` is `ray` in
// ray space.
// CPU twin: `CpuScene::intersect_primitive`.
fn intersect_primitive(i: u32, ray: Ray, sheared: ShearedRay, hit: ptr<function, Hit>) {
    let p = primitives[i];
    if p.triangle == NO_TRIANGLE {
        intersect_shape(p.object, objects[p.object], ray, hit);
        return;
    }
    hit_triangle(p.object, p.triangle, p.v0, p.v1, p.v2, sheared, hit);
}

// Primitive `i` of a top-level shape leaf: an instance is walked (`trace_instance`, on
// `stack` above its `sp` entries), a shape or a triangle tested; `inv_dir` and `backwards` are
// the ray's as `enter_children` takes them.
fn intersect_top_level(i: u32, ray: Ray, sheared: ShearedRay, inv_dir: vec3f, backwards: vec3<bool>, any_hit: bool, stack: ptr<function, array<vec2u, STACK_SIZE>>, sp: u32, hit: ptr<function, Hit>) {
    let p = primitives[i];
    if INSTANCES && p.triangle == INSTANCE {
        trace_instance(p, ray, inv_dir, backwards, any_hit, stack, sp, hit);
    } else {
        intersect_primitive(i, ray, sheared, hit);
    }
}

// Nearest hit among primitives `first .. first + count`, all triangles, as parts of their own
// objects, or of instance object `object` unless it is NO_HIT.
fn intersect_triangles(first: u32, count: u32, object: u32, ray: ShearedRay, hit: ptr<function, Hit>) {
    for (var i = first; i < first + count; i++) {
        let p = primitives[i];
        hit_triangle(select(object, p.object, object == NO_HIT), p.triangle, p.v0, p.v1, p.v2, ray, hit);
    }
}

// The walk through the tree of the instance that primitive `p` places, in its mesh's space:
// the ray moved by the instance's `to_object` (its direction not renormalised, so distances
// stay), the hits the instance object's. It walks on `stack` above its `sp` entries, or
// without a stack when `stack` is null... A leaf may hold several placements: each one's
// world box is tested first.
// CPU twin: `Walk::instance`.
fn trace_instance(p: Primitive, ray: Ray, inv_dir: vec3f, backwards: vec3<bool>, any_hit: bool, stack: ptr<function, array<vec2u, STACK_SIZE>>, sp: u32, hit: ptr<function, Hit>) {
    let o = objects[p.object];
    if !enters_box(o.a.xyz, o.b.xyz, ray.origin, inv_dir, backwards, (*hit).t) {
        return;
    }
    let m = instances[o.instance];
    let local = Ray(to_object_point(m, ray.origin), to_object_vector(m, ray.dir));
    trace_mesh(p.root, p.object, local, any_hit, stack, sp, hit);
}

// `trace_instance` for the walk without a stack (`trace_stackless`).
fn trace_instance_stackless(p: Primitive, ray: Ray, inv_dir: vec3f, backwards: vec3<bool>, any_hit: bool, hit: ptr<function, Hit>) {
    let o = objects[p.object];
    if !enters_box(o.a.xyz, o.b.xyz, ray.origin, inv_dir, backwards, (*hit).t) {
        return;
    }
    let m = instances[o.instance];
    let local = Ray(to_object_point(m, ray.origin), to_object_vector(m, ray.dir));
    let local_inv = safe_inverse(local.dir);
    trace_mesh_stackless(p.root, p.object, local, sheared_ray(local), local_inv, local_inv < vec3f(0.0), any_hit, hit);
}

// Nearest hit among the triangles of mesh object `i`, read from `triangles` and `vertices`.
fn intersect_mesh(i: u32, o: Object, ray: ShearedRay, hit: ptr<function, Hit>) {
    for (var tri = o.first_triangle; tri < o.first_triangle + o.triangle_count; tri++) {
        let v0 = vertices[triangles[3u * tri]].position;
        let v1 = vertices[triangles[3u * tri + 1u]].position;
        let v2 = vertices[triangles[3u * tri + 2u]].position;
        hit_triangle(i, tri, v0, v1, v2, ray, hit);
    }
}

// The slower `ACCEL` schemes: every object in turn.
fn intersect_linear(ray: Ray, sheared: ShearedRay, inv_dir: vec3f, object_count: u32, any_hit: bool, hit: ptr<function, Hit>) {
    for (var i = 0u; i < object_count; i++) {
        let o = objects[i];
        if o.kind != KIND_MESH {
            intersect_shape(i, o, ray, hit);
        } else if ACCEL == ACCEL_BRUTE_FORCE
            || intersect_aabb(Aabb(o.a.xyz, o.b.xyz), ray.origin, inv_dir, (*hit).t) != MISS {
            if INSTANCES && (o.flags & FLAG_INSTANCE) != 0u {
                let m = instances[o.instance];
                let local = Ray(to_object_point(m, ray.origin), to_object_vector(m, ray.dir));
                intersect_mesh(i, o, sheared_ray(local), hit);
            } else {
                intersect_mesh(i, o, sheared, hit);
            }
        }
        if any_hit && (*hit).object != NO_HIT {
            return;
        }
    }
}

// Entry distances (clamped at 0) of the four child boxes of `n`, MISS for those the ray does
// not enter before t_max. Per axis the near plane is the minimum one unless the ray runs
// backwards (`backwards`), so an unused child's inverted box is never entered.
// CPU twin: `RayLanes::enter`.
fn enter_children(n: WideNode, origin: vec3f, inv_dir: vec3f, backwards: vec3<bool>, t_max: f32) -> vec4f {
    let near_x = (select(n.lo_x, n.hi_x, backwards.x) - origin.x) * inv_dir.x;
    let far_x = (select(n.hi_x, n.lo_x, backwards.x) - origin.x) * inv_dir.x;
    let near_y = (select(n.lo_y, n.hi_y, backwards.y) - origin.y) * inv_dir.y;
    let far_y = (select(n.hi_y, n.lo_y, backwards.y) - origin.y) * inv_dir.y;
    let near_z = (select(n.lo_z, n.hi_z, backwards.z) - origin.z) * inv_dir.z;
    let far_z = (select(n.hi_z, n.lo_z, backwards.z) - origin.z) * inv_dir.z;
    let t_near = max(max(near_x, near_y), max(near_z, vec4f(0.0)));
    let t_far = min(min(far_x, far_y), min(far_z, vec4f(t_max)));
    return select(vec4f(MISS), t_near, t_near <= t_far * ROBUST_FAR);
}

// Whether the ray enters the box from `lo` to `hi` before `t_max`: `enter_children`'s slab
// test on one box.
// CPU twin: `RayLanes::enters_box`.
fn enters_box(lo: vec3f, hi: vec3f, origin: vec3f, inv_dir: vec3f, backwards: vec3<bool>, t_max: f32) -> bool {
    let near = (select(lo, hi, backwards) - origin) * inv_dir;
    let far = (select(hi, lo, backwards) - origin) * inv_dir;
    let t_near = max(max(near.x, near.y), max(near.z, 0.0));
    let t_far = min(min(far.x, far.y), min(far.z, t_max));
    return t_near <= t_far * ROBUST_FAR;
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
// CPU twin: `trace_scene`.
fn trace_scene(ray: Ray, t_max: f32, object_count: u32, any_hit: bool) -> Hit {
    var hit = Hit(t_max, NO_HIT, 0u, 0.0, 0.0);
    if object_count == 0u {
        return hit;
    }
    let inv_dir = safe_inverse(ray.dir);
    let sheared = sheared_ray(ray);
    if ACCEL != ACCEL_BVH {
        intersect_linear(ray, sheared, inv_dir, object_count, any_hit, &hit);
        return hit;
    }
    let backwards = inv_dir < vec3f(0.0);
    // Entries (node or LEAF entry, bits of the entry distance), one 8-byte store each.
    var stack: array<vec2u, STACK_SIZE>;
    var sp = 0u;
    var index = 0u;
    loop {
        let n = nodes[index];
        let t = enter_children(n, ray.origin, inv_dir, backwards, hit.t);
        // Entered leaves that hold shapes are tested now (cheaper than pushing them).
        let at_once = (n.count & vec4u(SHAPE_LEAF)) != vec4u(0u);
        if any(at_once & t < vec4f(hit.t)) {
            for (var lane = 0u; lane < 4u; lane++) {
                if !at_once[lane] || t[lane] >= hit.t {
                    continue;
                }
                let first = n.first[lane];
                let end = first + (n.count[lane] & ~SHAPE_LEAF);
                for (var i = first; i < end; i++) {
                    intersect_top_level(i, ray, sheared, inv_dir, backwards, any_hit, &stack, sp, &hit);
                }
            }
            if any_hit && hit.object != NO_HIT {
                return hit;
            }
        }
        // The other children still to visit (inner nodes, and leaves of triangles as LEAF
        // entries), sorted by entry distance: the nearest is taken next, the others are
        // pushed, farthest first.
        let o = order_children(n, index, t, t < vec4f(hit.t) & !at_once);
        let pushes = u32(o.keys.y != MISS) + u32(o.keys.z != MISS) + u32(o.keys.w != MISS);
        if sp + pushes > STACK_SIZE {
            // Deeper than the stack: walk again from the root without one, keeping the hit.
            trace_stackless(ray, sheared, inv_dir, backwards, any_hit, &hit);
            return hit;
        }
        var entry = push_children(&stack, &sp, 0u, o, hit.t);
        // Leaves of triangles, nearest first, until the next inner node ("while-while", Aila
        // and Laine: a warp's lanes intersect triangles together, then walk nodes together).
        loop {
            if entry == NO_NODE {
                return hit;
            }
            if (entry & LEAF) == 0u {
                break;
            }
            let node = (entry & ~LEAF) >> 2u;
            let lane = entry & 3u;
            intersect_triangles(nodes[node].first[lane], nodes[node].count[lane], NO_HIT, sheared, &hit);
            if any_hit && hit.object != NO_HIT {
                return hit;
            }
            entry = pop_entry(&stack, &sp, 0u, hit.t);
        }
        index = entry;
    }
    return hit;
}

// The children of node `n` (at `index`) that `take` selects, sorted by their entry distances
// `t` (a sorting network on four keys; MISS for the others): inner nodes by index, leaves as
// LEAF entries.
struct OrderedChildren {
    keys: vec4f,
    entries: vec4u,
}

fn order_children(n: WideNode, index: u32, t: vec4f, take: vec4<bool>) -> OrderedChildren {
    let leaves = vec4u(LEAF | (index << 2u)) | vec4u(0u, 1u, 2u, 3u);
    let entries = select(n.first, leaves, n.count != vec4u(0u));
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
    return OrderedChildren(vec4f(k0, k1, k2, k3), vec4u(c0, c1, c2, c3));
}

// Pushes the sorted children `o` but the nearest (which the caller has room for), farthest
// first, and returns the next entry to visit: the nearest child, else the next one popped
// above `base` nearer than `t` (NO_NODE when none is left).
fn push_children(stack: ptr<function, array<vec2u, STACK_SIZE>>, sp: ptr<function, u32>, base: u32, o: OrderedChildren, t: f32) -> u32 {
    for (var k = 3; k >= 1; k--) {
        if o.keys[k] != MISS {
            (*stack)[*sp] = vec2u(o.entries[k], bitcast<u32>(o.keys[k]));
            *sp += 1u;
        }
    }
    if o.keys.x == MISS {
        return pop_entry(stack, sp, base, t);
    }
    return o.entries.x;
}

// Nearest hit (or with `any_hit` the first) among the triangles of the shared mesh's tree at
// `root`, as parts of instance object `object`, updating `hit`: `trace_scene`'s walk without
// shapes, on `stack` above its `base` entries (the host sizes the stack for a top-level walk
// and a mesh's together; deeper, it walks the mesh without a stack).
fn trace_mesh(root: u32, object: u32, ray: Ray, any_hit: bool, stack: ptr<function, array<vec2u, STACK_SIZE>>, base: u32, hit: ptr<function, Hit>) {
    let inv_dir = safe_inverse(ray.dir);
    let sheared = sheared_ray(ray);
    let backwards = inv_dir < vec3f(0.0);
    var sp = base;
    var index = root;
    loop {
        let n = nodes[index];
        let t = enter_children(n, ray.origin, inv_dir, backwards, (*hit).t);
        let o = order_children(n, index, t, t < vec4f((*hit).t));
        let pushes = u32(o.keys.y != MISS) + u32(o.keys.z != MISS) + u32(o.keys.w != MISS);
        if sp + pushes > STACK_SIZE {
            trace_mesh_stackless(root, object, ray, sheared, inv_dir, backwards, any_hit, hit);
            return;
        }
        var entry = push_children(stack, &sp, base, o, (*hit).t);
        loop {
            if entry == NO_NODE {
                return;
            }
            if (entry & LEAF) == 0u {
                break;
            }
            let node = (entry & ~LEAF) >> 2u;
            let lane = entry & 3u;
            intersect_triangles(nodes[node].first[lane], nodes[node].count[lane], object, sheared, hit);
            if any_hit && (*hit).object != NO_HIT {
                return;
            }
            entry = pop_entry(stack, &sp, base, (*hit).t);
        }
        index = entry;
    }
}

// `trace_stackless` for the shared mesh's tree at `root` (`trace_mesh`'s walk when it is
// deeper than its stack), the hits instance object `object`'s.
fn trace_mesh_stackless(root: u32, object: u32, ray: Ray, sheared: ShearedRay, inv_dir: vec3f, backwards: vec3<bool>, any_hit: bool, hit: ptr<function, Hit>) {
    var index = root;
    var from_lane = 4u;
    loop {
        let n = nodes[index];
        let t = enter_children(n, ray.origin, inv_dir, backwards, (*hit).t);
        if from_lane == 4u {
            for (var lane = 0u; lane < 4u; lane++) {
                if n.count[lane] != 0u && t[lane] < (*hit).t {
                    intersect_triangles(n.first[lane], n.count[lane], object, sheared, hit);
                }
            }
            if any_hit && (*hit).object != NO_HIT {
                return;
            }
        }
        let next = next_stackless(n, t, from_lane, (*hit).t);
        if next != NO_NODE {
            index = next;
            from_lane = 4u;
        } else if index == root {
            return;
        } else {
            from_lane = parents[index] & 3u;
            index = parents[index] >> 2u;
        }
    }
}

// The stackless walks' next inner child of `n` after lane `from_lane` (from the first when it
// is 4) that the ray enters before `t_max` (entry distances `t`), or NO_NODE.
fn next_stackless(n: WideNode, t: vec4f, from_lane: u32, t_max: f32) -> u32 {
    for (var lane = select(from_lane + 1u, 0u, from_lane == 4u); lane < 4u; lane++) {
        if n.count[lane] == 0u && t[lane] < t_max {
            return n.first[lane];
        }
    }
    return NO_NODE;
}

// The walk of `trace_scene` for trees deeper than its stack: children in lane order, going
// down to the first entered inner child and back up through `parents` to the next one, so it
// needs no stack (Hapala et al. 2011, "Efficient stack-less BVH traversal for ray tracing",
// on a 4-wide tree). A node's entered leaves are tested when the walk first reaches it. It
// updates `hit` (which may already hold a hit) and stops at the first hit with `any_hit`.
fn trace_stackless(ray: Ray, sheared: ShearedRay, inv_dir: vec3f, backwards: vec3<bool>, any_hit: bool, hit: ptr<function, Hit>) {
    var index = 0u;
    // The lane of the child the walk came up from; 4 when it came down.
    var from_lane = 4u;
    loop {
        let n = nodes[index];
        let t = enter_children(n, ray.origin, inv_dir, backwards, (*hit).t);
        if from_lane == 4u {
            for (var lane = 0u; lane < 4u; lane++) {
                if n.count[lane] == 0u || t[lane] >= (*hit).t {
                    continue;
                }
                let first = n.first[lane];
                let end = first + (n.count[lane] & ~SHAPE_LEAF);
                for (var i = first; i < end; i++) {
                    let p = primitives[i];
                    if INSTANCES && p.triangle == INSTANCE {
                        trace_instance_stackless(p, ray, inv_dir, backwards, any_hit, hit);
                    } else {
                        intersect_primitive(i, ray, sheared, hit);
                    }
                }
            }
            if any_hit && (*hit).object != NO_HIT {
                return;
            }
        }
        let next = next_stackless(n, t, from_lane, (*hit).t);
        if next != NO_NODE {
            index = next;
            from_lane = 4u;
        } else if index == 0u {
            return;
        } else {
            from_lane = parents[index] & 3u;
            index = parents[index] >> 2u;
        }
    }
}

// Pops the next entry above `base` whose subtree may hold a hit nearer than `t` and returns
// it (an inner node or a LEAF entry), or NO_NODE when none is left.
fn pop_entry(stack: ptr<function, array<vec2u, STACK_SIZE>>, sp: ptr<function, u32>, base: u32, t: f32) -> u32 {
    while *sp > base {
        *sp -= 1u;
        let top = (*stack)[*sp];
        if bitcast<f32>(top.y) < t {
            return top.x;
        }
    }
    return NO_NODE;
}
