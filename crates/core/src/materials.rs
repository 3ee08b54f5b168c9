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
    GpuMaterial, GpuTextureSlot, MATERIAL_BLEND, MATERIAL_LONG_BLOCK, MATERIAL_MASK, WRAP_CLAMP,
    WRAP_MIRROR, WRAP_REPEAT,
};
use crate::sheen_table::SHEEN_ALBEDO;
use crate::textures::Textures;

/// [`GpuMaterial::model`]: the seed's lobe mixture (`lobes.wgsl`).
pub const MODEL_LOBES: u32 = 0;
/// [`GpuMaterial::model`]: glTF's metal-rough model (`metal_rough.wgsl`).
pub const MODEL_METAL_ROUGH: u32 = 1;

/// Vectors of a model's parameter block: the largest block of any model (WGSL
/// `MODEL_PARAMS`). The kernels load the first [`MODEL_PARAMS_SHORT`] for every material,
/// the last only for materials flagged [`MATERIAL_LONG_BLOCK`]. The buffer ends with this
/// many zero vectors, so that a load past a short block stays inside it.
pub const MODEL_PARAMS: usize = 5;
/// The vectors loaded for every material (WGSL `MODEL_PARAMS_SHORT`).
pub const MODEL_PARAMS_SHORT: usize = 4;

/// Where the parameter buffer holds the sheen albedo table
/// ([`crate::sheen_table::SHEEN_ALBEDO`], four entries a vector), ahead of
/// every material's block (WGSL `SHEEN_TABLE`).
pub const SHEEN_TABLE: u32 = 0;
/// Vectors the sheen albedo table fills.
pub const SHEEN_TABLE_VECTORS: usize = SHEEN_ALBEDO.len() / 4;

/// The materials of a scene in the kernels' form.
#[derive(Debug, Clone, PartialEq)]
pub struct PackedMaterials {
    /// Common parts, in the scene's order. Never empty.
    pub materials: Vec<GpuMaterial>,
    /// The sheen albedo table, every model's parameter blocks, then [`MODEL_PARAMS`] zero
    /// vectors.
    pub params: Vec<[f32; 4]>,
    /// Per material, its textures' slots ([`GpuMaterial::textures`] onwards). Never empty.
    pub texture_slots: Vec<GpuTextureSlot>,
}

impl PackedMaterials {
    /// Packs `materials`, whose textures `textures` holds.
    pub fn build(materials: &[Material], textures: &Textures) -> Self {
        let mut out = Self {
            materials: Vec::with_capacity(materials.len().max(1)),
            params: SHEEN_ALBEDO
                .chunks_exact(4)
                .map(|c| [c[0], c[1], c[2], c[3]])
                .collect(),
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
        let (model, block, model_textures, coat_normal_scale) = match &m.model {
            Model::Lobes(lobes) => (MODEL_LOBES, lobes_block(lobes), vec![], 1.0),
            Model::MetalRough(pbr) => (
                MODEL_METAL_ROUGH,
                metal_rough_block(pbr),
                [pbr.metal_rough_texture]
                    .into_iter()
                    .chain(pbr.textures.in_slot_order())
                    .collect(),
                pbr.clearcoat_normal_scale,
            ),
        };
        gpu.coat_normal_scale = coat_normal_scale;
        debug_assert!(block.len() <= MODEL_PARAMS);
        if block.len() > MODEL_PARAMS_SHORT {
            gpu.flags |= MATERIAL_LONG_BLOCK;
        }
        gpu.model = model;
        self.params.extend(block);
        gpu.textures = self.texture_slots.len() as u32;
        let mut uses: Vec<Option<TextureRef>> = [m.texture, m.normal_texture, m.emission_texture]
            .into_iter()
            .chain(model_textures)
            .collect();
        // Slots past the last texture the material has are never read.
        while uses.last().is_some_and(Option::is_none) {
            uses.pop();
        }
        for (i, r) in uses.iter().enumerate() {
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
/// clearcoat roughness]`, `[specular colour, 0]`, `[attenuation, 0]`, and with a sheen,
/// `[sheen colour, sheen roughness]`. Its textures are slot
/// [`TEXTURE_MODEL`](crate::gpu_types::TEXTURE_MODEL) (metallic in blue, roughness in
/// green) and the extensions' from `TEXTURE_TRANSMISSION` on.
fn metal_rough_block(m: &MetalRough) -> Vec<[f32; 4]> {
    let mut block = vec![
        [m.metallic, m.roughness, m.transmission, m.ior],
        [
            f32::from(u8::from(m.thin)),
            m.specular,
            m.clearcoat,
            m.clearcoat_roughness,
        ],
        m.specular_color.extend(0.0).to_array(),
        m.attenuation.extend(0.0).to_array(),
    ];
    if m.sheen_color.max_element() > 0.0 {
        block.push(m.sheen_color.extend(m.sheen_roughness).to_array());
    }
    block
}
