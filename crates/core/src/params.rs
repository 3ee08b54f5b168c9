//! The integrator's per-render constants, the same for both backends.

use pathlight_scene::{Camera, RenderSettings, Sampler};

use crate::gpu_types::{GpuCamera, GpuRenderParams, SAMPLER_INDEPENDENT, SAMPLER_SOBOL};
use crate::shading::Shading;

/// Probability of sampling the environment when shape lights exist too.
const ENV_SHARE: f32 = 0.5;

/// The shader's code for a sample generator (`SAMPLER_*`).
pub fn sampler_code(sampler: Sampler) -> u32 {
    match sampler {
        Sampler::Sobol => SAMPLER_SOBOL,
        Sampler::Independent => SAMPLER_INDEPENDENT,
    }
}

impl GpuRenderParams {
    /// The constants of a whole-image render of `shading` seen by `camera`: every row, one
    /// sample per pixel from sample 0 (a renderer sets the band and the samples of each
    /// dispatch).
    pub fn new(camera: &Camera, settings: &RenderSettings, shading: &Shading) -> Self {
        let mut params = Self {
            camera: GpuCamera::new(camera),
            width: camera.width,
            height: camera.height,
            sample_offset: 0,
            batch_samples: 1,
            row_offset: 0,
            row_end: camera.height,
            max_depth: settings.max_depth,
            rr_depth: settings.rr_depth,
            seed: settings.seed,
            sampler: sampler_code(settings.sampler),
            aovs: u32::from(settings.aovs),
            ..Self::zeroed_params()
        };
        params.set_shading(shading);
        params
    }

    /// Takes the camera and the image size from `camera` (the image restarts).
    pub fn set_camera(&mut self, camera: &Camera) {
        self.camera = GpuCamera::new(camera);
        self.width = camera.width;
        self.height = camera.height;
        self.row_offset = 0;
        self.row_end = camera.height;
    }

    /// Takes the environment, the counts and the split between the environment and the
    /// shape lights from `shading`.
    pub fn set_shading(&mut self, shading: &Shading) {
        let has_env = shading.environment.max_element() > 0.0
            || shading.environment_map.is_some_and(|m| m.scale > 0.0);
        self.env_pmf = match (has_env, shading.light_count > 0) {
            (false, _) => 0.0,
            (true, false) => 1.0,
            (true, true) => ENV_SHARE,
        };
        self.environment = shading.environment.to_array();
        let map = shading.environment_map;
        self.env_width = map.map_or(0, |m| m.width);
        self.env_height = map.map_or(0, |m| m.height);
        self.env_scale = map.map_or(0.0, |m| m.scale);
        let rotation = map.map_or(0.0, |m| m.rotation);
        self.env_rotation = [rotation.cos(), rotation.sin()];
        self.object_count = shading.object_count;
        self.light_count = shading.light_count;
    }

    fn zeroed_params() -> Self {
        bytemuck::Zeroable::zeroed()
    }
}
