//! Furnace rings: a sphere of every BSDF configuration (Lambert, smooth and rough conductors,
//! smooth and rough glass at three roughness values, the seed's presets in white) under a
//! constant environment of radiance 1, checked on both backends in three rings of the
//! sphere (centre, middle, rim) against Mitsuba 3.9.1 (the scenes `furnace-<name>.toml` in
//! `scenes/refs/`, their images in `scenes/refs/images/`). Whole-image means hid a +1.7% rim on rough glass.

use pathlight_core::Film;

use crate::common::{render, render_cpu, repo, scene};

/// Image side of the renders and the references.
const SIZE: u32 = 64;
/// Samples per pixel of each of the two renders per configuration.
const SPP: u32 = 256;
/// Allowed relative difference of a ring's mean from the reference, beyond the noise.
const TOLERANCE: f64 = 0.002;
/// Standard errors of noise allowed on top of [`TOLERANCE`].
const SIGMAS: f64 = 4.0;

/// The configurations, by scene name.
const CONFIGS: [&str; 13] = [
    "wall",
    "glass",
    "aluminium",
    "aluminium-rough-0.3",
    "aluminium-rough-0.6",
    "gold",
    "glass-rough-0.1",
    "glass-rough-0.316",
    "glass-rough-0.55",
    "metal",
    "plastic",
    "wood",
    "ceramic",
];

/// A ring of the sphere's image: radii as fractions of the silhouette's.
struct Ring {
    name: &'static str,
    inner: f32,
    outer: f32,
}

const RINGS: [Ring; 3] = [
    Ring {
        name: "centre",
        inner: 0.0,
        outer: 0.35,
    },
    Ring {
        name: "middle",
        inner: 0.45,
        outer: 0.7,
    },
    Ring {
        name: "rim",
        inner: 0.8,
        outer: 0.93,
    },
];

/// The pixels of `ring` (the furnace camera: distance 3.4, 40 degree fov, radius 0.8).
fn ring_pixels(ring: &Ring) -> Vec<(u32, u32)> {
    let tan_half = 20.0f32.to_radians().tan();
    let silhouette = (0.8f32 / 3.4).asin().tan() / tan_half * SIZE as f32 / 2.0;
    let mut pixels = Vec::new();
    for y in 0..SIZE {
        for x in 0..SIZE {
            let dx = x as f32 + 0.5 - SIZE as f32 / 2.0;
            let dy = y as f32 + 0.5 - SIZE as f32 / 2.0;
            let r = (dx * dx + dy * dy).sqrt() / silhouette;
            if r >= ring.inner && r < ring.outer {
                pixels.push((x, y));
            }
        }
    }
    pixels
}

/// Mean of `film` over `pixels` and channels.
fn mean(film: &Film, pixels: &[(u32, u32)]) -> f64 {
    let sum: f64 = pixels
        .iter()
        .flat_map(|&(x, y)| film.pixel(x, y))
        .map(f64::from)
        .sum();
    sum / (3 * pixels.len()) as f64
}

/// Standard error of the mean of two independent renders `a` and `b` over `pixels`, from
/// their per-pixel differences (each pixel's variance is about (a - b)^2 / 2).
fn standard_error(a: &Film, b: &Film, pixels: &[(u32, u32)]) -> f64 {
    let squares: f64 = pixels
        .iter()
        .flat_map(|&(x, y)| {
            let (pa, pb) = (a.pixel(x, y), b.pixel(x, y));
            (0..3).map(move |c| (f64::from(pa[c]) - f64::from(pb[c])).powi(2) / 2.0)
        })
        .sum();
    let n = (3 * pixels.len()) as f64;
    // Variance of one render's ring mean, halved for the mean of the two renders.
    (squares / (n * n) / 2.0).sqrt()
}

/// Checks every ring of every configuration with `render_with` (one backend).
fn check_rings(backend: &str, render_with: impl Fn(&pathlight_scene::Scene) -> Film) {
    let mut failures = Vec::new();
    for name in CONFIGS {
        let file = format!("refs/furnace-{name}.toml");
        let reference =
            Film::read_exr(&repo().join(format!("scenes/refs/images/furnace-{name}.exr"))).unwrap();
        assert_eq!((reference.width, reference.height), (SIZE, SIZE));
        let a = render_with(&scene(&file, SIZE, SPP, 1));
        let b = render_with(&scene(&file, SIZE, SPP, 2));
        for ring in &RINGS {
            let pixels = ring_pixels(ring);
            let ours = (mean(&a, &pixels) + mean(&b, &pixels)) / 2.0;
            let expected = mean(&reference, &pixels);
            // The reference has 64 times our samples per pixel: its error is an eighth of ours.
            let sigma = standard_error(&a, &b, &pixels) * (1.0 + 1.0 / 64.0f64).sqrt();
            let allowed = TOLERANCE * expected + SIGMAS * sigma;
            let line = format!(
                "{backend} {name} {}: {ours:.5} against Mitsuba {expected:.5} ({:+.3}%, \
                 allowed {:.3}%, noise {:.3}%)",
                ring.name,
                100.0 * (ours / expected - 1.0),
                100.0 * allowed / expected,
                100.0 * sigma / expected
            );
            eprintln!("{line}");
            if (ours - expected).abs() > allowed || sigma > 0.5 * TOLERANCE * expected {
                failures.push(line);
            }
        }
    }
    assert!(
        failures.is_empty(),
        "rings off (or too noisy to tell):\n{}",
        failures.join("\n")
    );
}

#[test]
fn furnace_rings_match_mitsuba_on_the_gpu() {
    check_rings("gpu", render);
}

#[test]
fn furnace_rings_match_mitsuba_on_the_cpu() {
    check_rings("cpu", render_cpu);
}
