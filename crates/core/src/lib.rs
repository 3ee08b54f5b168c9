//! pathlight's core: a [`Scene`](pathlight_scene::Scene) prepared once for rendering and
//! shared by both backends ([`PreparedScene`]: the BVH and the buffers both read, laid out
//! as WGSL declares them), the per-render constants (camera, settings), the film, and the
//! interface both backends implement ([`Renderer`]). Nothing here depends on wgpu.

pub mod accumulation;
pub mod bvh;
pub mod camera;
pub mod environment;
pub mod error;
pub mod film;
pub mod geometry;
pub mod gpu_types;
pub mod instance;
pub mod light_table;
pub mod materials;
pub mod octahedral;
pub mod params;
pub mod prepared;
pub mod renderer;
pub mod shading;
pub mod sheen_table;
pub mod state;
pub mod textures;
pub mod tonemap;

pub use accumulation::{Accumulation, SampleCursor};
pub use environment::EnvironmentData;
pub use error::{GeometryError, RenderError, error_message};
pub use film::Film;
pub use geometry::Geometry;
pub use prepared::PreparedScene;
pub use renderer::Renderer;
pub use shading::Shading;
pub use textures::Textures;
pub use tonemap::ToneMap;
