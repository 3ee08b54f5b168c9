//! The scene's textures in the form both backends read: one texel buffer and a table of
//! where each texture lies in it.

use bytemuck::Zeroable;
use pathlight_scene::Texture;

use crate::gpu_types::GpuTextureInfo;

/// Every texture's texels (packed sRGB8 RGBA, row 0 at the top) and where each lies.
#[derive(Debug, Clone)]
pub struct Textures {
    /// Texture table, indexed by a material's `texture`. Never empty.
    pub infos: Vec<GpuTextureInfo>,
    /// All texels. Never empty.
    pub texels: Vec<u32>,
}

impl Textures {
    /// Packs `textures` one after the other.
    pub fn build(textures: &[Texture]) -> Self {
        let mut out = Self {
            infos: Vec::with_capacity(textures.len().max(1)),
            texels: Vec::new(),
        };
        for texture in textures {
            out.infos.push(GpuTextureInfo {
                offset: out.texels.len() as u32,
                width: texture.width,
                height: texture.height,
                pad: 0,
            });
            out.texels.extend_from_slice(&texture.texels);
        }
        if out.infos.is_empty() {
            out.infos.push(GpuTextureInfo::zeroed());
        }
        if out.texels.is_empty() {
            out.texels.push(0);
        }
        out
    }
}
