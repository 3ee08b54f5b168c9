//! Shared helpers of the GPU tests: one device per test binary, scene loading, rendering.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use pathlight_core::{Film, PreparedScene, Renderer};
use pathlight_gpu::{Accel, GpuContext, GpuRenderer};
use pathlight_scene::{Scene, load_scene_file};

/// The device every test of this binary shares (the software adapter on CI).
pub fn context() -> &'static GpuContext {
    static CONTEXT: OnceLock<GpuContext> = OnceLock::new();
    CONTEXT.get_or_init(|| {
        GpuContext::new(None).expect("a wgpu adapter (install mesa-vulkan-drivers)")
    })
}

/// The repository root.
pub fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Loads `scenes/<relative>` at the given size, spp and seed.
pub fn scene(relative: &str, size: u32, spp: u32, seed: u32) -> Scene {
    let mut scene = load_scene_file(&repo().join("scenes").join(relative)).unwrap();
    scene.camera.width = size;
    scene.camera.height = size;
    scene.settings.spp = spp;
    scene.settings.seed = seed;
    scene
}

/// A GPU renderer of `scene` (prepared here) finding hits with the BVH.
pub fn gpu_renderer(scene: &Scene) -> GpuRenderer {
    let prepared = PreparedScene::new(scene).unwrap();
    GpuRenderer::new(
        context(),
        &prepared,
        &scene.camera,
        &scene.settings,
        Accel::Bvh,
    )
    .unwrap()
}

/// Renders with `renderer` to `spp` samples per pixel; every sample must have been finite.
pub fn render_to(renderer: &mut dyn Renderer, spp: u32) -> Film {
    let (film, dropped) = render_counting_dropped(renderer, spp);
    assert_eq!(dropped, 0, "{dropped} samples were not finite");
    film
}

/// Renders with `renderer` to `spp` samples per pixel; returns the image and the number of
/// samples dropped as not finite.
pub fn render_counting_dropped(renderer: &mut dyn Renderer, spp: u32) -> (Film, u64) {
    while renderer.samples_done() < spp {
        renderer.advance(spp - renderer.samples_done()).unwrap();
    }
    let dropped = renderer.samples_dropped().unwrap();
    (renderer.film().unwrap(), dropped)
}

/// Renders `scene` to its full spp on the GPU.
pub fn render(scene: &Scene) -> Film {
    render_to(&mut gpu_renderer(scene), scene.settings.spp)
}

/// Renders `scene` to its full spp on the CPU backend.
pub fn render_cpu(scene: &Scene) -> Film {
    let prepared = PreparedScene::new(scene).unwrap();
    let mut renderer = pathlight_cpu::CpuRenderer::new(&prepared, &scene.camera, &scene.settings);
    render_to(&mut renderer, scene.settings.spp)
}
