//! What the scene's surfaces are made of and what lights them: the materials, each
//! object's material, the light table and the environment. Cheap to rebuild (a light toggle
//! rebuilds it, keeping the [`Geometry`]).

use bytemuck::Zeroable;
use glam::Vec3;
use pathlight_scene::{Conductor, Environment, Material, Scene};

use crate::environment::texel_scale;
use crate::geometry::Geometry;
use crate::gpu_types::{GpuLight, GpuMaterial, GpuObject};
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
        let (lights, light_count) = light_table::build(&mut objects, &materials, geometry);
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
    GpuMaterial {
        base_color: m.base_color.to_array(),
        texture: m.texture.map_or(-1, |t| t as i32),
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
        pad: [0; 3],
    }
}
