//! Lights that are not surfaces: point, spot and sun lights, placed by the scene file's
//! `[[light]]` entries or a glTF file's `KHR_lights_punctual` nodes. No ray hits them; they
//! light the scene through next-event estimation alone.

use glam::Vec3;

/// A spot light's cone: full intensity within `inner_deg` of the axis, none beyond
/// `outer_deg`, and glTF's smooth falloff between (the square of the linear step in the
/// cosine of the angle).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cone {
    /// Unit direction the light shines along.
    pub axis: Vec3,
    /// Half-angle of full intensity, degrees (at most `outer_deg`).
    pub inner_deg: f32,
    /// Half-angle where the light ends, degrees (above 0, at most 90).
    pub outer_deg: f32,
}

/// What kind of light, with its placement.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LightKind {
    /// A point (or, with a radius, a small sphere seen by light samples only) shining in
    /// every direction, or within a cone.
    Point {
        /// Position.
        position: Vec3,
        /// Radius of the sphere the light is spread over; 0 is a true point.
        radius: f32,
        /// The cone of a spot light; `None` for a point light.
        cone: Option<Cone>,
    },
    /// Light from infinitely far away along one direction, or from a small disk of the sky.
    Sun {
        /// Unit direction the light travels (from the sun towards the scene).
        direction: Vec3,
        /// Angular diameter of the sun's disk, degrees; 0 is a true directional light.
        angular_diameter_deg: f32,
    },
}

/// A point, spot or sun light.
#[derive(Debug, Clone, PartialEq)]
pub struct Light {
    /// Name from the file, or `light<index>`.
    pub name: String,
    /// Linear RGB strength: for point and spot lights the radiant intensity along the axis
    /// in W/sr, for the sun the irradiance on a surface facing it in W/m^2.
    pub intensity: Vec3,
    /// Kind and placement.
    pub kind: LightKind,
}

impl Light {
    /// Whether it adds no light (zero or negative strength).
    pub fn is_dark(&self) -> bool {
        self.intensity.max_element() <= 0.0
    }
}
