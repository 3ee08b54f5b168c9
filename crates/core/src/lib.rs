//! pathlight's core: the scene description and its loading, the BVH, and the data laid out
//! for the GPU. Nothing here depends on wgpu.

pub mod accel;
pub mod default_scene;
pub mod desc;
pub mod error;
pub mod film;
pub mod frame;
pub mod gpu;
pub mod load;
pub mod mesh;
pub mod packet;
pub mod revolve;
pub mod scene;
pub mod texture;
pub mod trace;
pub mod wide_bvh;

pub use accel::GpuScene;
pub use error::SceneError;
pub use film::Film;
pub use load::{SceneSource, load_scene, load_scene_file};
pub use scene::{Camera, Material, Object, RenderSettings, Scene, Shape};
pub use wide_bvh::{Tracer, WideBvh};
