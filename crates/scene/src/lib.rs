//! pathlight's scene: the scene file format and its assets (OBJ meshes, surfaces of
//! revolution, textures), read into a [`Scene`] in world space and linear RGB. Plain data:
//! nothing here knows how a backend renders it (that is `pathlight-core`'s job).

pub mod camera;
pub mod default_scene;
pub mod desc;
pub mod environment;
pub mod error;
mod exact;
pub mod gltf_file;
pub mod light;
pub mod load;
pub mod material;
pub mod memory;
pub mod mesh;
pub mod revolve;
pub mod settings;
pub mod shape;
pub mod tangents;
#[cfg(feature = "test-support")]
pub mod testing;
pub mod texture;

pub use camera::Camera;
pub use environment::{Environment, EnvironmentMap, HdrImage};
pub use error::{RangeError, SceneError};
pub use gltf_file::{GREY_SKY, GltfModel, gltf_scene, load_gltf};
pub use light::{Cone, Light, LightKind};
pub use load::{SceneSource, load_materials, load_scene, load_scene_file};
pub use material::{
    AlphaMode, Conductor, LayerTextures, Lobes, Material, MetalRough, Model, TextureRef, Wrap,
};
pub use settings::{RenderSettings, Sampler};
pub use shape::{Instance, Object, Shape, TriangleMesh};
pub use texture::Texture;

/// A scene ready to be prepared for rendering: resolved, validated, in world space and
/// linear RGB.
#[derive(Debug, Clone, PartialEq)]
pub struct Scene {
    /// The camera.
    pub camera: Camera,
    /// Sampling settings.
    pub settings: RenderSettings,
    /// Light arriving from infinitely far away.
    pub environment: Environment,
    /// Materials.
    pub materials: Vec<Material>,
    /// Textures referenced by materials.
    pub textures: Vec<Texture>,
    /// Objects.
    pub objects: Vec<Object>,
    /// Point, spot and sun lights.
    pub lights: Vec<Light>,
}
