//! A scene prepared once for rendering and shared by both backends.

use std::sync::Arc;

use pathlight_scene::{Environment, Scene};

use crate::environment::EnvironmentData;
use crate::error::GeometryError;
use crate::geometry::Geometry;
use crate::shading::Shading;
use crate::textures::Textures;

/// Everything a backend needs of a scene but the camera and the settings: its geometry
/// and BVH and its textures (built once, shared), and its shading (rebuilt when materials
/// change). Cloning is cheap: the large parts are shared.
#[derive(Debug, Clone)]
pub struct PreparedScene {
    /// Shapes, triangles and the BVH.
    pub geometry: Arc<Geometry>,
    /// Texels, and where each texture lies.
    pub textures: Arc<Textures>,
    /// The environment map's texels and sampling distribution (placeholders without one).
    pub environment: Arc<EnvironmentData>,
    /// Materials, lights, environment.
    pub shading: Shading,
}

impl PreparedScene {
    /// Builds the BVH and the buffers of `scene`; refuses geometry that is not finite or
    /// beyond the coordinate limit.
    pub fn new(scene: &Scene) -> Result<Self, GeometryError> {
        let geometry = Geometry::build(&scene.objects)?;
        let textures = Textures::build(&scene.textures);
        let shading = Shading::build(scene, &geometry, &textures);
        Ok(Self {
            geometry: Arc::new(geometry),
            textures: Arc::new(textures),
            environment: Arc::new(match &scene.environment {
                Environment::Map(map) => EnvironmentData::build(&map.image),
                Environment::Constant(_) => EnvironmentData::none(),
            }),
            shading,
        })
    }

    /// The shading of `scene`, whose objects must be this scene's (only their materials,
    /// the materials themselves and a constant environment may differ; an environment map
    /// must be this scene's, its strength and rotation may differ). Textures are kept: a
    /// material may only use the textures the scene was prepared with.
    pub fn shading_of(&self, scene: &Scene) -> Shading {
        Shading::build(scene, &self.geometry, &self.textures)
    }
}
