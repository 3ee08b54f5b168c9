// Scene data shared by every pass: struct declarations (mirrored on the host by
// `crates/core/src/gpu_types.rs`, pinned by `crates/gpu/tests/shaders.rs`) and the bind
// group 0 buffers that `pathlight_core::PreparedScene` fills.
// No CPU twin: declarations only (the CPU backend reads the host structs, through
// `crates/cpu/src/cpu_scene.rs`).

const KIND_QUAD: u32 = 0u;
const KIND_SPHERE: u32 = 1u;
const KIND_CYLINDER: u32 = 2u;
const KIND_MESH: u32 = 3u;
const FLAG_FLAT: u32 = 1u;
const FLAG_CAPS: u32 = 2u;
const FLAG_ALPHA: u32 = 4u;
const FLAG_INSTANCE: u32 = 8u;
const FLAG_MIRRORED: u32 = 16u;

// One object, in the scene's order (a mesh's box is `a.xyz` to `b.xyz`). Host: `GpuObject`.
struct Object {
    a: vec4f,
    b: vec4f,
    c: vec4f,
    kind: u32,
    material: u32,
    flags: u32,
    // First light-table entry, or NO_LIGHT; a mesh has one per triangle.
    light: u32,
    // Mesh: its first triangle index.
    first_triangle: u32,
    // Mesh: how many triangles it has.
    triangle_count: u32,
    // An instance (FLAG_INSTANCE): its entry in `instances`.
    instance: u32,
    pad: u32,
}

const NO_LIGHT: u32 = 0xffffffffu;

// A light-table entry: a light of type `kind` (LIGHT_ of lights.wgsl; LIGHT_AREA: object
// `index`, its triangle `primitive`), chosen with probability pmf (cdf: cumulative). Host:
// `GpuLight`.
struct Light {
    kind: u32,
    index: u32,
    primitive: u32,
    cdf: f32,
    pmf: f32,
}

// A node of the 4-wide BVH: its children's boxes per axis (an unused child's box is
// inverted, +inf to -inf) and per child an inner node's index (count 0) or a leaf's
// primitives first .. first + count, with SHAPE_LEAF set in count when one is not a triangle.
// Host: `GpuWideNode`.
struct WideNode {
    lo_x: vec4f,
    lo_y: vec4f,
    lo_z: vec4f,
    hi_x: vec4f,
    hi_y: vec4f,
    hi_z: vec4f,
    first: vec4u,
    count: vec4u,
}

// A triangle corner; triangle i is vertices 3i, 3i+1, 3i+2. Host: `GpuVertex`.
// Normal and tangent are octahedral codes (`decode_unit` in surface.wgsl), the tangent's
// with the bitangent's sign in bit 16 (`tangent_sign`); the colour RGBA8 with sRGB-encoded
// colour channels (`vertex_color` in textures.wgsl), 0xffffffff for none.
struct Vertex {
    position: vec3f,
    normal: u32,
    uv: vec2f,
    tangent: u32,
    color: u32,
}

// A vertex colour's code for opaque white (host: `WHITE`).
const WHITE: u32 = 0xffffffffu;

// A primitive of the BVH, in leaf order: a triangle with its corners (`triangle` is its
// index in `vertices`) or, with `triangle` NO_TRIANGLE, the whole shape `object`. Host:
// `GpuPrimitive`.
struct Primitive {
    v0: vec3f,
    object: u32,
    v1: vec3f,
    triangle: u32,
    v2: vec3f,
    // An instance (triangle = INSTANCE): the root node of its mesh's tree.
    root: u32,
}

const NO_TRIANGLE: u32 = 0xffffffffu;
const INSTANCE: u32 = 0xfffffffeu;

// Whether the scene places instances (a pipeline constant): false compiles the instance paths
// out, which costs a scene without any nothing (on lavapipe the walk's nested mesh walk alone
// halved the default scene's samples/s).
override INSTANCES: bool = true;

// What the scene's materials and objects use (pipeline constants, set by the host from the
// scene, like INSTANCES): false compiles the feature's code out of the kernel, so a scene
// without glTF materials, textures or alpha cut-outs does not pay for them in registers.
// Metal-rough (glTF) materials.
override METAL_ROUGH: bool = true;
// Texture slots (colour, emission, normal maps, the model's own); see `has_texture`.
override TEXTURES: bool = true;
// Normal maps (TEXTURE_NORMAL, TEXTURE_COAT_NORMAL): the tangent frame in `surface_at`.
override NORMAL_MAPS: bool = true;
// Objects with alpha cut-outs (FLAG_ALPHA), tested in the walk.
override ALPHA: bool = true;

// The placement of an instance: rows of its affine transforms, each (x, y, z, translation).
struct Instance {
    to_object: array<vec4f, 3>,
    to_world: array<vec4f, 3>,
}
const SHAPE_LEAF: u32 = 0x80000000u;

// Vectors of a model's parameter block (host: `MODEL_PARAMS`); the last is loaded only for
// materials flagged MATERIAL_LONG_BLOCK.
const MODEL_PARAMS: u32 = 5u;
// Where `param_blocks` holds the sheen albedo table (host: `SHEEN_TABLE`).
const SHEEN_TABLE: u32 = 0u;
const MATERIAL_MASK: u32 = 1u;
const MATERIAL_BLEND: u32 = 2u;
const MATERIAL_LONG_BLOCK: u32 = 4u;
const TEXTURE_BASE: u32 = 0u;
const TEXTURE_NORMAL: u32 = 1u;
const TEXTURE_EMISSION: u32 = 2u;
const TEXTURE_MODEL: u32 = 3u;
const TEXTURE_TRANSMISSION: u32 = 4u;
const TEXTURE_SPECULAR: u32 = 5u;
const TEXTURE_SPECULAR_COLOR: u32 = 6u;
const TEXTURE_CLEARCOAT: u32 = 7u;
const TEXTURE_CLEARCOAT_ROUGHNESS: u32 = 8u;
const TEXTURE_SHEEN_COLOR: u32 = 9u;
const TEXTURE_SHEEN_ROUGHNESS: u32 = 10u;
const TEXTURE_COAT_NORMAL: u32 = 11u;
const WRAP_REPEAT: u32 = 0u;
const WRAP_CLAMP: u32 = 1u;
const WRAP_MIRROR: u32 = 2u;

// One use of a texture: its texels from `offset` (width x height), texture coordinates
// (dot(u.xy, uv) + u.z, dot(v.xy, uv) + v.z), and the WRAP_ modes of u (low 2 bits) and v.
// Host: `GpuTextureSlot`.
struct TextureSlot {
    u: vec3f,
    offset: u32,
    v: vec3f,
    wrap: u32,
    width: u32,
    height: u32,
    pad0: u32,
    pad1: u32,
}

// A material's common part in linear RGB: its model (MODEL_* of material.wgsl) reads its
// parameter block from `param_blocks[params]` on; its texture TEXTURE_* is
// `texture_slots[textures + TEXTURE_*]`, present when that bit of `texture_mask` is set.
// Host: `GpuMaterial`.
struct Material {
    base_color: vec3f,
    model: u32,
    emission: vec3f,
    flags: u32,
    alpha_cutoff: f32,
    alpha_factor: f32,
    normal_scale: f32,
    params: u32,
    textures: u32,
    texture_mask: u32,
    // Scale of the x and y of the coat's normal map (TEXTURE_COAT_NORMAL).
    coat_normal_scale: f32,
    pad0: u32,
}

@group(0) @binding(0) var<storage, read> nodes: array<WideNode>;
@group(0) @binding(1) var<storage, read> objects: array<Object>;
@group(0) @binding(2) var<storage, read> vertices: array<Vertex>;
// Per triangle, its three corners' indices into `vertices` (`pathlight_core::Geometry::triangles`).
@group(0) @binding(13) var<storage, read> triangles: array<u32>;
@group(0) @binding(3) var<storage, read> materials: array<Material>;
@group(0) @binding(4) var<storage, read> texture_slots: array<TextureSlot>;
@group(0) @binding(5) var<storage, read> texels: array<u32>;
@group(0) @binding(6) var<storage, read> lights: array<Light>;
// The BVH's leaves index these.
@group(0) @binding(7) var<storage, read> primitives: array<Primitive>;
// Per BVH node, its parent's index << 2 | its lane there (`pathlight_core::bvh::parents`).
@group(0) @binding(8) var<storage, read> parents: array<u32>;
// The parameter blocks: the sheen albedo table and the materials'
// (`pathlight_core::materials`), then the point and sun lights' (`pathlight_core::light_table`).
@group(0) @binding(11) var<storage, read> param_blocks: array<vec4f>;
// The placements of instances (`Object::instance` indexes them).
@group(0) @binding(12) var<storage, read> instances: array<Instance>;
