// The progressive path-tracing pass. One invocation per pixel of a band of rows adds
// `batch_samples` jittered (box-filtered) samples to an exact fixed-point accumulation
// buffer, and with `params.aovs` the same samples' auxiliary images (albedo and shading
// normal of the first surface that is not a perfect mirror or glass) to a second one. Paths are unidirectional: next-event estimation and BSDF sampling combined with
// the power heuristic, `max_depth` counted in segments as Mitsuba counts it, Russian
// roulette from `rr_depth` on the throughput without the 1/eta^2 radiance scaling (as
// Mitsuba). Non-finite samples are dropped (counted as zero), so no NaN or Inf reaches
// the film. CPU twin: `crates/cpu/src/integrator.rs`.

#import params
#import scene
#import bvh
#import sampler
#import camera
#import surface
#import material
#import lights

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
// CPU twin: `add_sample`
fn add_sample(acc: ptr<function, AccumPixel>, value: vec3f) {
    let v = clamp(value, vec3f(0.0), vec3f(SAMPLE_MAX));
    let whole = floor(v);
    let hi = vec3u(whole);
    // frac * 2^32 is exact: frac has 24 significant bits and the scale is a power of two.
    let lo = vec3u((v - whole) * 4294967296.0);
    add_fixed(acc, AccumPixel(vec4u(hi, 0u), vec4u(lo, 0u)));
}

// `acc += x` on 64-bit fixed point, saturating instead of wrapping (on the host:
// `GpuAccumPixel::accumulate`, and per channel `GpuAccumPixel::add_to_channel`).
fn add_fixed(acc: ptr<function, AccumPixel>, x: AccumPixel) {
    let lo = (*acc).lo + x.lo;
    let carry = select(vec4u(0u), vec4u(1u), lo < x.lo);
    let hi = (*acc).hi + x.hi + carry;
    let overflow = hi < (*acc).hi | (hi == (*acc).hi & (x.hi + carry) != vec4u(0u));
    (*acc).hi = select(hi, vec4u(0xffffffffu), overflow);
    (*acc).lo = select(lo, vec4u(0xffffffffu), overflow);
}

// The auxiliary images of one pixel: per channel a fixed-point sum, the normal stored as
// (n + 1) / 2. Host: `GpuAovPixel`.
struct AovPixel {
    albedo: AccumPixel,
    normal: AccumPixel,
}

@group(1) @binding(1) var<storage, read_write> accum: array<AccumPixel>;
// Since the counters were cleared: rays traced, as a 64-bit count [low word, high word], and
// samples dropped because their radiance was not finite (none in a correct render).
@group(1) @binding(2) var<storage, read_write> counters: array<atomic<u32>, 3>;

// Rays this invocation traced (camera, extension and shadow rays).
var<private> rays_traced: u32;
// Non-finite samples this invocation dropped.
var<private> samples_dropped: u32;
// Rays this workgroup traced and samples it dropped, added to `counters` once per workgroup.
var<workgroup> workgroup_rays: atomic<u32>;
var<workgroup> workgroup_dropped: atomic<u32>;
// With `params.aovs`: one pixel per pixel of `accum` (else a placeholder).
@group(1) @binding(3) var<storage, read_write> aov: array<AovPixel>;
// Whether the render can ask for auxiliary images (a pipeline constant, the host's
// `params.aovs != 0`): false compiles their bookkeeping out of the path loop.
override AOVS: bool = true;

const T_MAX: f32 = 1.0e30;

// Start of a ray leaving `p` on the side of `ng` that `dir` points to.
// CPU twin: `offset_origin`.
fn offset_origin(p: vec3f, ng: vec3f, dir: vec3f) -> vec3f {
    let eps = 1e-4 * (1.0 + max(max(abs(p.x), abs(p.y)), abs(p.z)));
    return p + select(-ng, ng, dot(dir, ng) > 0.0) * eps;
}

// The shadow ray testing light sample `ls` from surface point p (normal ng): from the offset
// origin to the light point, stopping just short of it (so a light never shadows itself).
struct ShadowRay {
    ray: Ray,
    t_max: f32,
}

// CPU twin: `shadow_ray`.
fn shadow_ray(p: vec3f, ng: vec3f, ls: LightSample) -> ShadowRay {
    let origin = offset_origin(p, ng, ls.wi);
    if !ls.finite {
        return ShadowRay(Ray(origin, ls.wi), T_MAX);
    }
    let to_light = ls.point - origin;
    let distance = length(to_light);
    return ShadowRay(Ray(origin, to_light / distance), distance * (1.0 - 1e-4));
}

// What a path brings back: its radiance and, with `params.aovs`, the albedo and shading
// normal of the first surface it met that is not a perfect mirror or glass (through those,
// weighted by what they pass on; the normal zero where it escaped at once).
// CPU twin: `PathSample`.
struct PathResult {
    radiance: vec3f,
    albedo: vec3f,
    normal: vec3f,
}

// One path. Extension and shadow rays go through a single `trace_scene` call site (a shadow
// ray is traced before the next extension ray), which keeps the kernel half as large as two
// inlined traversals; the estimator and the order of every sum are those of the CPU twin.
// CPU twin: `trace_path`.
fn trace_path(first: Ray, sampler: ptr<function, Sampler>) -> PathResult {
    var ray = first;
    var radiance = vec3f(0.0);
    // The auxiliary images: still looking for their surface, the weight of the perfect
    // mirrors and glass passed through so far, what was found.
    var aov_pending = AOVS && params.aovs != 0u;
    var aov_weight = vec3f(1.0);
    var albedo = vec3f(0.0);
    var normal = vec3f(0.0);
    var throughput = vec3f(1.0);
    // The BSDF sample that produced `ray`: its density and whether it was a delta lobe
    // (camera rays count as delta: emitters they see get full weight).
    var prev_pdf = 0.0;
    var prev_delta = true;
    var prev_position = ray.origin;
    // Normal (on the side of wo) at the vertex that produced `ray`.
    var prev_normal = vec3f(0.0);
    var eta_scale = 1.0;
    var depth = 1u;
    // A shadow ray waiting to be traced, and the radiance it adds if nothing blocks it.
    var shadow = ShadowRay(first, 0.0);
    var shadow_radiance = vec3f(0.0);
    var shadow_pending = false;
    // Whether `ray` still has to be traced.
    var extend = true;
    loop {
        let is_shadow = shadow_pending;
        var query = ShadowRay(ray, T_MAX);
        if is_shadow {
            query = shadow;
        }
        let hit = trace_scene(query.ray, query.t_max, params.object_count, is_shadow);
        rays_traced++;
        if is_shadow {
            shadow_pending = false;
            if hit.object == NO_HIT {
                radiance += shadow_radiance;
            }
            if extend {
                continue;
            }
            break;
        }
        extend = false;
        if hit.object == NO_HIT {
            let escape = env_escape(prev_normal, ray.dir, !prev_delta);
            var w = 1.0;
            if !prev_delta {
                w = power_heuristic(prev_pdf, escape.pdf);
            }
            let env = escape.radiance;
            radiance += throughput * env * w;
            if aov_pending {
                albedo = aov_weight * saturate(env);
                aov_pending = false;
            }
            break;
        }
        let s = surface_at(hit, ray);
        let material = material_at(s);
        let wo = -ray.dir;
        if dot(wo, s.ng) < 0.0 {
            // The segment ran inside the object it leaves: Beer-Lambert.
            let absorption = material_absorption(material);
            if max(max(absorption.x, absorption.y), absorption.z) > 0.0 {
                throughput *= exp(-absorption * hit.t);
            }
        }
        if dot(wo, s.ng) > 0.0 && max(max(material.emission.x, material.emission.y), material.emission.z) > 0.0 {
            var w = 1.0;
            if !prev_delta && objects[hit.object].light != NO_LIGHT {
                w = power_heuristic(prev_pdf, light_pdf(hit.object, hit.primitive, prev_position, s.position, s.ng));
            }
            radiance += throughput * material.emission * w;
        }
        let continuous = has_continuous_material_lobe(material);
        if aov_pending {
            normal = select(-s.ns, s.ns, dot(wo, s.ng) >= 0.0);
            if continuous {
                albedo = aov_weight * saturate(material_albedo(material));
                aov_pending = false;
            }
        }
        if depth == params.max_depth {
            break;
        }
        // Every bounce draws the same dimensions in the same order.
        let u_light_select = next_1d(sampler);
        let u_light = next_2d(sampler);
        let u_lobe = next_1d(sampler);
        let u_fresnel = next_1d(sampler);
        let u_bsdf = next_2d(sampler);
        let u_rr = next_1d(sampler);
        let n = select(-s.ns, s.ns, dot(wo, s.ng) >= 0.0);
        if continuous {
            let ls = sample_light(s.position, n, u_light_select, u_light);
            if ls.valid {
                let e = eval_material(material, s, wo, ls.wi);
                if max(max(e.f.x, e.f.y), e.f.z) > 0.0 {
                    shadow = shadow_ray(s.position, s.ng, ls);
                    shadow_radiance = throughput * e.f * ls.radiance * select(1.0, power_heuristic(ls.pdf, e.pdf), ls.mis) / ls.pdf;
                    shadow_pending = true;
                }
            }
        }
        let bs = sample_material(material, s, wo, u_lobe, u_fresnel, u_bsdf);
        if aov_pending && bs.valid {
            // A perfect mirror or glass passes on what it reflects or transmits (without
            // refraction's radiance scaling).
            aov_weight *= saturate(bs.weight * bs.eta * bs.eta);
        }
        if bs.valid {
            throughput *= bs.weight;
            prev_pdf = bs.pdf;
            prev_delta = bs.delta;
            prev_position = s.position;
            prev_normal = n;
            eta_scale *= bs.eta;
            extend = true;
            if depth >= params.rr_depth {
                let q = min(max(max(throughput.x, throughput.y), throughput.z) * eta_scale * eta_scale, 0.95);
                if u_rr >= q {
                    extend = false;
                } else {
                    throughput /= q;
                }
            }
            ray = Ray(offset_origin(s.position, s.ng, bs.wi), bs.wi);
            depth++;
        }
        if !extend && !shadow_pending {
            break;
        }
    }
    if aov_pending {
        // The path ended on mirrors or glass: they count as white.
        albedo = aov_weight;
    }
    return PathResult(radiance, albedo, normal);
}

// `acc += ` the auxiliary images of `path`: the albedo, and the normal as (n + 1) / 2
// (an albedo that is not finite counts as zero, such a normal as the zero vector).
// CPU twin: `add_aov_sample`
fn add_aov_sample(acc: ptr<function, AovPixel>, path: PathResult) {
    // Through locals: naga's SPIR-V writer fails on a pointer to a member of a pointee.
    var albedo = (*acc).albedo;
    add_sample(&albedo, select(vec3f(0.0), path.albedo, is_finite3(path.albedo)));
    var normal = (*acc).normal;
    add_sample(&normal, select(vec3f(0.5), (path.normal + 1.0) * 0.5, is_finite3(path.normal)));
    *acc = AovPixel(albedo, normal);
}

fn is_finite3(v: vec3f) -> bool {
    // NaN fails every comparison; Inf fails the bound.
    return all(abs(v) <= vec3f(3.0e38));
}

@compute @workgroup_size(8, 8)
fn render(@builtin(global_invocation_id) gid: vec3u, @builtin(local_invocation_index) local: u32) {
    let x = gid.x;
    let y = gid.y + params.row_offset;
    if x < params.width && y < params.row_end {
        let pixel = y * params.width + x;
        var batch = AccumPixel(vec4u(0u), vec4u(0u));
        var aov_batch = AovPixel(batch, batch);
        for (var i = 0u; i < params.batch_samples; i++) {
            var sampler = sampler_init(params.sampler, pixel, params.sample_offset + i, params.seed);
            let path = trace_path(camera_ray(x, y, &sampler), &sampler);
            if is_finite3(path.radiance) {
                add_sample(&batch, path.radiance);
            } else {
                samples_dropped++;
            }
            if AOVS && params.aovs != 0u {
                add_aov_sample(&aov_batch, path);
            }
        }
        var total = accum[pixel];
        add_fixed(&total, batch);
        accum[pixel] = total;
        if AOVS && params.aovs != 0u {
            var albedo = aov[pixel].albedo;
            add_fixed(&albedo, aov_batch.albedo);
            var normal = aov[pixel].normal;
            add_fixed(&normal, aov_batch.normal);
            aov[pixel] = AovPixel(albedo, normal);
        }
    }
    atomicAdd(&workgroup_rays, rays_traced);
    atomicAdd(&workgroup_dropped, samples_dropped);
    workgroupBarrier();
    if local == 0u {
        let n = atomicLoad(&workgroup_rays);
        let old = atomicAdd(&counters[0], n);
        if old > 0xffffffffu - n {
            atomicAdd(&counters[1], 1u);
        }
        atomicAdd(&counters[2], atomicLoad(&workgroup_dropped));
    }
}
