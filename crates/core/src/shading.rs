//! What the scene's surfaces are made of and what lights them: the materials, each
//! object's material, the light table and the environment. Cheap to rebuild (a light toggle
//! rebuilds it, keeping the [`Geometry`]).

use bytemuck::Zeroable;
use glam::Vec3;
use pathlight_scene::{
    AlphaMode, Conductor, Environment, Material, Scene, Texture, TextureRef, Wrap,
};

use crate::environment::texel_scale;
use crate::geometry::Geometry;
use crate::gpu_types::{
    FLAG_ALPHA, GpuLight, GpuMaterial, GpuObject, GpuTextureSlot, KIND_MESH, MATERIAL_BLEND,
    MATERIAL_MASK, MATERIAL_THIN, MODEL_LOBES, MODEL_METAL_ROUGH, SLOT_BASE, SLOT_EMISSION,
    SLOT_METAL_ROUGH, SLOT_NORMAL, WRAP_CLAMP, WRAP_MIRROR, WRAP_REPEAT,
};
use crate::light_table;

/// The materials and lights of a scene, in the form both backends read.
#[derive(Debug, Clone, PartialEq)]
pub struct Shading {
    /// Objects in the scene's order: [`Geometry::shapes`] with their material and first
    /// light-table entry. Never empty (a placeholder when there are no objects).
    pub objects: Vec<GpuObject>,
    /// Number of real objects.
    pub object_count: u32,
    /// Materials. Never empty.
    pub materials: Vec<GpuMaterial>,
    /// The light table ([`light_table::build`]). Never empty.
    pub lights: Vec<GpuLight>,
    /// Number of real light-table entries.
    pub light_count: u32,
    /// Constant environment radiance (zero with a map).
    pub environment: Vec3,
    /// The environment map's size and placement, when there is one.
    pub environment_map: Option<MapPlacement>,
}

/// An environment map's size and how the scene places it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MapPlacement {
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// Factor from decoded texels to radiance: the strength times [`texel_scale`].
    pub scale: f32,
    /// Turn about +y, radians.
    pub rotation: f32,
}

impl Shading {
    /// The materials, lights and environment of `scene`, whose objects `geometry` holds.
    pub fn build(scene: &Scene, geometry: &Geometry) -> Self {
        let mut materials: Vec<GpuMaterial> = scene.materials.iter().map(gpu_material).collect();
        if materials.is_empty() {
            materials.push(GpuMaterial::zeroed());
        }
        let mut objects: Vec<GpuObject> = geometry
            .shapes
            .iter()
            .zip(&scene.objects)
            .map(|(shape, object)| GpuObject {
                material: object.material,
                ..*shape
            })
            .collect();
        for object in &mut objects {
            let flags = materials[object.material as usize].flags;
            if object.kind == KIND_MESH && flags & (MATERIAL_MASK | MATERIAL_BLEND) != 0 {
                object.flags |= FLAG_ALPHA;
            }
        }
        let emission: Vec<Vec3> = scene
            .materials
            .iter()
            .map(|m| mean_emission(m, &scene.textures))
            .collect();
        let (lights, light_count) = light_table::build(&mut objects, &emission, geometry);
        let object_count = objects.len() as u32;
        if objects.is_empty() {
            objects.push(GpuObject::zeroed());
        }
        Self {
            objects,
            object_count,
            materials,
            lights,
            light_count,
            environment: match &scene.environment {
                Environment::Constant(radiance) => *radiance,
                Environment::Map(_) => Vec3::ZERO,
            },
            environment_map: match &scene.environment {
                Environment::Constant(_) => None,
                Environment::Map(map) => Some(MapPlacement {
                    width: map.image.width,
                    height: map.image.height,
                    scale: map.strength * texel_scale(map.image.max),
                    rotation: map.rotation_deg.to_radians(),
                }),
            },
        }
    }
}

/// A material as the BSDF reads it.
fn gpu_material(m: &Material) -> GpuMaterial {
    let conductor = m.conductor.unwrap_or(Conductor {
        eta: Vec3::ONE,
        k: Vec3::ZERO,
    });
    let mut slots = [GpuTextureSlot::NONE; 4];
    slots[SLOT_BASE] = texture_slot(m.texture.as_ref());
    let mut out = GpuMaterial {
        base_color: m.base_color.to_array(),
        model: MODEL_LOBES,
        emission: m.emission.to_array(),
        specular_rate: m.lobes.specular_rate,
        eta: conductor.eta.to_array(),
        specular_tint: m.lobes.specular_tint,
        k: conductor.k.to_array(),
        specular_roughness: m.lobes.specular_roughness,
        refract_rate: m.lobes.refract_rate,
        refract_tint: m.lobes.refract_tint,
        ior: m.lobes.ior,
        refract_roughness: m.lobes.refract_roughness,
        conductor: u32::from(m.conductor.is_some()),
        metallic: 0.0,
        roughness: 0.0,
        transmission: 0.0,
        normal_scale: 1.0,
        alpha_cutoff: 0.0,
        alpha_factor: 1.0,
        flags: 0,
        slots,
    };
    if let Some(pbr) = &m.metal_rough {
        out.model = MODEL_METAL_ROUGH;
        out.metallic = pbr.metallic;
        out.roughness = pbr.roughness;
        out.ior = pbr.ior;
        out.transmission = pbr.transmission;
        out.normal_scale = pbr.normal_scale;
        out.alpha_factor = pbr.alpha_factor;
        out.flags = if pbr.thin { MATERIAL_THIN } else { 0 };
        match pbr.alpha {
            AlphaMode::Opaque => {}
            AlphaMode::Mask(cutoff) => {
                out.flags |= MATERIAL_MASK;
                out.alpha_cutoff = cutoff;
            }
            AlphaMode::Blend => out.flags |= MATERIAL_BLEND,
        }
        out.slots[SLOT_METAL_ROUGH] = texture_slot(pbr.metal_rough_texture.as_ref());
        out.slots[SLOT_NORMAL] = texture_slot(pbr.normal_texture.as_ref());
        out.slots[SLOT_EMISSION] = texture_slot(pbr.emission_texture.as_ref());
    }
    out
}

/// A texture use as the shaders read it; texture -1 for none.
fn texture_slot(r: Option<&TextureRef>) -> GpuTextureSlot {
    let Some(r) = r else {
        return GpuTextureSlot::NONE;
    };
    let mode = |w: Wrap| match w {
        Wrap::Repeat => WRAP_REPEAT,
        Wrap::Clamp => WRAP_CLAMP,
        Wrap::Mirror => WRAP_MIRROR,
    };
    GpuTextureSlot {
        u: r.transform[0],
        texture: r.texture as i32,
        v: r.transform[1],
        wrap: mode(r.wrap[0]) | (mode(r.wrap[1]) << 2),
    }
}

/// A material's mean emitted radiance: its emission times its emission texture's mean (what
/// its emitters are chosen by).
fn mean_emission(m: &Material, textures: &[Texture]) -> Vec3 {
    let texture = m
        .metal_rough
        .and_then(|pbr| pbr.emission_texture)
        .and_then(|r| textures.get(r.texture as usize));
    m.emission * texture.map_or(Vec3::ONE, Texture::mean_linear)
}
