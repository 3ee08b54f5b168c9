//! What every light type's sampling returns: a direction towards the light, the point it
//! reaches (for a finite light), the radiance arriving, the density of having sampled it
//! and whether BSDF sampling could have found it too. Twin of `light_sample.wgsl`.

use glam::Vec3A;

use crate::environment::MapCell;

/// A sampled light direction. Twin of WGSL `LightSample`.
#[derive(Debug, Clone, Copy)]
pub struct LightSample {
    /// Unit direction from the shading point to the light.
    pub wi: Vec3A,
    /// The sampled point on the light (unused for the environment).
    pub point: Vec3A,
    /// False for the environment (infinitely far).
    pub finite: bool,
    /// Emitted radiance towards the shading point (zero when `map_cell` is set).
    pub radiance: Vec3A,
    /// Solid-angle density, including the choice of the light.
    pub pdf: f32,
    /// False when the sample cannot contribute (back side, zero density).
    pub valid: bool,
    /// Whether a ray can hit the light too, so that the sample is weighted against BSDF
    /// sampling (multiple importance sampling); false for point and sun lights, which
    /// only light samples reach.
    pub mis: bool,
    /// For the environment map: the cell and position the sample points to, whose radiance
    /// [`crate::lights::light_radiance`] looks up only once the BSDF is found to pass it on
    /// (half of a map's samples fall below an opaque surface, and the lookup is two cache
    /// misses in a large map). WGSL fills `radiance` at once: a GPU's lanes wait for one
    /// another anyway.
    pub map_cell: Option<MapCell>,
}

/// No sample. Twin of WGSL `invalid_light_sample`.
pub const INVALID: LightSample = LightSample {
    wi: Vec3A::ZERO,
    point: Vec3A::ZERO,
    finite: false,
    radiance: Vec3A::ZERO,
    pdf: 0.0,
    valid: false,
    mis: true,
    map_cell: None,
};
