//! The built-in default scene, compiled into the binary with its texture.

use crate::Scene;
use crate::error::SceneError;
use crate::load::{SceneSource, load_scene};

/// The default scene's file text (`scenes/default.toml`).
pub const TEXT: &str = include_str!("../../../scenes/default.toml");

/// Assets the default scene names, by the path it names them with.
pub const ASSETS: &[(&str, &[u8])] = &[(
    "../assets/earth.jpg",
    include_bytes!("../../../assets/earth.jpg"),
)];

/// Builds the default scene from the embedded text and assets.
pub fn load() -> Result<Scene, SceneError> {
    load_scene(&SceneSource {
        name: "<default scene>".into(),
        text: TEXT,
        base_dir: Default::default(),
        embedded: ASSETS,
    })
}
