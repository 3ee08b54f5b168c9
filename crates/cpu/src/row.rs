//! One row of samples, the CPU backend's unit of parallel work, with the whole path tracer
//! inlined and compiled once per instruction-set level; the best level the CPU has runs.

use std::ops::Range;

use glam::{Vec3, Vec3A};
use pathlight_core::gpu_types::{GpuAccumPixel, GpuAovPixel, GpuRenderParams};

use crate::bsdf_lanes::{LaneBsdf, ONE_BY_ONE_NARROW, ONE_BY_ONE_WIDE, SampleLanes};
use crate::camera::{film_point, lens_ray, primary_directions};
use crate::cpu_scene::CpuScene;
use crate::integrator::{
    FixedSum, Path, ShadingLanes, ShadowTest, T_MAX, accumulated_value, add_aov_sample,
};
use crate::intersect::Ray;
use crate::packet::{Lanes, PACKET, PacketHits, RayPacket};
use crate::sampler::{CameraPoints, PixelSamplers, SampleIndex, Sampler, SeedCache};
use crate::surface::{Surface, surface_at};
use crate::textures::prefetch_texels;
use crate::tracer::Tracer;

/// A row's running sums: the colour's, and the auxiliary images' (empty when the render has
/// none).
pub(crate) struct RowSums<'a> {
    pub color: &'a mut [GpuAccumPixel],
    pub aovs: &'a mut [GpuAovPixel],
}

/// What a row renderer adds its samples to: sums of the colours of its own (added to the
/// row's once it is done), and the row's auxiliary images' sums.
struct RowTotals<'a> {
    color: &'a mut [FixedSum],
    aovs: &'a mut [GpuAovPixel],
}

/// One row's share of an `advance`.
pub(crate) struct RowJob<'a> {
    pub scene: &'a CpuScene<'a>,
    pub params: &'a GpuRenderParams,
    /// The row.
    pub y: u32,
    /// Sample indices to add to every pixel.
    pub samples: Range<u32>,
}

/// What rendering some samples did: the rays traced (camera, extension and shadow rays) and
/// the samples dropped because their radiance was not finite.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub(crate) struct Tally {
    pub rays: u64,
    pub dropped: u64,
}

impl std::ops::Add for Tally {
    type Output = Self;
    fn add(self, other: Self) -> Self {
        Self {
            rays: self.rays + other.rays,
            dropped: self.dropped + other.dropped,
        }
    }
}

impl std::iter::Sum for Tally {
    fn sum<I: Iterator<Item = Self>>(iter: I) -> Self {
        iter.fold(Self::default(), |a, b| a + b)
    }
}

/// Adds the samples of `job` to its row's sums; returns what it did. The row's samples
/// (pixel by pixel, each pixel's in turn) are traced as paths side by side, [`PACKET`] at a
/// time, their rays traced together as packets; a path that ends hands its lane to the next
/// sample. The whole path tracer is inlined here, so that each [`InstructionSet`] level
/// compiles all of it. `WIDE`: the level has AVX-512's 32 registers of sixteen lanes, worth
/// computing two paths' sampler windows at once (with AVX2's sixteen registers they cost
/// the furnace 7%: spilled), and a few rough glass or mirror lanes one by one rather than
/// side by side ([`ONE_BY_ONE_WIDE`], [`ONE_BY_ONE_NARROW`]).
#[inline(always)]
fn render_row<const WIDE: bool>(tracer: &mut Tracer, job: &RowJob, row: &mut RowTotals) -> Tally {
    let (scene, params) = (job.scene, job.params);
    let mut starter = Starter::new(job, row.color.len());
    // Each lane's path, its sampler and the pixel column it adds to; `occupied` says which
    // hold one.
    let mut lanes = RowLanes {
        paths: std::array::repeat(starter.idle_path()),
        samplers: std::array::repeat(Sampler::new(params.sampler, 0, 0, 0)),
        columns: [0; PACKET],
    };
    let mut tally = Tally::default();
    // Reused from round to round: only the lanes in use are written.
    let mut packet = RayPacket {
        t_max: [T_MAX; PACKET],
        ..RayPacket::default()
    };
    let mut shadows = RayPacket::default();
    let mut shading = ShadingLanes::default();
    let mut hits = PacketHits::default();
    let mut surfaces = [Surface::default(); PACKET];
    // The lanes holding a path; their next rays are in `packet` (written as each went on).
    let mut occupied: Lanes = 0;
    loop {
        packet.active = occupied;
        tally = tally + starter.fill(&mut lanes, &mut packet, row);
        if packet.active == 0 {
            return tally;
        }
        occupied = packet.active;
        tracer.intersect_packet::<WIDE>(&packet, &mut hits);
        let RowLanes {
            paths,
            samplers,
            columns,
        } = &mut lanes;
        let found = hits.found();
        // The windows due of the paths that go on (a new path's first among them), their
        // seeds from the row's cache.
        if WIDE {
            prepare_windows(samplers, found & occupied, &mut starter.seeds);
        } else {
            let mut left = found & occupied;
            while left != 0 {
                let l = left.trailing_zeros() as usize;
                left &= left - 1;
                samplers[l].prepare_cached(&mut starter.seeds);
            }
        }
        shading.escape(scene, params, occupied & !found, |l| {
            packet.rays[l].dir.to_array()
        });
        shadows.active = 0;
        shading.clear();
        let mut shadow_tests = ShadowTests {
            packet: &mut shadows,
            unblocked: [Vec3A::ZERO; PACKET],
        };
        // In a scene with textures, the surfaces the hits lie on first, their textures' texels
        // asked for together: on a texture of megabytes the bounces' lookups miss the caches,
        // and a packet's misses overlap so instead of each stalling its step (textured-sphere
        // 5-11% sooner, one thread). Elsewhere each step computes its surface (the pass's copies
        // cost 2% of cornell-materials' instructions).
        let mut left = if scene.textured { occupied & found } else { 0 };
        while left != 0 {
            let l = left.trailing_zeros() as usize;
            left &= left - 1;
            let s = surface_at(scene, &hits.nearest(l), &paths[l].ray);
            prefetch_texels(scene, s.material, s.uv);
            surfaces[l] = s;
        }
        // The lanes whose rays escaped, then those whose rays hit: in each loop every step
        // takes the same way there (a branch per lane on it, where the two mix at random,
        // cost lights and env-sun 3-5%: mispredicted, presumably).
        let mut left = occupied & !found;
        while left != 0 {
            let l = left.trailing_zeros() as usize;
            left &= left - 1;
            paths[l].step(&mut samplers[l], scene, params, None, &mut shading, l);
        }
        let mut left = occupied & found;
        while left != 0 {
            let l = left.trailing_zeros() as usize;
            left &= left - 1;
            let (sampler, hit) = (&mut samplers[l], hits.nearest(l));
            let surface = if scene.textured {
                surfaces[l]
            } else {
                surface_at(scene, &hit, &paths[l].ray)
            };
            let at = Some((&hit, &surface));
            let shadow = paths[l].step(sampler, scene, params, at, &mut shading, l);
            shadow_tests.add(l, shadow);
        }
        let one_by_one = if WIDE {
            ONE_BY_ONE_WIDE
        } else {
            ONE_BY_ONE_NARROW
        };
        shading.compute(scene, params, one_by_one);
        let mut left = shading.lights_left();
        while left != 0 {
            let l = left.trailing_zeros() as usize;
            left &= left - 1;
            shadow_tests.add(l, paths[l].left_light_test(scene, params, &shading, l));
        }
        let diffuse = &shading.diffuse;
        let mut left = diffuse.mask();
        while left != 0 {
            let l = left.trailing_zeros() as usize;
            left &= left - 1;
            shadow_tests.add(l, paths[l].leave_diffuse(params, diffuse, l));
        }
        leave_sampled(paths, &shading.glass, params);
        leave_sampled(paths, &shading.glossy, params);
        leave_sampled(paths, &shading.metal_rough, params);
        let unblocked = shadow_tests.unblocked;
        let blocked = tracer.occluded_packet::<WIDE>(&shadows);
        // Each lane's outcome as a bit first, then a loop over each outcome's lanes: a branch
        // per lane on whether its path ended, which comes at random, cost lights 5%
        // (mispredicted, presumably).
        let mut left = shadows.active & !blocked;
        while left != 0 {
            let l = left.trailing_zeros() as usize;
            left &= left - 1;
            paths[l].add_unblocked(unblocked[l]);
        }
        let mut ended: Lanes = 0;
        let mut left = occupied;
        while left != 0 {
            let l = left.trailing_zeros() as usize;
            left &= left - 1;
            ended |= Lanes::from(!paths[l].alive) << l;
        }
        let mut left = occupied & !ended;
        while left != 0 {
            let l = left.trailing_zeros() as usize;
            left &= left - 1;
            packet.rays[l] = paths[l].ray;
        }
        let mut left = ended;
        while left != 0 {
            let l = left.trailing_zeros() as usize;
            left &= left - 1;
            tally = tally + finish(&paths[l], row, columns[l]);
        }
        occupied &= !ended;
    }
}

/// A row's lanes: per lane a path, its sampler and the pixel column it adds to.
struct RowLanes {
    paths: [Path; PACKET],
    samplers: [Sampler; PACKET],
    columns: [usize; PACKET],
}

/// Computes the windows due of the `samplers` in `going_on` (those whose path's ray hit
/// something: their next bounce draws from it), two side by side at a time
/// ([`Sampler::prepare_pair`]), an odd one left alone, their scrambles' seeds from `seeds`.
#[inline(always)]
fn prepare_windows(samplers: &mut [Sampler; PACKET], going_on: Lanes, seeds: &mut SeedCache) {
    let mut due: Lanes = 0;
    let mut left = going_on;
    while left != 0 {
        let l = left.trailing_zeros() as usize;
        left &= left - 1;
        due |= Lanes::from(samplers[l].window_due()) << l;
    }
    // A loop, not a closure called per pair, which the compiler left out of line here
    // (compiled for the baseline: cornell-diffuse 0.66 times as fast).
    while due != 0 {
        let a = due.trailing_zeros() as usize;
        due &= due - 1;
        if due == 0 {
            samplers[a].prepare_cached(seeds);
            break;
        }
        let b = due.trailing_zeros() as usize;
        due &= due - 1;
        if let Ok([sampler_a, sampler_b]) = samplers.get_disjoint_mut([a, b]) {
            Sampler::prepare_pair(sampler_a, sampler_b, seeds);
        }
    }
}

/// A round's shadow rays, and the radiance each adds unless something blocks it.
struct ShadowTests<'a> {
    packet: &'a mut RayPacket,
    unblocked: [Vec3A; PACKET],
}

impl ShadowTests<'_> {
    /// Lane `l`'s shadow test, if it has one.
    #[inline(always)]
    fn add(&mut self, l: usize, shadow: Option<ShadowTest>) {
        if let Some(shadow) = shadow {
            self.packet.rays[l] = shadow.ray;
            self.packet.t_max[l] = shadow.t_max;
            self.packet.active |= 1 << l;
            self.unblocked[l] = shadow.radiance;
        }
    }
}

/// Goes on with the `paths` whose BSDF samples `computed` holds.
#[inline(always)]
fn leave_sampled<M: LaneBsdf>(
    paths: &mut [Path; PACKET],
    computed: &SampleLanes<M>,
    params: &GpuRenderParams,
) {
    let mut left = computed.mask();
    while left != 0 {
        let l = left.trailing_zeros() as usize;
        left &= left - 1;
        paths[l].leave_sampled(params, computed, l);
    }
}

/// The samples of a row still to start (pixel by pixel, each pixel's in turn), and what
/// starting them needs: a new path's sampler is started lane by lane, then the camera's
/// sample values ([`CameraPoints`]) and (for a pinhole) the camera rays of all the lanes
/// starting at once, side by side, so that new paths do not each wait on hash chains, a
/// division and a square root.
struct Starter<'a> {
    job: &'a RowJob<'a>,
    width: usize,
    /// The pixel column whose samples start now (`width` once all have started), what its
    /// samplers share, and the index of its next sample to start.
    column: usize,
    pixel: PixelSamplers,
    index: SampleIndex,
    pinhole: bool,
    /// The camera's sample values of the samples starting.
    camera: CameraPoints,
    /// The scrambles' seeds of the pixels started last.
    seeds: SeedCache,
    /// Per lane, of the sample starting there: its film point (for a pinhole) or camera ray
    /// (with a lens).
    film_x: [f32; PACKET],
    film_y: [f32; PACKET],
    lens_rays: [Ray; PACKET],
}

impl<'a> Starter<'a> {
    #[inline(always)]
    fn new(job: &'a RowJob<'a>, width: usize) -> Self {
        let params = job.params;
        let mut seeds = SeedCache::default();
        let mut pixel = PixelSamplers::new(params.sampler, job.y * params.width, params.seed);
        seeds.begin(&mut pixel);
        Self {
            job,
            width,
            column: if job.samples.is_empty() { width } else { 0 },
            pixel,
            index: SampleIndex::new(job.samples.start),
            pinhole: params.camera.lens_radius <= 0.0,
            camera: CameraPoints::new(if params.camera.lens_radius <= 0.0 {
                1
            } else {
                2
            }),
            film_x: [0.0; PACKET],
            film_y: [0.0; PACKET],
            lens_rays: RayPacket::default().rays,
            seeds,
        }
    }

    /// A path for a lane that holds none yet (ended: never stepped).
    #[inline(always)]
    fn idle_path(&self) -> Path {
        let params = self.job.params;
        let mut path = Path::from_camera_ray(params, Ray::new(params.camera.position, Vec3::Z));
        path.alive = false;
        path
    }

    /// Starts the next samples in the `lanes` that `packet.active` leaves empty (it marks
    /// those holding a path), their camera rays into `packet`; a path that ends at once
    /// (max_depth 0) is added to `row` and hands its lane to the next sample. Returns what
    /// those did. A new path's first sampler window is left due: computed once its camera
    /// ray is known to meet something ([`Sampler::prepare_cached`]).
    #[inline(always)]
    fn fill(&mut self, lanes: &mut RowLanes, packet: &mut RayPacket, row: &mut RowTotals) -> Tally {
        let (job, params) = (self.job, self.job.params);
        let mut tally = Tally::default();
        loop {
            let mut starting: Lanes = 0;
            let mut empty = !packet.active & Lanes::MAX >> (Lanes::BITS - PACKET as u32);
            while empty != 0 && self.column != self.width {
                let l = empty.trailing_zeros() as usize;
                empty &= empty - 1;
                let sampler = &mut lanes.samplers[l];
                self.camera.start(sampler, &self.pixel, self.index);
                lanes.columns[l] = self.column;
                starting |= 1 << l;
                self.index = self.index.next();
                if self.index.value() == job.samples.end {
                    self.column += 1;
                    self.index = SampleIndex::new(job.samples.start);
                    if self.column != self.width {
                        let pixel = job.y * params.width + self.column as u32;
                        self.pixel = PixelSamplers::new(params.sampler, pixel, params.seed);
                        self.seeds.begin(&mut self.pixel);
                    }
                }
            }
            if starting == 0 {
                return tally;
            }
            self.camera.draw(params.sampler);
            let mut left = starting;
            // The samples in the order they started.
            let mut n = 0;
            while left != 0 {
                let l = left.trailing_zeros() as usize;
                left &= left - 1;
                let film = film_point(lanes.columns[l] as u32, job.y, self.camera.point(n, 0));
                if self.pinhole {
                    (self.film_x[l], self.film_y[l]) = (film.x, film.y);
                } else {
                    self.lens_rays[l] = lens_ray(params, film, self.camera.point(n, 1));
                }
                n += 1;
            }
            self.camera.clear();
            let dir = self
                .pinhole
                .then(|| primary_directions(params, &self.film_x, &self.film_y));
            let mut left = starting;
            while left != 0 {
                let l = left.trailing_zeros() as usize;
                left &= left - 1;
                let ray = match &dir {
                    Some(dir) => Ray::new(
                        params.camera.position,
                        Vec3::new(dir[0][l], dir[1][l], dir[2][l]),
                    ),
                    None => self.lens_rays[l],
                };
                let path = &mut lanes.paths[l];
                *path = Path::from_camera_ray(params, ray);
                if path.alive {
                    packet.rays[l] = ray;
                    packet.active |= 1 << l;
                } else {
                    tally = tally + finish(path, row, lanes.columns[l]);
                }
            }
            if params.max_depth > 0 {
                return tally; // Every new path lives: a lane stays empty only for want of samples.
            }
        }
    }
}

/// Adds the sample of the ended `path` to the sums of pixel `x` of `row` (a non-finite
/// radiance as zero); returns its rays and whether it was dropped.
#[inline(always)]
fn finish(path: &Path, row: &mut RowTotals, x: usize) -> Tally {
    row.color[x].add(accumulated_value(path.sample.radiance));
    if let Some(aov) = row.aovs.get_mut(x) {
        add_aov_sample(aov, &path.sample);
    }
    Tally {
        rays: u64::from(path.sample.rays),
        dropped: u64::from(!path.sample.radiance.is_finite()),
    }
}

/// The variable naming the CPU backend's level, for comparing levels on one machine.
pub const LEVEL_VARIABLE: &str = "PATHLIGHT_CPU_LEVEL";

/// A [`LEVEL_VARIABLE`] naming a level this CPU cannot run.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{LEVEL_VARIABLE}={name}: this CPU runs the levels {levels}")]
pub struct UnknownLevel {
    /// The level named.
    pub name: String,
    /// The levels this CPU runs, comma-separated.
    pub levels: String,
}

/// The instruction set a row renderer is compiled for: `render_row` is compiled once per
/// level and the best one the CPU has is chosen at run time (AVX2 and FMA give the scalar
/// code three-operand SSE/AVX encodings, BMI2 shifts, GFNI one-instruction bit reversal;
/// +27% on cornell-spheres on an AMD EPYC with AVX-512). Rust never fuses a multiply and an
/// add on its own, so every level computes the same image bit for bit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InstructionSet {
    /// The target's baseline (SSE2 on x86-64).
    Baseline,
    /// x86-64-v3: AVX2, FMA, BMI1/2, LZCNT, MOVBE, F16C.
    #[cfg(target_arch = "x86_64")]
    X86_64V3,
    /// x86-64-v4 (AVX-512 F/VL/BW/DQ/CD) and GFNI.
    #[cfg(target_arch = "x86_64")]
    X86_64V4Gfni,
}

impl InstructionSet {
    /// Every level this CPU can run, baseline first.
    pub fn supported() -> Vec<Self> {
        #[cfg_attr(
            not(target_arch = "x86_64"),
            expect(unused_mut, reason = "only x86-64 has levels above the baseline")
        )]
        let mut levels = vec![Self::Baseline];
        #[cfg(target_arch = "x86_64")]
        {
            use std::arch::is_x86_feature_detected as has;
            let v3 = has!("avx2") && has!("fma") && has!("bmi1") && has!("bmi2");
            let v3 = v3 && has!("lzcnt") && has!("movbe") && has!("f16c");
            if v3 {
                levels.push(Self::X86_64V3);
                let v4 = has!("avx512f") && has!("avx512vl") && has!("avx512bw");
                if v4 && has!("avx512dq") && has!("avx512cd") && has!("gfni") {
                    levels.push(Self::X86_64V4Gfni);
                } else if cfg!(pathlight_pgo_stand_in) {
                    // tools/pgo.sh's training build: its x86-64-v4+gfni row renderer is
                    // compiled for x86-64-v3 (tools/rustc-pgo).
                    levels.push(Self::X86_64V4Gfni);
                }
            }
        }
        levels
    }

    /// The best level this CPU can run.
    pub fn best() -> Self {
        Self::supported().pop().unwrap_or(Self::Baseline)
    }

    /// The level the CPU backend runs: the best this CPU has, or the one
    /// [`LEVEL_VARIABLE`] names when set and not empty (refused, with the levels there are,
    /// when this CPU cannot run it).
    pub fn from_environment() -> Result<Self, UnknownLevel> {
        let name = std::env::var_os(LEVEL_VARIABLE).unwrap_or_default();
        let name = name.to_string_lossy();
        if name.is_empty() {
            return Ok(Self::best());
        }
        Self::named(&name).ok_or_else(|| UnknownLevel {
            name: name.into_owned(),
            levels: Self::supported()
                .iter()
                .map(|level| level.name())
                .collect::<Vec<_>>()
                .join(", "),
        })
    }

    /// The level this CPU can run whose [`name`](Self::name) is `name`.
    pub fn named(name: &str) -> Option<Self> {
        Self::supported()
            .into_iter()
            .find(|level| level.name() == name)
    }

    /// Its name, as reports show it.
    pub fn name(self) -> &'static str {
        match self {
            Self::Baseline => "baseline",
            #[cfg(target_arch = "x86_64")]
            Self::X86_64V3 => "x86-64-v3",
            #[cfg(target_arch = "x86_64")]
            Self::X86_64V4Gfni => "x86-64-v4+gfni",
        }
    }
}

/// [`render_row`] compiled for `isa`, which the CPU must support.
pub(crate) fn render_row_with(
    isa: InstructionSet,
    tracer: &mut Tracer,
    job: &RowJob,
    row: &mut RowSums,
) -> Tally {
    let mut color = vec![FixedSum::default(); row.color.len()];
    let totals = &mut RowTotals {
        color: &mut color,
        aovs: row.aovs,
    };
    let tally = match isa {
        InstructionSet::Baseline => render_row::<false>(tracer, job, totals),
        // SAFETY: `InstructionSet::supported` found the features on this CPU.
        #[cfg(target_arch = "x86_64")]
        InstructionSet::X86_64V3 => unsafe { render_row_x86_64_v3(tracer, job, totals) },
        // SAFETY: as above.
        #[cfg(target_arch = "x86_64")]
        InstructionSet::X86_64V4Gfni => unsafe { render_row_x86_64_v4_gfni(tracer, job, totals) },
    };
    for (acc, sum) in row.color.iter_mut().zip(&color) {
        sum.add_to(acc);
    }
    tally
}

/// [`render_row`] for x86-64-v3.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx,avx2,fma,bmi1,bmi2,lzcnt,popcnt,f16c,movbe")]
fn render_row_x86_64_v3(tracer: &mut Tracer, job: &RowJob, row: &mut RowTotals) -> Tally {
    render_row::<false>(tracer, job, row)
}

/// [`render_row`] for x86-64-v4 with GFNI.
#[cfg(target_arch = "x86_64")]
#[target_feature(
    enable = "avx,avx2,fma,bmi1,bmi2,lzcnt,popcnt,f16c,movbe,avx512f,avx512vl,avx512bw,avx512dq,avx512cd,gfni"
)]
fn render_row_x86_64_v4_gfni(tracer: &mut Tracer, job: &RowJob, row: &mut RowTotals) -> Tally {
    render_row::<true>(tracer, job, row)
}
