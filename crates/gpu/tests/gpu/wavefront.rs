//! The wavefront kernels against the megakernel: the same sums bit for bit (radiance and
//! auxiliary images), the same ray and dropped-sample counts, whatever the scene's features,
//! the path length, and however the work is cut into bands of rows, batches of samples and
//! overlapped frames; and the `auto` kernel, which renders its first passes with both.

use pathlight_core::{Accumulation, Renderer};
use pathlight_gpu::{GpuRenderer, Kernel};
use pathlight_scene::Scene;

use crate::common::{gpu_renderer, repo, scene};

/// What a render leaves: the exact sums, the rays traced and samples dropped, and the
/// renderer's report of its kernel.
struct Outcome {
    accumulation: Accumulation,
    rays: u64,
    dropped: u64,
    kernel: String,
}

/// Renders `scene` to `spp` with `kernel`, `rows` rows and `samples` samples per dispatch.
fn render(scene: &Scene, kernel: Kernel, spp: u32, rows: u32, samples: u32) -> Outcome {
    let mut renderer = gpu_renderer(scene);
    renderer.set_kernel(kernel).unwrap();
    renderer.set_piece(rows, samples);
    while renderer.samples_done() < spp {
        renderer.advance(spp - renderer.samples_done()).unwrap();
    }
    outcome(&renderer)
}

/// Renders `frames` frames of `scene` with `kernel` as `pathlight bench` does (queued
/// together, which the wavefront overlaps), after `band` rows of a first pass when not 0.
fn render_frames(scene: &Scene, kernel: Kernel, frames: u32, band: u32) -> Outcome {
    let mut renderer = gpu_renderer(scene);
    renderer.set_kernel(kernel).unwrap();
    if band > 0 {
        renderer.set_piece(band, 1);
        assert_eq!(renderer.advance(1).unwrap(), 0, "a band, not a pass");
    }
    renderer.queue_frames(frames).unwrap();
    renderer.finish().unwrap();
    outcome(&renderer)
}

/// What `renderer` has rendered.
fn outcome(renderer: &GpuRenderer) -> Outcome {
    Outcome {
        accumulation: renderer.accumulation().unwrap(),
        rays: renderer.rays_traced().unwrap(),
        dropped: renderer.samples_dropped().unwrap(),
        kernel: renderer.kernel().unwrap(),
    }
}

/// Renders `scene` with the megakernel and the wavefront and asserts the outcomes are the
/// same.
fn assert_same(label: &str, scene: &Scene, spp: u32, rows: u32, samples: u32) {
    let wave = render(scene, Kernel::Wavefront, spp, rows, samples);
    assert_same_as_megakernel(label, scene, spp, rows, samples, &wave);
}

/// Renders `scene` with the megakernel and asserts the outcome is `wave`'s.
fn assert_same_as_megakernel(
    label: &str,
    scene: &Scene,
    spp: u32,
    rows: u32,
    samples: u32,
    wave: &Outcome,
) {
    let mega = render(scene, Kernel::Megakernel, spp, rows, samples);
    assert!(mega.rays > 0, "{label}: no rays traced");
    assert_eq!(mega.rays, wave.rays, "{label}: rays traced");
    assert_eq!(mega.dropped, wave.dropped, "{label}: samples dropped");
    assert_eq!(
        mega.accumulation.cursor, wave.accumulation.cursor,
        "{label}: samples held"
    );
    let differ = mega
        .accumulation
        .sums
        .iter()
        .zip(&wave.accumulation.sums)
        .filter(|(a, b)| a != b)
        .count();
    assert_eq!(differ, 0, "{label}: {differ} pixels' sums differ");
    assert!(
        mega.accumulation.aovs == wave.accumulation.aovs,
        "{label}: auxiliary images differ"
    );
}

/// The default scene (a texture, glass, metal) at an odd size, with auxiliary images.
fn default_scene() -> Scene {
    let mut default =
        pathlight_scene::load_scene_file(&repo().join("scenes/default.toml")).unwrap();
    default.camera.width = 37;
    default.camera.height = 23;
    default.settings.aovs = true;
    default
}

/// cornell-materials at 20x20 with camera rays only (max_depth 1).
fn camera_rays_only() -> Scene {
    let mut direct = scene("refs/cornell-materials.toml", 20, 2, 3);
    direct.settings.max_depth = 1;
    direct
}

/// cornell-diffuse at 16x16 whose emitters' red is NaN: every sample that sees one is dropped.
fn nan_emission() -> Scene {
    let mut s = scene("refs/cornell-diffuse.toml", 16, 2, 1);
    for m in &mut s.materials {
        if m.emission.max_element() > 0.0 {
            m.emission.x = f32::NAN;
        }
    }
    s
}

#[test]
fn wavefront_matches_the_megakernel_bit_for_bit() {
    // The default scene with auxiliary images, in bands of 5 rows, then in batches of 3
    // samples over the whole image.
    let default = default_scene();
    assert_same("default scene, bands", &default, 2, 5, 1);
    assert_same("default scene, batches", &default, 6, 23, 3);
    // Instances; glTF's metal-rough layers; an environment map and the sun; many lights.
    for name in [
        "instances.toml",
        "layers.toml",
        "refs/env-sun.toml",
        "refs/lights.toml",
    ] {
        assert_same(name, &scene(name, 24, 2, 7), 2, 24, 2);
    }
    // Camera rays only; long paths (64 segments, no roulette) in glass.
    assert_same("max_depth 1", &camera_rays_only(), 2, 20, 2);
    assert_same(
        "glass furnace, 64 segments",
        &scene("refs/furnace-glass.toml", 16, 2, 5),
        2,
        16,
        2,
    );
}

#[test]
fn overlapped_frames_match_the_megakernel_bit_for_bit() {
    // Frames queued together start every few segments in layers of the path state of their
    // own (3 layers, a frame every 3 segments at max_depth 8); the default scene with
    // auxiliary images, from the start and after a band of a first pass.
    let default = default_scene();
    for band in [0, 5] {
        let frames = render_frames(&default, Kernel::Wavefront, 7, band);
        let label = format!("default scene, 7 frames after {band} rows");
        assert_same_as_megakernel(&label, &default, 7, 23, 1, &frames);
    }
    // A frame every segment (max_depth 1, 2 layers); 4 layers of 64 segments of glass, a
    // frame every 17; the environment map and the sun; samples dropped as NaN.
    for (label, s, n) in [
        ("max_depth 1", camera_rays_only(), 5),
        (
            "glass furnace",
            scene("refs/furnace-glass.toml", 16, 2, 5),
            6,
        ),
        ("env-sun", scene("refs/env-sun.toml", 24, 2, 7), 5),
        ("NaN emission", nan_emission(), 5),
    ] {
        let frames = render_frames(&s, Kernel::Wavefront, n, 0);
        let height = s.camera.height;
        assert_same_as_megakernel(label, &s, n, height, 1, &frames);
    }
}

#[test]
fn wavefront_cuts_a_large_image_into_waves() {
    // 1,000,000 paths: more than lavapipe's 128 MiB bindings hold of path state (838,860
    // paths), so the image is rendered in two waves of rows.
    let mut large = scene("refs/cornell-diffuse.toml", 1000, 1, 9);
    large.settings.max_depth = 2;
    assert_same("1000x1000 in waves", &large, 1, 1000, 1);
}

#[test]
fn wavefront_counts_the_samples_it_drops() {
    let s = nan_emission();
    let wave = render(&s, Kernel::Wavefront, 2, 16, 2);
    assert!(wave.dropped > 10, "{} of 512 samples counted", wave.dropped);
    assert_same("NaN emission", &s, 2, 16, 2);
}

#[test]
fn auto_renders_its_first_passes_with_both_kernels_then_keeps_one() {
    // 330 samples: the trial takes at most 321 passes (a step of one, then five of up to 64).
    let spp = 330;
    let s = scene("refs/cornell-spheres.toml", 16, spp, 4);
    // Bands of 8 rows (a pass short enough to time whole), then batches of 3 samples.
    for (rows, samples) in [(8, 1), (16, 3)] {
        let label = format!("auto, {rows} rows, {samples} samples");
        let auto = render(&s, Kernel::Auto, spp, rows, samples);
        assert!(
            ["megakernel (auto: ", "wavefront (auto: "]
                .iter()
                .any(|k| auto.kernel.starts_with(k)),
            "{label}: {}",
            auto.kernel
        );
        assert_same_as_megakernel(&label, &s, spp, rows, samples, &auto);
    }
    // Three samples: the trial's second step, the wavefront's first, is cut to two passes
    // and the trial goes on.
    let early = render(&s, Kernel::Auto, 3, 16, 1);
    assert!(
        early.kernel.starts_with("auto (not chosen yet"),
        "{}",
        early.kernel
    );
}
