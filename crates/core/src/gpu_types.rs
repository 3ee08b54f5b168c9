//! Every host struct that WGSL also declares (in `crates/gpu/shaders/scene.wgsl`,
//! `camera.wgsl` and `integrator.wgsl`; each declaration names its host struct here).
//!
//! Every struct is `#[repr(C)]` + `Pod`, uses no `vec3` without the scalar that pads it to
//! 16 bytes, and is pinned in size here and in field offsets by a naga test in
//! `crates/gpu/tests/shaders.rs`.

use bytemuck::{Pod, Zeroable};

/// [`GpuObject::kind`] of a parallelogram.
pub const KIND_QUAD: u32 = 0;
/// [`GpuObject::kind`] of a sphere.
pub const KIND_SPHERE: u32 = 1;
/// [`GpuObject::kind`] of a cylinder.
pub const KIND_CYLINDER: u32 = 2;
/// [`GpuObject::kind`] of a triangle mesh.
pub const KIND_MESH: u32 = 3;

/// [`GpuObject::light`] of an object that does not emit.
pub const NO_LIGHT: u32 = u32::MAX;

/// [`GpuRenderParams::sampler`]: padded Owen-scrambled Sobol.
pub const SAMPLER_SOBOL: u32 = 0;
/// [`GpuRenderParams::sampler`]: independent hashed random numbers.
pub const SAMPLER_INDEPENDENT: u32 = 1;

/// [`GpuObject::flags`] bit: shade a mesh with geometric normals.
pub const FLAG_FLAT: u32 = 1;
/// [`GpuObject::flags`] bit: a cylinder closed by two disks.
pub const FLAG_CAPS: u32 = 2;
/// [`GpuObject::flags`] bit: a mesh whose material has alpha holes (masked or blended), so
/// that a ray tests the texel where it hits before it stops.
pub const FLAG_ALPHA: u32 = 4;
/// [`GpuObject::flags`] bit: a mesh placed as an instance of a shared mesh, whose triangles
/// and tree are in its own space; [`GpuObject::instance`] names its transforms.
pub const FLAG_INSTANCE: u32 = 8;
/// [`GpuObject::flags`] bit: an instance whose placement mirrors (negative determinant), so
/// that its triangles' front side and bitangents turn over.
pub const FLAG_MIRRORED: u32 = 16;

/// One object of the scene, in the scene's order. WGSL: `Object`.
///
/// Geometry by kind: quad `a` = origin, `b` = edge_u, `c` = edge_v; sphere `a.xyz` = centre,
/// `a.w` = radius, `b.x` = texture rotation (radians); cylinder `a.xyz` = p0, `a.w` = radius,
/// `b.xyz` = p1; mesh: its triangles `first_triangle ..` in the vertex buffer, and the box
/// around them in the world from `a.xyz` to `b.xyz` (for the seed's bounding-volume scheme);
/// an instance ([`FLAG_INSTANCE`]) shares its triangles with the other placements of its mesh.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct GpuObject {
    /// First geometry vector.
    pub a: [f32; 4],
    /// Second geometry vector.
    pub b: [f32; 4],
    /// Third geometry vector.
    pub c: [f32; 4],
    /// `KIND_*`.
    pub kind: u32,
    /// Index into the material buffer.
    pub material: u32,
    /// `FLAG_*` bits.
    pub flags: u32,
    /// Its first entry in the light table, or [`NO_LIGHT`]. A mesh has one entry per
    /// triangle: triangle `t` is entry `light + t - first_triangle`.
    pub light: u32,
    /// Mesh only: index of its first triangle in the vertex buffer (in triangles).
    pub first_triangle: u32,
    /// Mesh only: number of its triangles (`first_triangle ..` in the vertex buffer).
    pub triangle_count: u32,
    /// An instance ([`FLAG_INSTANCE`]): its entry in the instance buffer.
    pub instance: u32,
    /// Padding to 16 bytes.
    pub pad: u32,
}
const _: () = assert!(size_of::<GpuObject>() == 80);

/// [`GpuLight::kind`] of an emissive quad, sphere or cylinder, or one triangle of an
/// emissive mesh (`area_light.wgsl`).
pub const LIGHT_AREA: u32 = 0;
/// [`GpuLight::kind`] of a point or spot light (`point_light.wgsl`).
pub const LIGHT_POINT: u32 = 1;
/// [`GpuLight::kind`] of a sun: a directional light, or a small disk of the sky
/// (`sun_light.wgsl`).
pub const LIGHT_SUN: u32 = 2;

/// One entry of the light table, chosen with probability proportional to its power: a light
/// of type `kind` (a `LIGHT_*`; its file in the kernels samples it). WGSL: `Light`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct GpuLight {
    /// `LIGHT_*`.
    pub kind: u32,
    /// [`LIGHT_AREA`]: index into the object buffer; [`LIGHT_POINT`], [`LIGHT_SUN`]: the
    /// first `vec4` of its parameter block (`crate::light_table`).
    pub index: u32,
    /// [`LIGHT_AREA`]: the triangle of a mesh, 0 for a whole shape.
    pub primitive: u32,
    /// Probability of choosing a light up to and including this one (among the table's
    /// lights; the environment is chosen first with `env_pmf`).
    pub cdf: f32,
    /// Probability of choosing this light among the table's.
    pub pmf: f32,
}
const _: () = assert!(size_of::<GpuLight>() == 20);

/// One node of the 4-wide BVH both backends walk ([`crate::geometry::Geometry::nodes`]): its
/// four children's boxes in structure-of-arrays form, and what each child is. Aligned to 16
/// bytes so that the CPU loads each row of four as one SIMD register. WGSL: `WideNode`.
#[repr(C, align(16))]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct GpuWideNode {
    /// The children's minimum x coordinates; an unused child has an inverted box
    /// (+inf to -inf) that no ray enters.
    pub lo_x: [f32; 4],
    /// The children's minimum y coordinates.
    pub lo_y: [f32; 4],
    /// The children's minimum z coordinates.
    pub lo_z: [f32; 4],
    /// The children's maximum x coordinates.
    pub hi_x: [f32; 4],
    /// The children's maximum y coordinates.
    pub hi_y: [f32; 4],
    /// The children's maximum z coordinates.
    pub hi_z: [f32; 4],
    /// Per child: an inner node's index, or a leaf's first primitive.
    pub first: [u32; 4],
    /// Per child: a leaf's number of primitives, with [`SHAPE_LEAF`] set when any of them
    /// is not a triangle; 0 for an inner node or an unused child.
    pub count: [u32; 4],
}
const _: () = assert!(size_of::<GpuWideNode>() == 128);

/// [`GpuWideNode::count`] bit: the leaf holds a shape (not only triangles), and the GPU tests
/// it as soon as it enters the box instead of pushing it.
pub const SHAPE_LEAF: u32 = 1 << 31;

/// One mesh vertex. WGSL: `Vertex`; a triangle names three ([`crate::Geometry::triangles`],
/// WGSL `triangles`).
/// Unit vectors are octahedral-encoded ([`crate::octahedral`]) to keep a corner in 32 bytes.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct GpuVertex {
    /// World position.
    pub position: [f32; 3],
    /// Shading normal (unit, or [`crate::octahedral::ZERO`] for none).
    pub normal: u32,
    /// Texture coordinates.
    pub uv: [f32; 2],
    /// Tangent along +u (unit; [`crate::octahedral::ZERO`] when the mesh has none), with the
    /// sign of the bitangent in [`crate::octahedral::SIGN_BIT`]: `cross(normal, tangent) *
    /// sign` points along +v.
    pub tangent: u32,
    /// Vertex colour as RGBA8: red in the low byte, the colour channels sRGB-encoded
    /// (linear once decoded), alpha linear; [`WHITE`] without one.
    pub color: u32,
}

/// [`GpuVertex::color`] of a vertex without a colour: opaque white.
pub const WHITE: u32 = u32::MAX;
const _: () = assert!(size_of::<GpuVertex>() == 32);

/// [`GpuPrimitive::triangle`] of a quad, sphere or cylinder.
pub const NO_TRIANGLE: u32 = u32::MAX;

/// One primitive of the BVH, in leaf order: a triangle with its three corners (the
/// watertight test needs the corners themselves: corners rebuilt from edges would round
/// differently in the triangles that share them) or a whole analytic shape. WGSL:
/// `Primitive`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct GpuPrimitive {
    /// Triangle: corner 0.
    pub v0: [f32; 3],
    /// The object it belongs to (index into the object buffer).
    pub object: u32,
    /// Triangle: corner 1.
    pub v1: [f32; 3],
    /// The triangle's index in the vertex buffer, or [`NO_TRIANGLE`] for a shape.
    pub triangle: u32,
    /// Triangle: corner 2.
    pub v2: [f32; 3],
    /// An instance ([`INSTANCE`]): the root node of its mesh's tree.
    pub root: u32,
}
const _: () = assert!(size_of::<GpuPrimitive>() == 48);

/// [`GpuPrimitive::triangle`] of a placed instance: a ray that enters its box walks its
/// mesh's tree from [`GpuPrimitive::root`] in the mesh's space.
pub const INSTANCE: u32 = u32::MAX - 1;

/// The placement of an instance ([`FLAG_INSTANCE`]): rows of its affine transforms, each
/// `[x, y, z, translation]`. WGSL: `Instance`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct GpuInstance {
    /// World to the mesh's space (rays enter by it; normals leave by its transpose).
    pub to_object: [[f32; 4]; 3],
    /// The mesh's space to the world (light samples and tangents leave by it).
    pub to_world: [[f32; 4]; 3],
}
const _: () = assert!(size_of::<GpuInstance>() == 96);

/// [`GpuMaterial::flags`] bit: texels with alpha below `alpha_cutoff` are holes.
pub const MATERIAL_MASK: u32 = 1;
/// [`GpuMaterial::flags`] bit: alpha is the probability that a ray stops.
pub const MATERIAL_BLEND: u32 = 2;
/// [`GpuMaterial::flags`] bit: the model's block has its last, rarely used vector (of
/// `MODEL_PARAMS` in `crate::materials`; the metal-rough model's sheen), which the kernels
/// load only for materials with this bit.
pub const MATERIAL_LONG_BLOCK: u32 = 4;
/// A material's texture `TEXTURE_*` is slot `textures + TEXTURE_*` of the texture slots,
/// present when bit `TEXTURE_*` of `texture_mask` is set: the base colour (sRGB; alpha in
/// its fourth channel).
pub const TEXTURE_BASE: u32 = 0;
/// [`TEXTURE_BASE`]'s kin: the tangent-space normal map (linear).
pub const TEXTURE_NORMAL: u32 = 1;
/// [`TEXTURE_BASE`]'s kin: the emission (sRGB).
pub const TEXTURE_EMISSION: u32 = 2;
/// [`TEXTURE_BASE`]'s kin: the model's own textures, from this index on, in the order its
/// kernel file names them.
pub const TEXTURE_MODEL: u32 = 3;
/// The metal-rough model's `KHR_materials_transmission` texture (red: transmission).
pub const TEXTURE_TRANSMISSION: u32 = TEXTURE_MODEL + 1;
/// ... `KHR_materials_specular`'s strength texture (alpha).
pub const TEXTURE_SPECULAR: u32 = TEXTURE_MODEL + 2;
/// ... `KHR_materials_specular`'s colour texture (sRGB).
pub const TEXTURE_SPECULAR_COLOR: u32 = TEXTURE_MODEL + 3;
/// ... `KHR_materials_clearcoat`'s strength texture (red).
pub const TEXTURE_CLEARCOAT: u32 = TEXTURE_MODEL + 4;
/// ... `KHR_materials_clearcoat`'s roughness texture (green).
pub const TEXTURE_CLEARCOAT_ROUGHNESS: u32 = TEXTURE_MODEL + 5;
/// ... `KHR_materials_sheen`'s colour texture (sRGB).
pub const TEXTURE_SHEEN_COLOR: u32 = TEXTURE_MODEL + 6;
/// ... `KHR_materials_sheen`'s roughness texture (alpha).
pub const TEXTURE_SHEEN_ROUGHNESS: u32 = TEXTURE_MODEL + 7;
/// The normal map of a model's top layer, its coat (the metal-rough model's
/// `KHR_materials_clearcoat` normal texture; linear), scaled by
/// [`GpuMaterial::coat_normal_scale`]: the surface gives it a shading normal of its own.
pub const TEXTURE_COAT_NORMAL: u32 = TEXTURE_MODEL + 8;

/// [`GpuTextureSlot::wrap`] mode (2 bits per axis, u in the low bits): tile.
pub const WRAP_REPEAT: u32 = 0;
/// [`GpuTextureSlot::wrap`] mode: hold the edge texel.
pub const WRAP_CLAMP: u32 = 1;
/// [`GpuTextureSlot::wrap`] mode: tile, every other copy mirrored.
pub const WRAP_MIRROR: u32 = 2;

/// One use of a texture by a material: where its texels lie, the affine map from surface
/// to texture coordinates and the wrapping (all zero for a texture the material lacks).
/// WGSL: `TextureSlot`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct GpuTextureSlot {
    /// Texture u = dot(u.xy, uv) + u.z.
    pub u: [f32; 3],
    /// The texture's first texel in the texel buffer.
    pub offset: u32,
    /// Texture v = dot(v.xy, uv) + v.z.
    pub v: [f32; 3],
    /// `WRAP_*` of u, then of v shifted left by 2.
    pub wrap: u32,
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// Padding.
    pub pad: [u32; 2],
}
const _: () = assert!(size_of::<GpuTextureSlot>() == 48);

/// A material's common part in linear RGB; its model's parameters are a block of
/// `vec4f`s in the material parameter buffer ([`crate::materials`] writes both, each model's
/// kernel file reads its block). A new model changes neither this struct nor its layout.
/// WGSL: `Material`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct GpuMaterial {
    /// Base colour, multiplied by the base texture.
    pub base_color: [f32; 3],
    /// `MODEL_*` of [`crate::materials`].
    pub model: u32,
    /// Emitted radiance (front side), multiplied by the emission texture.
    pub emission: [f32; 3],
    /// `MATERIAL_*` bits.
    pub flags: u32,
    /// Alpha below which a masked texel is a hole.
    pub alpha_cutoff: f32,
    /// Base colour alpha factor.
    pub alpha_factor: f32,
    /// Scale of the normal map's x and y.
    pub normal_scale: f32,
    /// Index of its model's first parameter vector in the parameter buffer.
    pub params: u32,
    /// Index of its first texture slot (see [`TEXTURE_BASE`]).
    pub textures: u32,
    /// Bit `TEXTURE_*` set when the material has that texture; 0 for none.
    pub texture_mask: u32,
    /// Scale of the x and y of the coat's normal map ([`TEXTURE_COAT_NORMAL`]).
    pub coat_normal_scale: f32,
    /// Padding.
    pub pad: u32,
}
const _: () = assert!(size_of::<GpuMaterial>() == 64);

impl GpuMaterial {
    /// A black, non-emissive, opaque and untextured material of model `model` (a `MODEL_*`
    /// of [`crate::materials`]) whose parameters start at vector `params`.
    pub const fn new(model: u32, params: u32) -> Self {
        Self {
            base_color: [0.0; 3],
            model,
            emission: [0.0; 3],
            flags: 0,
            alpha_cutoff: 0.0,
            alpha_factor: 1.0,
            normal_scale: 1.0,
            params,
            textures: 0,
            texture_mask: 0,
            coat_normal_scale: 1.0,
            pad: 0,
        }
    }
}

/// The camera as the integrator reads it: the eye and the image plane at unit distance.
/// WGSL: `CameraParams`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct GpuCamera {
    /// Eye position (the lens centre).
    pub position: [f32; 3],
    /// Radius of the thin lens; 0 for a pinhole.
    pub lens_radius: f32,
    /// Unit view direction.
    pub forward: [f32; 3],
    /// Distance along `forward` of the plane in focus.
    pub focus_distance: f32,
    /// Right vector scaled to half the image width at unit distance.
    pub right: [f32; 3],
    /// Padding.
    pub pad2: u32,
    /// Up vector scaled to half the image height at unit distance.
    pub up: [f32; 3],
    /// Padding.
    pub pad3: u32,
}
const _: () = assert!(size_of::<GpuCamera>() == 64);

/// Per-dispatch constants of the integrator: the camera, the image, the settings and the
/// light selection. WGSL: `RenderParams`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct GpuRenderParams {
    /// The camera.
    pub camera: GpuCamera,
    /// Constant environment radiance.
    pub environment: [f32; 3],
    /// Probability of sampling the environment rather than a shape light.
    pub env_pmf: f32,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Samples per pixel already accumulated before this dispatch.
    pub sample_offset: u32,
    /// Samples per pixel this dispatch adds.
    pub batch_samples: u32,
    /// First row this dispatch covers (long renders are split into row bands).
    pub row_offset: u32,
    /// End (exclusive) of the row band this dispatch covers.
    pub row_end: u32,
    /// Maximum path length in segments.
    pub max_depth: u32,
    /// Depth from which Russian roulette applies.
    pub rr_depth: u32,
    /// Seed of the random sequence.
    pub seed: u32,
    /// `SAMPLER_*`.
    pub sampler: u32,
    /// Number of objects.
    pub object_count: u32,
    /// Number of entries in the light table.
    pub light_count: u32,
    /// Environment map width in texels; 0 when there is none.
    pub env_width: u32,
    /// Environment map height in texels.
    pub env_height: u32,
    /// Factor from decoded environment texels to radiance.
    pub env_scale: f32,
    /// 1: the passes also accumulate the auxiliary images ([`GpuAovPixel`]); 0: not.
    pub aovs: u32,
    /// Cosine and sine of the map's turn about +y.
    pub env_rotation: [f32; 2],
    /// Padding.
    pub pad1: [u32; 2],
}
const _: () = assert!(size_of::<GpuRenderParams>() == 160);

/// One pixel of the accumulation buffer. WGSL: `AccumPixel`.
///
/// Per RGB channel the running sum of samples is the 64-bit fixed-point number
/// `hi + lo / 2^32`, added with integer carries on the GPU, so it is exact and merges
/// exactly; the fourth lane is unused.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
pub struct GpuAccumPixel {
    /// Integer part of the sum.
    pub hi: [u32; 4],
    /// Fraction of the sum, in units of 2^-32.
    pub lo: [u32; 4],
}

impl GpuAccumPixel {
    /// `self += other` per channel on the 64-bit fixed point, saturating instead of
    /// wrapping (WGSL `add_fixed`): exact, and the same in any order.
    pub fn accumulate(&mut self, other: &Self) {
        for c in 0..4 {
            let (lo, carry) = self.lo[c].overflowing_add(other.lo[c]);
            let (hi, wrapped) = self.hi[c].overflowing_add(other.hi[c]);
            let (hi, carried_over) = hi.overflowing_add(u32::from(carry));
            (self.hi[c], self.lo[c]) = if wrapped || carried_over {
                (u32::MAX, u32::MAX)
            } else {
                (hi, lo)
            };
        }
    }

    /// `channel c += x`, `x` a 64-bit fixed-point number (whole part in the high word),
    /// saturating as [`Self::accumulate`] does.
    #[inline(always)]
    pub fn add_to_channel(&mut self, c: usize, x: u64) {
        let sum = (u64::from(self.hi[c]) << 32 | u64::from(self.lo[c])).saturating_add(x);
        self.hi[c] = (sum >> 32) as u32;
        self.lo[c] = sum as u32;
    }

    /// The sum of channel `c` as a float.
    pub fn channel_sum(&self, c: usize) -> f64 {
        f64::from(self.hi[c]) + f64::from(self.lo[c]) / 4_294_967_296.0
    }
}
const _: () = assert!(size_of::<GpuAccumPixel>() == 32);

/// One pixel of the auxiliary images a denoiser reads, accumulated like the colour (a sum
/// per channel in [`GpuAccumPixel`]'s fixed point) from the same samples: per sample, the
/// albedo (in [0, 1]) and the shading normal mapped from [-1, 1] to `(n + 1) / 2`, both of
/// the first surface a path meets that is not a perfect mirror or glass (ARCHITECTURE.md,
/// "Auxiliary images"). WGSL: `AovPixel`.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
pub struct GpuAovPixel {
    /// Sums of the albedo.
    pub albedo: GpuAccumPixel,
    /// Sums of the normal, as `(n + 1) / 2`.
    pub normal: GpuAccumPixel,
}
const _: () = assert!(size_of::<GpuAovPixel>() == 64);

impl GpuAovPixel {
    /// `self += other`, both images, exactly (see [`GpuAccumPixel::accumulate`]).
    pub fn accumulate(&mut self, other: &Self) {
        self.albedo.accumulate(&other.albedo);
        self.normal.accumulate(&other.normal);
    }
}
