// From a hit to the local surface: position, normals (normal maps applied), texture
// coordinates, material.
// CPU twin: `crates/cpu/src/surface.rs`.

#import scene
#import textures
#import intersect
#import instance
#import bvh
#import sampling

// CPU twin: `Surface`.
struct Surface {
    position: vec3f,
    // Geometric normal on the shape's front side (quad: edge_u x edge_v; solids: outward).
    ng: vec3f,
    // Shading normal, in the same hemisphere as `ng`.
    ns: vec3f,
    // The shading normal of the material's coat: its own normal map (TEXTURE_COAT_NORMAL)
    // applied, else `ns`; in the same hemisphere as `ng`.
    nc: vec3f,
    uv: vec2f,
    material: u32,
    // The vertex colour (white but on meshes with COLOR_0), multiplying the base colour.
    color: vec3f,
}

// The sign of the bitangent in a tangent's code: -1 or 1.
// Host twin: `pathlight_core::octahedral::tangent_sign`.
fn tangent_sign(code: u32) -> f32 {
    return select(1.0, -1.0, (code & 0x10000u) != 0u);
}

// The unit vector of an octahedral code; zero for the code 0x80008000.
// Host twin (encoder and decoder): `pathlight_core::octahedral`.
fn decode_unit(code: u32) -> vec3f {
    if code == 0x80008000u {
        return vec3f(0.0);
    }
    let e = unpack2x16snorm(code);
    let z = 1.0 - abs(e.x) - abs(e.y);
    let t = max(-z, 0.0);
    return normalize(vec3f(e.x + select(t, -t, e.x >= 0.0), e.y + select(t, -t, e.y >= 0.0), z));
}

// The shading normal `ns` bent by material `m`'s normal map `which` (TEXTURE_NORMAL or
// TEXTURE_COAT_NORMAL, its x and y scaled by `scale`) at `uv`, in the frame of the
// corner-interpolated tangent `tangent` (bitangent cross(ns, tangent) * sign).
// CPU twin: `normal_mapped`.
fn normal_mapped(m: Material, which: u32, scale: f32, uv: vec2f, ns: vec3f, tangent: vec3f, sign: f32) -> vec3f {
    let t = tangent - dot(tangent, ns) * ns;
    if dot(t, t) < 1e-12 {
        return ns;
    }
    let tn = normalize(t);
    let b = cross(ns, tn) * sign;
    let c = material_texture(m, which, uv).xyz * 2.0 - 1.0;
    let n = tn * (c.x * scale) + b * (c.y * scale) + ns * c.z;
    if dot(n, n) < 1e-12 {
        return ns;
    }
    return normalize(n);
}

// `n` turned towards `ng` (both on the side of the unit `wo`) just enough that the mirror
// reflection of `wo` about it leaves the surface at least as steeply as
// min(0.9 wo.ng, 0.01) (Cycles' `ensure_valid_specular_reflection`).
// CPU twin: `valid_reflection_normal`.
fn valid_reflection_normal(ng: vec3f, wo: vec3f, n: vec3f) -> vec3f {
    let iz = dot(wo, ng);
    let threshold = min(0.9 * iz, 0.01);
    if dot(2.0 * dot(n, wo) * n - wo, ng) >= threshold || iz <= 0.0 {
        return n;
    }
    let x0 = n - dot(n, ng) * ng;
    let x = select(vec3f(0.0), normalize(x0), dot(x0, x0) > 0.0);
    let ix = dot(wo, x);
    let a = ix * ix + iz * iz;
    let b = 2.0 * (a + iz * threshold);
    let c = (threshold + iz) * (threshold + iz);
    let root = sqrt(max(b * b - 4.0 * a * c, 0.0));
    let nz2 = 0.25 * select(b - root, b + root, ix < 0.0) / a;
    return sqrt(max(1.0 - nz2, 0.0)) * x + sqrt(max(nz2, 0.0)) * ng;
}

// CPU twin: `surface_at`.
fn surface_at(hit: Hit, ray: Ray) -> Surface {
    let o = objects[hit.object];
    let p = ray.origin + hit.t * ray.dir;
    var s = Surface(p, vec3f(0.0, 1.0, 0.0), vec3f(0.0, 1.0, 0.0), vec3f(0.0, 1.0, 0.0), vec2f(0.0), o.material, vec3f(1.0));
    switch o.kind {
        case KIND_QUAD: {
            s.ng = normalize(cross(o.b.xyz, o.c.xyz));
            s.ns = s.ng;
            s.uv = vec2f(hit.b1, 1.0 - hit.b2);
        }
        case KIND_SPHERE: {
            let n = normalize(p - o.a.xyz);
            s.ng = n;
            s.ns = n;
            let phi = atan2(n.x, n.z) + o.b.x;
            s.uv = vec2f(fract(0.5 + phi / TAU), acos(clamp(n.y, -1.0, 1.0)) / PI);
        }
        case KIND_CYLINDER: {
            let axis_full = o.b.xyz - o.a.xyz;
            let height = length(axis_full);
            let axis = axis_full / height;
            let local = p - o.a.xyz;
            let y = dot(local, axis);
            let radial = local - y * axis;
            let radius = o.a.w;
            let frame = frame_around(axis);
            let phi = atan2(dot(radial, frame[1]), dot(radial, frame[0]));
            if (o.flags & FLAG_CAPS) != 0u && dot(radial, radial) < radius * radius * 0.999 {
                s.ng = select(axis, -axis, y < 0.5 * height);
                s.uv = vec2f(fract(phi / TAU), length(radial) / radius);
            } else {
                s.ng = normalize(radial);
                s.uv = vec2f(fract(phi / TAU), 1.0 - y / height);
            }
            s.ns = s.ng;
        }
        default: {
            let i = 3u * hit.primitive;
            let v0 = vertices[triangles[i]];
            let v1 = vertices[triangles[i + 1u]];
            let v2 = vertices[triangles[i + 2u]];
            let b0 = 1.0 - hit.b1 - hit.b2;
            let instanced = INSTANCES && (o.flags & FLAG_INSTANCE) != 0u;
            var ng = cross(v1.position - v0.position, v2.position - v0.position);
            var n0 = decode_unit(v0.normal);
            var n1 = decode_unit(v1.normal);
            var n2 = decode_unit(v2.normal);
            if instanced {
                // Corner by corner, as a glTF viewer's vertex shader places them.
                let placement = instances[o.instance];
                ng = to_world_normal(placement, ng);
                n0 = normalize_or_zero(to_world_normal(placement, n0));
                n1 = normalize_or_zero(to_world_normal(placement, n1));
                n2 = normalize_or_zero(to_world_normal(placement, n2));
            }
            let n = b0 * n0 + hit.b1 * n1 + hit.b2 * n2;
            s.ng = normalize(ng);
            s.uv = b0 * v0.uv + hit.b1 * v1.uv + hit.b2 * v2.uv;
            s.color = triangle_color(hit.primitive, hit.b1, hit.b2).rgb;
            if (o.flags & FLAG_FLAT) != 0u || dot(n, n) < 1e-12 {
                s.ns = s.ng;
            } else {
                s.ns = normalize(n);
            }
            let m = materials[o.material];
            let interpolated = s.ns;
            var tangent = vec3f(0.0);
            let wo = -ray.dir;
            let side = select(-1.0, 1.0, dot(wo, s.ng) >= 0.0);
            if NORMAL_MAPS && (m.texture_mask & ((1u << TEXTURE_NORMAL) | (1u << TEXTURE_COAT_NORMAL))) != 0u {
                var t0 = decode_unit(v0.tangent);
                var t1 = decode_unit(v1.tangent);
                var t2 = decode_unit(v2.tangent);
                if instanced {
                    let placement = instances[o.instance];
                    t0 = normalize_or_zero(to_world_vector(placement, t0));
                    t1 = normalize_or_zero(to_world_vector(placement, t1));
                    t2 = normalize_or_zero(to_world_vector(placement, t2));
                }
                tangent = b0 * t0 + hit.b1 * t1 + hit.b2 * t2;
            }
            let sign = tangent_sign(v0.tangent) * select(1.0, -1.0, (o.flags & FLAG_MIRRORED) != 0u);
            if NORMAL_MAPS && has_texture(m, TEXTURE_NORMAL) {
                s.ns = normal_mapped(m, TEXTURE_NORMAL, m.normal_scale, s.uv, s.ns, tangent, sign);
                s.ns = side * valid_reflection_normal(side * s.ng, wo, side * s.ns);
            }
            if dot(s.ns, s.ng) < 0.0 {
                s.ns = -s.ns;
            }
            s.nc = s.ns;
            if NORMAL_MAPS && has_texture(m, TEXTURE_COAT_NORMAL) {
                s.nc = normal_mapped(m, TEXTURE_COAT_NORMAL, m.coat_normal_scale, s.uv, interpolated, tangent, sign);
                s.nc = side * valid_reflection_normal(side * s.ng, wo, side * s.nc);
                if dot(s.nc, s.ng) < 0.0 {
                    s.nc = -s.nc;
                }
            }
            return s;
        }
    }
    s.nc = s.ns;
    return s;
}
