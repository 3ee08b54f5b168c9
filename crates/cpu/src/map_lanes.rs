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
use crate::slots::{Slots, in_groups};
use crate::table::Table;

/// The map's light samples of the lanes in `lanes`, at `u[l]` for lane `l`, given to
/// `take(l, sample)` in lane order. The lanes' numbers are packed in slots first, so that
/// the searches work on as many groups of [`GROUP`](crate::slots::GROUP) slots as there
/// are lanes (env-sun's packets hold 19 a pass on average), not on the whole packet.
#[inline(always)]
pub fn sample_env_maps(
    scene: &CpuScene,
    params: &GpuRenderParams,
    lanes: Lanes,
    u: &[Vec2; PACKET],
    mut take: impl FnMut(usize, LightSample),
) {
    let mut u0 = [0.0f32; PACKET];
    let mut u1 = [0.0f32; PACKET];
    let slots = Slots::packed(lanes, |l, k| {
        (u0[k], u1[k]) = (u[l].x.min(MAX_U), u[l].y.min(MAX_U));
    });
    let mut s = SlotSamples::default();
    in_groups!(slots.count(), N => s.compute::<N>(scene, params, &u0, &u1));
    for k in 0..slots.count() {
        prefetch_cell(scene, params, s.row[k], s.column[k]);
        let cell = MapCell::new(s.column[k], s.row[k], [s.f[0][k], s.f[1][k]]);
        let dir = Vec3A::new(s.wi[0][k], s.wi[1][k], s.wi[2][k]);
        take(slots.lane(k), map_light_sample(params, dir, s.pdf[k], cell));
    }
}

/// Map samples per slot, as [`SlotSamples::compute`] computes them side by side: the cell's
/// row and column, the direction, its density and the position in the cell.
#[derive(Debug, Clone, Default)]
struct SlotSamples {
    row: [u32; PACKET],
    column: [u32; PACKET],
    wi: [[f32; PACKET]; 3],
    pdf: [f32; PACKET],
    f: [[f32; PACKET]; 2],
}

impl SlotSamples {
    /// The samples of the first `N` slots, a count the loops know: slot `k` at (`u0[k]`,
    /// `u1[k]`).
    #[inline(always)]
    fn compute<const N: usize>(
        &mut self,
        scene: &CpuScene,
        params: &GpuRenderParams,
        u0: &[f32; PACKET],
        u1: &[f32; PACKET],
    ) {
        let (d, guides) = (scene.env_distribution, scene.env_guides);
        let w = params.env_width;
        let rows = params.env_height - 1;
        let u0: [f32; N] = std::array::from_fn(|k| u0[k]);
        let u1: [f32; N] = std::array::from_fn(|k| u1[k]);
        let row = cdf_search_lanes(d, guides, rows, &[0; N], &[0; N], &u0);
        let mut start = [0u32; N];
        let mut guide = [0u32; N];
        for k in 0..N {
            start[k] = rows + params.env_height + row[k] * w;
            guide[k] = rows + 1 + row[k] * (w + 1);
        }
        let column = cdf_search_lanes(d, guides, w, &start, &guide, &u1);
        // Computed in locals, side by side, then stored.
        let mut wi = [[0.0f32; N]; 3];
        let mut pdf = [0.0f32; N];
        let mut f = [[0.0f32; N]; 2];
        for k in 0..N {
            let s = map_sample(d, params, [u0[k], u1[k]], row[k], column[k]);
            (wi[0][k], wi[1][k], wi[2][k]) = (s.wi[0], s.wi[1], s.wi[2]);
            pdf[k] = s.pdf;
            (f[0][k], f[1][k]) = (s.f[0], s.f[1]);
        }
        self.row[..N].copy_from_slice(&row);
        self.column[..N].copy_from_slice(&column);
        self.pdf[..N].copy_from_slice(&pdf);
        for (to, from) in self.wi.iter_mut().zip(&wi) {
            to[..N].copy_from_slice(from);
        }
        for (to, from) in self.f.iter_mut().zip(&f) {
            to[..N].copy_from_slice(from);
        }
    }
}

/// `environment::cdf_search` for each of `N` lanes: the first entry of the `n`-entry CDF at
/// `start[l]` of `d` exceeding `u[l]` (the last when none does), searched from its guide
/// table at `guide[l]` of `guides` with `first_above`'s halving steps (the same entries, so
/// the same result), each step taken for every lane at once until every lane's window is one
/// entry.
#[inline(always)]
fn cdf_search_lanes<const N: usize>(
    d: Table<'_, f32>,
    guides: Table<'_, u16>,
    n: u32,
    start: &[u32; N],
    guide: &[u32; N],
    u: &[f32; N],
) -> [u32; N] {
    let mut base = [0u32; N];
    let mut size = [0u32; N];
    for l in 0..N {
        let k = guide[l] + guide_bucket(u[l], n);
        let (lo, hi) = (guides.at(k), guides.at(k + 1));
        (base[l], size[l]) = (u32::from(lo), u32::from(hi.saturating_sub(lo)) + 1);
    }
    loop {
        let mut wider = false;
        for l in 0..N {
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
    /// Per slot (the escaping lanes packed in lane order), the radiance and the density.
    radiance: [[f32; PACKET]; 3],
    pdf: [f32; PACKET],
    /// The escaping lanes' slots.
    slots: Slots,
}

impl Default for MapEscapes {
    fn default() -> Self {
        Self {
            radiance: [[0.0; PACKET]; 3],
            pdf: [0.0; PACKET],
            slots: Slots::default(),
        }
    }
}

impl MapEscapes {
    /// Computes the escapes of the lanes in `lanes` along `dir(l)`, side by side, in as
    /// many groups of [`GROUP`](crate::slots::GROUP) as they fill (env-sun's packets have 15
    /// escaping a pass on average).
    #[inline(always)]
    pub fn compute(
        &mut self,
        scene: &CpuScene,
        params: &GpuRenderParams,
        lanes: Lanes,
        dir: impl Fn(usize) -> [f32; 3],
    ) {
        // The directions, everything the lanes read and what they write, in locals: the
        // compiler cannot tell that stores to `self` leave `scene` and `params` be, or that
        // `dir` reads nothing the lanes write, and computes one lane at a time unless it can.
        let mut dirs = [[0.0f32; PACKET]; 3];
        self.slots = Slots::packed(lanes, |l, k| {
            [dirs[0][k], dirs[1][k], dirs[2][k]] = dir(l);
        });
        in_groups!(self.slots.count(), N => self.compute_slots::<N>(scene, params, &dirs));
    }

    /// [`MapEscapes::compute`] of the first `N` slots, slot `k` along direction
    /// (`dirs[0][k]`, `dirs[1][k]`, `dirs[2][k]`), a count the loop knows.
    #[inline(always)]
    fn compute_slots<const N: usize>(
        &mut self,
        scene: &CpuScene,
        params: &GpuRenderParams,
        dirs: &[[f32; PACKET]; 3],
    ) {
        let params = *params;
        let (d, texels) = (scene.env_distribution, scene.env_texels);
        let mut pdf = [0.0f32; N];
        let mut radiance = [[0.0f32; N]; 3];
        for k in 0..N {
            let dir = [dirs[0][k], dirs[1][k], dirs[2][k]];
            let c = map_cell(&params, map_uv(to_map(&params, dir)));
            pdf[k] = params.env_pmf * cell_pdf(d, &params, &c);
            [radiance[0][k], radiance[1][k], radiance[2][k]] = cell_color(texels, &params, &c);
        }
        self.pdf[..N].copy_from_slice(&pdf);
        for (to, from) in self.radiance.iter_mut().zip(&radiance) {
            to[..N].copy_from_slice(from);
        }
    }

    /// Lane `l`'s radiance and density, once [`MapEscapes::compute`] ran with it.
    #[inline(always)]
    pub fn get(&self, l: usize) -> (Vec3A, f32) {
        let k = self.slots.slot(l);
        let radiance = Vec3A::new(
            self.radiance[0][k],
            self.radiance[1][k],
            self.radiance[2][k],
        );
        (radiance, self.pdf[k])
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
            for round in 0..200 {
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
                let lanes = some_lanes(&mut next, round);
                escapes.compute(&scene, &params, lanes, |l| dirs[l].to_array());
                for (l, dir) in dirs.iter().enumerate().filter(|(l, _)| lanes >> l & 1 != 0) {
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

    /// Lanes for round `round`: every lane in every fifth, otherwise `round % 32 + 1` lanes
    /// at random places, so that every count of slots (each group of eight full, part full
    /// or empty) is computed.
    fn some_lanes(next: &mut impl FnMut() -> f32, round: usize) -> Lanes {
        if round.is_multiple_of(5) {
            return Lanes::MAX;
        }
        let mut lanes: Lanes = 0;
        while (lanes.count_ones() as usize) < round % PACKET + 1 {
            lanes |= 1 << ((next() * PACKET as f32) as usize).min(PACKET - 1);
        }
        lanes
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
                let lanes = some_lanes(&mut next, round);
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
