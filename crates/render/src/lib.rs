//! pathlight's GPU side: adapter choice, the WGSL integrator and the progressive film.

pub mod context;
pub mod display;
pub mod error;
pub mod renderer;
pub mod scene_buffers;
pub mod shaders;

pub use context::GpuContext;
pub use error::RenderError;
pub use pathlight_core::Film;
pub use renderer::{Accel, ProgressiveRenderer};
