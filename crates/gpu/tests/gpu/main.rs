//! GPU tests on a real wgpu adapter (lavapipe on CI), one binary sharing one device.

mod common;
mod display;
mod extreme;
mod furnace;
mod metal_rough;
mod profile;
mod render;
mod state;
mod trace;
mod twin;
mod wavefront;
