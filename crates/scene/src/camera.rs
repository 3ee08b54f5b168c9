//! The camera and the image it makes.

use glam::Vec3;

/// A pinhole or thin-lens camera and the image it makes.
#[derive(Debug, Clone, PartialEq)]
pub struct Camera {
    /// Eye position.
    pub position: Vec3,
    /// Point the camera looks at.
    pub look_at: Vec3,
    /// Up direction.
    pub up: Vec3,
    /// Full vertical field of view, degrees.
    pub fov_y_deg: f32,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Radius of the lens, sampled uniformly over its disk (Mitsuba's `thinlens`); 0 is a
    /// pinhole.
    pub aperture_radius: f32,
    /// Distance along the view direction of the plane in focus (> 0).
    pub focus_distance: f32,
}

impl Camera {
    /// The distance from the eye to the point looked at: the default focus distance.
    pub fn look_distance(&self) -> f32 {
        self.position.distance(self.look_at)
    }
}
