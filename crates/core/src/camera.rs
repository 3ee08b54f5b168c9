//! The camera as the integrator reads it: the eye and the image plane at unit distance.

use pathlight_scene::Camera;

use crate::gpu_types::GpuCamera;

impl GpuCamera {
    /// The eye, the view direction, and the right and up vectors scaled to half the image
    /// width and height at unit distance (so that a point of the image at normalised device
    /// coordinates (x, y) in [-1, 1] lies along `forward + x right + y up`).
    pub fn new(camera: &Camera) -> Self {
        let forward = (camera.look_at - camera.position).normalize();
        let right = forward.cross(camera.up).normalize();
        let up = right.cross(forward);
        let tan_half = (camera.fov_y_deg.to_radians() * 0.5).tan();
        let aspect = camera.width as f32 / camera.height as f32;
        Self {
            position: camera.position.to_array(),
            lens_radius: camera.aperture_radius,
            forward: forward.to_array(),
            focus_distance: camera.focus_distance,
            right: (right * tan_half * aspect).to_array(),
            pad2: 0,
            up: (up * tan_half).to_array(),
            pad3: 0,
        }
    }
}
