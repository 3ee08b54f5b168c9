//! The viewer's camera controls: orbit about the point looked at, pan, and zoom, applied to
//! the scene's [`Camera`].

use glam::Vec3;
use pathlight_scene::Camera;

/// Radians of orbit per pixel dragged.
const ORBIT_PER_PIXEL: f32 = 0.005;
/// Distance factor per wheel step towards the target.
const ZOOM_PER_STEP: f32 = 0.9;
/// Closest the eye may come to the target.
const MIN_DISTANCE: f32 = 1e-3;
/// Largest elevation above or below the horizon, radians (short of the pole, where the
/// view direction would be parallel to the up vector).
const MAX_ELEVATION: f32 = 1.55;

/// An eye orbiting a target: azimuth and elevation about the camera's up vector.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Orbit {
    target: Vec3,
    distance: f32,
    azimuth: f32,
    elevation: f32,
    up: Vec3,
    /// Horizontal unit vectors: azimuth 0 points along `east`, pi/2 along `north`.
    east: Vec3,
    north: Vec3,
}

impl Orbit {
    /// The orbit that reproduces `camera`'s eye and target.
    pub fn from_camera(camera: &Camera) -> Self {
        let up = camera.up.normalize();
        let offset = camera.position - camera.look_at;
        let distance = offset.length().max(MIN_DISTANCE);
        let east = up.any_orthonormal_vector();
        let north = up.cross(east);
        let dir = offset / distance;
        let elevation = dir
            .dot(up)
            .clamp(-1.0, 1.0)
            .asin()
            .clamp(-MAX_ELEVATION, MAX_ELEVATION);
        let azimuth = dir.dot(north).atan2(dir.dot(east));
        Self {
            target: camera.look_at,
            distance,
            azimuth,
            elevation,
            up,
            east,
            north,
        }
    }

    /// Unit vector from the target to the eye.
    fn direction(&self) -> Vec3 {
        let (sin_e, cos_e) = self.elevation.sin_cos();
        let (sin_a, cos_a) = self.azimuth.sin_cos();
        cos_e * (cos_a * self.east + sin_a * self.north) + sin_e * self.up
    }

    /// Eye position.
    pub fn eye(&self) -> Vec3 {
        self.target + self.distance * self.direction()
    }

    /// Turns the eye about the target by a drag of (dx, dy) pixels (right and down
    /// positive): dragging right turns the scene right, dragging down looks from higher.
    pub fn orbit(&mut self, dx: f32, dy: f32) {
        self.azimuth -= dx * ORBIT_PER_PIXEL;
        self.elevation =
            (self.elevation + dy * ORBIT_PER_PIXEL).clamp(-MAX_ELEVATION, MAX_ELEVATION);
    }

    /// Moves eye and target together so the point at the target's depth follows a drag of
    /// (dx, dy) pixels in a view `view_height` pixels tall with vertical field of view
    /// `fov_y_deg`.
    pub fn pan(&mut self, dx: f32, dy: f32, view_height: f32, fov_y_deg: f32) {
        let forward = -self.direction();
        let right = forward.cross(self.up).normalize();
        let screen_up = right.cross(forward);
        let metres_per_pixel =
            2.0 * self.distance * (fov_y_deg.to_radians() * 0.5).tan() / view_height.max(1.0);
        self.target += (-dx * right + dy * screen_up) * metres_per_pixel;
    }

    /// Moves the eye towards the target by `steps` wheel steps (negative: away).
    pub fn zoom(&mut self, steps: f32) {
        self.distance = (self.distance * ZOOM_PER_STEP.powf(steps)).max(MIN_DISTANCE);
    }

    /// Writes eye and target into `camera` (up, field of view and size unchanged).
    pub fn apply(&self, camera: &mut Camera) {
        camera.position = self.eye();
        camera.look_at = self.target;
    }
}

/// Smallest lens the viewer opens, as a fraction of the focus distance: `]` on a pinhole
/// opens to it, `[` below it closes to a pinhole.
const SMALLEST_APERTURE: f32 = 0.005;

/// The aperture radius after opening (`factor` > 1) or closing (< 1) `camera`'s lens.
pub fn next_aperture(camera: &Camera, factor: f32) -> f32 {
    let smallest = SMALLEST_APERTURE * camera.focus_distance;
    let radius = camera.aperture_radius * factor;
    if factor > 1.0 {
        radius.max(smallest)
    } else if radius < smallest * 0.999 {
        0.0
    } else {
        radius
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn brackets_open_a_pinhole_step_by_step_and_close_it_again() {
        let mut c = camera();
        let mut radii = Vec::new();
        for _ in 0..3 {
            c.aperture_radius = next_aperture(&c, 1.5);
            radii.push(c.aperture_radius);
        }
        assert!((radii[0] - 0.025).abs() < 1e-7 && (radii[2] - 0.025 * 2.25).abs() < 1e-6);
        for _ in 0..2 {
            c.aperture_radius = next_aperture(&c, 1.0 / 1.5);
        }
        assert!((c.aperture_radius - 0.025).abs() < 1e-6);
        c.aperture_radius = next_aperture(&c, 1.0 / 1.5);
        assert_eq!(c.aperture_radius, 0.0);
    }

    fn camera() -> Camera {
        Camera {
            position: Vec3::new(0.3, 1.2, 3.5),
            look_at: Vec3::new(0.0, 0.85, -1.5),
            up: Vec3::Y,
            fov_y_deg: 40.0,
            width: 500,
            height: 500,
            aperture_radius: 0.0,
            focus_distance: 5.0,
        }
    }

    fn close(a: Vec3, b: Vec3) -> bool {
        (a - b).length() < 1e-4
    }

    #[test]
    fn round_trip_keeps_the_camera() {
        let c = camera();
        let mut out = c.clone();
        Orbit::from_camera(&c).apply(&mut out);
        assert!(close(out.position, c.position), "{out:?}");
        assert!(close(out.look_at, c.look_at));
    }

    #[test]
    fn orbit_keeps_target_and_distance_and_turns_about_up() {
        let c = camera();
        let mut orbit = Orbit::from_camera(&c);
        let height = (c.position - c.look_at).dot(Vec3::Y);
        orbit.orbit(200.0, 0.0);
        let eye = orbit.eye();
        assert!(((eye - c.look_at).length() - (c.position - c.look_at).length()).abs() < 1e-4);
        assert!(
            ((eye - c.look_at).dot(Vec3::Y) - height).abs() < 1e-4,
            "a horizontal drag keeps the height"
        );
        assert!((eye - c.position).length() > 0.5, "the eye moved");
        // Dragging right moves the eye to the left of where it was (the scene turns right).
        let right = (c.look_at - c.position).cross(Vec3::Y);
        assert!((eye - c.position).dot(right) < 0.0);
    }

    #[test]
    fn elevation_stops_short_of_the_pole() {
        let mut orbit = Orbit::from_camera(&camera());
        orbit.orbit(0.0, 1e6);
        let dir = (orbit.eye() - orbit.target).normalize();
        assert!(dir.y > 0.99 && dir.y < 1.0, "{dir}");
        orbit.orbit(0.0, -1e7);
        let dir = (orbit.eye() - orbit.target).normalize();
        assert!(dir.y < -0.99 && dir.y > -1.0, "{dir}");
    }

    #[test]
    fn pan_moves_eye_and_target_alike_across_the_view() {
        let c = camera();
        let mut orbit = Orbit::from_camera(&c);
        let view = (c.look_at - c.position).normalize();
        orbit.pan(100.0, 0.0, 500.0, 40.0);
        let moved = orbit.target - c.look_at;
        assert!(close(orbit.eye() - c.position, moved));
        assert!(
            moved.dot(view).abs() < 1e-5,
            "pan is perpendicular to the view"
        );
        // 100 of 500 pixels at the target's depth: a fifth of the visible height.
        let visible = 2.0 * (c.position - c.look_at).length() * 20f32.to_radians().tan();
        assert!((moved.length() - visible / 5.0).abs() < 1e-4);
        // The scene follows the mouse: dragging right moves the camera left.
        assert!(moved.dot(view.cross(Vec3::Y)) < 0.0);
    }

    #[test]
    fn zoom_moves_along_the_view_and_never_reaches_the_target() {
        let c = camera();
        let mut orbit = Orbit::from_camera(&c);
        let d0 = (c.position - c.look_at).length();
        orbit.zoom(1.0);
        assert!(((orbit.eye() - c.look_at).length() - 0.9 * d0).abs() < 1e-4);
        assert!(close(
            (orbit.eye() - c.look_at).normalize(),
            (c.position - c.look_at).normalize()
        ));
        orbit.zoom(1e4);
        assert!((orbit.eye() - c.look_at).length() >= MIN_DISTANCE * 0.999);
    }
}
