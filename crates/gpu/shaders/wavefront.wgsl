// The integrator of `integrator.wgsl` split into kernels over queues of paths (a wavefront,
// Laine, Karras and Aila 2013): the walk of extension rays and the walk of shadow rays run in
// kernels of their own, without the shading's live state beside them, and each kernel's
// lanes take the paths still alive from a queue, so a warp's lanes stay busy.
//
// A wave of paths (one or more samples of every pixel of a band of rows): `wf_start` makes
// every path's camera ray; then, per segment, `wf_trace` traces the shadow rays the last
// shading queued and the extension rays it queued (one kernel, so a segment is two
// dispatches), and `wf_shade` shades the hits (emission, the light sample as a shadow ray,
// the BSDF sample as the next extension ray); a last `wf_trace` traces the last shadow rays
// and `wf_finish` adds the samples to the film. A shadow ray is traced before the path's next
// extension ray is shaded, so the estimator and the order of every sum are `trace_path`'s and
// the images are the same bit for bit (`crates/gpu/tests/gpu/wavefront.rs` holds them
// together).
//
// Frames of one sample each can overlap: a frame's `wf_start` puts its paths in another layer
// of the path state and appends them to the extension queue while the frames before it are in
// their last segments, so that those segments, with few paths left, are not traced alone
// (`Wavefront::submit_frames`). A path's segments do not depend on the paths beside it, and
// the film's sums are exact, so the image is the same.
// No CPU twin: the same pass as `integrator.wgsl`, cut into kernels; the CPU backend's twin of
// that pass is `crates/cpu/src/integrator.rs`.

#import integrator

// Fields of a path's state, each an array of `CAPACITY` vec4s in `paths`.
// Ray origin; the density of the BSDF sample that produced the ray.
const F_ORIGIN: u32 = 0u;
// Ray direction; the product of the refractions' eta.
const F_DIR: u32 = 1u;
// Throughput; flags (depth | PATH_PREV_DELTA | PATH_AOV_PENDING), bitcast.
const F_THROUGHPUT: u32 = 2u;
// Radiance so far; the sampler's next dimension, bitcast.
const F_RADIANCE: u32 = 3u;
// The vertex that produced the ray; the sampler's PCG state, bitcast.
const F_PREV_POSITION: u32 = 4u;
// The normal there (on the side of wo); the sample index, bitcast.
const F_PREV_NORMAL: u32 = 5u;
// The shadow ray: origin and t_max, direction, the radiance it adds unblocked (w: the
// hit's b2).
const F_SHADOW_ORIGIN: u32 = 6u;
const F_SHADOW_DIR: u32 = 7u;
const F_SHADOW_RADIANCE: u32 = 8u;
// The extension ray's hit: t, object, primitive, b1 (bitcast; b2 in F_SHADOW_RADIANCE.w).
const F_HIT: u32 = 9u;
// With auxiliary images: the weight of the mirrors and glass passed, the albedo, the normal.
const F_AOV_WEIGHT: u32 = 10u;
const F_ALBEDO: u32 = 11u;
const F_NORMAL: u32 = 12u;

const PATH_DEPTH: u32 = 0xffffu;
const PATH_PREV_DELTA: u32 = 0x10000u;
const PATH_AOV_PENDING: u32 = 0x20000u;

// Slots of `queue_counts`: the paths in the two extension queues (in and out, alternating
// by segment) and the two shadow queues (filled by one segment's shading, traced with the
// next segment's extension rays); the segment as the trace kernel reads it and as the shading
// reads it (each kernel writes the other's, so no kernel writes what its own lanes read); the
// sample of the batch.
const COUNT_SHADOW: u32 = 2u;
const SEGMENT_TRACE: u32 = 4u;
const SEGMENT_SHADE: u32 = 5u;
const COUNT_SAMPLE: u32 = 6u;
const COUNT_WAVE_SAMPLES: u32 = 7u;
const QUEUE_SHADOW: u32 = 2u;

@group(2) @binding(0) var<storage, read_write> paths: array<vec4f>;
// Four queues of `CAPACITY` path slots each: extension 0 and 1, shadow 0 and 1.
@group(2) @binding(1) var<storage, read_write> queues: array<u32>;
@group(2) @binding(2) var<storage, read_write> queue_counts: array<atomic<u32>, 8>;
// The same buffer read with plain loads: a kernel reads only words that no invocation of its
// own writes (the previous kernels wrote them), so every lane may load them as constants,
// without an atomic each or a barrier to share one.
@group(2) @binding(3) var<storage, read_write> queue_lengths: array<u32, 8>;

// Where a wave's paths lie and which samples they are: `x`, the first layer of the path state
// its `wf_start` fills and its `wf_finish` reads (layer l: slots l * band .. (l + 1) * band);
// `y`, the waves started and not yet finished when its `wf_start` runs. A wave with none
// ahead of it starts the segments afresh; one with waves ahead appends its camera rays to the
// extension queue they are in, so that frames overlap (`Wavefront::submit_frames`). The host
// keeps one entry for each pair in a table and binds it with a dynamic offset.
@group(2) @binding(4) var<uniform> wave_layer: vec2u;

// The next segment's dispatches, as `dispatch_workgroups_indirect` reads them: the trace
// kernel's workgroups (x, 1, 1), then the shading's. Each counts one workgroup more than its
// queues need, so no dispatch is empty (its first invocation resets the other buffer), and
// counts a queue's workgroups on its own, so the trace kernel's may be one more again.
// Two buffers alternate by segment: one is read as a dispatch while the kernels fill the other.
@group(3) @binding(0) var<storage, read_write> next_dispatch: array<atomic<u32>, 8>;

// Appends `slot` to queue `q`, counting the workgroups of 64 invocations its entries take.
fn enqueue(q: u32, slot: u32) {
    let i = atomicAdd(&queue_counts[q], 1u);
    queues[q * CAPACITY + i] = slot;
    if i % 64u == 0u {
        atomicAdd(&next_dispatch[0], 1u);
        if q < QUEUE_SHADOW {
            atomicAdd(&next_dispatch[3], 1u);
        }
    }
}

// Sets `next_dispatch` to `trace` and `shade` workgroups.
fn set_next_dispatch(trace: u32, shade: u32) {
    atomicStore(&next_dispatch[0], trace);
    atomicStore(&next_dispatch[3], shade);
    for (var k = 1u; k < 6u; k++) {
        if k != 3u {
            atomicStore(&next_dispatch[k], 1u);
        }
    }
}

// Adds `n` rays to the 64-bit ray count of `counters`.
fn count_rays(n: u32) {
    let old = atomicAdd(&counters[0], n);
    if old > 0xffffffffu - n {
        atomicAdd(&counters[1], 1u);
    }
}

// Path slots: the most paths of a wave (a band of rows, or the part of one the host cuts so
// that the state fits a binding and the dispatches their limit). The host sets it.
override CAPACITY: u32 = 1048576u;

fn field(f: u32, slot: u32) -> u32 {
    return f * CAPACITY + slot;
}

// Pixels of the band; a wave holds one or more samples of each (slot: sample * band + pixel).
fn band_pixels() -> u32 {
    return params.width * (params.row_end - params.row_offset);
}

// The pixel of slot `slot` of the wave.
fn slot_pixel(slot: u32) -> u32 {
    return params.row_offset * params.width + slot % band_pixels();
}

// The sampler of a path at its dimension and PCG state.
fn path_sampler(slot: u32, dimension: u32, rng_state: u32, sample_index: u32) -> Sampler {
    var s = sampler_init(params.sampler, slot_pixel(slot), sample_index, params.seed);
    s.dimension = dimension;
    s.rng_state = rng_state;
    return s;
}

// Every path of the wave (one path per pixel of the band for each of `num_workgroups.z`
// samples, from layer `wave_layer.x` on): its camera ray, queued for extension.
var<workgroup> start_count: atomic<u32>;
var<workgroup> start_base: u32;

@compute @workgroup_size(8, 8)
fn wf_start(
    @builtin(global_invocation_id) gid: vec3u,
    @builtin(local_invocation_index) lane: u32,
    @builtin(num_workgroups) groups: vec3u,
) {
    let x = gid.x;
    let y = gid.y + params.row_offset;
    let inside = x < params.width && y < params.row_end;
    let slot = (wave_layer.x + gid.z) * band_pixels() + (y - params.row_offset) * params.width + x;
    if wave_layer.y == 0u {
        if all(gid == vec3u(0u)) {
            let n = band_pixels() * groups.z;
            atomicStore(&queue_counts[0], n);
            atomicStore(&queue_counts[1], 0u);
            atomicStore(&queue_counts[COUNT_SHADOW], 0u);
            atomicStore(&queue_counts[COUNT_SHADOW + 1u], 0u);
            atomicStore(&queue_counts[SEGMENT_TRACE], 0u);
            atomicStore(&queue_counts[COUNT_WAVE_SAMPLES], groups.z);
            set_next_dispatch(1u + (n + 63u) / 64u, 1u + (n + 63u) / 64u);
        }
        if inside {
            queues[slot] = slot;
        }
    } else {
        // Waves ahead are in flight: the workgroup's paths join the extension queue the next
        // segment traces, as one run of entries (one atomic a workgroup), counting the
        // workgroups of 64 entries the run opens as `enqueue` does.
        let into = queue_lengths[SEGMENT_TRACE] & 1u;
        var entry = 0u;
        if inside {
            entry = atomicAdd(&start_count, 1u);
        }
        workgroupBarrier();
        if lane == 0u {
            let count = atomicLoad(&start_count);
            let base = atomicAdd(&queue_counts[into], count);
            let opened = (base + count + 63u) / 64u - (base + 63u) / 64u;
            atomicAdd(&next_dispatch[0], opened);
            atomicAdd(&next_dispatch[3], opened);
            start_base = base;
        }
        let base = workgroupUniformLoad(&start_base);
        if inside {
            queues[into * CAPACITY + base + entry] = slot;
        }
    }
    if !inside {
        return;
    }
    let sample_index = params.sample_offset + queue_lengths[COUNT_SAMPLE] + wave_layer.y + gid.z;
    var sampler = sampler_init(params.sampler, y * params.width + x, sample_index, params.seed);
    let ray = camera_ray(x, y, &sampler);
    var flags = 1u | PATH_PREV_DELTA;
    if AOVS && params.aovs != 0u {
        flags |= PATH_AOV_PENDING;
        paths[field(F_AOV_WEIGHT, slot)] = vec4f(1.0);
        paths[field(F_ALBEDO, slot)] = vec4f(0.0);
        paths[field(F_NORMAL, slot)] = vec4f(0.0);
    }
    paths[field(F_ORIGIN, slot)] = vec4f(ray.origin, 0.0);
    paths[field(F_DIR, slot)] = vec4f(ray.dir, 1.0);
    paths[field(F_THROUGHPUT, slot)] = vec4f(vec3f(1.0), bitcast<f32>(flags));
    paths[field(F_RADIANCE, slot)] = vec4f(vec3f(0.0), bitcast<f32>(sampler.dimension));
    paths[field(F_PREV_POSITION, slot)] = vec4f(ray.origin, bitcast<f32>(sampler.rng_state));
    paths[field(F_PREV_NORMAL, slot)] = vec4f(vec3f(0.0), bitcast<f32>(sample_index));
}

// The shadow rays the last segment's shading queued (their light samples' radiance where
// nothing blocks them), then the nearest hits of the extension rays it queued.
@compute @workgroup_size(64)
fn wf_trace(@builtin(global_invocation_id) gid: vec3u) {
    let segment = queue_lengths[SEGMENT_TRACE];
    let into = segment & 1u;
    let n_shadow = queue_lengths[QUEUE_SHADOW + 1u - into];
    let n = n_shadow + queue_lengths[into];
    let i = gid.x;
    if i == 0u {
        // The queues and dispatches this segment's shading fills; nothing reads them now.
        set_next_dispatch(1u, 1u);
        atomicStore(&queue_counts[1u - into], 0u);
        atomicStore(&queue_counts[QUEUE_SHADOW + into], 0u);
        atomicStore(&queue_counts[SEGMENT_SHADE], segment);
        count_rays(n);
    }
    if i < n {
        if i < n_shadow {
            trace_shadow(queues[(QUEUE_SHADOW + 1u - into) * CAPACITY + i]);
        } else {
            trace_extension(queues[into * CAPACITY + i - n_shadow]);
        }
    }
}

// The shadow ray of path `slot`: its radiance added where nothing blocks it.
fn trace_shadow(slot: u32) {
    let o = paths[field(F_SHADOW_ORIGIN, slot)];
    let d = paths[field(F_SHADOW_DIR, slot)];
    let hit = trace_scene(Ray(o.xyz, d.xyz), o.w, params.object_count, true);
    if hit.object == NO_HIT {
        let r = paths[field(F_RADIANCE, slot)];
        paths[field(F_RADIANCE, slot)] = vec4f(r.xyz + paths[field(F_SHADOW_RADIANCE, slot)].xyz, r.w);
    }
}

// The nearest hit of path `slot`'s extension ray.
fn trace_extension(slot: u32) {
    let ray = Ray(paths[field(F_ORIGIN, slot)].xyz, paths[field(F_DIR, slot)].xyz);
    let hit = trace_scene(ray, T_MAX, params.object_count, false);
    paths[field(F_HIT, slot)] = vec4f(hit.t, bitcast<f32>(hit.object), bitcast<f32>(hit.primitive), hit.b1);
    paths[field(F_SHADOW_RADIANCE, slot)].w = hit.b2;
}

// Shades every queued path at its hit.
@compute @workgroup_size(64)
fn wf_shade(@builtin(global_invocation_id) gid: vec3u) {
    let segment = queue_lengths[SEGMENT_SHADE];
    let into = segment & 1u;
    let n = queue_lengths[into];
    let i = gid.x;
    if i == 0u {
        atomicStore(&queue_counts[SEGMENT_TRACE], segment + 1u);
    }
    if i < n {
        shade_path(queues[into * CAPACITY + i], into);
    }
}

// `trace_path`'s loop body for path `slot` of extension queue `into`, at its hit.
fn shade_path(slot: u32, into: u32) {
    let origin = paths[field(F_ORIGIN, slot)];
    let direction = paths[field(F_DIR, slot)];
    let through = paths[field(F_THROUGHPUT, slot)];
    let rad = paths[field(F_RADIANCE, slot)];
    let prev = paths[field(F_PREV_POSITION, slot)];
    let prev_n = paths[field(F_PREV_NORMAL, slot)];
    let h = paths[field(F_HIT, slot)];
    let hit = Hit(h.x, bitcast<u32>(h.y), bitcast<u32>(h.z), h.w, paths[field(F_SHADOW_RADIANCE, slot)].w);
    let ray = Ray(origin.xyz, direction.xyz);
    var flags = bitcast<u32>(through.w);
    var radiance = rad.xyz;
    var throughput = through.xyz;
    let prev_pdf = origin.w;
    let prev_delta = (flags & PATH_PREV_DELTA) != 0u;
    let prev_position = prev.xyz;
    let prev_normal = prev_n.xyz;
    var eta_scale = direction.w;
    let depth = flags & PATH_DEPTH;
    var aov_pending = (flags & PATH_AOV_PENDING) != 0u;
    var aov_weight = vec3f(1.0);
    var albedo = vec3f(0.0);
    var normal = vec3f(0.0);
    if aov_pending {
        aov_weight = paths[field(F_AOV_WEIGHT, slot)].xyz;
        normal = paths[field(F_NORMAL, slot)].xyz;
    }
    var sampler = path_sampler(slot, bitcast<u32>(rad.w), bitcast<u32>(prev.w), bitcast<u32>(prev_n.w));
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
            paths[field(F_ALBEDO, slot)] = vec4f(albedo, 0.0);
        }
        paths[field(F_RADIANCE, slot)] = vec4f(radiance, rad.w);
        paths[field(F_THROUGHPUT, slot)] = vec4f(throughput, bitcast<f32>(flags & ~PATH_AOV_PENDING));
        return;
    }
    let s = surface_at(hit, ray);
    let material = material_at(s);
    let wo = -ray.dir;
    if dot(wo, s.ng) < 0.0 {
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
            paths[field(F_ALBEDO, slot)] = vec4f(albedo, 0.0);
        }
        paths[field(F_NORMAL, slot)] = vec4f(normal, 0.0);
    }
    flags = select(flags & ~PATH_AOV_PENDING, flags | PATH_AOV_PENDING, aov_pending);
    if depth == params.max_depth {
        paths[field(F_RADIANCE, slot)] = vec4f(radiance, rad.w);
        paths[field(F_THROUGHPUT, slot)] = vec4f(throughput, bitcast<f32>(flags));
        return;
    }
    let u_light_select = next_1d(&sampler);
    let u_light = next_2d(&sampler);
    let u_lobe = next_1d(&sampler);
    let u_fresnel = next_1d(&sampler);
    let u_bsdf = next_2d(&sampler);
    let u_rr = next_1d(&sampler);
    let n_side = select(-s.ns, s.ns, dot(wo, s.ng) >= 0.0);
    if continuous {
        let ls = sample_light(s.position, n_side, u_light_select, u_light);
        if ls.valid {
            let e = eval_material(material, s, wo, ls.wi);
            if max(max(e.f.x, e.f.y), e.f.z) > 0.0 {
                let shadow = shadow_ray(s.position, s.ng, ls);
                let shadow_radiance = throughput * e.f * ls.radiance * select(1.0, power_heuristic(ls.pdf, e.pdf), ls.mis) / ls.pdf;
                paths[field(F_SHADOW_ORIGIN, slot)] = vec4f(shadow.ray.origin, shadow.t_max);
                paths[field(F_SHADOW_DIR, slot)] = vec4f(shadow.ray.dir, 0.0);
                paths[field(F_SHADOW_RADIANCE, slot)] = vec4f(shadow_radiance, 0.0);
                enqueue(QUEUE_SHADOW + into, slot);
            }
        }
    }
    let bs = sample_material(material, s, wo, u_lobe, u_fresnel, u_bsdf);
    if aov_pending && bs.valid {
        aov_weight *= saturate(bs.weight * bs.eta * bs.eta);
        paths[field(F_AOV_WEIGHT, slot)] = vec4f(aov_weight, 0.0);
    }
    var extend = false;
    var next = ray;
    var pdf = prev_pdf;
    if bs.valid {
        throughput *= bs.weight;
        pdf = bs.pdf;
        flags = select(flags & ~PATH_PREV_DELTA, flags | PATH_PREV_DELTA, bs.delta);
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
        next = Ray(offset_origin(s.position, s.ng, bs.wi), bs.wi);
        flags += 1u;
        paths[field(F_PREV_POSITION, slot)] = vec4f(s.position, bitcast<f32>(sampler.rng_state));
        paths[field(F_PREV_NORMAL, slot)] = vec4f(n_side, prev_n.w);
    } else {
        paths[field(F_PREV_POSITION, slot)] = vec4f(prev_position, bitcast<f32>(sampler.rng_state));
    }
    paths[field(F_ORIGIN, slot)] = vec4f(next.origin, pdf);
    paths[field(F_DIR, slot)] = vec4f(next.dir, eta_scale);
    paths[field(F_THROUGHPUT, slot)] = vec4f(throughput, bitcast<f32>(flags));
    paths[field(F_RADIANCE, slot)] = vec4f(radiance, bitcast<f32>(sampler.dimension));
    if extend {
        enqueue(1u - into, slot);
    }
}

// Adds every path of the wave to the film (and its auxiliary images), a pixel's samples in
// one invocation.
@compute @workgroup_size(8, 8)
fn wf_finish(@builtin(global_invocation_id) gid: vec3u) {
    let x = gid.x;
    let y = gid.y + params.row_offset;
    if x < params.width && y < params.row_end {
        let samples = queue_lengths[COUNT_WAVE_SAMPLES];
        let first = (y - params.row_offset) * params.width + x;
        if first == 0u {
            // The next `wf_start` takes the batch's next samples.
            atomicAdd(&queue_counts[COUNT_SAMPLE], samples);
        }
        let pixel = y * params.width + x;
        var total = accum[pixel];
        var zero = AccumPixel(vec4u(0u), vec4u(0u));
        var aovs = AovPixel(zero, zero);
        for (var s = 0u; s < samples; s++) {
            let slot = (wave_layer.x + s) * band_pixels() + first;
            let radiance = paths[field(F_RADIANCE, slot)].xyz;
            if is_finite3(radiance) {
                add_sample(&total, radiance);
            } else {
                atomicAdd(&counters[2], 1u);
            }
            if AOVS && params.aovs != 0u {
                var albedo = paths[field(F_ALBEDO, slot)].xyz;
                if (bitcast<u32>(paths[field(F_THROUGHPUT, slot)].w) & PATH_AOV_PENDING) != 0u {
                    albedo = paths[field(F_AOV_WEIGHT, slot)].xyz;
                }
                add_aov_sample(&aovs, PathResult(radiance, albedo, paths[field(F_NORMAL, slot)].xyz));
            }
        }
        accum[pixel] = total;
        if AOVS && params.aovs != 0u {
            var albedo = aov[pixel].albedo;
            add_fixed(&albedo, aovs.albedo);
            var normal = aov[pixel].normal;
            add_fixed(&normal, aovs.normal);
            aov[pixel] = AovPixel(albedo, normal);
        }
    }
}
