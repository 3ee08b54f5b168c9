//! The scene's textures in the form both backends read: one texel buffer, and where each
//! texture lies in it (which the materials' texture slots repeat).

use pathlight_scene::Texture;

/// Where a texture lies in the texel buffer (its materials' texture slots repeat it).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TexturePlace {
    /// First texel.
    pub offset: u32,
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
}

/// Every texture's texels (packed sRGB8 RGBA, row 0 at the top) and where each lies.
#[derive(Debug, Clone)]
pub struct Textures {
    /// Per texture of the scene, where it lies.
    pub places: Vec<TexturePlace>,
    /// All texels. Never empty.
    pub texels: Vec<u32>,
}

impl Textures {
    /// Packs `textures` one after the other.
    pub fn build(textures: &[Texture]) -> Self {
        let mut out = Self {
            places: Vec::with_capacity(textures.len()),
            texels: Vec::new(),
        };
        for texture in textures {
            out.places.push(TexturePlace {
                offset: out.texels.len() as u32,
                width: texture.width,
                height: texture.height,
            });
            out.texels.extend_from_slice(&texture.texels);
        }
        if out.texels.is_empty() {
            out.texels.push(0);
        }
        out
    }
}
