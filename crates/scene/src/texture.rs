//! Image textures: decoded once into packed sRGB8 texels (decoded to linear on the GPU).

use std::path::Path;

use crate::error::SceneError;

/// An sRGB-encoded 8-bit RGBA image.
#[derive(Debug, Clone, PartialEq)]
pub struct Texture {
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// Row-major texels, row 0 at the top, packed RGBA8 (red in the low byte).
    pub texels: Vec<u32>,
}

/// Largest accepted texture side, in texels.
pub const MAX_TEXTURE_SIDE: u32 = 16384;

impl Texture {
    /// Decodes a PNG or JPEG held in memory; `path` only names it in errors.
    pub fn decode(bytes: &[u8], path: &Path) -> Result<Self, SceneError> {
        let image = image::load_from_memory(bytes).map_err(|err| SceneError::Asset {
            path: path.to_owned(),
            message: format!("cannot decode image: {err}"),
        })?;
        let rgba = image.to_rgba8();
        let (width, height) = rgba.dimensions();
        if width > MAX_TEXTURE_SIDE || height > MAX_TEXTURE_SIDE {
            return Err(SceneError::Asset {
                path: path.to_owned(),
                message: format!(
                    "image is {width}x{height}; the largest side accepted is {MAX_TEXTURE_SIDE}"
                ),
            });
        }
        let texels = rgba
            .pixels()
            .map(|p| u32::from_le_bytes(p.0))
            .collect::<Vec<_>>();
        Ok(Self {
            width,
            height,
            texels,
        })
    }
}

impl Texture {
    /// The mean linear colour of its texels.
    pub fn mean_linear(&self) -> glam::Vec3 {
        let sum = self.texels.iter().fold(glam::DVec3::ZERO, |acc, &t| {
            let [r, g, b, _] = t.to_le_bytes();
            acc + glam::DVec3::new(
                f64::from(srgb_to_linear(f32::from(r) / 255.0)),
                f64::from(srgb_to_linear(f32::from(g) / 255.0)),
                f64::from(srgb_to_linear(f32::from(b) / 255.0)),
            )
        });
        (sum / self.texels.len().max(1) as f64).as_vec3()
    }
}

/// The sRGB transfer function's inverse: encoded [0, 1] to linear.
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// The sRGB transfer function: linear to encoded [0, 1] (input clamped to [0, 1]).
pub fn linear_to_srgb(c: f32) -> f32 {
    let c = c.clamp(0.0, 1.0);
    if c <= 0.003_130_8 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }
}
