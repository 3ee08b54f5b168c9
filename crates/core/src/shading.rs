//! What the scene's surfaces are made of and what lights them: the materials, each
//! object's material, the light table and the environment. Cheap to rebuild (a light toggle
//! rebuilds it, keeping the [`Geometry`]).

use bytemuck::Zeroable;
use glam::Vec3;
use pathlight_scene::{Environment, Material, Scene, Texture};

use crate::environment::texel_scale;
use crate::geometry::Geometry;
use crate::gpu_types::{
    FLAG_ALPHA, GpuLight, GpuMaterial, GpuObject, GpuTextureSlot, KIND_MESH, MATERIAL_BLEND,
    MATERIAL_MASK,
};
use crate::light_table;
use crate::materials::PackedMaterials;
use crate::textures::Textures;

/// The materials and lights of a scene, in the form both backends read.
#[derive(Debug, Clone, PartialEq)]
pub struct Shading {
    /// Objects in the scene's order: [`Geometry::shapes`] with their material and first
    /// light-table entry. Never empty (a placeholder when there are no objects).
    pub objects: Vec<GpuObject>,
    /// Number of real objects.
    pub object_count: u32,
    /// Materials' common parts ([`PackedMaterials::materials`]). Never empty.
    pub materials: Vec<GpuMaterial>,
    /// The parameter blocks: the materials' models' ([`PackedMaterials::params`]), then the
    /// point and sun lights' ([`light_table::build`]).
    pub param_blocks: Vec<[f32; 4]>,
    /// Their texture slots ([`PackedMaterials::texture_slots`]). Never empty.
    pub texture_slots: Vec<GpuTextureSlot>,
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
    /// The materials, lights and environment of `scene`, whose objects `geometry` holds and
    /// whose textures `textures` holds.
    pub fn build(scene: &Scene, geometry: &Geometry, textures: &Textures) -> Self {
        let PackedMaterials {
            materials,
            params: mut param_blocks,
            texture_slots,
        } = PackedMaterials::build(&scene.materials, textures);
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
        let (lights, light_count) = light_table::build(
            &mut objects,
            &emission,
            geometry,
            &scene.lights,
            &mut param_blocks,
        );
        let object_count = objects.len() as u32;
        if objects.is_empty() {
            objects.push(GpuObject::zeroed());
        }
        Self {
            objects,
            object_count,
            materials,
            param_blocks,
            texture_slots,
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

/// A material's mean emitted radiance: its emission times its emission texture's mean (what
/// its emitters are chosen by).
fn mean_emission(m: &Material, textures: &[Texture]) -> Vec3 {
    let texture = m
        .emission_texture
        .and_then(|r| textures.get(r.texture as usize));
    m.emission * texture.map_or(Vec3::ONE, Texture::mean_linear)
}
