//! The scene as the CPU backend shades it.

use glam::Vec3A;
use pathlight_core::GpuScene;
use pathlight_core::gpu::{GpuObject, KIND_QUAD};

/// The scene's GPU buffers, and per object what shading would otherwise recompute on every
/// hit and light sample: a quad's unit normal and area (the same values, bit for bit, as
/// computing them there).
#[derive(Debug, Clone)]
pub struct CpuScene {
    /// The buffers the WGSL twin reads.
    pub gpu: GpuScene,
    /// Per object: a quad's unit normal and area; zero for other kinds.
    quads: Vec<(Vec3A, f32)>,
}

impl CpuScene {
    /// Adds the per-object values to `gpu`.
    pub fn new(gpu: GpuScene) -> Self {
        let quads = gpu
            .objects
            .iter()
            .map(|o| {
                if o.kind != KIND_QUAD {
                    return (Vec3A::ZERO, 0.0);
                }
                let normal = Vec3A::from_slice(&o.b).cross(Vec3A::from_slice(&o.c));
                (normal.normalize(), normal.length())
            })
            .collect();
        Self { gpu, quads }
    }

    /// The unit normal of quad `object` (the direction of `edge_u x edge_v`).
    #[inline(always)]
    pub fn quad_normal(&self, object: u32) -> Vec3A {
        self.quads[object as usize].0
    }

    /// The area of emitter `object` (`o` is its [`GpuObject`]), or of its triangle
    /// `primitive` for a mesh: [`GpuScene::emitter_area`].
    #[inline(always)]
    pub fn emitter_area(&self, object: u32, o: &GpuObject, primitive: u32) -> f32 {
        if o.kind == KIND_QUAD {
            self.quads[object as usize].1
        } else {
            self.gpu.emitter_area(o, primitive)
        }
    }
}
