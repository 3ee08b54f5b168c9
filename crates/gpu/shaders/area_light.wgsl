// The area light: an emissive quad, sphere or cylinder, or one triangle of an emissive mesh
// (a light-table entry of kind LIGHT_AREA, `index` its object). Quads, cylinders and
// triangles are sampled by area, spheres by the solid angle they subtend from outside; the
// radiance is the material's emission (a mesh's, textured at the point).
// CPU twin: `crates/cpu/src/area_light.rs`.

#import scene
#import intersect
#import instance
#import sampling
#import textures
#import material
#import light_sample

// Surface area of light-table entry (o, primitive): the whole shape, or one triangle of a
// mesh. The host computes the same areas to weigh the light table by power
// (`crates/core/src/light_table.rs`).
// CPU twin: `emitter_area`.
fn emitter_area(o: Object, primitive: u32) -> f32 {
    switch o.kind {
        case KIND_QUAD: {
            return length(cross(o.b.xyz, o.c.xyz));
        }
        case KIND_SPHERE: {
            return 4.0 * PI * o.a.w * o.a.w;
        }
        case KIND_CYLINDER: {
            let r = o.a.w;
            let caps = select(0.0, 2.0 * PI * r * r, (o.flags & FLAG_CAPS) != 0u);
            return TAU * r * length(o.b.xyz - o.a.xyz) + caps;
        }
        default: {
            let v = world_triangle(o, primitive);
            return 0.5 * length(cross(v[1] - v[0], v[2] - v[0]));
        }
    }
}

// 1 - cos of the half-angle of the cone a sphere subtends from p; negative inside it.
// CPU twin: `sphere_cone`.
fn sphere_cone(center: vec3f, radius: f32, p: vec3f) -> f32 {
    let d = center - p;
    let d2 = dot(d, d);
    let r2 = radius * radius;
    if d2 <= r2 * 1.0001 {
        return -1.0;
    }
    let sin2_max = r2 / d2;
    let cos_max = sqrt(max(0.0, 1.0 - sin2_max));
    return sin2_max / (1.0 + cos_max);
}

// Density (solid angle) of sampling point `p_light` with normal `n_light` on entry
// (object, primitive) from `p`, which was chosen with probability `pmf`.
// CPU twin: `area_light_pdf`.
fn area_light_pdf(object: u32, primitive: u32, pmf: f32, p: vec3f, p_light: vec3f, n_light: vec3f) -> f32 {
    let o = objects[object];
    let to_light = p_light - p;
    let d2 = dot(to_light, to_light);
    let cos_l = abs(dot(n_light, -to_light)) / sqrt(d2);
    if o.kind == KIND_SPHERE {
        let one_minus_cos = sphere_cone(o.a.xyz, o.a.w, p);
        if one_minus_cos > 0.0 {
            return pmf / (TAU * one_minus_cos);
        }
    }
    let area = emitter_area(o, primitive);
    if cos_l <= 0.0 || area <= 0.0 {
        return 0.0;
    }
    return pmf * d2 / (cos_l * area);
}

// A point on a shape: point, normal, and its area density (a negative value: the
// solid-angle density of a sphere's cone sample).
struct ShapeSample {
    point: vec3f,
    normal: vec3f,
    density: f32,
    // Mesh triangle: its barycentrics (b1, b2) at the point.
    barycentrics: vec2f,
}

// CPU twin: `sample_shape`.
fn sample_shape(o: Object, primitive: u32, p: vec3f, u: vec2f, u_part: f32) -> ShapeSample {
    let a = o.a.xyz;
    let b = o.b.xyz;
    let c = o.c.xyz;
    switch o.kind {
        case KIND_QUAD: {
            let n = cross(b, c);
            return ShapeSample(a + u.x * b + u.y * c, normalize(n), 1.0 / length(n), vec2f(0.0));
        }
        case KIND_SPHERE: {
            let radius = o.a.w;
            let one_minus_cos = sphere_cone(a, radius, p);
            if one_minus_cos > 0.0 {
                let dir = sample_cone(normalize(a - p), one_minus_cos, u);
                var t = intersect_sphere(a, radius, Ray(p, dir), 1e30);
                if t == MISS {
                    t = dot(a - p, dir);
                }
                let q = p + t * dir;
                return ShapeSample(q, normalize(q - a), -1.0 / (TAU * one_minus_cos), vec2f(0.0));
            }
            let n = sample_uniform_sphere(u);
            return ShapeSample(a + radius * n, n, 1.0 / (4.0 * PI * radius * radius), vec2f(0.0));
        }
        case KIND_CYLINDER: {
            let radius = o.a.w;
            let axis_full = b - a;
            let height = length(axis_full);
            let axis = axis_full / height;
            let frame = frame_around(axis);
            let area = emitter_area(o, primitive);
            let side = TAU * radius * height;
            if u_part * area < side || (o.flags & FLAG_CAPS) == 0u {
                let phi = TAU * u.x;
                let radial = frame[0] * cos(phi) + frame[1] * sin(phi);
                return ShapeSample(a + axis * (u.y * height) + radial * radius, radial, 1.0 / area, vec2f(0.0));
            }
            let top = u_part * area >= side + 0.5 * (area - side);
            let d = sample_disk(u) * radius;
            let center = select(a, b, top);
            return ShapeSample(center + frame[0] * d.x + frame[1] * d.y, select(-axis, axis, top), 1.0 / area, vec2f(0.0));
        }
        default: {
            let v = world_triangle(o, primitive);
            let v0 = v[0];
            let v1 = v[1];
            let v2 = v[2];
            let su = sqrt(u.x);
            let b1 = 1.0 - su;
            let b2 = u.y * su;
            let n = cross(v1 - v0, v2 - v0);
            return ShapeSample(v0 + b1 * (v1 - v0) + b2 * (v2 - v0), normalize(n), 2.0 / length(n), vec2f(b1, b2));
        }
    }
}

// A point on entry (object, primitive), chosen with probability `pmf`, as seen from `p`;
// `u_part` picks a cylinder's side or cap.
// CPU twin: `sample_area_light`.
fn sample_area_light(object: u32, primitive: u32, pmf: f32, p: vec3f, u: vec2f, u_part: f32) -> LightSample {
    let o = objects[object];
    let ss = sample_shape(o, primitive, p, u, u_part);
    let to_light = ss.point - p;
    let distance = length(to_light);
    if distance <= 0.0 {
        return invalid_light_sample();
    }
    let wi = to_light / distance;
    let cos_l = dot(ss.normal, -wi);
    if cos_l <= 0.0 {
        return invalid_light_sample();
    }
    var pdf: f32;
    if ss.density < 0.0 {
        pdf = pmf * -ss.density;
    } else {
        pdf = pmf * ss.density * distance * distance / cos_l;
    }
    var radiance = materials[o.material].emission;
    if o.kind == KIND_MESH {
        radiance = emission_at(o.material, triangle_uv(primitive, ss.barycentrics.x, ss.barycentrics.y));
    }
    return LightSample(wi, ss.point, true, radiance, pdf, pdf > 0.0 && pdf <= 3.0e38, true);
}
