//! The environment map's light samples of a packet's lanes, and what its escaping rays see,
//! computed side by side: the same values as [`crate::environment::sample_environment`] and
//! [`crate::environment::env_escape`], bit for bit, each step one vector operation over the
//! lanes. A sample is a chain of dependent loads (the row's guide entry and CDF entries, then
//! the column's from megabytes of tables) and polynomials, an escape a chain of polynomials
//! (`atan2`, `acos`) and loads (the cell's density and texels); taken one lane after another,
//! the core waited on each step of each chain in turn (`perf`: a quarter and a fifth of
//! env-sun's time), where side by side the lanes' loads are gathered at once.

use glam::{Vec2, Vec3A};
use pathlight_core::environment::guide_bucket;
use pathlight_core::gpu_types::GpuRenderParams;

use crate::cpu_scene::CpuScene;
use crate::environment::{
    MAX_U, MapCell, cell_color, cell_pdf, map_cell, map_light_sample, map_sample, map_uv,
    prefetch_cell, to_map,
};
use crate::light_sample::LightSample;
use crate::packet::{Lanes, PACKET};
use crate::table::Table;

/// The map's light samples of the lanes in `lanes`, at `u[l]` for lane `l`, given to
/// `take(l, sample)` in lane order. Every lane is computed (a lane outside `lanes` from
/// whatever its `u` holds) and only those in `lanes` are given.
#[inline(always)]
pub fn sample_env_maps(
    scene: &CpuScene,
    params: &GpuRenderParams,
    lanes: Lanes,
    u: &[Vec2; PACKET],
    mut take: impl FnMut(usize, LightSample),
) {
    let (d, guides) = (scene.env_distribution, scene.env_guides);
    if lanes == 0 {
        return;
    }
    let w = params.env_width;
    let rows = params.env_height - 1;
    let mut u0 = [0.0f32; PACKET];
    let mut u1 = [0.0f32; PACKET];
    for l in 0..PACKET {
        (u0[l], u1[l]) = (u[l].x.min(MAX_U), u[l].y.min(MAX_U));
    }
    let row = cdf_search_lanes(d, guides, rows, &[0; PACKET], &[0; PACKET], &u0);
    let mut start = [0u32; PACKET];
    let mut guide = [0u32; PACKET];
    for l in 0..PACKET {
        start[l] = rows + params.env_height + row[l] * w;
        guide[l] = rows + 1 + row[l] * (w + 1);
    }
    let column = cdf_search_lanes(d, guides, w, &start, &guide, &u1);
    // The samples per coordinate, as computed side by side.
    let mut wi = [[0.0f32; PACKET]; 3];
    let mut pdf = [0.0f32; PACKET];
    let mut f = [[0.0f32; PACKET]; 2];
    for l in 0..PACKET {
        let s = map_sample(d, params, [u0[l], u1[l]], row[l], column[l]);
        (wi[0][l], wi[1][l], wi[2][l]) = (s.wi[0], s.wi[1], s.wi[2]);
        pdf[l] = s.pdf;
        (f[0][l], f[1][l]) = (s.f[0], s.f[1]);
    }
    let mut left = lanes;
    while left != 0 {
        let l = left.trailing_zeros() as usize;
        left &= left - 1;
        prefetch_cell(scene, params, row[l], column[l]);
        let cell = MapCell::new(column[l], row[l], [f[0][l], f[1][l]]);
        let dir = Vec3A::new(wi[0][l], wi[1][l], wi[2][l]);
        take(l, map_light_sample(params, dir, pdf[l], cell));
    }
}

/// `environment::cdf_search` for each lane: the first entry of the `n`-entry CDF at
/// `start[l]` of `d` exceeding `u[l]` (the last when none does), searched from its guide
/// table at `guide[l]` of `guides` with `first_above`'s halving steps (the same entries, so
/// the same result), each step taken for every lane at once until every lane's window is one
/// entry.
#[inline(always)]
fn cdf_search_lanes(
    d: Table<'_, f32>,
    guides: Table<'_, u16>,
    n: u32,
    start: &[u32; PACKET],
    guide: &[u32; PACKET],
    u: &[f32; PACKET],
) -> [u32; PACKET] {
    let mut base = [0u32; PACKET];
    let mut size = [0u32; PACKET];
    for l in 0..PACKET {
        let k = guide[l] + guide_bucket(u[l], n);
        let (lo, hi) = (guides.at(k), guides.at(k + 1));
        (base[l], size[l]) = (u32::from(lo), u32::from(hi.saturating_sub(lo)) + 1);
    }
    loop {
        let mut wider = false;
        for l in 0..PACKET {
            let half = size[l] / 2;
            // (A lane whose window is one entry reads its entry and moves by 0.)
            let value = d.at(start[l] + base[l] + half.max(1) - 1);
            base[l] += half * u32::from(value <= u[l]);
            size[l] -= half;
            wider |= size[l] > 1;
        }
        if !wider {
            return base;
        }
    }
}

/// What the map shows the rays of a packet that escape: per lane, the radiance seen and the
/// density of sampling the direction from the map, the environment's choice included
/// ([`crate::environment::env_escape`]'s values with `mis`).
#[derive(Debug, Clone)]
pub struct MapEscapes {
    radiance: [[f32; PACKET]; 3],
    pdf: [f32; PACKET],
}

impl Default for MapEscapes {
    fn default() -> Self {
        Self {
            radiance: [[0.0; PACKET]; 3],
            pdf: [0.0; PACKET],
        }
    }
}

impl MapEscapes {
    /// Computes every lane's escape along `dir(l)` when a lane of `lanes` escapes (the other
    /// lanes' values are thrown away).
    #[inline(always)]
    pub fn compute(
        &mut self,
        scene: &CpuScene,
        params: &GpuRenderParams,
        lanes: Lanes,
        dir: impl Fn(usize) -> [f32; 3],
    ) {
        if lanes == 0 {
            return;
        }
        // The directions, everything the lanes read and what they write, in locals: the
        // compiler cannot tell that stores to `self` leave `scene` and `params` be, or that
        // `dir` reads nothing the lanes write, and computes one lane at a time unless it can.
        let mut dirs = [[0.0f32; PACKET]; 3];
        for (l, [x, y, z]) in (0..PACKET).map(dir).enumerate() {
            (dirs[0][l], dirs[1][l], dirs[2][l]) = (x, y, z);
        }
        let params = *params;
        let (d, texels) = (scene.env_distribution, scene.env_texels);
        let mut pdf = [0.0f32; PACKET];
        let mut radiance = [[0.0f32; PACKET]; 3];
        for l in 0..PACKET {
            let dir = [dirs[0][l], dirs[1][l], dirs[2][l]];
            let c = map_cell(&params, map_uv(to_map(&params, dir)));
            pdf[l] = params.env_pmf * cell_pdf(d, &params, &c);
            [radiance[0][l], radiance[1][l], radiance[2][l]] = cell_color(texels, &params, &c);
        }
        (self.pdf, self.radiance) = (pdf, radiance);
    }

    /// Lane `l`'s radiance and density, once [`MapEscapes::compute`] ran with it.
    #[inline(always)]
    pub fn get(&self, l: usize) -> (Vec3A, f32) {
        let radiance = Vec3A::new(
            self.radiance[0][l],
            self.radiance[1][l],
            self.radiance[2][l],
        );
        (radiance, self.pdf[l])
    }
}

#[cfg(test)]
mod tests {
    use pathlight_core::PreparedScene;

    use super::*;
    use crate::environment::tests::{map_scene, uniform};
    use crate::environment::{env_escape, sample_env_map};

    /// A `w` x `h` map of random radiance with a few bright texels, turned by 30 degrees,
    /// chosen for 0.625 of the light samples.
    fn random_map(w: u32, h: u32, seed: u32) -> (PreparedScene, GpuRenderParams) {
        let mut next = uniform(seed);
        let texels = (0..w * h)
            .map(|_| {
                let v = if next() < 0.01 { 1000.0 } else { next() };
                [v, v * next(), v * 0.5]
            })
            .collect();
        let (prepared, mut params) = map_scene(w, h, texels, 1.5, 30.0);
        // The environment's share of light samples as beside other lights.
        params.env_pmf = 0.625;
        (prepared, params)
    }

    #[test]
    fn escapes_see_what_each_lane_sees_alone() {
        for (w, h, seed) in [(64, 33, 7), (300, 150, 11), (5, 3, 13)] {
            let (prepared, params) = random_map(w, h, seed);
            let scene = CpuScene::new(&prepared);
            let mut next = uniform(0x85eb_ca6b ^ seed);
            let mut escapes = MapEscapes::default();
            for _ in 0..200 {
                let mut dirs = [Vec3A::ZERO; PACKET];
                for d in &mut dirs {
                    let v = Vec3A::new(next(), next(), next()) * 2.0 - 1.0;
                    *d = v.normalize_or(Vec3A::Y);
                }
                // Straight up and down, and on the map's seam (map frame -z, where u wraps
                // from 1 to 0) and either side of it.
                let [c, s] = params.env_rotation;
                let seam = Vec3A::new(-s, 0.0, -c);
                let across = Vec3A::new(c, 0.0, -s) * 1e-4;
                dirs[..5].copy_from_slice(&[
                    Vec3A::Y,
                    -Vec3A::Y,
                    seam,
                    (seam + across).normalize(),
                    (seam - across).normalize(),
                ]);
                escapes.compute(&scene, &params, Lanes::MAX, |l| dirs[l].to_array());
                for (l, dir) in dirs.iter().enumerate() {
                    let (radiance, pdf) = escapes.get(l);
                    let (alone, alone_pdf) = env_escape(&scene, &params, Vec3A::Y, *dir, true);
                    assert_eq!(
                        (bits(radiance), pdf.to_bits()),
                        (bits(alone), alone_pdf.to_bits()),
                        "{w}x{h}, lane {l}, direction {dir}"
                    );
                }
            }
        }
    }

    fn bits(v: Vec3A) -> [u32; 3] {
        v.to_array().map(f32::to_bits)
    }

    #[test]
    fn lanes_sample_what_each_lane_samples_alone() {
        for (w, h, seed) in [(64, 33, 7), (300, 150, 11), (5, 3, 13)] {
            let (prepared, params) = random_map(w, h, seed);
            let scene = CpuScene::new(&prepared);
            let mut next = uniform(0x9e37_79b9 ^ seed);
            for round in 0..200 {
                let mut u = [Vec2::ZERO; PACKET];
                for v in &mut u {
                    *v = Vec2::new(next(), next());
                }
                // The ends of [0, 1) too.
                u[0] = Vec2::new(0.0, 1.0f32.next_down());
                u[1] = Vec2::new(1.0f32.next_down(), 0.0);
                let lanes = if round % 2 == 0 {
                    Lanes::MAX
                } else {
                    (next() * Lanes::MAX as f32) as Lanes
                };
                let mut given = 0;
                sample_env_maps(&scene, &params, lanes, &u, |l, got| {
                    given |= 1 << l;
                    let (wi, pdf, cell) = sample_env_map(&scene, &params, u[l]);
                    assert_eq!(
                        (bits(got.wi), got.pdf.to_bits(), got.map_cell),
                        (bits(wi), (params.env_pmf * pdf).to_bits(), Some(cell)),
                        "{w}x{h}, lane {l}, u {}",
                        u[l]
                    );
                });
                assert_eq!(given, lanes);
            }
        }
    }
}
