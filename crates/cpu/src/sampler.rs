//! Sample values for every dimension of a path. Twin of `sampler.wgsl`.
//!
//! Padded Owen-scrambled Sobol (Burley, "Practical Hash-based Owen Scrambling", JCGT 2020):
//! every 1D or 2D request of a path gets its own dimension number; its values are the first
//! two Sobol dimensions (a (0,2)-sequence) at a per-(pixel, dimension) shuffled index, each
//! Owen-scrambled with its own seed (pbrt-v4's `PaddedSobolSampler` scheme). Each sample uses a fixed number of dimensions per bounce, so a dimension
//! always serves the same purpose. The independent alternative is a PCG stream seeded by
//! (pixel, sample, seed).

use glam::Vec2;
use pathlight_core::gpu_types::SAMPLER_SOBOL;

use crate::packet::PACKET;

/// PCG hash (Jarzynski and Olano, JCGT 2020). Twin of WGSL `pcg_hash`.
pub const fn pcg_hash(v: u32) -> u32 {
    let state = v.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
    let word = ((state >> ((state >> 28) + 4)) ^ state).wrapping_mul(277_803_737);
    (word >> 22) ^ word
}

/// `pcg_hash` of the first dimension numbers (a path of depth 8 uses 2 + 7 * 6 = 44).
const DIMENSION_HASHES: [u32; 64] = {
    let mut table = [0; 64];
    let mut i = 0;
    while i < 64 {
        table[i] = pcg_hash(i as u32);
        i += 1;
    }
    table
};

/// Seed of `pixel` for `sample_index` under `seed`. Twin of WGSL `rng_init`.
pub fn rng_init(pixel: u32, sample_index: u32, seed: u32) -> u32 {
    pcg_hash(pixel ^ pcg_hash(sample_index ^ pcg_hash(seed)))
}

/// Owen scrambling of the bits of `x` from low to high (Laine and Karras 2011, Burley's
/// constants). Twin of WGSL `laine_karras`.
fn laine_karras(mut x: u32, seed: u32) -> u32 {
    x = x.wrapping_add(seed);
    x ^= x.wrapping_mul(0x6c50_b47c);
    x ^= x.wrapping_mul(0xb82f_1e52);
    x ^= x.wrapping_mul(0xc7af_e638);
    x ^= x.wrapping_mul(0x8d22_f6e6);
    x
}

/// Sobol dimension 1 (primitive polynomial x + 1) before its final bit reversal: the
/// generator matrix is the binary Pascal matrix, so by Lucas' theorem bit p of the value
/// (from the top) is the XOR of the index bits k that are supersets of p, a superset-XOR
/// transform. Twin of WGSL `sobol_1_reversed`.
fn sobol_1_reversed(index: u32) -> u32 {
    let mut y = index;
    y ^= (y >> 1) & 0x5555_5555;
    y ^= (y >> 2) & 0x3333_3333;
    y ^= (y >> 4) & 0x0f0f_0f0f;
    y ^= (y >> 8) & 0x00ff_00ff;
    y ^= (y >> 16) & 0x0000_ffff;
    y
}

/// Owen scrambling (from high bits to low) of a Sobol value given bit-reversed, as
/// `laine_karras` scrambles from low to high: `reverse(laine_karras(reverse(v)))` where
/// `v` is the value, without reversing it twice. Twin of WGSL `owen_scramble_reversed`.
fn owen_scramble_reversed(reversed: u32, seed: u32) -> u32 {
    laine_karras(reversed, seed).reverse_bits()
}

/// The top 24 bits of `x` as a float in [0, 1). Twin of WGSL `to_unit_float`.
fn to_unit_float(x: u32) -> f32 {
    (x >> 8) as f32 * (1.0 / 16_777_216.0)
}

/// A sample's index and its bits reversed (which the Sobol scrambles read), stepped to the
/// next index together: the increment's carry (the index's trailing ones and the zero above
/// them) is the reversal's leading ones and the zero below them, a few instructions where a
/// reversal is a dozen without a bit-reversal instruction (AVX2 has none).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SampleIndex {
    value: u32,
    reversed: u32,
}

impl SampleIndex {
    /// Index `value`.
    #[inline(always)]
    pub fn new(value: u32) -> Self {
        Self {
            value,
            reversed: value.reverse_bits(),
        }
    }

    /// The index.
    #[inline(always)]
    pub fn value(self) -> u32 {
        self.value
    }

    /// The next index (after `u32::MAX`, 0).
    #[inline(always)]
    pub fn next(self) -> Self {
        let carry = self.reversed.leading_ones() + 1;
        Self {
            value: self.value.wrapping_add(1),
            reversed: self.reversed ^ !u32::MAX.checked_shr(carry).unwrap_or(0),
        }
    }
}

/// How [`Sampler::next_batch`] draws one of its dimensions.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Draw {
    /// A value, as [`Sampler::next_1d`].
    One,
    /// A point, as [`Sampler::next_2d`].
    Two,
}

/// Most dimensions [`Sampler::next_batch`] draws at once: the lanes it computes.
const LANES: usize = 8;
/// Dimensions a bounce of the integrator draws in one batch (`Path::step`): a window of
/// [`LANES`] values is computed anew when what is left of it cannot serve that many.
const BOUNCE_DIMENSIONS: usize = 6;
/// What a bounce of the integrator draws, in order (`Path::step`): the light's choice, the
/// point on it, the lobe's choice, the Fresnel choice, the BSDF's direction, Russian roulette.
pub const BOUNCE_DRAWS: [Draw; BOUNCE_DIMENSIONS] = [
    Draw::One,
    Draw::Two,
    Draw::One,
    Draw::One,
    Draw::Two,
    Draw::One,
];

/// The sample values of one path. Twin of WGSL `Sampler`.
#[derive(Debug, Clone)]
pub struct Sampler {
    kind: u32,
    pixel_seed: u32,
    /// The sample index, bit-reversed (the shuffle scrambles it from the top).
    index_reversed: u32,
    dimension: u32,
    rng_state: u32,
    /// Sobol: the values of the [`LANES`] dimensions from `ahead_from`, per coordinate,
    /// the window [`Sampler::next_batch`] serves from, computed ahead of their use
    /// ([`Sampler::prepare`], or with a row's [`SeedCache`], [`Sampler::prepare_cached`], or
    /// two samplers' at once, [`Sampler::prepare_pair`]) so that their hash chains' latency
    /// overlaps the shading that comes between.
    ahead: Window<LANES>,
    /// The first dimension in `ahead`.
    ahead_from: u32,
    /// The window from `ahead_from` is due: not computed yet ([`Sampler::prepare`] or the
    /// next request computes it).
    due: bool,
    /// Sobol: its pixel's slot in a row's [`SeedCache`].
    seed_slot: u8,
}

/// What the samplers of one pixel share, hashed once for all its samples (the row renderer
/// starts a pixel's samples one after another).
#[derive(Debug, Clone, Copy)]
pub struct PixelSamplers {
    kind: u32,
    pixel: u32,
    seed: u32,
    /// Sobol: the hash of the pixel under the seed, which seeds every dimension's scramble.
    pixel_seed: u32,
    /// Sobol: the scrambles' seeds of the first window's dimensions (0 to [`LANES`] - 1),
    /// which depend on the pixel alone.
    first_seeds: ScrambleSeeds<LANES>,
    /// Sobol: its slot in a row's [`SeedCache`] ([`SeedCache::begin`]).
    seed_slot: u8,
}

/// The seeds of the three Owen scrambles of `N` Sobol dimensions' values, per lane: of the
/// shuffled index, of its x and of its y coordinate.
#[derive(Debug, Clone, Copy)]
struct ScrambleSeeds<const N: usize> {
    index: [u32; N],
    x: [u32; N],
    y: [u32; N],
}

impl<const N: usize> ScrambleSeeds<N> {
    /// All zero.
    const ZERO: Self = Self {
        index: [0; N],
        x: [0; N],
        y: [0; N],
    };

    /// Copies `other`'s seeds into lanes `at..at + M`.
    #[inline(always)]
    fn put<const M: usize>(&mut self, at: usize, other: &ScrambleSeeds<M>) {
        self.index[at..at + M].copy_from_slice(&other.index);
        self.x[at..at + M].copy_from_slice(&other.x);
        self.y[at..at + M].copy_from_slice(&other.y);
    }

    /// Lane `i`'s seeds for the dimension whose hash is `dimension_hash[i]` in the pixel
    /// whose seed is `pixel_seed[i]`.
    #[inline(always)]
    fn new(pixel_seed: &[u32; N], dimension_hash: &[u32; N]) -> Self {
        let mut seeds = Self {
            index: [0; N],
            x: [0; N],
            y: [0; N],
        };
        for i in 0..N {
            let seed = pcg_hash(pixel_seed[i] ^ dimension_hash[i]);
            seeds.index[i] = seed;
            seeds.x[i] = pcg_hash(seed ^ 1);
            seeds.y[i] = pcg_hash(seed ^ 2);
        }
        seeds
    }
}

impl PixelSamplers {
    /// The samplers of `pixel` under `seed`, of kind `SAMPLER_*`.
    #[inline(always)]
    pub fn new(kind: u32, pixel: u32, seed: u32) -> Self {
        let pixel_seed = Sampler::pixel_seed(kind, pixel, seed);
        let mut hashes = [0; LANES];
        dimension_hashes(0, &mut hashes);
        Self {
            kind,
            pixel,
            seed,
            pixel_seed,
            first_seeds: ScrambleSeeds::new(&[pixel_seed; LANES], &hashes),
            seed_slot: 0,
        }
    }

    /// The sampler of sample `index` of this pixel: [`Sampler::new`]'s.
    #[inline(always)]
    pub fn sampler(&self, index: u32) -> Sampler {
        let mut sampler = Sampler {
            kind: self.kind,
            pixel_seed: 0,
            index_reversed: 0,
            dimension: 0,
            rng_state: 0,
            ahead: Window {
                x: [0.0; LANES],
                y: [0.0; LANES],
            },
            ahead_from: 0,
            due: false,
            seed_slot: 0,
        };
        sampler.restart(self, SampleIndex::new(index));
        sampler
    }
}

impl Sampler {
    /// Sample `index` of `pixel` under `seed`, of kind `SAMPLER_*`. Twin of WGSL `sampler_init`.
    #[inline(always)]
    pub fn new(kind: u32, pixel: u32, index: u32, seed: u32) -> Self {
        PixelSamplers::new(kind, pixel, seed).sampler(index)
    }

    /// Makes this sampler [`PixelSamplers::sampler`]'s of `pixel` for sample `index`, its
    /// window left as it is (due: no draw reads it before it is computed anew).
    #[inline(always)]
    pub fn restart(&mut self, pixel: &PixelSamplers, index: SampleIndex) {
        let sobol = pixel.kind == SAMPLER_SOBOL;
        self.kind = pixel.kind;
        self.pixel_seed = pixel.pixel_seed;
        self.index_reversed = index.reversed;
        self.dimension = 0;
        self.rng_state = if sobol {
            0
        } else {
            rng_init(pixel.pixel, index.value, pixel.seed)
        };
        self.seed_slot = pixel.seed_slot;
        // The camera's dimensions and the first bounce's come from the window at 0.
        self.ahead_from = 0;
        self.due = sobol;
    }

    /// Sobol: the seed of `pixel` under `seed` (each kind hashes only the state it reads;
    /// WGSL hashes both).
    #[inline(always)]
    fn pixel_seed(kind: u32, pixel: u32, seed: u32) -> u32 {
        if kind == SAMPLER_SOBOL {
            pcg_hash(pixel ^ pcg_hash(seed))
        } else {
            0
        }
    }

    /// Computes the window the next bounce will draw from, if due: called where the path
    /// is known to go on (a hit), ahead of the draw, so that the window's hash chains overlap
    /// the shading before it, and no window is computed for a path that ends.
    #[inline(always)]
    pub fn prepare(&mut self) {
        if self.due {
            self.ahead = self.sobol_lanes(self.ahead_from);
            self.due = false;
        }
    }

    /// Takes the window of `a` (`self`) from the first half of `values`, `b`'s from the
    /// second.
    #[inline(always)]
    fn take_pair_half(&mut self, b: &mut Self, values: &Window<{ 2 * LANES }>) {
        self.ahead.x.copy_from_slice(&values.x[..LANES]);
        self.ahead.y.copy_from_slice(&values.y[..LANES]);
        b.ahead.x.copy_from_slice(&values.x[LANES..]);
        b.ahead.y.copy_from_slice(&values.y[LANES..]);
        self.due = false;
        b.due = false;
    }

    /// Whether the window the next request draws from is due ([`Sampler::prepare`] would
    /// compute it).
    #[inline(always)]
    pub fn window_due(&self) -> bool {
        self.due
    }

    /// [`Sampler::prepare`], the scrambles' seeds taken from `cache` where it holds them.
    #[inline(always)]
    pub fn prepare_cached(&mut self, cache: &mut SeedCache) {
        if self.due {
            let mut seeds = ScrambleSeeds::<LANES>::ZERO;
            self.window_seeds(cache, &mut seeds, 0);
            self.ahead = scrambled_sobol(&[self.index_reversed; LANES], &seeds);
            self.due = false;
        }
    }

    /// Puts the scrambles' seeds of the window due into lanes `at..at + LANES` of `seeds`:
    /// from `cache` where it holds them, else computed.
    #[inline(always)]
    fn window_seeds<const N: usize>(
        &self,
        cache: &mut SeedCache,
        seeds: &mut ScrambleSeeds<N>,
        at: usize,
    ) {
        if !cache.window(self.seed_slot, self.pixel_seed, self.ahead_from, seeds, at) {
            let mut hashes = [0u32; LANES];
            dimension_hashes(self.ahead_from, &mut hashes);
            seeds.put(at, &ScrambleSeeds::new(&[self.pixel_seed; LANES], &hashes));
        }
    }

    /// [`Sampler::prepare_cached`] of `a` and `b`, their windows computed side by side when
    /// both are due: sixteen lanes, one AVX-512 register an operation, so that a window costs
    /// half the instructions where the registers are that wide (with AVX2's, the CPU backend
    /// does not pair them: twice the registers live, spilled).
    #[inline(always)]
    pub fn prepare_pair(a: &mut Self, b: &mut Self, cache: &mut SeedCache) {
        if !(a.due && b.due) {
            a.prepare_cached(cache);
            b.prepare_cached(cache);
            return;
        }
        let mut index_reversed = [a.index_reversed; 2 * LANES];
        index_reversed[LANES..].fill(b.index_reversed);
        let mut seeds = ScrambleSeeds::<{ 2 * LANES }>::ZERO;
        a.window_seeds(cache, &mut seeds, 0);
        b.window_seeds(cache, &mut seeds, LANES);
        a.take_pair_half(b, &scrambled_sobol(&index_reversed, &seeds));
    }

    fn next_random(&mut self) -> f32 {
        self.rng_state = self
            .rng_state
            .wrapping_mul(747_796_405)
            .wrapping_add(2_891_336_453);
        let s = self.rng_state;
        let word = ((s >> ((s >> 28) + 4)) ^ s).wrapping_mul(277_803_737);
        to_unit_float((word >> 22) ^ word)
    }

    /// The next value in [0, 1). Twin of WGSL `next_1d`.
    #[inline(always)]
    pub fn next_1d(&mut self) -> f32 {
        self.next_batch([Draw::One])[0].x
    }

    /// The next point in [0, 1)^2, stratified with the other samples of the pixel. Twin of
    /// WGSL `next_2d`.
    #[inline(always)]
    pub fn next_2d(&mut self) -> Vec2 {
        self.next_batch([Draw::Two])[0]
    }

    /// The next `N` (at most 8) dimensions at once: the values that `next_1d` (a value in `x`) and
    /// `next_2d` would give in turn, as `draws` says. A Sobol dimension's value is its
    /// Owen-scrambled shuffled index (dimension 0, the van der Corput sequence, is the index
    /// reversed; dimension 1 is `sobol_1_reversed` of it), each scramble seeded by hashing
    /// the pixel and dimension. The dimensions' hash chains are independent, so they run
    /// `LANES` (eight) at a time side by side in SIMD lanes, into a window of values that serves
    /// the requests in turn: the camera's one or two dimensions and the first bounce's six
    /// come from one window. When what is left of the window cannot serve a bounce, the next
    /// window is due (as is a new sampler's first, at dimension 0): [`Sampler::prepare`] or
    /// [`Sampler::prepare_pair`] computes it ahead of its use once the path is known to go
    /// on (else this does when asked), so that its latency overlaps the shading in between
    /// and a path that ends computes none. The WGSL draws them one by one.
    #[inline(always)]
    pub fn next_batch<const N: usize>(&mut self, draws: [Draw; N]) -> [Vec2; N] {
        const { assert!(N <= LANES) };
        // Plain loops rather than `array::map` and `from_fn`, whose closures the compiler
        // may leave out of line (and then compiled for the baseline instruction set).
        let mut out = [Vec2::ZERO; N];
        if self.kind != SAMPLER_SOBOL {
            for (value, draw) in out.iter_mut().zip(draws) {
                value.x = self.next_random();
                if draw == Draw::Two {
                    value.y = self.next_random();
                }
            }
            return out;
        }
        self.prepare();
        let mut offset = self.dimension.wrapping_sub(self.ahead_from) as usize;
        if offset + N > LANES {
            // Not in the window (a larger batch than a bounce's).
            self.ahead = self.sobol_lanes(self.dimension);
            self.ahead_from = self.dimension;
            offset = 0;
        }
        for i in 0..N {
            out[i].x = self.ahead.x[offset + i];
            if draws[i] == Draw::Two {
                out[i].y = self.ahead.y[offset + i];
            }
        }
        self.dimension += N as u32;
        if offset + N + BOUNCE_DIMENSIONS > LANES {
            self.ahead_from = self.dimension;
            self.due = true;
        }
        out
    }

    /// Both coordinates of the [`LANES`] Sobol dimensions from `first`.
    #[inline(always)]
    fn sobol_lanes(&self, first: u32) -> Window<LANES> {
        // Always eight lanes (one AVX2 register; the unused ones are wasted): measured 2%
        // faster on a bounce's six than six lanes.
        let mut hashes = [0u32; LANES];
        dimension_hashes(first, &mut hashes);
        let seeds = ScrambleSeeds::new(&[self.pixel_seed; LANES], &hashes);
        scrambled_sobol(&[self.index_reversed; LANES], &seeds)
    }
}

/// Pixels whose seeds a [`SeedCache`] holds at once.
const CACHED_PIXELS: usize = 8;
/// Dimensions whose seeds a [`SeedCache`] holds per pixel: a path of ten bounces.
const CACHED_DIMENSIONS: usize = 64;

/// The scrambles' seeds of the Sobol dimensions of the last eight pixels a row started (three
/// `pcg_hash`es a dimension), computed once per pixel as its first sample to reach a window
/// needs them, not once per sample. A sampler finds its pixel's by the slot its pixel took
/// ([`SeedCache::begin`]); where that slot went to a newer pixel since (over eight pixels
/// started while its path went on: a few samples a pixel), or past the 64th dimension, the
/// seeds are computed as before. They depend on the pixel's seed and the dimension alone:
/// the values drawn are the same bit for bit.
#[derive(Debug, Clone)]
pub struct SeedCache {
    pixels: [CachedSeeds; CACHED_PIXELS],
    /// The slot the next pixel takes.
    next: usize,
}

/// A pixel's seeds in a [`SeedCache`].
#[derive(Debug, Clone)]
struct CachedSeeds {
    /// The pixel's seed (which seeds every scramble).
    pixel_seed: u32,
    /// The dimensions below hold their seeds (a multiple of [`LANES`]).
    filled: usize,
    seeds: ScrambleSeeds<CACHED_DIMENSIONS>,
}

impl Default for SeedCache {
    #[inline(always)]
    fn default() -> Self {
        Self {
            pixels: [const {
                CachedSeeds {
                    pixel_seed: 0,
                    filled: 0,
                    seeds: ScrambleSeeds::ZERO,
                }
            }; CACHED_PIXELS],
            next: 0,
        }
    }
}

impl SeedCache {
    /// Gives `pixel`, whose samples start now, the next slot (the oldest pixel's), with its
    /// first window's seeds.
    #[inline(always)]
    pub fn begin(&mut self, pixel: &mut PixelSamplers) {
        let slot = self.next;
        self.next = (slot + 1) % CACHED_PIXELS;
        let cached = &mut self.pixels[slot];
        cached.pixel_seed = pixel.pixel_seed;
        cached.seeds.put(0, &pixel.first_seeds);
        cached.filled = LANES;
        pixel.seed_slot = slot as u8;
    }

    /// Puts the seeds of the [`LANES`] dimensions from `first` of the pixel of seed
    /// `pixel_seed` into lanes `at..at + LANES` of `seeds`, if slot `slot` still holds that
    /// pixel (computing those not held yet); returns whether it did.
    #[inline(always)]
    fn window<const N: usize>(
        &mut self,
        slot: u8,
        pixel_seed: u32,
        first: u32,
        seeds: &mut ScrambleSeeds<N>,
        at: usize,
    ) -> bool {
        let cached = &mut self.pixels[usize::from(slot) % CACHED_PIXELS];
        let (first, end) = (first as usize, first as usize + LANES);
        if cached.pixel_seed != pixel_seed || end > CACHED_DIMENSIONS {
            return false;
        }
        while cached.filled < end {
            let mut hashes = [0u32; LANES];
            dimension_hashes(cached.filled as u32, &mut hashes);
            let group = ScrambleSeeds::new(&[pixel_seed; LANES], &hashes);
            cached.seeds.put(cached.filled, &group);
            cached.filled += LANES;
        }
        seeds.index[at..at + LANES].copy_from_slice(&cached.seeds.index[first..end]);
        seeds.x[at..at + LANES].copy_from_slice(&cached.seeds.x[first..end]);
        seeds.y[at..at + LANES].copy_from_slice(&cached.seeds.y[first..end]);
        true
    }
}

/// `pcg_hash` of the dimensions from `first`, one per element of `hashes`.
#[inline(always)]
fn dimension_hashes(first: u32, hashes: &mut [u32]) {
    match DIMENSION_HASHES.get(first as usize..first as usize + hashes.len()) {
        Some(table) => hashes.copy_from_slice(table),
        None => {
            for (i, hash) in hashes.iter_mut().enumerate() {
                *hash = pcg_hash(first + i as u32);
            }
        }
    }
}

/// Both coordinates of `N` Sobol values side by side, lane `i` of the sample whose reversed
/// index is `index_reversed[i]`, in the dimension (of its pixel) whose scrambles' seeds are
/// lane `i` of `seeds`.
#[inline(always)]
fn scrambled_sobol<const N: usize>(
    index_reversed: &[u32; N],
    seeds: &ScrambleSeeds<N>,
) -> Window<N> {
    let mut values = Window {
        x: [0.0; N],
        y: [0.0; N],
    };
    for (i, &reversed) in index_reversed.iter().enumerate() {
        let index = owen_scramble_reversed(reversed, seeds.index[i]);
        values.x[i] = to_unit_float(owen_scramble_reversed(index, seeds.x[i]));
        let y = owen_scramble_reversed(sobol_1_reversed(index), seeds.y[i]);
        values.y[i] = to_unit_float(y);
    }
    values
}

/// `N` points side by side, per coordinate: a sampler's window (`N` Sobol dimensions' values
/// of its sample), or values of several samples ([`CameraPoints`]).
#[derive(Debug, Clone)]
struct Window<const N: usize> {
    x: [f32; N],
    y: [f32; N],
}

/// Groups of [`LANES`] values in [`CameraPoints`], enough for two dimensions of every lane of
/// a packet.
const CAMERA_GROUPS: usize = 2 * PACKET / LANES;

/// The camera's sample values (the film's point, then the lens's if there is one) of a
/// packet's new samplers, gathered as they start ([`CameraPoints::start`]) and then drawn all
/// at once ([`CameraPoints::draw`]): Sobol's eight side by side, packed together, so that
/// a packet's few new paths cost a few lanes' work, not a packet's, and no path waits on its
/// own hash chain. Each sampler goes on past them, its first window (from dimension 0, the
/// dimensions drawn here in it unused) still due, for [`Sampler::prepare_cached`] once the
/// path is known to go on: a camera ray that meets nothing computes no window.
pub struct CameraPoints {
    /// The camera's dimensions: 1 or 2.
    dimensions: usize,
    /// Values gathered.
    count: usize,
    /// Sobol: value `k` (sampler by sampler, each one's dimensions in turn) is element
    /// `k % LANES` of group `k / LANES`: its sample's reversed index, its dimension's seeds.
    index_reversed: [[u32; LANES]; CAMERA_GROUPS],
    seeds: [ScrambleSeeds<LANES>; CAMERA_GROUPS],
    /// The values, once drawn (the independent kind's as each sampler starts).
    values: [Window<LANES>; CAMERA_GROUPS],
}

impl CameraPoints {
    /// None gathered yet, of a camera drawing `dimensions` (1 or 2) points.
    #[inline(always)]
    pub fn new(dimensions: usize) -> Self {
        debug_assert!((1..=2).contains(&dimensions));
        Self {
            dimensions,
            count: 0,
            index_reversed: [[0; LANES]; CAMERA_GROUPS],
            seeds: [const {
                ScrambleSeeds {
                    index: [0; LANES],
                    x: [0; LANES],
                    y: [0; LANES],
                }
            }; CAMERA_GROUPS],
            values: [const {
                Window {
                    x: [0.0; LANES],
                    y: [0.0; LANES],
                }
            }; CAMERA_GROUPS],
        }
    }

    /// Starts `sampler` as sample `index` of `pixel` ([`Sampler::restart`]) and gathers its
    /// camera's points, the next ones [`CameraPoints::point`] gives. At most [`PACKET`]
    /// samplers between two [`CameraPoints::clear`]s.
    #[inline(always)]
    pub fn start(&mut self, sampler: &mut Sampler, pixel: &PixelSamplers, index: SampleIndex) {
        sampler.restart(pixel, index);
        for d in 0..self.dimensions {
            let (group, i) = (self.count / LANES, self.count % LANES);
            if pixel.kind == SAMPLER_SOBOL {
                self.index_reversed[group][i] = sampler.index_reversed;
                self.seeds[group].index[i] = pixel.first_seeds.index[d];
                self.seeds[group].x[i] = pixel.first_seeds.x[d];
                self.seeds[group].y[i] = pixel.first_seeds.y[d];
            } else {
                let value = sampler.next_2d();
                (self.values[group].x[i], self.values[group].y[i]) = (value.x, value.y);
            }
            self.count += 1;
        }
        if pixel.kind == SAMPLER_SOBOL {
            sampler.dimension = self.dimensions as u32;
        }
    }

    /// Draws the Sobol values gathered (of the samplers of `kind`, `SAMPLER_*`).
    #[inline(always)]
    pub fn draw(&mut self, kind: u32) {
        if kind == SAMPLER_SOBOL {
            for group in 0..self.count.div_ceil(LANES) {
                self.values[group] =
                    scrambled_sobol(&self.index_reversed[group], &self.seeds[group]);
            }
        }
    }

    /// Dimension `d` of the camera's points of the `n`th sampler started since the last
    /// [`CameraPoints::clear`], once drawn.
    #[inline(always)]
    pub fn point(&self, n: usize, d: usize) -> Vec2 {
        let k = n * self.dimensions + d;
        let (group, i) = (k / LANES, k % LANES);
        Vec2::new(self.values[group].x[i], self.values[group].y[i])
    }

    /// Forgets the samplers started (their points read).
    #[inline(always)]
    pub fn clear(&mut self) {
        self.count = 0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use pathlight_core::gpu_types::SAMPLER_INDEPENDENT;

    /// Sobol dimension 0 (van der Corput).
    fn sobol_0(index: u32) -> u32 {
        index.reverse_bits()
    }

    /// Sobol dimension 1.
    fn sobol_1(index: u32) -> u32 {
        sobol_1_reversed(index).reverse_bits()
    }

    /// Owen scrambling from high bits to low, as written in Burley's paper.
    fn nested_uniform_scramble(x: u32, seed: u32) -> u32 {
        laine_karras(x.reverse_bits(), seed).reverse_bits()
    }

    /// Stepping an index reverses its bits as `reverse_bits` does: every index up to 2^20
    /// stepped in turn, then around each power of two's carry and the wrap past `u32::MAX`.
    #[test]
    fn stepped_indices_are_reversed_as_new_ones() {
        let mut index = SampleIndex::new(0);
        for value in 1..=1u32 << 20 {
            index = index.next();
            assert_eq!(index, SampleIndex::new(value));
        }
        for bit in 0..32 {
            for below in [2u32, 1, 0] {
                let value = (1u32 << bit).wrapping_sub(below);
                let expected = SampleIndex::new(value.wrapping_add(1));
                assert_eq!(SampleIndex::new(value).next(), expected, "index {value}");
            }
        }
        assert_eq!(SampleIndex::new(u32::MAX).next(), SampleIndex::new(0));
    }

    #[test]
    fn sampler_values_are_the_papers_composition() {
        // Burley's listing: index = nus(i, seed); x = nus(sobol_0(index), hash(seed ^ 1)),
        // y = nus(sobol_1(index), hash(seed ^ 2)); the sampler skips reversals that cancel.
        for (pixel, i) in [(0, 0), (7, 1), (1234, 77), (99_999, 65_535), (3, u32::MAX)] {
            let mut s = Sampler::new(SAMPLER_SOBOL, pixel, i, 5);
            let pixel_seed = pcg_hash(pixel ^ pcg_hash(5));
            for dimension in 0..70u32 {
                let seed = pcg_hash(pixel_seed ^ pcg_hash(dimension));
                let index = nested_uniform_scramble(i, seed);
                let x = to_unit_float(nested_uniform_scramble(sobol_0(index), pcg_hash(seed ^ 1)));
                if dimension % 3 == 0 {
                    assert_eq!(s.next_1d(), x, "pixel {pixel}, sample {i}, dim {dimension}");
                } else {
                    let y = nested_uniform_scramble(sobol_1(index), pcg_hash(seed ^ 2));
                    let expected = Vec2::new(x, to_unit_float(y));
                    assert_eq!(
                        s.next_2d(),
                        expected,
                        "pixel {pixel}, sample {i}, dim {dimension}"
                    );
                }
            }
        }
    }

    /// Dimension 1 from its direction numbers v_0 = 2^31, v_b = v_(b-1) ^ (v_(b-1) >> 1).
    fn sobol_1_by_direction_numbers(index: u32) -> u32 {
        let (mut x, mut v) = (0u32, 0x8000_0000u32);
        for bit in 0..32 {
            if (index >> bit) & 1 == 1 {
                x ^= v;
            }
            v ^= v >> 1;
        }
        x
    }

    /// Draws `draws` as a batch and one by one after `skip` values: the same values, and
    /// the sampler left at the same dimension.
    fn check_batch<const N: usize>(kind: u32, skip: usize, draws: [Draw; N]) {
        let mut batched = Sampler::new(kind, 4321, 9, 2);
        let mut single = batched.clone();
        for _ in 0..skip {
            batched.next_1d();
            single.next_1d();
        }
        let values = batched.next_batch(draws);
        for (i, draw) in draws.iter().enumerate() {
            let expected = match draw {
                Draw::One => Vec2::new(single.next_1d(), 0.0),
                Draw::Two => single.next_2d(),
            };
            assert_eq!(values[i], expected, "kind {kind}, skip {skip}, draw {i}");
        }
        assert_eq!(
            batched.next_2d(),
            single.next_2d(),
            "kind {kind}, skip {skip}"
        );
    }

    #[test]
    fn batches_draw_what_one_by_one_draws() {
        // Starting at dimensions within, across the end of, and beyond the hash table.
        use Draw::{One, Two};
        for kind in [SAMPLER_SOBOL, SAMPLER_INDEPENDENT] {
            for skip in [0, 3, 57, 61, 70] {
                check_batch(kind, skip, BOUNCE_DRAWS);
                check_batch(kind, skip, [Two; 8]);
                check_batch(kind, skip, [One]);
            }
        }
    }

    #[test]
    fn paired_windows_draw_what_single_ones_draw() {
        // Two samplers prepared side by side draw what each draws alone: fresh ones (their
        // window at dimension 0 due), ones a bounce or more along (their next window due, within
        // and beyond the hash table), and pairs where only one window is due.
        let draws = BOUNCE_DRAWS;
        for (skip_a, skip_b) in [(0, 0), (0, 8), (8, 14), (56, 62), (62, 80), (2, 0)] {
            let mut a = Sampler::new(SAMPLER_SOBOL, 17, 3, 9);
            let mut b = Sampler::new(SAMPLER_SOBOL, 18, 5, 9);
            for (sampler, skip) in [(&mut a, skip_a), (&mut b, skip_b)] {
                for _ in 0..skip {
                    sampler.next_1d();
                }
            }
            let (mut alone_a, mut alone_b) = (a.clone(), b.clone());
            Sampler::prepare_pair(&mut a, &mut b, &mut SeedCache::default());
            assert!(!a.window_due() && !b.window_due());
            for _ in 0..3 {
                assert_eq!(a.next_batch(draws), alone_a.next_batch(draws), "{skip_a}");
                assert_eq!(b.next_batch(draws), alone_b.next_batch(draws), "{skip_b}");
            }
        }
    }

    #[test]
    fn windows_through_the_seed_cache_draw_what_samplers_draw_alone() {
        // Samplers of more pixels than the cache holds (the first ones' slots taken by later
        // pixels since), alone and in pairs (of one pixel, of two, one of them no longer
        // held), drawing bounce after bounce past the dimensions the cache holds: every
        // window draws what a sampler of its own draws.
        let mut cache = SeedCache::default();
        let pixels: Vec<PixelSamplers> = (0..CACHED_PIXELS as u32 + 3)
            .map(|p| {
                let mut pixel = PixelSamplers::new(SAMPLER_SOBOL, 100 + p, 9);
                cache.begin(&mut pixel);
                pixel
            })
            .collect();
        let last = pixels.len() - 1;
        let cases = [
            (last, 3, Some((last, 4))),
            (last, 5, Some((0, 6))),
            (1, 7, None),
        ];
        for (pixel_a, index_a, b) in cases {
            let sampler = |pixel: usize, index: u32| {
                let alone = Sampler::new(SAMPLER_SOBOL, 100 + pixel as u32, index, 9);
                (pixels[pixel].sampler(index), alone)
            };
            let (mut a, mut alone_a) = sampler(pixel_a, index_a);
            let mut b = b.map(|(pixel, index)| sampler(pixel, index));
            for bounce in 0..14 {
                match &mut b {
                    Some((b, _)) => Sampler::prepare_pair(&mut a, b, &mut cache),
                    None => a.prepare_cached(&mut cache),
                }
                assert!(!a.window_due(), "bounce {bounce}");
                let draws = BOUNCE_DRAWS;
                assert_eq!(a.next_batch(draws), alone_a.next_batch(draws), "{bounce}");
                if let Some((b, alone_b)) = &mut b {
                    assert_eq!(b.next_batch(draws), alone_b.next_batch(draws), "{bounce}");
                }
            }
            assert!(a.dimension as usize > CACHED_DIMENSIONS + LANES);
        }
    }

    #[test]
    fn first_windows_from_the_seed_cache_draw_what_new_samplers_draw() {
        // A pixel's samplers, their first windows computed from the seeds their pixels put
        // in the cache (alone, or two side by side of the same or of two pixels), draw what
        // `Sampler::new` draws, past the first window too; the independent kind is untouched.
        let draws = BOUNCE_DRAWS;
        for kind in [SAMPLER_SOBOL, SAMPLER_INDEPENDENT] {
            let mut cache = SeedCache::default();
            let pixels = [17, 18].map(|pixel| {
                let mut pixel = PixelSamplers::new(kind, pixel, 9);
                cache.begin(&mut pixel);
                pixel
            });
            for (index_a, index_b, pixel_b) in [(3, 4, 0), (3, 5, 1), (0, 1 << 20, 1)] {
                let pixel_b = &pixels[pixel_b];
                let mut a = pixels[0].sampler(index_a);
                let mut b = pixel_b.sampler(index_b);
                let mut alone = pixels[0].sampler(index_a);
                let mut new_a = Sampler::new(kind, 17, index_a, 9);
                let mut new_b = Sampler::new(kind, pixel_b.pixel, index_b, 9);
                Sampler::prepare_pair(&mut a, &mut b, &mut cache);
                alone.prepare_cached(&mut cache);
                assert!(!a.window_due() && !b.window_due() && !alone.window_due());
                for _ in 0..3 {
                    let expected = new_a.next_batch(draws);
                    assert_eq!(a.next_batch(draws), expected, "{kind} {index_a}");
                    assert_eq!(alone.next_batch(draws), expected, "{kind} {index_a}");
                    assert_eq!(b.next_batch(draws), new_b.next_batch(draws), "{index_b}");
                }
            }
        }
    }

    #[test]
    fn camera_points_are_what_each_sampler_draws_one_by_one() {
        // Samplers of several pixels started over used ones (two packets' worth, the second
        // after a clear): the camera's one or two points drawn side by side are each new
        // sampler's first `next_2d`s, and the samplers go on (their first window computed
        // from the seed cache, where more pixels began than it holds, or by the next draw)
        // as they would have.
        for kind in [SAMPLER_SOBOL, SAMPLER_INDEPENDENT] {
            for dimensions in [1, 2] {
                let mut camera = CameraPoints::new(dimensions);
                let mut cache = SeedCache::default();
                for round in 0..2 {
                    let count = [PACKET, 11][round];
                    let pixels: Vec<PixelSamplers> = (0..count.div_ceil(3) as u32)
                        .map(|p| {
                            let mut pixel = PixelSamplers::new(kind, 40 + p, 7);
                            cache.begin(&mut pixel);
                            pixel
                        })
                        .collect();
                    let pixel = |i: usize| pixels[i / 3];
                    let index = |i: usize| (i * 5 + round) as u32;
                    let mut samplers: Vec<Sampler> = (0..count)
                        .map(|_| {
                            let mut used = Sampler::new(kind, 99, 1234, 5);
                            used.next_batch(BOUNCE_DRAWS);
                            used
                        })
                        .collect();
                    for (i, sampler) in samplers.iter_mut().enumerate() {
                        camera.start(sampler, &pixel(i), SampleIndex::new(index(i)));
                    }
                    camera.draw(kind);
                    for (i, sampler) in samplers.iter_mut().enumerate() {
                        let mut alone = pixel(i).sampler(index(i));
                        for d in 0..dimensions {
                            let drawn = camera.point(i, d);
                            assert_eq!(drawn, alone.next_2d(), "{kind}: sample {i}, dimension {d}");
                        }
                        let mut prepared = sampler.clone();
                        prepared.prepare_cached(&mut cache);
                        for _ in 0..3 {
                            let expected = alone.next_batch(BOUNCE_DRAWS);
                            assert_eq!(sampler.next_batch(BOUNCE_DRAWS), expected, "{i}");
                            assert_eq!(prepared.next_batch(BOUNCE_DRAWS), expected, "{i}");
                        }
                    }
                    camera.clear();
                }
            }
        }
    }

    #[test]
    fn pascal_transform_equals_direction_numbers() {
        let mut state = 1u32;
        for i in (0..4096).chain((0..4096).map(|_| {
            state = pcg_hash(state);
            state
        })) {
            assert_eq!(sobol_1(i), sobol_1_by_direction_numbers(i), "index {i:#x}");
        }
    }

    #[test]
    fn first_sobol_points_are_the_known_values() {
        // Dimension 1 by binary (not Gray-code) index: 0, 1/2, 3/4, 1/4, 5/8, 1/8, 3/8, 7/8.
        let expected = [0.0, 0.5, 0.75, 0.25, 0.625, 0.125, 0.375, 0.875];
        for (i, e) in expected.iter().enumerate() {
            assert_eq!(f64::from(sobol_1(i as u32)) / 4294967296.0, *e);
            assert_eq!(sobol_0(i as u32), (i as u32).reverse_bits());
        }
    }

    #[test]
    fn the_two_dimensions_form_a_0_2_sequence() {
        // Every block of 256 points has one point in each elementary interval of area
        // 1/256: boxes of 2^-a x 2^-(8-a) for a = 0..=8.
        for block in 0..4u32 {
            for a in 0..=8u32 {
                let mut seen = [false; 256];
                for i in block * 256..(block + 1) * 256 {
                    let x = if a == 0 { 0 } else { sobol_0(i) >> (32 - a) };
                    let y = if a == 8 { 0 } else { sobol_1(i) >> (24 + a) };
                    seen[((x << (8 - a)) | y) as usize] = true;
                }
                assert!(
                    seen.iter().all(|s| *s),
                    "block {block}, boxes 2^-{a} x 2^-{}",
                    8 - a
                );
            }
        }
    }

    #[test]
    fn sobol_2d_samples_of_a_pixel_are_stratified() {
        // 256 samples of one pixel, second 2D dimension: one point per cell of 16 x 16.
        let mut seen = [false; 256];
        for i in 0..256 {
            let mut s = Sampler::new(SAMPLER_SOBOL, 1234, i, 7);
            s.next_2d();
            let p = s.next_2d();
            seen[(p.y * 16.0) as usize * 16 + (p.x * 16.0) as usize] = true;
        }
        assert!(seen.iter().all(|s| *s));
    }

    #[test]
    fn values_are_uniform_and_decorrelated_across_pixels() {
        // Mean and variance of 4096 values (64 pixels x 64 samples) per dimension:
        // 1/2 and 1/12 within 4 standard errors; the pixels differ from each other.
        for kind in [SAMPLER_SOBOL, SAMPLER_INDEPENDENT] {
            for dim in 0..6 {
                let mut values = Vec::new();
                for pixel in 0..64 {
                    for i in 0..64 {
                        let mut s = Sampler::new(kind, pixel, i, 3);
                        for _ in 0..dim {
                            s.next_1d();
                        }
                        values.push(f64::from(s.next_1d()));
                    }
                }
                let n = values.len() as f64;
                let mean = values.iter().sum::<f64>() / n;
                let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n;
                assert!(
                    (mean - 0.5).abs() < 4.0 * (1.0 / 12.0f64 / n).sqrt(),
                    "kind {kind} dim {dim}: mean {mean}"
                );
                assert!(
                    (var - 1.0 / 12.0).abs() < 0.01,
                    "kind {kind} dim {dim}: variance {var}"
                );
                assert_ne!(values[0..64], values[64..128]);
            }
        }
    }
}
