//! The integrator's per-render constants, shared by the GPU and CPU backends.

use crate::accel::GpuScene;
use crate::gpu::GpuFrameParams;
use crate::scene::Scene;

/// Probability of sampling the environment when shape lights exist too.
const ENV_SHARE: f32 = 0.5;

/// Camera vectors (eye, forward, right and up scaled to the image plane), settings, and the
/// light-selection split between the environment and the shape lights.
pub fn frame_params(scene: &Scene, gpu_scene: &GpuScene) -> GpuFrameParams {
    let c = &scene.camera;
    let forward = (c.look_at - c.position).normalize();
    let right = forward.cross(c.up).normalize();
    let up = right.cross(forward);
    let tan_half = (c.fov_y_deg.to_radians() * 0.5).tan();
    let aspect = c.width as f32 / c.height as f32;
    let has_env = scene.environment.max_element() > 0.0;
    let env_pmf = match (has_env, gpu_scene.light_count > 0) {
        (false, _) => 0.0,
        (true, false) => 1.0,
        (true, true) => ENV_SHARE,
    };
    GpuFrameParams {
        camera_position: c.position.to_array(),
        width: c.width,
        camera_forward: forward.to_array(),
        height: c.height,
        camera_right: (right * tan_half * aspect).to_array(),
        sample_offset: 0,
        camera_up: (up * tan_half).to_array(),
        batch_samples: 1,
        environment: scene.environment.to_array(),
        max_depth: scene.settings.max_depth,
        rr_depth: scene.settings.rr_depth,
        seed: scene.settings.seed,
        object_count: gpu_scene.object_count,
        row_offset: 0,
        light_count: gpu_scene.light_count,
        env_pmf,
        sampler: scene.settings.sampler,
        row_end: c.height,
    }
}
