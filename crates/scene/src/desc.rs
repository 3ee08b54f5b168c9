//! The scene file format as plain description data (`docs/scene-format.md`).
//!
//! Parsing yields these structs, with the source span of every entity, and nothing
//! else: building the runtime [`crate::Scene`] from them is [`crate::load`]'s job.
//! Unknown keys are errors.

use std::collections::BTreeMap;

use serde::Deserialize;
use toml::Spanned;

use crate::exact;

/// A whole scene file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneDesc {
    /// How `color` values are to be read: `"srgb"` (default) or `"linear"`.
    #[serde(default)]
    pub color_space: ColorSpace,
    /// The camera.
    pub camera: Spanned<CameraDesc>,
    /// Sampling settings; defaults when absent.
    pub render: Option<Spanned<RenderDesc>>,
    /// Light arriving from infinitely far away; absent means black.
    pub environment: Option<Spanned<EnvironmentDesc>>,
    /// Materials by name.
    #[serde(default)]
    pub materials: BTreeMap<String, Spanned<MaterialDesc>>,
    /// Parallelograms.
    #[serde(default)]
    pub quad: Vec<Spanned<QuadDesc>>,
    /// Analytic spheres.
    #[serde(default)]
    pub sphere: Vec<Spanned<SphereDesc>>,
    /// Cylinders along any axis, optionally capped.
    #[serde(default)]
    pub cylinder: Vec<Spanned<CylinderDesc>>,
    /// Triangle meshes read from OBJ files.
    #[serde(default)]
    pub mesh: Vec<Spanned<MeshDesc>>,
    /// Surfaces of revolution of a profile curve.
    #[serde(default)]
    pub revolve: Vec<Spanned<RevolveDesc>>,
    /// glTF 2.0 files placed in the scene with their own materials and punctual lights.
    #[serde(default)]
    pub gltf: Vec<Spanned<GltfDesc>>,
    /// Point, spot and sun lights.
    #[serde(default)]
    pub light: Vec<Spanned<LightDesc>>,
}

/// A point, spot or sun light (`docs/scene-format.md`, "Lights"): the loader checks which
/// keys its `type` takes.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LightDesc {
    /// Optional name.
    pub name: Option<String>,
    /// `"point"`, `"spot"` or `"sun"`.
    #[serde(rename = "type")]
    pub kind: LightType,
    /// Colour, in the file's `color_space`; white when absent.
    #[serde(default = "white", deserialize_with = "exact::array")]
    pub color: [f32; 3],
    /// Point and spot: radiant intensity in W/sr; sun: irradiance in W/m^2 (times `color`).
    pub intensity: f32,
    /// Point and spot: position.
    #[serde(default, deserialize_with = "exact::optional_array")]
    pub position: Option<[f32; 3]>,
    /// Spot and sun: the direction the light travels (a spot's may be `look_at` instead).
    #[serde(default, deserialize_with = "exact::optional_array")]
    pub direction: Option<[f32; 3]>,
    /// Spot: a point on its axis (instead of `direction`).
    #[serde(default, deserialize_with = "exact::optional_array")]
    pub look_at: Option<[f32; 3]>,
    /// Point and spot: radius of the small sphere the light is spread over (default 0).
    pub radius: Option<f32>,
    /// Spot: half-angle of full intensity, degrees (default 0).
    pub inner_angle: Option<f32>,
    /// Spot: half-angle where the light ends, degrees (default 45).
    pub outer_angle: Option<f32>,
    /// Sun: angular diameter of its disk, degrees (default 0, a true directional light).
    pub angular_diameter: Option<f32>,
}

/// A light's `type`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum LightType {
    /// Shines in every direction from a point.
    Point,
    /// Shines within a cone from a point.
    Spot,
    /// Shines along one direction from infinitely far away.
    Sun,
}

fn white() -> [f32; 3] {
    [1.0, 1.0, 1.0]
}

/// A glTF 2.0 file (`.gltf` or `.glb`) placed in the scene: the triangles of its default
/// scene with their materials, and its punctual lights (its cameras are not used).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GltfDesc {
    /// The file, relative to the scene file.
    pub file: String,
    /// Placement in the world, applied after the file's own node transforms.
    #[serde(default)]
    pub transform: TransformDesc,
}

/// How `color` triples in the file are encoded.
#[derive(Debug, Default, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ColorSpace {
    /// sRGB-encoded values in [0, 1], decoded to linear for transport (the seed's convention).
    #[default]
    Srgb,
    /// Linear RGB, used verbatim.
    Linear,
}

/// A pinhole or thin-lens camera.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraDesc {
    /// Eye position.
    #[serde(deserialize_with = "exact::array")]
    pub position: [f32; 3],
    /// Point the camera looks at.
    #[serde(deserialize_with = "exact::array")]
    pub look_at: [f32; 3],
    /// Up direction (need not be orthogonal to the view direction).
    #[serde(default = "default_up", deserialize_with = "exact::array")]
    pub up: [f32; 3],
    /// Full vertical field of view in degrees.
    pub fov_y: f32,
    /// Image size in pixels, `[width, height]`.
    #[serde(default = "default_resolution", deserialize_with = "exact::array")]
    pub resolution: [u32; 2],
    /// Radius of the lens (Mitsuba's thin lens); 0, the default, is a pinhole.
    #[serde(default)]
    pub aperture_radius: f32,
    /// Distance along the view direction of the plane in focus; default: to `look_at`.
    pub focus_distance: Option<f32>,
}

fn default_up() -> [f32; 3] {
    [0.0, 1.0, 0.0]
}

fn default_resolution() -> [u32; 2] {
    [500, 500]
}

/// Sampling settings.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RenderDesc {
    /// Samples per pixel.
    pub spp: u32,
    /// Maximum path length in segments, as Mitsuba counts it (1 = emitters only, 2 = direct light).
    pub max_depth: u32,
    /// Path depth from which Russian roulette may end paths.
    pub rr_depth: u32,
    /// Seed of the random sequence.
    pub seed: u32,
    /// Sample generator.
    pub sampler: SamplerDesc,
}

/// The sample generator.
#[derive(Debug, Default, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum SamplerDesc {
    /// Padded Owen-scrambled Sobol (the default).
    #[default]
    Sobol,
    /// Independent hashed random numbers.
    Independent,
}

impl Default for RenderDesc {
    fn default() -> Self {
        Self {
            spp: 64,
            max_depth: 8,
            rr_depth: 5,
            seed: 0,
            sampler: SamplerDesc::Sobol,
        }
    }
}

/// Light arriving from every direction: a constant radiance or an equirectangular HDR map.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EnvironmentDesc {
    /// Constant linear RGB radiance (instead of `map`).
    #[serde(default, deserialize_with = "exact::optional_array")]
    pub radiance: Option<[f32; 3]>,
    /// Equirectangular map (`.exr`, `.hdr`), relative to the scene file (instead of
    /// `radiance`).
    pub map: Option<String>,
    /// Factor on the map's texels.
    pub strength: Option<f32>,
    /// Turn of the map about the up (+y) axis, degrees.
    pub rotation: Option<f32>,
}

/// A material: the keys every model shares (colour, texture, emission), `model`, and the
/// keys of each model (the loader refuses another model's keys).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialDesc {
    /// The material model; the seed's lobes when absent.
    pub model: Option<ModelDesc>,
    /// Base colour, in the file's `color_space`.
    #[serde(default = "default_color", deserialize_with = "exact::array")]
    pub color: [f32; 3],
    /// Image (PNG/JPEG, sRGB), path relative to the scene file: it replaces `color` under the
    /// lobes and multiplies it under the metal-rough model.
    pub texture: Option<String>,
    /// Emitted linear radiance (W m^-2 sr^-1), on the front side only.
    #[serde(default, deserialize_with = "exact::optional_array")]
    pub emission: Option<[f32; 3]>,
    /// Lobes: one of the seed's materials (`metal`, `plastic`, `wall`, `glass`, `wood`, `ceramic`)
    /// giving defaults for the lobe parameters below.
    pub preset: Option<String>,
    /// Lobes: weight of the specular reflection lobe.
    pub specular_rate: Option<f32>,
    /// Lobes: specular colour between white (0) and the base colour (1).
    pub specular_tint: Option<f32>,
    /// Lobes: roughness of the specular lobe (GGX alpha = roughness^2).
    pub specular_roughness: Option<f32>,
    /// Lobes: weight of the transmission lobe.
    pub refract_rate: Option<f32>,
    /// Lobes: transmitted colour between white (0) and the base colour (1).
    pub refract_tint: Option<f32>,
    /// Both models: index of refraction of the inside (lobes: of the transmission lobe;
    /// metal-rough: of the dielectric).
    pub ior: Option<f32>,
    /// Lobes: roughness of transmission (GGX alpha = roughness^2).
    pub refract_roughness: Option<f32>,
    /// Lobes: conductor Fresnel for the specular lobe: a preset name (`"gold"`, `"aluminium"`, ...).
    pub conductor: Option<String>,
    /// Lobes: conductor Fresnel from a complex index of refraction: real part per RGB channel.
    #[serde(default, deserialize_with = "exact::optional_array")]
    pub eta: Option<[f32; 3]>,
    /// Lobes: conductor Fresnel from a complex index of refraction: imaginary part per RGB channel.
    #[serde(default, deserialize_with = "exact::optional_array")]
    pub k: Option<[f32; 3]>,
    /// Metal-rough: 0 dielectric, 1 metal.
    pub metallic: Option<f32>,
    /// Metal-rough: perceptual roughness (GGX alpha = roughness^2).
    pub roughness: Option<f32>,
    /// Metal-rough: fraction of the dielectric base that transmits, through a
    /// thin wall (`KHR_materials_transmission`).
    pub transmission: Option<f32>,
    /// Metal-rough: strength of the dielectric's specular reflection, in [0, 1]
    /// (`KHR_materials_specular`'s `specularFactor`).
    pub specular: Option<f32>,
    /// Metal-rough: linear colour multiplying the dielectric's F0 (`specularColorFactor`).
    #[serde(default, deserialize_with = "exact::optional_array")]
    pub specular_color: Option<[f32; 3]>,
    /// Metal-rough: strength of a clear coat over the material, in [0, 1]
    /// (`KHR_materials_clearcoat`'s `clearcoatFactor`).
    pub clearcoat: Option<f32>,
    /// Metal-rough: the coat's perceptual roughness, in [0, 1].
    pub clearcoat_roughness: Option<f32>,
    /// Metal-rough: linear colour of a sheen over the material, in [0, 1]
    /// (`KHR_materials_sheen`'s `sheenColorFactor`; black: none).
    #[serde(default, deserialize_with = "exact::optional_array")]
    pub sheen_color: Option<[f32; 3]>,
    /// Metal-rough: the sheen's perceptual roughness, in [0, 1].
    pub sheen_roughness: Option<f32>,
}

/// A material model, as `model = "..."` names it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
pub enum ModelDesc {
    /// The seed's lobe mixture.
    #[serde(rename = "lobes")]
    Lobes,
    /// glTF's metallic-roughness model.
    #[serde(rename = "metal-rough")]
    MetalRough,
}

impl ModelDesc {
    /// Its name in scene files.
    pub fn name(self) -> &'static str {
        match self {
            Self::Lobes => "lobes",
            Self::MetalRough => "metal-rough",
        }
    }
}

fn default_color() -> [f32; 3] {
    [0.8, 0.8, 0.8]
}

/// The parallelogram `origin + s edge_u + t edge_v`, s, t in [0, 1]; normal `edge_u x edge_v`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct QuadDesc {
    /// Optional name, shown when picked.
    pub name: Option<String>,
    /// Material name.
    pub material: String,
    /// Corner at s = t = 0.
    #[serde(deserialize_with = "exact::array")]
    pub origin: [f32; 3],
    /// First edge.
    #[serde(deserialize_with = "exact::array")]
    pub edge_u: [f32; 3],
    /// Second edge.
    #[serde(deserialize_with = "exact::array")]
    pub edge_v: [f32; 3],
}

/// A sphere.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SphereDesc {
    /// Optional name, shown when picked.
    pub name: Option<String>,
    /// Material name.
    pub material: String,
    /// Centre.
    #[serde(deserialize_with = "exact::array")]
    pub center: [f32; 3],
    /// Radius.
    pub radius: f32,
    /// Rotation of the texture about the vertical (y) axis, degrees.
    #[serde(default)]
    pub texture_rotation: f32,
}

/// A cylinder between two axis end points.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CylinderDesc {
    /// Optional name, shown when picked.
    pub name: Option<String>,
    /// Material name.
    pub material: String,
    /// Axis start (bottom).
    #[serde(deserialize_with = "exact::array")]
    pub p0: [f32; 3],
    /// Axis end (top).
    #[serde(deserialize_with = "exact::array")]
    pub p1: [f32; 3],
    /// Radius.
    pub radius: f32,
    /// Closed by two flat disks.
    #[serde(default = "default_true")]
    pub caps: bool,
}

fn default_true() -> bool {
    true
}

/// A placement: scale, then rotate (degrees about x, then y, then z), then translate.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TransformDesc {
    /// Scale, uniform or per axis.
    pub scale: Option<ScaleDesc>,
    /// Euler angles in degrees, applied x, then y, then z.
    #[serde(default, deserialize_with = "exact::array")]
    pub rotate: [f32; 3],
    /// Translation.
    #[serde(default, deserialize_with = "exact::array")]
    pub translate: [f32; 3],
}

/// A uniform or per-axis scale.
#[derive(Debug, Clone, Copy)]
pub enum ScaleDesc {
    /// The same factor on every axis.
    Uniform(f32),
    /// One factor per axis.
    PerAxis([f32; 3]),
}

impl<'de> Deserialize<'de> for ScaleDesc {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        /// What the file may hold, before the length check.
        #[derive(Deserialize)]
        #[serde(untagged)]
        enum Raw {
            Uniform(f32),
            PerAxis(Vec<f32>),
        }
        let wanted = "scale must be a number or an array of 3 numbers";
        match Raw::deserialize(deserializer).map_err(|_| serde::de::Error::custom(wanted))? {
            Raw::Uniform(s) => Ok(Self::Uniform(s)),
            Raw::PerAxis(v) => <[f32; 3]>::try_from(v)
                .map(Self::PerAxis)
                .map_err(|v| serde::de::Error::custom(format!("{wanted}, not {}", v.len()))),
        }
    }
}

/// A triangle mesh from an OBJ file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeshDesc {
    /// Optional name, shown when picked.
    pub name: Option<String>,
    /// Material name.
    pub material: String,
    /// OBJ file, relative to the scene file.
    pub file: String,
    /// `"smooth"` (interpolated vertex normals, the default) or `"flat"` (geometric normals).
    #[serde(default)]
    pub shading: Shading,
    /// Placement in the world.
    #[serde(default)]
    pub transform: TransformDesc,
    /// Further placements of the same mesh, which share one copy of its triangles.
    #[serde(default)]
    pub instances: Vec<InstanceDesc>,
}

/// One more placement of a `[[mesh]]` entry's mesh.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InstanceDesc {
    /// Optional name, shown when picked (default: the mesh's name and `#` and its number).
    pub name: Option<String>,
    /// Material name (default: the mesh's).
    pub material: Option<String>,
    /// Placement in the world of the OBJ file's own coordinates.
    #[serde(default)]
    pub transform: TransformDesc,
}

/// Normals used for shading a mesh.
#[derive(Debug, Default, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Shading {
    /// Vertex normals interpolated across each triangle (from the file, or averaged).
    #[default]
    Smooth,
    /// The geometric normal of each triangle.
    Flat,
}

/// A surface of revolution: a profile curve revolved about an axis.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RevolveDesc {
    /// Optional name, shown when picked.
    pub name: Option<String>,
    /// Material name.
    pub material: String,
    /// Point on the axis where the profile's height is 0.
    #[serde(deserialize_with = "exact::array")]
    pub base: [f32; 3],
    /// Axis direction.
    #[serde(default = "default_up", deserialize_with = "exact::array")]
    pub axis: [f32; 3],
    /// Control points `[radius, height]`, bottom to top; a Catmull-Rom spline runs through them.
    #[serde(deserialize_with = "exact::array_list")]
    pub profile: Vec<[f32; 2]>,
    /// Segments around the axis.
    #[serde(default = "default_segments")]
    pub segments: u32,
    /// Rings along the profile.
    #[serde(default = "default_rings")]
    pub rings: u32,
    /// Close the bottom with a disk (a fan of triangles).
    #[serde(default = "default_true")]
    pub cap_bottom: bool,
}

fn default_segments() -> u32 {
    64
}

fn default_rings() -> u32 {
    32
}
