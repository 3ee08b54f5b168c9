//! Shared helpers of the GPU tests: one device per test binary, scene loading, rendering.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use pathlight_core::{GpuScene, Scene, load_scene_file};
use pathlight_render::{Film, GpuContext, ProgressiveRenderer};

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

/// Renders `scene` to its full spp.
pub fn render(scene: &Scene) -> Film {
    let gpu_scene = GpuScene::build(scene);
    let mut renderer = ProgressiveRenderer::new(context(), scene, &gpu_scene).unwrap();
    while renderer.samples_done() < scene.settings.spp {
        renderer
            .advance(scene.settings.spp - renderer.samples_done())
            .unwrap();
    }
    renderer.read_film().unwrap()
}
