//! The environment light: light from infinitely far away, a constant radiance or an
//! equirectangular map evaluated bilinearly as Mitsuba 3's `envmap` and importance-sampled
//! cell by cell (`pathlight_core::environment` describes the buffers). [`crate::lights`]
//! picks it with probability `env_pmf`; a constant environment samples directions
//! cosine-weighted about the shading normal (the ideal density at a diffuse point). Twin of
//! `environment.wgsl`.

use std::f32::consts::{FRAC_1_PI, PI, TAU};

use glam::{Vec2, Vec3A};
use pathlight_core::environment::{decode_rgb9e5, guide_bucket};
use pathlight_core::gpu_types::GpuRenderParams;

use crate::cpu_scene::CpuScene;
use crate::light_sample::LightSample;
use crate::prefetch::prefetch;
use crate::sampling::sin_cos_turns;
use crate::sampling::{Frame, acos, atan2, first_above, sample_cosine_hemisphere};
use crate::table::Table;

/// Whether the environment is a map. Twin of WGSL `has_env_map`.
#[inline(always)]
pub fn has_env_map(params: &GpuRenderParams) -> bool {
    params.env_width != 0
}

/// World direction `[x, y, z]` to the map's frame. These helpers work on plain numbers:
/// [`crate::map_lanes`] computes them for many lanes side by side. Twin of WGSL `to_map`.
#[inline(always)]
pub(crate) fn to_map(params: &GpuRenderParams, [x, y, z]: [f32; 3]) -> [f32; 3] {
    let [c, s] = params.env_rotation;
    [c * x - s * z, y, s * x + c * z]
}

/// Map-frame direction `[x, y, z]` to the world. Twin of WGSL `from_map`.
#[inline(always)]
fn from_map(params: &GpuRenderParams, [x, y, z]: [f32; 3]) -> [f32; 3] {
    let [c, s] = params.env_rotation;
    [c * x + s * z, y, -s * x + c * z]
}

/// Mitsuba's latitude-longitude coordinates of map-frame `[x, y, z]` (through [`atan2`] and
/// [`acos`], polynomials within 5e-7 of libm's, inline). Twin of WGSL `map_uv`.
#[inline(always)]
pub(crate) fn map_uv([x, y, z]: [f32; 3]) -> [f32; 2] {
    let u = atan2(x, -z) * (1.0 / TAU);
    [u - u.floor(), acos(y.clamp(-1.0, 1.0)) * FRAC_1_PI]
}

/// A cell of the map (between texel columns `column` and `column + 1`, wrapping, and rows
/// `row` and `row + 1`) and a position in it, `f` in [0, 1]^2 from texel (`column`, `row`).
/// Twin of WGSL `MapCell`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MapCell {
    column: u32,
    row: u32,
    f: [f32; 2],
}

impl MapCell {
    /// Position `f` in the cell between columns `column`, `column + 1` and rows `row`,
    /// `row + 1`.
    #[inline(always)]
    pub(crate) fn new(column: u32, row: u32, f: [f32; 2]) -> Self {
        Self { column, row, f }
    }
}

/// Twin of WGSL `map_cell`.
#[inline(always)]
pub(crate) fn map_cell(params: &GpuRenderParams, [u, v]: [f32; 2]) -> MapCell {
    let (w, h) = (params.env_width, params.env_height);
    let mut x = u * w as f32 - 0.5;
    // Wrapped into [0, w): x starts in [-0.5, w - 0.5] (u in [0, 1]), so this is WGSL's
    // `x - floor(x / w) * w` bit for bit, without its division.
    if x < 0.0 {
        x += w as f32;
    }
    let y = v * (h - 1) as f32;
    let column = (x as u32).min(w - 1);
    let row = (y as u32).min(h - 2);
    MapCell {
        column,
        row,
        f: [x - column as f32, y - row as f32],
    }
}

/// What a path escaping along world direction `dir` from a point of normal `n` sees: the
/// radiance and, when `mis`, the density [`env_pdf`] gives the direction (0 otherwise).
/// The same values as those two functions, the map's coordinates computed once. Twin of
/// WGSL `env_escape`.
#[inline(always)]
pub fn env_escape(
    scene: &CpuScene,
    params: &GpuRenderParams,
    n: Vec3A,
    dir: Vec3A,
    mis: bool,
) -> (Vec3A, f32) {
    if !has_env_map(params) {
        let pdf = if mis {
            env_pdf(scene, params, n, dir)
        } else {
            0.0
        };
        return (Vec3A::from(params.environment), pdf);
    }
    let c = map_cell(params, map_uv(to_map(params, dir.to_array())));
    let pdf = if mis {
        params.env_pmf * cell_pdf(scene.env_distribution, params, &c)
    } else {
        0.0
    };
    (cell_radiance(scene, params, &c), pdf)
}

/// The map's bilinear radiance at `c`, from its `texels`: [`cell_radiance`]'s, in plain
/// numbers.
#[inline(always)]
pub(crate) fn cell_color(
    texels: Table<'_, u32>,
    params: &GpuRenderParams,
    c: &MapCell,
) -> [f32; 3] {
    let w = params.env_width;
    let right = if c.column + 1 == w { 0 } else { c.column + 1 };
    let top = c.row * w;
    let v00 = decode_rgb9e5(texels.at(top + c.column));
    let v10 = decode_rgb9e5(texels.at(top + right));
    let v01 = decode_rgb9e5(texels.at(top + w + c.column));
    let v11 = decode_rgb9e5(texels.at(top + w + right));
    let [fx, fy] = c.f;
    // Channel by channel (written out: `array::from_fn` is left out of line).
    let channel = |i: usize| {
        let v0 = v00[i] * (1.0 - fx) + v10[i] * fx;
        let v1 = v01[i] * (1.0 - fx) + v11[i] * fx;
        (v0 * (1.0 - fy) + v1 * fy) * params.env_scale
    };
    [channel(0), channel(1), channel(2)]
}

/// The map's bilinear radiance at `c` (`cell_color`'s values). Twin of WGSL `cell_radiance`.
#[inline(always)]
pub fn cell_radiance(scene: &CpuScene, params: &GpuRenderParams, c: &MapCell) -> Vec3A {
    Vec3A::from(cell_color(scene.env_texels, params, c))
}

/// Probability of entry `k` of the CDF at `start` of `d`. Twin of WGSL `cdf_pmf`.
#[inline(always)]
fn cdf_pmf(d: Table<'_, f32>, start: u32, k: u32) -> f32 {
    // The entry before read whatever `k` (a select, not a branch, over many lanes).
    let before = d.at((start + k).saturating_sub(1));
    d.at(start + k) - if k == 0 { 0.0 } else { before }
}

/// First entry of the `n`-entry CDF at `start` exceeding `u` (the last when none does),
/// searched from its guide table at `guide` (`pathlight_core::environment`) between the
/// entries of `u`'s bucket and the next. Twin of WGSL `cdf_search`, which searches the whole
/// CDF.
#[inline(always)]
fn cdf_search(scene: &CpuScene, start: u32, n: u32, guide: u32, u: f32) -> u32 {
    let d = scene.env_distribution;
    let bucket = guide_bucket(u, n);
    // The entry sought usually lies near the bucket's position: its line is loaded while
    // the guide's is.
    prefetch(d.values(), (start + bucket) as usize);
    let k = guide + bucket;
    let (lo, hi) = (
        u32::from(scene.env_guides.at(k)),
        u32::from(scene.env_guides.at(k + 1)),
    );
    lo + first_above(hi - lo + 1, u, |i| d.at(start + lo + i))
}

/// Solid angle of a cell of `row`. Twin of WGSL `cell_solid_angle`.
#[inline(always)]
fn cell_solid_angle(d: Table<'_, f32>, params: &GpuRenderParams, row: u32) -> f32 {
    let rows = params.env_height - 1;
    TAU / params.env_width as f32 * (d.at(rows + row) - d.at(rows + row + 1))
}

/// Solid-angle density of sampling world direction `dir` from the map. Twin of WGSL
/// `env_map_pdf`.
#[inline(always)]
pub fn env_map_pdf(scene: &CpuScene, params: &GpuRenderParams, dir: Vec3A) -> f32 {
    let c = map_cell(params, map_uv(to_map(params, dir.to_array())));
    cell_pdf(scene.env_distribution, params, &c)
}

/// The map's sampling density (solid angle) in cell `c`, from its distribution `d`. Twin of
/// WGSL `cell_pdf`.
#[inline(always)]
pub(crate) fn cell_pdf(d: Table<'_, f32>, params: &GpuRenderParams, c: &MapCell) -> f32 {
    let rows = params.env_height - 1;
    let conditional = rows + params.env_height + c.row * params.env_width;
    let p = cdf_pmf(d, 0, c.row) * cdf_pmf(d, conditional, c.column);
    p / cell_solid_angle(d, params, c.row)
}

/// The largest `u` a map sample searches its CDFs for (below 1).
pub(crate) const MAX_U: f32 = 0.999_999_94;

/// What a map sample in cell (`column`, `row`) gives, in plain numbers so that
/// [`crate::map_lanes`] computes it for many lanes side by side: the world direction, its
/// solid-angle density and the position in the cell.
#[derive(Debug, Clone, Copy)]
pub(crate) struct MapSample {
    pub(crate) wi: [f32; 3],
    pub(crate) pdf: f32,
    pub(crate) f: [f32; 2],
}

/// The direction, density and cell position of the map sample at `u0`, `u1` (below 1) that
/// the CDFs' searches put in cell (`column`, `row`): the rest of WGSL `sample_env_map`.
#[inline(always)]
pub(crate) fn map_sample(
    d: Table<'_, f32>,
    params: &GpuRenderParams,
    [u0, u1]: [f32; 2],
    row: u32,
    column: u32,
) -> MapSample {
    let w = params.env_width;
    let rows = params.env_height - 1;
    let start = rows + params.env_height + row * w;
    let p_row = cdf_pmf(d, 0, row);
    let p_column = cdf_pmf(d, start, column);
    let r0 = ((u0 - (d.at(row) - p_row)) / p_row).clamp(0.0, 1.0);
    let r1 = ((u1 - (d.at(start + column) - p_column)) / p_column).clamp(0.0, 1.0);
    let cos0 = d.at(rows + row);
    let cos1 = d.at(rows + row + 1);
    let cos_theta = cos0 + (cos1 - cos0) * r0;
    let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    let mut turns = (column as f32 + 0.5 + r1) / w as f32;
    if turns >= 1.0 {
        turns -= 1.0;
    }
    let (sin_phi, cos_phi) = sin_cos_turns(turns);
    let dir = [sin_theta * sin_phi, cos_theta, -sin_theta * cos_phi];
    // The texel position map_cell gives the direction: r1 of the way from column to column
    // + 1; between the rows by the polar angle (map_uv's v times h - 1).
    let y = acos(cos_theta.clamp(-1.0, 1.0)) * FRAC_1_PI * rows as f32;
    // `cell_solid_angle`, from the cosines at hand.
    let solid_angle = TAU / w as f32 * (cos0 - cos1);
    MapSample {
        wi: from_map(params, dir),
        pdf: p_row * p_column / solid_angle,
        f: [r1, (y - row as f32).clamp(0.0, 1.0)],
    }
}

/// Asks for the cache lines of the texels of cell (`column`, `row`), read once the BSDF is
/// found to pass the sample on (`light_radiance`).
#[inline(always)]
pub(crate) fn prefetch_cell(scene: &CpuScene, params: &GpuRenderParams, row: u32, column: u32) {
    let top = (row * params.env_width + column) as usize;
    prefetch(scene.env_texels.values(), top);
    prefetch(scene.env_texels.values(), top + params.env_width as usize);
}

/// A direction sampled from the map, its solid-angle density, and the cell and position
/// there that the direction points to (where [`cell_radiance`] gives the radiance seen along
/// it: [`env_escape`]'s up to rounding, without turning the direction back into map
/// coordinates). Twin of WGSL `sample_env_map`.
#[inline(always)]
pub fn sample_env_map(
    scene: &CpuScene,
    params: &GpuRenderParams,
    u: Vec2,
) -> (Vec3A, f32, MapCell) {
    let w = params.env_width;
    let rows = params.env_height - 1;
    let (u0, u1) = (u.x.min(MAX_U), u.y.min(MAX_U));
    let row = cdf_search(scene, 0, rows, 0, u0);
    let start = rows + params.env_height + row * w;
    let column = cdf_search(scene, start, w, rows + 1 + row * (w + 1), u1);
    prefetch_cell(scene, params, row, column);
    let s = map_sample(scene.env_distribution, params, [u0, u1], row, column);
    (Vec3A::from(s.wi), s.pdf, MapCell::new(column, row, s.f))
}

/// The light sample of direction `wi`, drawn from the map with density `pdf`, at `cell`.
#[inline(always)]
pub(crate) fn map_light_sample(
    params: &GpuRenderParams,
    wi: Vec3A,
    pdf: f32,
    cell: MapCell,
) -> LightSample {
    let pdf = params.env_pmf * pdf;
    LightSample {
        wi,
        point: Vec3A::ZERO,
        finite: false,
        radiance: Vec3A::ZERO,
        pdf,
        valid: pdf > 0.0 && pdf.is_finite(),
        mis: true,
        map_cell: Some(cell),
    }
}

/// Density of choosing the environment and direction `wi` from a point with normal `n`
/// (on the side light is gathered from). Twin of WGSL `env_pdf`.
#[inline(always)]
pub fn env_pdf(scene: &CpuScene, params: &GpuRenderParams, n: Vec3A, wi: Vec3A) -> f32 {
    if has_env_map(params) {
        return params.env_pmf * env_map_pdf(scene, params, wi);
    }
    params.env_pmf * n.dot(wi).max(0.0) / PI
}

/// A direction towards the environment from a point with normal `n`, its density including
/// the choice of the environment (`env_pmf`); a map's radiance is left to
/// [`crate::lights::light_radiance`]. Twin of WGSL `sample_environment`.
#[inline(always)]
pub fn sample_environment(
    scene: &CpuScene,
    params: &GpuRenderParams,
    n: Vec3A,
    u: Vec2,
) -> LightSample {
    if has_env_map(params) {
        let (wi, pdf, cell) = sample_env_map(scene, params, u);
        return map_light_sample(params, wi, pdf, cell);
    }
    let wi = Frame::around(n).to_world(sample_cosine_hemisphere(u));
    let radiance = Vec3A::from(params.environment);
    let pdf = env_pdf(scene, params, n, wi);
    LightSample {
        wi,
        point: Vec3A::ZERO,
        finite: false,
        radiance,
        pdf,
        valid: pdf > 0.0,
        mis: true,
        map_cell: None,
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use std::sync::Arc;

    use glam::Vec3;
    use pathlight_core::PreparedScene;
    use pathlight_scene::testing::scene_of;
    use pathlight_scene::{Environment, EnvironmentMap, HdrImage};

    use super::*;

    /// A 16 x 9 map: a dim sky with a gradient, a bright 1-texel "sun" at column 11, row 2,
    /// and a black bottom row; turned by `rotation_deg`.
    fn sun_map(rotation_deg: f32) -> (PreparedScene, GpuRenderParams) {
        let (w, h) = (16u32, 9u32);
        let mut texels = Vec::new();
        for y in 0..h {
            for x in 0..w {
                let sky = 0.2 + 0.05 * x as f32 + 0.1 * y as f32;
                texels.push(if y == h - 1 {
                    [0.0; 3]
                } else {
                    [sky, sky * 0.8, sky * 0.5]
                });
            }
        }
        texels[(2 * w + 11) as usize] = [500.0, 400.0, 300.0];
        map_scene(w, h, texels, 2.0, rotation_deg)
    }

    /// A scene lit by a `w` x `h` map of `texels` (row by row) alone, `strength` times as
    /// bright, turned by `rotation_deg`.
    pub(crate) fn map_scene(
        w: u32,
        h: u32,
        texels: Vec<[f32; 3]>,
        strength: f32,
        rotation_deg: f32,
    ) -> (PreparedScene, GpuRenderParams) {
        let max = texels.iter().flatten().fold(0.0f32, |m, &v| m.max(v));
        let mut scene = scene_of(Vec::new());
        scene.environment = Environment::Map(EnvironmentMap {
            image: Arc::new(HdrImage {
                width: w,
                height: h,
                texels,
                max,
            }),
            strength,
            rotation_deg,
        });
        let prepared = PreparedScene::new(&scene).unwrap();
        let params = GpuRenderParams::new(&scene.camera, &scene.settings, &prepared.shading);
        (prepared, params)
    }

    /// Uniform numbers in [0, 1) from `seed` (xorshift).
    pub(crate) fn uniform(seed: u32) -> impl FnMut() -> f32 {
        let mut rng = seed | 1;
        move || {
            rng ^= rng << 13;
            rng ^= rng >> 17;
            rng ^= rng << 5;
            (rng >> 8) as f32 / (1u32 << 24) as f32
        }
    }

    /// A uniform direction on the sphere from `u`.
    fn uniform_direction(u: Vec2) -> Vec3A {
        let z = 1.0 - 2.0 * u.x;
        let r = (1.0 - z * z).max(0.0).sqrt();
        let phi = TAU * u.y;
        Vec3A::new(r * phi.cos(), r * phi.sin(), z)
    }

    #[test]
    fn the_density_integrates_to_one_and_sampling_reports_it() {
        for rotation in [0.0, 73.0] {
            let (prepared, params) = sun_map(rotation);
            let scene = CpuScene::new(&prepared);
            // Stratified over the sphere: 800 x 800 strata, the density being piecewise
            // constant over 16 x 8 cells; measured error below 1e-3.
            let n = 800;
            let mut integral = 0.0f64;
            for i in 0..n {
                for j in 0..n {
                    let u = Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
                    integral += f64::from(env_map_pdf(&scene, &params, uniform_direction(u)));
                }
            }
            integral *= 4.0 * std::f64::consts::PI / f64::from(n * n);
            assert!(
                (integral - 1.0).abs() < 2e-3,
                "rotation {rotation}: {integral}"
            );
            // Every sample's density is the density of its direction, and the radiance at
            // its cell the radiance seen along it (to rounding: the texels reach 1000 and
            // change by that much across a cell).
            let mut next = uniform(0x2545_f491);
            for _ in 0..20_000 {
                let (wi, pdf, cell) = sample_env_map(&scene, &params, Vec2::new(next(), next()));
                assert!((wi.length() - 1.0).abs() < 1e-5);
                let at_cell = cell_radiance(&scene, &params, &cell);
                let along = env_escape(&scene, &params, Vec3A::ZERO, wi, false).0;
                assert!(
                    (at_cell - along).abs().max_element() <= 0.05,
                    "rotation {rotation}: {at_cell} at the cell, {along} along {wi}"
                );
                let eval = env_map_pdf(&scene, &params, wi);
                assert!(
                    (pdf - eval).abs() <= 2e-3 * pdf,
                    "rotation {rotation}: sampled {pdf}, evaluated {eval} at {wi}"
                );
            }
        }
    }

    #[test]
    fn sample_counts_match_the_cell_probabilities() {
        let (prepared, params) = sun_map(0.0);
        let scene = CpuScene::new(&prepared);
        let d = scene.env_distribution;
        let (w, rows) = (params.env_width, params.env_height - 1);
        let n = 400u32;
        let mut counts = vec![0u32; (w * rows) as usize];
        for i in 0..n {
            for j in 0..n {
                let u = Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
                let (wi, _, _) = sample_env_map(&scene, &params, u);
                let c = map_cell(&params, map_uv(to_map(&params, wi.to_array())));
                counts[(c.row * w + c.column) as usize] += 1;
            }
        }
        // A cell is the rectangle p_row x p_column of the unit square of `u`: the n x n
        // stratum centres in it number its area n^2 to within its half-perimeter n
        // (p_row + p_column) plus one, if and only if each sample lands in the cell its `u`
        // chose.
        let total = f64::from(n * n);
        for row in 0..rows {
            for column in 0..w {
                let p_row = f64::from(cdf_pmf(d, 0, row));
                let p_column = f64::from(cdf_pmf(d, rows + params.env_height + row * w, column));
                let p = p_row * p_column;
                let got = f64::from(counts[(row * w + column) as usize]);
                assert!(
                    (got - p * total).abs() <= f64::from(n) * (p_row + p_column) + 1.0,
                    "cell ({column}, {row}): {got} samples, expected {}",
                    p * total
                );
            }
        }
        // The sun's cells (its texel is a corner of four) take most samples; the bottom row
        // of cells, between a lit row and the black one, some.
        let sun: u32 = [(1, 10), (1, 11), (2, 10), (2, 11)]
            .iter()
            .map(|&(r, c)| counts[(r * w + c) as usize])
            .sum();
        assert!(f64::from(sun) > 0.5 * total, "{sun} of {total}");
    }

    #[test]
    fn the_cell_wraps_as_wgsl_wraps_it() {
        // WGSL's `x - floor(x / w) * w`, bit for bit, at the ends of [0, 1] and between.
        let (_, params) = sun_map(0.0);
        let w = params.env_width as f32;
        let mut us = vec![0.0, 1.0, 1.0f32.next_down(), 1e-9, 0.5 / w, 0.5 / w - 1e-7];
        us.extend((0..10_000).map(|i| i as f32 / 9_999.0));
        for u in us {
            let c = map_cell(&params, [u, 0.3]);
            let mut x = u * w - 0.5;
            x -= (x / w).floor() * w;
            let column = (x as u32).min(params.env_width - 1);
            assert_eq!(
                (c.column, c.f[0].to_bits()),
                (column, (x - column as f32).to_bits()),
                "u {u}"
            );
        }
    }

    #[test]
    fn the_map_is_oriented_as_mitsuba_orients_it() {
        // Mitsuba: u = atan2(x, -z) / 2pi, v = acos(y) / pi; texel column j centred at
        // u = (j + 0.5) / w, row i at v = i / (h - 1). The sun texel (11, 2) lies at
        // phi = 2 pi 11.5 / 16, theta = pi 2 / 8.
        for rotation in [0.0f32, 90.0, -30.0] {
            let (prepared, params) = sun_map(rotation);
            let scene = CpuScene::new(&prepared);
            // Radiance seen at longitude `phi` on the sun's row, turned as Mitsuba's
            // to_world rotation about +y by `rotation` turns it.
            let theta = std::f32::consts::PI * 0.25;
            let seen_at = |phi: f32| {
                let local = Vec3::new(
                    theta.sin() * phi.sin(),
                    theta.cos(),
                    -theta.sin() * phi.cos(),
                );
                let world = glam::Quat::from_rotation_y(rotation.to_radians()) * local;
                env_escape(&scene, &params, Vec3A::ZERO, world.into(), false).0
            };
            let seen = seen_at(TAU * 11.5 / 16.0);
            let expected = Vec3A::new(500.0, 400.0, 300.0) * 2.0;
            assert!(
                (seen - expected).abs().max_element() <= 1e-3 * 1000.0,
                "rotation {rotation}: {seen}"
            );
            // Halfway to the next column the bilinear weight is one half.
            let seen = seen_at(TAU * 12.0 / 16.0);
            assert!((seen.x - 500.0).abs() < 2.0, "rotation {rotation}: {seen}");
        }
        // Straight up reads the top row, straight down the black bottom one.
        let (prepared, params) = sun_map(0.0);
        let scene = CpuScene::new(&prepared);
        assert!(
            env_escape(&scene, &params, Vec3A::ZERO, Vec3A::Y, false)
                .0
                .x
                > 0.0
        );
        assert_eq!(
            env_escape(&scene, &params, Vec3A::ZERO, -Vec3A::Y, false).0,
            Vec3A::ZERO
        );
    }
}
