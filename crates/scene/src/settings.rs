//! Sampling settings of a render and the limits every input is checked against.

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
