// Hash-based random numbers: a PCG stream seeded per (pixel, sample index, seed), so each
// sample is reproducible on its own and batches can be split any way.
// PCG hash: Jarzynski & Olano, "Hash Functions for GPU Rendering", JCGT 2020.

fn pcg_hash(v: u32) -> u32 {
    let state = v * 747796405u + 2891336453u;
    let word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

fn rng_init(pixel: u32, sample_index: u32, seed: u32) -> u32 {
    return pcg_hash(pixel ^ pcg_hash(sample_index ^ pcg_hash(seed)));
}

// Next uniform float in [0, 1) from `state`, 24 bits of precision.
fn rng_next(state: ptr<function, u32>) -> f32 {
    *state = *state * 747796405u + 2891336453u;
    let word = ((*state >> ((*state >> 28u) + 4u)) ^ *state) * 277803737u;
    return f32(((word >> 22u) ^ word) >> 8u) * (1.0 / 16777216.0);
}
