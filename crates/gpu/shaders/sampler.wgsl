// Sample values for every dimension of a path. CPU twin: `crates/cpu/src/sampler.rs`.
//
// Padded Owen-scrambled Sobol (Burley, "Practical Hash-based Owen Scrambling", JCGT 2020):
// every 1D or 2D request of a path gets its own dimension number; its values are the first
// two Sobol dimensions (a (0,2)-sequence) at a per-(pixel, dimension) shuffled index, each
// Owen-scrambled with its own seed. The independent alternative is a PCG stream seeded by
// (pixel, sample, seed).

const SAMPLER_SOBOL: u32 = 0u;
const SAMPLER_INDEPENDENT: u32 = 1u;

// PCG hash: Jarzynski and Olano, "Hash Functions for GPU Rendering", JCGT 2020.
// CPU twin: `pcg_hash`.
fn pcg_hash(v: u32) -> u32 {
    let state = v * 747796405u + 2891336453u;
    let word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

// CPU twin: `rng_init`.
fn rng_init(pixel: u32, sample_index: u32, seed: u32) -> u32 {
    return pcg_hash(pixel ^ pcg_hash(sample_index ^ pcg_hash(seed)));
}

// Owen scrambling of bits from low to high (Laine and Karras 2011, Burley's constants).
// CPU twin: `laine_karras`.
fn laine_karras(v: u32, seed: u32) -> u32 {
    var x = v + seed;
    x ^= x * 0x6c50b47cu;
    x ^= x * 0xb82f1e52u;
    x ^= x * 0xc7afe638u;
    x ^= x * 0x8d22f6e6u;
    return x;
}

// Sobol dimension 1 (primitive polynomial x + 1) before its final bit reversal: its
// generator matrix is the binary Pascal matrix, so by Lucas' theorem bit p of the value
// (counted from the top) is the XOR of the index bits k that are supersets of p: a
// superset-XOR transform in five bit-parallel steps. (Dimension 0, van der Corput, is the
// index reversed.)
// CPU twin: `sobol_1_reversed`.
fn sobol_1_reversed(index: u32) -> u32 {
    var y = index;
    y ^= (y >> 1u) & 0x55555555u;
    y ^= (y >> 2u) & 0x33333333u;
    y ^= (y >> 4u) & 0x0f0f0f0fu;
    y ^= (y >> 8u) & 0x00ff00ffu;
    y ^= (y >> 16u) & 0x0000ffffu;
    return y;
}

// Owen scrambling (high bits to low) of a Sobol value given bit-reversed:
// reverseBits(laine_karras(reverseBits(v))) without reversing v twice.
// CPU twin: `owen_scramble_reversed`.
fn owen_scramble_reversed(reversed: u32, seed: u32) -> u32 {
    return reverseBits(laine_karras(reversed, seed));
}

// CPU twin: `to_unit_float`.
fn to_unit_float(x: u32) -> f32 {
    return f32(x >> 8u) * (1.0 / 16777216.0);
}

// CPU twin: `Sampler`.
struct Sampler {
    kind: u32,
    pixel_seed: u32,
    index_reversed: u32,
    dimension: u32,
    rng_state: u32,
}

// CPU twin: `Sampler::new`.
fn sampler_init(kind: u32, pixel: u32, index: u32, seed: u32) -> Sampler {
    return Sampler(kind, pcg_hash(pixel ^ pcg_hash(seed)), reverseBits(index), 0u, rng_init(pixel, index, seed));
}

fn next_random(s: ptr<function, Sampler>) -> f32 {
    (*s).rng_state = (*s).rng_state * 747796405u + 2891336453u;
    let st = (*s).rng_state;
    let word = ((st >> ((st >> 28u) + 4u)) ^ st) * 277803737u;
    return to_unit_float((word >> 22u) ^ word);
}

fn dimension_seed(s: ptr<function, Sampler>) -> u32 {
    let seed = pcg_hash((*s).pixel_seed ^ pcg_hash((*s).dimension));
    (*s).dimension += 1u;
    return seed;
}

// The dimension's shuffled Sobol index: the sample index Owen-scrambled.
fn shuffled_index(s: ptr<function, Sampler>, seed: u32) -> u32 {
    return owen_scramble_reversed((*s).index_reversed, seed);
}

// CPU twin: `Sampler::next_1d`.
fn next_1d(s: ptr<function, Sampler>) -> f32 {
    if (*s).kind != SAMPLER_SOBOL {
        return next_random(s);
    }
    let seed = dimension_seed(s);
    let index = shuffled_index(s, seed);
    return to_unit_float(owen_scramble_reversed(index, pcg_hash(seed ^ 1u)));
}

// CPU twin: `Sampler::next_2d`.
fn next_2d(s: ptr<function, Sampler>) -> vec2f {
    if (*s).kind != SAMPLER_SOBOL {
        let x = next_random(s);
        return vec2f(x, next_random(s));
    }
    let seed = dimension_seed(s);
    let index = shuffled_index(s, seed);
    return vec2f(
        to_unit_float(owen_scramble_reversed(index, pcg_hash(seed ^ 1u))),
        to_unit_float(owen_scramble_reversed(sobol_1_reversed(index), pcg_hash(seed ^ 2u))),
    );
}
