// Two-level BVH traversal: the top level over objects, a BLAS per mesh, both obvhs BVH2s in
// `nodes` (see `crates/core/src/accel.rs`). Ordered depth-first with an explicit stack: the
// nearer child is visited first, the farther one pushed with its entry distance and skipped
// on pop if a closer hit was found meanwhile.
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

// Nearest hit among the triangles under BLAS `root`, updating `hit`.
fn intersect_mesh(object: u32, root: u32, ray: Ray, inv_dir: vec3f, hit: ptr<function, Hit>) {
    var stack_node: array<u32, STACK_SIZE>;
    var stack_t: array<f32, STACK_SIZE>;
    var sp = 0u;
    var index = root;
    if intersect_aabb(nodes[root], ray.origin, inv_dir, (*hit).t) == MISS {
        return;
    }
    loop {
        let node = nodes[index];
        var descend = false;
        if node.prim_count > 0u {
            for (var i = node.first_index; i < node.first_index + node.prim_count; i++) {
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
        } else {
            let a = node.first_index;
            let ta = intersect_aabb(nodes[a], ray.origin, inv_dir, (*hit).t);
            let tb = intersect_aabb(nodes[a + 1u], ray.origin, inv_dir, (*hit).t);
            if ta != MISS && tb != MISS {
                let near_is_a = ta <= tb;
                index = select(a, a + 1u, !near_is_a);
                if sp < STACK_SIZE {
                    stack_node[sp] = select(a + 1u, a, !near_is_a);
                    stack_t[sp] = max(ta, tb);
                    sp++;
                }
                descend = true;
            } else if ta != MISS || tb != MISS {
                index = select(a + 1u, a, ta != MISS);
                descend = true;
            }
        }
        if !descend {
            // Pop the next subtree still nearer than the current hit.
            var found = false;
            while sp > 0u {
                sp--;
                if stack_t[sp] < (*hit).t {
                    index = stack_node[sp];
                    found = true;
                    break;
                }
            }
            if !found {
                break;
            }
        }
    }
}

// Nearest hit among a mesh's triangles without its BLAS (the slower `ACCEL` schemes).
fn intersect_triangles(object: u32, o: Object, ray: Ray, inv_dir: vec3f, hit: ptr<function, Hit>) {
    if ACCEL == ACCEL_BOUNDING_VOLUME && intersect_aabb(nodes[o.blas_root], ray.origin, inv_dir, (*hit).t) == MISS {
        return;
    }
    for (var i = o.first_triangle; i < o.first_triangle + o.triangle_count; i++) {
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

// Nearest hit on object `i` (in top-level order), updating `hit`.
fn intersect_object(i: u32, ray: Ray, inv_dir: vec3f, hit: ptr<function, Hit>) {
    let o = objects[i];
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
        case KIND_CYLINDER: {
            let t = intersect_cylinder(o.a.xyz, o.b.xyz, o.a.w, (o.flags & FLAG_CAPS) != 0u, ray, (*hit).t);
            if t < (*hit).t {
                *hit = Hit(t, i, 0u, 0.0, 0.0);
            }
        }
        default: {
            if ACCEL == ACCEL_BVH {
                intersect_mesh(i, o.blas_root, ray, inv_dir, hit);
            } else {
                intersect_triangles(i, o, ray, inv_dir, hit);
            }
        }
    }
}

// Nearest hit in (0, t_max) over the whole scene; `object_count` 0 means an empty scene.
fn intersect_scene(ray: Ray, t_max: f32, object_count: u32) -> Hit {
    var hit = Hit(t_max, NO_HIT, 0u, 0.0, 0.0);
    if object_count == 0u {
        return hit;
    }
    let inv_dir = safe_inverse(ray.dir);
    if ACCEL != ACCEL_BVH {
        for (var i = 0u; i < object_count; i++) {
            intersect_object(i, ray, inv_dir, &hit);
        }
        return hit;
    }
    var stack_node: array<u32, STACK_SIZE>;
    var stack_t: array<f32, STACK_SIZE>;
    var sp = 0u;
    var index = 0u;
    if intersect_aabb(nodes[0], ray.origin, inv_dir, hit.t) == MISS {
        return hit;
    }
    loop {
        let node = nodes[index];
        var descend = false;
        if node.prim_count > 0u {
            for (var i = node.first_index; i < node.first_index + node.prim_count; i++) {
                intersect_object(i, ray, inv_dir, &hit);
            }
        } else {
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
                descend = true;
            } else if ta != MISS || tb != MISS {
                index = select(a + 1u, a, ta != MISS);
                descend = true;
            }
        }
        if !descend {
            var found = false;
            while sp > 0u {
                sp--;
                if stack_t[sp] < hit.t {
                    index = stack_node[sp];
                    found = true;
                    break;
                }
            }
            if !found {
                break;
            }
        }
    }
    return hit;
}
