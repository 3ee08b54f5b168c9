//! Materials as the kernels read them: per material its common part ([`GpuMaterial`]), its
//! model's parameter block (a few `vec4f`s in one buffer), and the texture slots both
//! point into. This file holds the only host-side `match` on the material model: each
//! model's block is laid out by its `*_block` function here and read by its kernel twins
//! (`crates/gpu/shaders/<model>.wgsl`, `crates/cpu/src/<model>.rs`), whose decoders name the
//! layout back.

use bytemuck::Zeroable;
use glam::Vec3;
use pathlight_scene::{AlphaMode, Conductor, Lobes, Material, MetalRough, Model, TextureRef, Wrap};

use crate::gpu_types::{
    GpuMaterial, GpuTextureSlot, MATERIAL_BLEND, MATERIAL_MASK, WRAP_CLAMP, WRAP_MIRROR,
    WRAP_REPEAT,
};
use crate::textures::Textures;

/// [`GpuMaterial::model`]: the seed's lobe mixture (`lobes.wgsl`).
pub const MODEL_LOBES: u32 = 0;
/// [`GpuMaterial::model`]: glTF's metal-rough model (`metal_rough.wgsl`).
pub const MODEL_METAL_ROUGH: u32 = 1;

/// Vectors of parameters the kernels load for every material: the largest block of any
/// model (WGSL `MODEL_PARAMS`). The buffer ends with this many zero vectors, so that a load
/// past a short block stays inside it.
pub const MODEL_PARAMS: usize = 4;

/// The materials of a scene in the kernels' form.
#[derive(Debug, Clone, PartialEq)]
pub struct PackedMaterials {
    /// Common parts, in the scene's order. Never empty.
    pub materials: Vec<GpuMaterial>,
    /// Every model's parameter blocks, then [`MODEL_PARAMS`] zero vectors.
    pub params: Vec<[f32; 4]>,
    /// Per material, its textures' slots ([`GpuMaterial::textures`] onwards). Never empty.
    pub texture_slots: Vec<GpuTextureSlot>,
}

impl PackedMaterials {
    /// Packs `materials`, whose textures `textures` holds.
    pub fn build(materials: &[Material], textures: &Textures) -> Self {
        let mut out = Self {
            materials: Vec::with_capacity(materials.len().max(1)),
            params: Vec::new(),
            texture_slots: Vec::new(),
        };
        for m in materials {
            let gpu = out.pack(m, textures);
            out.materials.push(gpu);
        }
        if out.materials.is_empty() {
            out.materials.push(GpuMaterial::new(MODEL_LOBES, 0));
        }
        out.params.extend([[0.0; 4]; MODEL_PARAMS]);
        if out.texture_slots.is_empty() {
            out.texture_slots.push(GpuTextureSlot::zeroed());
        }
        out
    }

    /// Adds `m`'s block and texture slots; returns its common part.
    fn pack(&mut self, m: &Material, textures: &Textures) -> GpuMaterial {
        let mut gpu = GpuMaterial::new(0, self.params.len() as u32);
        gpu.base_color = m.base_color.to_array();
        gpu.emission = m.emission.to_array();
        gpu.normal_scale = m.normal_scale;
        gpu.alpha_factor = m.alpha_factor;
        match m.alpha {
            AlphaMode::Opaque => {}
            AlphaMode::Mask(cutoff) => {
                gpu.flags |= MATERIAL_MASK;
                gpu.alpha_cutoff = cutoff;
            }
            AlphaMode::Blend => gpu.flags |= MATERIAL_BLEND,
        }
        let (model, block, model_textures) = match &m.model {
            Model::Lobes(lobes) => (MODEL_LOBES, lobes_block(lobes), vec![]),
            Model::MetalRough(pbr) => (
                MODEL_METAL_ROUGH,
                metal_rough_block(pbr),
                vec![pbr.metal_rough_texture],
            ),
        };
        debug_assert!(block.len() <= MODEL_PARAMS);
        gpu.model = model;
        self.params.extend(block);
        gpu.textures = self.texture_slots.len() as u32;
        let uses = [m.texture, m.normal_texture, m.emission_texture]
            .into_iter()
            .chain(model_textures);
        for (i, r) in uses.enumerate() {
            if r.is_some() {
                gpu.texture_mask |= 1 << i;
            }
            self.texture_slots.push(texture_slot(r.as_ref(), textures));
        }
        gpu
    }
}

/// Texture use `r` as a slot (all zero for none).
fn texture_slot(r: Option<&TextureRef>, textures: &Textures) -> GpuTextureSlot {
    let Some(r) = r else {
        return GpuTextureSlot::zeroed();
    };
    let place = textures.places[r.texture as usize];
    let mode = |w: Wrap| match w {
        Wrap::Repeat => WRAP_REPEAT,
        Wrap::Clamp => WRAP_CLAMP,
        Wrap::Mirror => WRAP_MIRROR,
    };
    GpuTextureSlot {
        u: r.transform[0],
        offset: place.offset,
        v: r.transform[1],
        wrap: mode(r.wrap[0]) | (mode(r.wrap[1]) << 2),
        width: place.width,
        height: place.height,
        pad: [0; 2],
    }
}

/// The lobe model's block (WGSL `lobes_params`, CPU `LobesParams::decode`):
/// `[specular_rate, specular_tint, specular_roughness, refract_rate]`,
/// `[refract_tint, ior, refract_roughness, conductor (1 or 0)]`, `[eta, 0]`, `[k, 0]`; `eta`
/// and `k` are the conductor's complex IOR (1 and 0 without one).
fn lobes_block(l: &Lobes) -> Vec<[f32; 4]> {
    let conductor = l.conductor.unwrap_or(Conductor {
        eta: Vec3::ONE,
        k: Vec3::ZERO,
    });
    vec![
        [
            l.specular_rate,
            l.specular_tint,
            l.specular_roughness,
            l.refract_rate,
        ],
        [
            l.refract_tint,
            l.ior,
            l.refract_roughness,
            f32::from(u8::from(l.conductor.is_some())),
        ],
        conductor.eta.extend(0.0).to_array(),
        conductor.k.extend(0.0).to_array(),
    ]
}

/// The metal-rough model's block (WGSL `metal_rough_params`, CPU `MetalRoughParams::decode`):
/// `[metallic, roughness, transmission, ior]`, `[thin (1 or 0), specular, clearcoat,
/// clearcoat roughness]`, `[specular colour, 0]`, `[attenuation, 0]`. Its one texture
/// is slot [`TEXTURE_MODEL`](crate::gpu_types::TEXTURE_MODEL): metallic in blue, roughness
/// in green.
fn metal_rough_block(m: &MetalRough) -> Vec<[f32; 4]> {
    vec![
        [m.metallic, m.roughness, m.transmission, m.ior],
        [
            f32::from(u8::from(m.thin)),
            m.specular,
            m.clearcoat,
            m.clearcoat_roughness,
        ],
        m.specular_color.extend(0.0).to_array(),
        m.attenuation.extend(0.0).to_array(),
    ]
}
