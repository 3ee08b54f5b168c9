//! A long render's resident memory stays flat on both backends: many submissions after a
//! warm-up must not grow the process. Its own test binary, so no other test allocates beside it.
//! (Before the render parameters left the uniform buffer, lavapipe grew 2.6 MB a submission.)

#![cfg(target_os = "linux")]

use pathlight_core::{PreparedScene, Renderer};
use pathlight_cpu::CpuRenderer;
use pathlight_gpu::{Accel, GpuContext, GpuRenderer};
use pathlight_scene::Scene;

/// Submissions measured after the warm-up.
const SUBMISSIONS: u32 = 200;
/// Growth allowed over all of them: allocator and driver pools settling, far below the
/// 500 MB the leak made.
const ALLOWED_GROWTH: u64 = 8 << 20;

/// The process's resident set in bytes.
fn resident_bytes() -> u64 {
    let statm = std::fs::read_to_string("/proc/self/statm").unwrap();
    let pages: u64 = statm.split_whitespace().nth(1).unwrap().parse().unwrap();
    pages * 4096
}

/// The default scene at 8x8.
fn tiny_scene() -> Scene {
    let mut scene = pathlight_scene::default_scene::load().unwrap();
    scene.camera.width = 8;
    scene.camera.height = 8;
    scene
}

/// Advances `renderer` one sample per pixel `SUBMISSIONS` times after a warm-up; returns how
/// much the process grew.
fn growth_over_submissions(renderer: &mut dyn Renderer) -> u64 {
    for _ in 0..20 {
        renderer.advance(1).unwrap();
    }
    let before = resident_bytes();
    for _ in 0..SUBMISSIONS {
        renderer.advance(1).unwrap();
    }
    renderer.film().unwrap();
    resident_bytes().saturating_sub(before)
}

#[test]
fn many_submissions_do_not_grow_the_process() {
    let scene = tiny_scene();
    let prepared = PreparedScene::new(&scene).unwrap();

    let ctx = GpuContext::new(None).expect("a wgpu adapter (install mesa-vulkan-drivers)");
    let mut gpu =
        GpuRenderer::new(&ctx, &prepared, &scene.camera, &scene.settings, Accel::Bvh).unwrap();
    gpu.set_piece(scene.camera.height, 1);
    let gpu_growth = growth_over_submissions(&mut gpu);

    let mut cpu = CpuRenderer::new(&prepared, &scene.camera, &scene.settings);
    let cpu_growth = growth_over_submissions(&mut cpu);

    assert!(
        gpu_growth < ALLOWED_GROWTH && cpu_growth < ALLOWED_GROWTH,
        "{SUBMISSIONS} submissions grew the process by {gpu_growth} bytes on the GPU backend \
         and {cpu_growth} on the CPU backend (allowed {ALLOWED_GROWTH})"
    );
}
