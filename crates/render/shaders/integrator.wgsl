// The progressive path-tracing pass. One invocation per pixel of a band of rows adds
// `batch_samples` jittered (box-filtered) samples to an exact fixed-point accumulation
// buffer. Paths are unidirectional with BSDF sampling, `max_depth` counted in segments as
// Mitsuba counts it, and Russian roulette from `rr_depth`. Non-finite samples are dropped
// (counted as zero) so no NaN or Inf reaches the film.

// Per-batch constants. Host: `GpuFrameParams`.
struct FrameParams {
    camera_position: vec3f,
    width: u32,
    camera_forward: vec3f,
    height: u32,
    camera_right: vec3f,
    sample_offset: u32,
    camera_up: vec3f,
    batch_samples: u32,
    environment: vec3f,
    max_depth: u32,
    rr_depth: u32,
    seed: u32,
    object_count: u32,
    row_offset: u32,
}

// Running sum of samples per channel as a 64-bit fixed-point number hi + lo / 2^32.
// Integer adds are exact and cannot be reassociated by a shader compiler (a Kahan sum
// was: Mesa folds its compensation away), so the mean is exact to 2^-32 per sample
// however many samples and batches there are, and partial sums merge exactly.
// Host: `GpuAccumPixel`.
struct AccumPixel {
    hi: vec4u,
    lo: vec4u,
}

// Largest radiance a single sample may add per channel (2^24); larger values are clamped.
const SAMPLE_MAX: f32 = 16777216.0;

// `acc += value` in fixed point; `value` is clamped to [0, SAMPLE_MAX].
fn add_sample(acc: ptr<function, AccumPixel>, value: vec3f) {
    let v = clamp(value, vec3f(0.0), vec3f(SAMPLE_MAX));
    let whole = floor(v);
    let hi = vec3u(whole);
    // frac * 2^32 is exact: frac has 24 significant bits and the scale is a power of two.
    let lo = vec3u((v - whole) * 4294967296.0);
    add_fixed(acc, AccumPixel(vec4u(hi, 0u), vec4u(lo, 0u)));
}

// `acc += x` on 64-bit fixed point, saturating instead of wrapping.
fn add_fixed(acc: ptr<function, AccumPixel>, x: AccumPixel) {
    let lo = (*acc).lo + x.lo;
    let carry = select(vec4u(0u), vec4u(1u), lo < x.lo);
    let hi = (*acc).hi + x.hi + carry;
    let overflow = hi < (*acc).hi | (hi == (*acc).hi & (x.hi + carry) != vec4u(0u));
    (*acc).hi = select(hi, vec4u(0xffffffffu), overflow);
    (*acc).lo = select(lo, vec4u(0xffffffffu), overflow);
}

@group(1) @binding(0) var<uniform> params: FrameParams;
@group(1) @binding(1) var<storage, read_write> accum: array<AccumPixel>;

const T_MAX: f32 = 1.0e30;

// Start of a ray leaving `p` on the side of `ng` that `dir` points to.
fn offset_origin(p: vec3f, ng: vec3f, dir: vec3f) -> vec3f {
    let eps = 1e-4 * (1.0 + max(max(abs(p.x), abs(p.y)), abs(p.z)));
    return p + select(-ng, ng, dot(dir, ng) > 0.0) * eps;
}

fn camera_ray(x: u32, y: u32, rng: ptr<function, u32>) -> Ray {
    let jitter = vec2f(rng_next(rng), rng_next(rng));
    let ndc = vec2f(
        2.0 * (f32(x) + jitter.x) / f32(params.width) - 1.0,
        1.0 - 2.0 * (f32(y) + jitter.y) / f32(params.height),
    );
    let dir = params.camera_forward + ndc.x * params.camera_right + ndc.y * params.camera_up;
    return Ray(params.camera_position, normalize(dir));
}

fn trace_path(first: Ray, rng: ptr<function, u32>) -> vec3f {
    var ray = first;
    var radiance = vec3f(0.0);
    var throughput = vec3f(1.0);
    for (var depth = 1u; depth <= params.max_depth; depth++) {
        let hit = intersect_scene(ray, T_MAX, params.object_count);
        if hit.object == NO_HIT {
            radiance += throughput * params.environment;
            break;
        }
        let s = surface_at(hit, ray);
        let material = materials[s.material];
        let wo = -ray.dir;
        if dot(wo, s.ng) > 0.0 {
            radiance += throughput * material.emission;
        }
        if depth == params.max_depth {
            break;
        }
        let color = base_color(material, s.uv);
        let u_lobe = rng_next(rng);
        let u_fresnel = rng_next(rng);
        let u = vec2f(rng_next(rng), rng_next(rng));
        let bs = sample_bsdf(material, color, s, wo, u_lobe, u_fresnel, u);
        if !bs.valid {
            break;
        }
        throughput *= bs.weight;
        if depth >= params.rr_depth {
            let q = min(max(max(throughput.x, throughput.y), throughput.z), 0.95);
            if rng_next(rng) >= q {
                break;
            }
            throughput /= q;
        }
        ray = Ray(offset_origin(s.position, s.ng, bs.wi), bs.wi);
    }
    return radiance;
}

fn is_finite3(v: vec3f) -> bool {
    // NaN fails every comparison; Inf fails the bound.
    return all(abs(v) <= vec3f(3.0e38));
}

@compute @workgroup_size(8, 8)
fn render(@builtin(global_invocation_id) gid: vec3u) {
    let x = gid.x;
    let y = gid.y + params.row_offset;
    if x >= params.width || y >= params.height {
        return;
    }
    let pixel = y * params.width + x;
    var batch = AccumPixel(vec4u(0u), vec4u(0u));
    for (var i = 0u; i < params.batch_samples; i++) {
        var rng = rng_init(pixel, params.sample_offset + i, params.seed);
        let radiance = trace_path(camera_ray(x, y, &rng), &rng);
        if is_finite3(radiance) {
            add_sample(&batch, radiance);
        }
    }
    var total = accum[pixel];
    add_fixed(&total, batch);
    accum[pixel] = total;
}
