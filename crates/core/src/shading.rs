//! What the scene's surfaces are made of and what lights them: the materials, each
//! object's material, the light table and the environment. Cheap to rebuild (a light toggle
//! rebuilds it, keeping the [`Geometry`]).

use bytemuck::Zeroable;
use glam::Vec3;
use pathlight_scene::{Conductor, Material, Scene};

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
    /// Constant environment radiance.
    pub environment: Vec3,
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
            environment: scene.environment,
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
