// Two-level BVH traversal: the top level over objects, a BLAS per mesh, both obvhs BVH2s in
// `nodes` (see `crates/core/src/accel.rs`). Ordered depth-first with one explicit stack for
// both levels: the nearer child is visited first, the farther one pushed with its entry
// distance and skipped on pop if a closer hit was found meanwhile. A mesh met in a top-level
// leaf is pushed as an ENTER_MESH entry; popping it pushes a LEAVE_MESH marker and walks the
// mesh's BLAS, whose entries all lie above the marker. Shadow rays stop at the first hit.
// CPU twin: `crates/core/src/trace.rs`.
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
// Stack entry tags: an object whose BLAS is still to be walked (its index in the low bits),
// and the end of the BLAS being walked.
const ENTER_MESH: u32 = 0x80000000u;
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
        let r = intersect_triangle(
            vertices[3u * i].position,
            vertices[3u * i + 1u].position,
            vertices[3u * i + 2u].position,
            ray,
            (*hit).t,
        );
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
            || intersect_aabb(nodes[o.blas_root], ray.origin, inv_dir, (*hit).t) != MISS {
            intersect_triangles(i, o.first_triangle, o.triangle_count, ray, hit);
        }
        if any_hit && (*hit).object != NO_HIT {
            return;
        }
    }
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
    if intersect_aabb(nodes[0], ray.origin, inv_dir, hit.t) == MISS {
        return hit;
    }
    var stack_node: array<u32, STACK_SIZE>;
    var stack_t: array<f32, STACK_SIZE>;
    var sp = 0u;
    var index = 0u;
    // The mesh whose BLAS is being walked, or NO_HIT in the top level.
    var mesh = NO_HIT;
    // "While-while" (Aila and Laine): a warp's lanes walk inner nodes together, then
    // intersect leaves together, instead of alternating between the two each step.
    loop {
        var node = nodes[index];
        while node.prim_count == 0u {
            let a = node.first_index;
            let ta = intersect_aabb(nodes[a], ray.origin, inv_dir, hit.t);
            let tb = intersect_aabb(nodes[a + 1u], ray.origin, inv_dir, hit.t);
            if ta != MISS && tb != MISS {
                let near_is_a = ta <= tb;
                index = select(a, a + 1u, !near_is_a);
                if sp < STACK_SIZE {
                    stack_node[sp] = select(a + 1u, a, !near_is_a);
                    stack_t[sp] = max(ta, tb);
                    sp++;
                }
            } else if ta != MISS || tb != MISS {
                index = select(a + 1u, a, ta != MISS);
            } else {
                index = pop_entry(&stack_node, &stack_t, &sp, &mesh, hit.t);
                if index == NO_NODE {
                    return hit;
                }
            }
            node = nodes[index];
        }
        if mesh != NO_HIT {
            intersect_triangles(mesh, node.first_index, node.prim_count, ray, &hit);
        } else {
            for (var i = node.first_index; i < node.first_index + node.prim_count; i++) {
                let o = objects[i];
                if o.kind != KIND_MESH {
                    intersect_shape(i, o, ray, &hit);
                } else if sp < STACK_SIZE {
                    let t = intersect_aabb(nodes[o.blas_root], ray.origin, inv_dir, hit.t);
                    if t != MISS {
                        stack_node[sp] = ENTER_MESH | i;
                        stack_t[sp] = t;
                        sp++;
                    }
                }
            }
        }
        if any_hit && hit.object != NO_HIT {
            return hit;
        }
        index = pop_entry(&stack_node, &stack_t, &sp, &mesh, hit.t);
        if index == NO_NODE {
            return hit;
        }
    }
    return hit;
}

// Pops the next entry whose subtree may hold a hit nearer than `t` and returns its node, or
// NO_NODE when none is left; entering or leaving a mesh's BLAS on the way updates `mesh`.
fn pop_entry(
    stack_node: ptr<function, array<u32, STACK_SIZE>>,
    stack_t: ptr<function, array<f32, STACK_SIZE>>,
    sp: ptr<function, u32>,
    mesh: ptr<function, u32>,
    t: f32,
) -> u32 {
    while *sp > 0u {
        *sp -= 1u;
        let entry = (*stack_node)[*sp];
        if entry == LEAVE_MESH {
            *mesh = NO_HIT;
            continue;
        }
        if (*stack_t)[*sp] >= t {
            continue;
        }
        if (entry & ENTER_MESH) != 0u {
            *mesh = entry & ~ENTER_MESH;
            // The slot just freed holds the marker below the BLAS entries.
            (*stack_node)[*sp] = LEAVE_MESH;
            *sp += 1u;
            return objects[*mesh].blas_root;
        }
        return entry;
    }
    return NO_NODE;
}
