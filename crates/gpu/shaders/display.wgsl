// The viewer's display pass: one full-screen triangle whose fragments read the linear
// accumulation (fixed-point sums, see integrator.wgsl), divide by the sample count, apply
// exposure and an optional tone mapper, and encode sRGB unless the surface does. The
// accumulation itself is never changed. Host: `crates/gpu/src/display.rs`. The CPU
// backend's viewer runs its CPU twin: `crates/cpu/src/display.rs`.

// Host: `GpuDisplayParams`.
struct DisplayParams {
    // Image size in pixels.
    width: u32,
    height: u32,
    // Samples in rows >= rows_ahead; rows below hold one more.
    samples: u32,
    rows_ahead: u32,
    // Surface size in pixels.
    target_width: f32,
    target_height: f32,
    // TONEMAP_*.
    tonemap: u32,
    // 1: apply the sRGB curve here (the surface format is not sRGB).
    encode_srgb: u32,
}

// Same layout as the integrator's `AccumPixel`.
struct DisplayPixel {
    hi: vec4u,
    lo: vec4u,
}

const TONEMAP_CLAMP: u32 = 0u;
const TONEMAP_ACES: u32 = 1u;
const TONEMAP_AGX: u32 = 2u;

// Storage, not uniform, for the reason in params.wgsl.
@group(0) @binding(0) var<storage, read> display: DisplayParams;
@group(0) @binding(1) var<storage, read> pixels: array<DisplayPixel>;

@vertex
fn vertex_main(@builtin(vertex_index) i: u32) -> @builtin(position) vec4f {
    // A triangle covering the screen: (-1,-1), (3,-1), (-1,3).
    let p = vec2f(f32((i << 1u) & 2u), f32(i & 2u));
    return vec4f(p * 2.0 - 1.0, 0.0, 1.0);
}

// Narkowicz's fit of the ACES filmic curve.
// CPU twin: `aces`
fn aces(x: vec3f) -> vec3f {
    return clamp((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), vec3f(0.0), vec3f(1.0));
}

// AgX (Troy Sobotka) with its default look: log2 encoding in the AgX inset space, the
// polynomial fit of its sigmoid (Benjamin Wrensch's), back to linear Rec.709.
// CPU twin: `agx`
fn agx(color: vec3f) -> vec3f {
    let inset = mat3x3f(
        vec3f(0.842479062253094, 0.0423282422610123, 0.0423756549057051),
        vec3f(0.0784335999999992, 0.878468636469772, 0.0784336),
        vec3f(0.0792237451477643, 0.0791661274605434, 0.879142973793104),
    );
    let outset = mat3x3f(
        vec3f(1.19687900512017, -0.0528968517574562, -0.0529716355144438),
        vec3f(-0.0980208811401368, 1.15190312990417, -0.0980434501171241),
        vec3f(-0.0990297440797205, -0.0989611768448433, 1.15107367264116),
    );
    let min_ev = -12.47393;
    let max_ev = 4.026069;
    var x = inset * max(color, vec3f(1e-10));
    x = clamp((log2(x) - min_ev) / (max_ev - min_ev), vec3f(0.0), vec3f(1.0));
    let x2 = x * x;
    let x4 = x2 * x2;
    let s = 15.5 * x4 * x2 - 40.14 * x4 * x + 31.96 * x4 - 6.868 * x2 * x + 0.4298 * x2
        + 0.1191 * x - 0.00232;
    // Back to Rec.709, then decode the sigmoid's display encoding to linear.
    return clamp(pow(max(outset * s, vec3f(0.0)), vec3f(2.2)), vec3f(0.0), vec3f(1.0));
}

// CPU twin: `srgb_encode`
fn srgb_encode(c: vec3f) -> vec3f {
    let x = clamp(c, vec3f(0.0), vec3f(1.0));
    return select(1.055 * pow(x, vec3f(1.0 / 2.4)) - 0.055, 12.92 * x, x <= vec3f(0.0031308));
}

@fragment
// CPU twin: `display_color`
fn fragment_main(@builtin(position) position: vec4f) -> @location(0) vec4f {
    let x = min(u32(position.x * f32(display.width) / display.target_width), display.width - 1u);
    let y = min(u32(position.y * f32(display.height) / display.target_height), display.height - 1u);
    let count = display.samples + select(0u, 1u, y < display.rows_ahead);
    if count == 0u {
        return vec4f(0.0, 0.0, 0.0, 1.0);
    }
    let p = pixels[y * display.width + x];
    let sum = vec3f(p.hi.xyz) + vec3f(p.lo.xyz) * (1.0 / 4294967296.0);
    var color = sum / f32(count);
    switch display.tonemap {
        case TONEMAP_ACES: {
            color = aces(color);
        }
        case TONEMAP_AGX: {
            color = agx(color);
        }
        default: {
            color = clamp(color, vec3f(0.0), vec3f(1.0));
        }
    }
    if display.encode_srgb == 1u {
        color = srgb_encode(color);
    }
    return vec4f(color, 1.0);
}
