// The per-render constants every pass of the integrator reads (bind group 1, binding 0): the
// camera, the image and the band of rows a dispatch covers, the settings, and the split
// between the environment and the shape lights. Host: `crates/core/src/params.rs` fills
// them; their layout is `GpuCamera` and `GpuRenderParams` in `crates/core/src/gpu_types.rs`.
// No CPU twin: declarations only (the CPU backend reads the host structs).

// The eye and the image plane at unit distance: a point at normalised device coordinates
// (x, y) in [-1, 1] lies along forward + x right + y up. Host: `GpuCamera`.
struct CameraParams {
    // The lens centre; the lens radius (0: a pinhole).
    position: vec3f,
    lens_radius: f32,
    // The plane in focus lies at `focus_distance` along `forward`.
    forward: vec3f,
    focus_distance: f32,
    // Scaled to half the image width at unit distance.
    right: vec3f,
    pad2: u32,
    // Scaled to half the image height at unit distance.
    up: vec3f,
    pad3: u32,
}

// Host: `GpuRenderParams`.
struct RenderParams {
    camera: CameraParams,
    environment: vec3f,
    // Probability of sampling the environment rather than a shape light.
    env_pmf: f32,
    width: u32,
    height: u32,
    // Samples per pixel accumulated before this dispatch, and how many it adds.
    sample_offset: u32,
    batch_samples: u32,
    // The band of rows this dispatch covers: row_offset .. row_end.
    row_offset: u32,
    row_end: u32,
    max_depth: u32,
    rr_depth: u32,
    seed: u32,
    // SAMPLER_* (sampler.wgsl).
    sampler: u32,
    object_count: u32,
    light_count: u32,
    // Environment map size (width 0: none), the factor from decoded texels to radiance, and
    // the cosine and sine of its turn about +y.
    env_width: u32,
    env_height: u32,
    env_scale: f32,
    // 1: also accumulate the auxiliary images (`aov` in integrator.wgsl).
    aovs: u32,
    env_rotation: vec2f,
    pad1: vec2u,
}

// A read-only storage buffer, not a uniform: on lavapipe (Mesa 22.3, measured) every
// submission grew the process by 2.6 MB and paid a shader compile while `sample_offset`
// changed in a uniform buffer (lavapipe inlines uniform values into shader variants, which it
// keeps); as storage it stays flat (crates/gpu/tests/memory.rs).
@group(1) @binding(0) var<storage, read> params: RenderParams;
