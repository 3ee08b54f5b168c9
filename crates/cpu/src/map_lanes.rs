//! The environment map's light samples of a packet's lanes, computed side by side: the same
//! samples as [`crate::environment::sample_environment`], bit for bit, each step of their
//! searches one vector operation over the lanes. A sample is a chain of dependent loads
//! (the row's guide entry and CDF entries, then the column's from megabytes of tables) and
//! polynomials; taken one lane after another, the core waited on each step of each chain in
//! turn (`perf`: a quarter of env-sun's time), where side by side the lanes' loads are
//! gathered at once.

use glam::{Vec2, Vec3A};
use pathlight_core::environment::guide_bucket;
use pathlight_core::gpu_types::GpuRenderParams;

use crate::cpu_scene::CpuScene;
use crate::environment::{MAX_U, MapCell, Table, map_light_sample, map_sample, prefetch_cell};
use crate::light_sample::LightSample;
use crate::packet::{Lanes, PACKET};

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
    let (Some(d), Some(guides)) = (
        Table::new(scene.env_distribution),
        Table::new(scene.env_guides),
    ) else {
        return;
    };
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

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use pathlight_core::PreparedScene;
    use pathlight_scene::testing::scene_of;
    use pathlight_scene::{Environment, EnvironmentMap, HdrImage};

    use super::*;
    use crate::environment::sample_env_map;

    /// A `w` x `h` map of random radiance with a few bright texels, turned by 30 degrees.
    fn random_map(w: u32, h: u32, seed: u32) -> (PreparedScene, GpuRenderParams) {
        let mut rng = seed | 1;
        let mut next = move || {
            rng ^= rng << 13;
            rng ^= rng >> 17;
            rng ^= rng << 5;
            (rng >> 8) as f32 / (1u32 << 24) as f32
        };
        let texels = (0..w * h)
            .map(|_| {
                let v = if next() < 0.01 { 1000.0 } else { next() };
                [v, v * next(), v * 0.5]
            })
            .collect();
        let mut scene = scene_of(Vec::new());
        scene.environment = Environment::Map(EnvironmentMap {
            image: Arc::new(HdrImage {
                width: w,
                height: h,
                texels,
                max: 1000.0,
            }),
            strength: 1.5,
            rotation_deg: 30.0,
        });
        let prepared = PreparedScene::new(&scene).unwrap();
        let params = GpuRenderParams::new(&scene.camera, &scene.settings, &prepared.shading);
        (prepared, params)
    }

    fn bits(v: Vec3A) -> [u32; 3] {
        v.to_array().map(f32::to_bits)
    }

    #[test]
    fn lanes_sample_what_each_lane_samples_alone() {
        for (w, h, seed) in [(64, 33, 7), (300, 150, 11), (5, 3, 13)] {
            let (prepared, params) = random_map(w, h, seed);
            let scene = CpuScene::new(&prepared);
            let mut rng = 0x9e37_79b9_u32 ^ seed;
            let mut next = move || {
                rng ^= rng << 13;
                rng ^= rng >> 17;
                rng ^= rng << 5;
                (rng >> 8) as f32 / (1u32 << 24) as f32
            };
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
