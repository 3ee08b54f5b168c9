// From a hit to the local surface: position, normals, texture coordinates, base colour.
// CPU twin: `crates/cpu/src/surface.rs`.

#import scene
#import intersect
#import bvh
#import sampling

// CPU twin: `Surface`.
struct Surface {
    position: vec3f,
    // Geometric normal on the shape's front side (quad: edge_u x edge_v; solids: outward).
    ng: vec3f,
    // Shading normal, in the same hemisphere as `ng`.
    ns: vec3f,
    uv: vec2f,
    material: u32,
}

// CPU twin: `srgb_to_linear`.
fn srgb_to_linear(c: vec3f) -> vec3f {
    let low = c / 12.92;
    let high = pow((c + 0.055) / 1.055, vec3f(2.4));
    return select(high, low, c <= vec3f(0.04045));
}

// CPU twin: `texel`.
fn texel(info: TextureInfo, x: u32, y: u32) -> vec3f {
    let packed = texels[info.offset + y * info.width + x];
    return srgb_to_linear(unpack4x8unorm(packed).rgb);
}

// Bilinear lookup in linear RGB: u wraps, v clamps; v = 0 is the top row.
// CPU twin: `sample_texture`.
fn sample_texture(index: u32, uv: vec2f) -> vec3f {
    let info = textures[index];
    let size = vec2f(f32(info.width), f32(info.height));
    let p = vec2f(fract(uv.x), clamp(uv.y, 0.0, 1.0)) * size - 0.5;
    let f = fract(p);
    let base = floor(p);
    let x0 = u32(i32(base.x + size.x) % i32(info.width));
    let x1 = (x0 + 1u) % info.width;
    let y0 = u32(clamp(base.y, 0.0, size.y - 1.0));
    let y1 = u32(clamp(base.y + 1.0, 0.0, size.y - 1.0));
    let top = mix(texel(info, x0, y0), texel(info, x1, y0), f.x);
    let bottom = mix(texel(info, x0, y1), texel(info, x1, y1), f.x);
    return mix(top, bottom, f.y);
}

// CPU twin: `base_color`.
fn base_color(material: Material, uv: vec2f) -> vec3f {
    if material.texture >= 0 {
        return sample_texture(u32(material.texture), uv);
    }
    return material.base_color;
}

// CPU twin: `surface_at`.
fn surface_at(hit: Hit, ray: Ray) -> Surface {
    let o = objects[hit.object];
    let p = ray.origin + hit.t * ray.dir;
    var s = Surface(p, vec3f(0.0, 1.0, 0.0), vec3f(0.0, 1.0, 0.0), vec2f(0.0), o.material);
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
            let v0 = vertices[i];
            let v1 = vertices[i + 1u];
            let v2 = vertices[i + 2u];
            let b0 = 1.0 - hit.b1 - hit.b2;
            s.ng = normalize(cross(v1.position - v0.position, v2.position - v0.position));
            let n = b0 * v0.normal + hit.b1 * v1.normal + hit.b2 * v2.normal;
            if (o.flags & FLAG_FLAT) != 0u || dot(n, n) < 1e-12 {
                s.ns = s.ng;
            } else {
                s.ns = normalize(n);
                if dot(s.ns, s.ng) < 0.0 {
                    s.ns = -s.ns;
                }
            }
            s.uv = b0 * vec2f(v0.u, v0.v) + hit.b1 * vec2f(v1.u, v1.v) + hit.b2 * vec2f(v2.u, v2.v);
        }
    }
    return s;
}
