//! A material at a surface point, and the one dispatch on its model: the common textures
//! (base colour, emission) applied here, the model's own texture step, BSDF evaluation and
//! sampling in the model's module ([`crate::lobes`], [`crate::metal_rough`]). Twin of
//! `material.wgsl`.

use glam::{Vec2, Vec3A, Vec4};
use pathlight_core::gpu_types::{GpuMaterial, MATERIAL_LONG_BLOCK, TEXTURE_BASE, TEXTURE_EMISSION};
use pathlight_core::materials::MODEL_METAL_ROUGH;

use crate::cpu_scene::CpuScene;
use crate::lobes::{LobesParams, eval_lobes, has_continuous_lobes, lobes_albedo, sample_lobes};
use crate::metal_rough::{
    MetalRoughParams, has_continuous_metal_rough, metal_rough_albedo, metal_rough_textured, sample,
};
use crate::microfacet::{BsdfEval, BsdfSample};
use crate::surface::Surface;
use crate::textures::{has_texture, material_color};

/// Vectors of a model's parameter block (WGSL `MODEL_PARAMS`; `material_at` loads them one
/// by one, the last only for a material flagged `MATERIAL_LONG_BLOCK`).
pub const MODEL_PARAMS: usize = pathlight_core::materials::MODEL_PARAMS;
const _: () = assert!(MODEL_PARAMS == 5 && pathlight_core::materials::MODEL_PARAMS_SHORT == 4);

/// A material with its textures applied at a point: what its model's BSDF reads. Twin of
/// WGSL `MaterialPoint`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MaterialPoint {
    /// `MODEL_*` of `pathlight_core::materials`.
    pub model: u32,
    /// Base colour (texture times factor).
    pub base_color: Vec3A,
    /// Emitted radiance (texture times factor).
    pub emission: Vec3A,
    /// The model's parameter block, its texture step applied; its module decodes it.
    pub params: [Vec4; MODEL_PARAMS],
}

/// The material of surface `s` at its texture coordinates, its base colour times the vertex
/// colour. Twin of WGSL `material_at`.
#[inline(always)]
pub fn material_at(scene: &CpuScene, s: &Surface) -> MaterialPoint {
    let (index, uv) = (s.material, s.uv);
    let m = &scene.materials[index as usize];
    let first = m.params as usize;
    let block = &scene.param_blocks[first..first + MODEL_PARAMS];
    let mut params = [
        Vec4::from_array(block[0]),
        Vec4::from_array(block[1]),
        Vec4::from_array(block[2]),
        Vec4::from_array(block[3]),
        Vec4::ZERO,
    ];
    if m.flags & MATERIAL_LONG_BLOCK != 0 {
        params[4] = Vec4::from_array(block[4]);
    }
    let mut base_color = Vec3A::from(m.base_color) * s.color;
    if has_texture(m, TEXTURE_BASE) {
        base_color *= Vec3A::from(material_color(scene, m, TEXTURE_BASE, uv).truncate());
    }
    if m.model == MODEL_METAL_ROUGH {
        metal_rough_textured(scene, &mut params, m, uv);
    }
    MaterialPoint {
        model: m.model,
        base_color,
        emission: emission(scene, m, uv),
        params,
    }
}

/// The radiance material `index` emits at `uv` (its front side). Twin of WGSL
/// `emission_at`.
#[inline(always)]
pub fn emission_at(scene: &CpuScene, index: u32, uv: Vec2) -> Vec3A {
    emission(scene, &scene.materials[index as usize], uv)
}

/// The radiance material `m` emits at `uv`.
#[inline(always)]
fn emission(scene: &CpuScene, m: &GpuMaterial, uv: Vec2) -> Vec3A {
    let emission = Vec3A::from(m.emission);
    if has_texture(m, TEXTURE_EMISSION) {
        return emission * Vec3A::from(material_color(scene, m, TEXTURE_EMISSION, uv).truncate());
    }
    emission
}

/// `f * |cos_i|` of the non-delta part of the BSDF and the density with which
/// [`sample_material`] produces `wi`. Twin of WGSL `eval_material`. (Here and below, the
/// last arm is `MODEL_LOBES`.)
#[inline(always)]
pub fn eval_material(p: &MaterialPoint, s: &Surface, wo: Vec3A, wi: Vec3A) -> BsdfEval {
    match p.model {
        MODEL_METAL_ROUGH => crate::metal_rough::eval(
            &MetalRoughParams::decode(&p.params),
            p.base_color,
            s,
            wo,
            wi,
        ),
        _ => eval_lobes(&LobesParams::decode(&p.params), p.base_color, s, wo, wi),
    }
}

/// A direction sampled from the BSDF. Twin of WGSL `sample_material`.
#[inline(always)]
pub fn sample_material(
    p: &MaterialPoint,
    s: &Surface,
    wo: Vec3A,
    u_lobe: f32,
    u_fresnel: f32,
    u: Vec2,
) -> BsdfSample {
    let color = p.base_color;
    match p.model {
        MODEL_METAL_ROUGH => {
            let m = MetalRoughParams::decode(&p.params);
            sample(&m, color, s, wo, u_lobe, u_fresnel, u)
        }
        _ => sample_lobes(
            &LobesParams::decode(&p.params),
            color,
            s,
            wo,
            u_lobe,
            u_fresnel,
            u,
        ),
    }
}

/// The material's albedo for a denoiser's auxiliary image (the approximate colour of the
/// surface, independent of light and view; in [0, 1] for colours in [0, 1]). Twin of WGSL
/// `material_albedo`.
#[inline(always)]
pub fn material_albedo(p: &MaterialPoint) -> Vec3A {
    match p.model {
        MODEL_METAL_ROUGH => metal_rough_albedo(&MetalRoughParams::decode(&p.params), p.base_color),
        _ => lobes_albedo(&LobesParams::decode(&p.params), p.base_color),
    }
}

/// What the inside of a solid material absorbs per unit length (zero for every other):
/// a path that reaches it from inside keeps `exp(-absorption t)` of its segment of length
/// `t`. Twin of WGSL `material_absorption`.
#[inline(always)]
pub fn material_absorption(p: &MaterialPoint) -> Vec3A {
    match p.model {
        MODEL_METAL_ROUGH => {
            let m = MetalRoughParams::decode(&p.params);
            if m.thin { Vec3A::ZERO } else { m.attenuation }
        }
        _ => Vec3A::ZERO,
    }
}

/// Whether the material is purely diffuse: the lobes model with its Lambert lobe alone
/// ([`LobesParams::is_lambert`]).
#[inline(always)]
pub fn is_lambert(p: &MaterialPoint) -> bool {
    p.model != MODEL_METAL_ROUGH && LobesParams::decode(&p.params).is_lambert()
}

/// Whether the BSDF has a non-delta lobe (next-event estimation is worth doing). Twin of
/// WGSL `has_continuous_material_lobe`.
#[inline(always)]
pub fn has_continuous_material_lobe(p: &MaterialPoint) -> bool {
    match p.model {
        MODEL_METAL_ROUGH => {
            has_continuous_metal_rough(&MetalRoughParams::decode(&p.params), p.base_color)
        }
        _ => has_continuous_lobes(&LobesParams::decode(&p.params)),
    }
}
