// The transforms of a placed instance (`Instance`, rows of affine matrices): rays into its
// mesh's space, hit normals, tangents and light samples back out into the world.
// No CPU twin: the Rust side is `crates/core/src/instance.rs`, which the host's light table
// uses too (its functions name these as their twins).

#import scene

// `rows` applied to `v` extended by `w` (1: a point, 0: a direction).
fn apply_rows(rows: array<vec4f, 3>, v: vec3f, w: f32) -> vec3f {
    let x = vec4f(v, w);
    return vec3f(dot(rows[0], x), dot(rows[1], x), dot(rows[2], x));
}

// World point `p` in the mesh's space.
fn to_object_point(m: Instance, p: vec3f) -> vec3f {
    return apply_rows(m.to_object, p, 1.0);
}

// World direction `d` in the mesh's space, not renormalised (distances along a ray stay).
fn to_object_vector(m: Instance, d: vec3f) -> vec3f {
    return apply_rows(m.to_object, d, 0.0);
}

// The mesh's point `p` in the world.
fn to_world_point(m: Instance, p: vec3f) -> vec3f {
    return apply_rows(m.to_world, p, 1.0);
}

// The mesh's direction `d` (a tangent) in the world, not renormalised.
fn to_world_vector(m: Instance, d: vec3f) -> vec3f {
    return apply_rows(m.to_world, d, 0.0);
}

// The mesh's normal `n` in the world (by the transpose of `to_object`), not renormalised.
fn to_world_normal(m: Instance, n: vec3f) -> vec3f {
    return m.to_object[0].xyz * n.x + m.to_object[1].xyz * n.y + m.to_object[2].xyz * n.z;
}

// The world corners of triangle `triangle` (in `triangles`, its corners in `vertices`) of mesh
// object `o`: placed by its transform when it is an instance.
fn world_triangle(o: Object, triangle: u32) -> array<vec3f, 3> {
    let i = 3u * triangle;
    var corners = array<vec3f, 3>(
        vertices[triangles[i]].position,
        vertices[triangles[i + 1u]].position,
        vertices[triangles[i + 2u]].position,
    );
    if INSTANCES && (o.flags & FLAG_INSTANCE) != 0u {
        let m = instances[o.instance];
        for (var k = 0u; k < 3u; k++) {
            corners[k] = to_world_point(m, corners[k]);
        }
    }
    return corners;
}

// `v` made unit, or zero when it has no length (a corner without a normal or tangent).
fn normalize_or_zero(v: vec3f) -> vec3f {
    let l = length(v);
    return select(vec3f(0.0), v / l, l > 0.0);
}
