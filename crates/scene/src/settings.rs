//! Sampling settings of a render and the limits every input is checked against, by the
//! scene loader and the command line alike (each names the key or option it checked).

use glam::Vec3;

use crate::error::RangeError;

/// Largest magnitude of a coordinate or a length in a scene: far below f32's range, so that
/// boxes, areas and distances computed from the scene stay finite.
pub const MAX_COORDINATE: f32 = 1e15;
/// Largest accepted image side, in pixels.
pub const MAX_RESOLUTION: u32 = 8192;
/// Largest accepted samples per pixel for one render.
pub const MAX_SPP: u32 = 1 << 20;
/// Largest accepted path length in segments.
pub const MAX_DEPTH: u32 = 1024;

/// Sampling settings of a render.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RenderSettings {
    /// Samples per pixel.
    pub spp: u32,
    /// Maximum path length in segments (Mitsuba's `max_depth`).
    pub max_depth: u32,
    /// Depth from which Russian roulette may end a path.
    pub rr_depth: u32,
    /// Seed of the random sequence.
    pub seed: u32,
    /// The sample generator.
    pub sampler: Sampler,
    /// Whether the render also accumulates the auxiliary images a denoiser reads (the
    /// first non-specular hit's albedo and shading normal). A choice of the command, not of
    /// the scene file: false after loading.
    pub aovs: bool,
}

/// The sample generator of a render.
#[derive(Debug, Default, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Sampler {
    /// Padded Owen-scrambled Sobol: less noise at the same sample count (the default).
    #[default]
    Sobol,
    /// Independent hashed random numbers (Mitsuba's `independent` sampler).
    Independent,
}

/// Checks an image size against [`MAX_RESOLUTION`].
pub fn check_resolution(width: u32, height: u32) -> Result<(), RangeError> {
    if (1..=MAX_RESOLUTION).contains(&width) && (1..=MAX_RESOLUTION).contains(&height) {
        Ok(())
    } else {
        Err(RangeError(format!(
            "resolution {width}x{height} is out of range: each side must lie in 1..={MAX_RESOLUTION}"
        )))
    }
}

/// Checks samples per pixel against [`MAX_SPP`].
pub fn check_spp(spp: u32) -> Result<(), RangeError> {
    if (1..=MAX_SPP).contains(&spp) {
        Ok(())
    } else {
        Err(RangeError(format!(
            "spp = {spp} is out of range 1..={MAX_SPP}"
        )))
    }
}

/// Checks a camera's view: a `look_at` apart from its `position`, an `up` not along the view
/// and a vertical field of view `fov_y` (degrees) strictly between 0 and 180. `prefix` goes
/// before the keys' names in the message (`camera.` in a scene file).
pub fn check_view(
    prefix: &str,
    position: Vec3,
    look_at: Vec3,
    up: Vec3,
    fov_y: f32,
) -> Result<(), RangeError> {
    if position.distance(look_at) <= 0.0 {
        return Err(RangeError(format!(
            "{prefix}look_at equals {prefix}position"
        )));
    }
    if up.cross(look_at - position).length_squared() <= 0.0 {
        return Err(RangeError(format!(
            "{prefix}up is parallel to the view direction"
        )));
    }
    if !(fov_y > 0.0 && fov_y < 180.0) {
        return Err(RangeError(format!(
            "{prefix}fov_y = {fov_y} must lie strictly between 0 and 180 degrees"
        )));
    }
    Ok(())
}

/// Checks a path length against [`MAX_DEPTH`].
pub fn check_max_depth(max_depth: u32) -> Result<(), RangeError> {
    if (1..=MAX_DEPTH).contains(&max_depth) {
        Ok(())
    } else {
        Err(RangeError(format!(
            "max_depth = {max_depth} is out of range 1..={MAX_DEPTH}"
        )))
    }
}

/// Checks a thin lens's radius (`name` is the key or option that gave it): 0 (a pinhole) up
/// to [`MAX_COORDINATE`].
pub fn check_aperture(name: &str, radius: f32) -> Result<f32, RangeError> {
    if (0.0..=MAX_COORDINATE).contains(&radius) {
        Ok(radius)
    } else {
        Err(RangeError(format!(
            "{name} = {radius} must be >= 0 and at most {MAX_COORDINATE:e}"
        )))
    }
}

/// Checks a length that must be positive, such as a focus distance (`name` is the key or
/// option that gave it): above 0, up to [`MAX_COORDINATE`].
pub fn check_length(name: &str, length: f32) -> Result<f32, RangeError> {
    if length > 0.0 && length <= MAX_COORDINATE {
        Ok(length)
    } else {
        Err(RangeError(format!(
            "{name} = {length} must be > 0 and at most {MAX_COORDINATE:e}"
        )))
    }
}

/// Checks an environment map's strength (`name` is the key or option that gave it): finite
/// and >= 0.
pub fn check_env_strength(name: &str, strength: f32) -> Result<f32, RangeError> {
    if strength.is_finite() && strength >= 0.0 {
        Ok(strength)
    } else {
        Err(RangeError(format!(
            "{name} = {strength} must be finite and >= 0"
        )))
    }
}

/// Checks an environment map's rotation in degrees (`name` is the key or option that gave
/// it): finite.
pub fn check_env_rotation(name: &str, degrees: f32) -> Result<f32, RangeError> {
    if degrees.is_finite() {
        Ok(degrees)
    } else {
        Err(RangeError(format!("{name} = {degrees} must be finite")))
    }
}
