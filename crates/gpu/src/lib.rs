//! pathlight's GPU backend: adapter choice ([`context`]), the WGSL integrator assembled from
//! `shaders/` ([`wgsl`]), the scene on the device ([`scene_buffers`]), the progressive
//! renderer ([`GpuRenderer`]) and the viewer's display pass ([`display`]).

pub mod context;
pub mod dispatch_times;
pub mod display;
pub mod gpu_renderer;
pub mod kernel_trial;
pub mod pipeline;
pub mod scene_buffers;
pub mod wavefront;
pub mod wgsl;

pub use context::GpuContext;
pub use gpu_renderer::{Accel, GpuRenderer, IntegratorKernel, Kernel};
