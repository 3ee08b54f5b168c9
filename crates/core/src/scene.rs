//! The runtime scene: resolved, validated, in world space and linear RGB.

use glam::{Vec2, Vec3};

/// Largest accepted image side, in pixels.
pub const MAX_RESOLUTION: u32 = 8192;
/// Largest accepted samples per pixel for one render.
pub const MAX_SPP: u32 = 1 << 20;
/// Largest accepted path length in segments.
pub const MAX_DEPTH: u32 = 1024;

/// A pinhole camera and the image it makes.
#[derive(Debug, Clone, PartialEq)]
pub struct Camera {
    /// Eye position.
    pub position: Vec3,
    /// Point the camera looks at.
    pub look_at: Vec3,
    /// Up direction.
    pub up: Vec3,
    /// Full vertical field of view, degrees.
    pub fov_y_deg: f32,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
}

/// Sampling settings of a render.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RenderSettings {
    /// Samples per pixel.
    pub spp: u32,
    /// Maximum path length in segments (Mitsuba's `max_depth`).
    pub max_depth: u32,
    /// Depth from which Russian roulette may end a path.
    pub rr_depth: u32,
    /// Seed of the random sequence.
    pub seed: u32,
    /// `gpu::SAMPLER_*`: Owen-scrambled Sobol or independent random numbers.
    pub sampler: u32,
}

/// A conductor's complex index of refraction, per RGB channel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Conductor {
    /// Real part.
    pub eta: Vec3,
    /// Imaginary part (extinction).
    pub k: Vec3,
}

impl Conductor {
    /// Mitsuba 3's RGB values for measured gold (`Au`).
    pub const GOLD: Self = Self {
        eta: Vec3::new(0.143036, 0.375307, 1.44205),
        k: Vec3::new(3.983, 2.38556, 1.60336),
    };
    /// Mitsuba 3's RGB values for measured aluminium (`Al`).
    pub const ALUMINIUM: Self = Self {
        eta: Vec3::new(1.6575, 0.880405, 0.521244),
        k: Vec3::new(9.22381, 6.2695, 4.837),
    };

    /// The named presets accepted by the scene format.
    pub const PRESETS: [(&'static str, Self); 2] =
        [("gold", Self::GOLD), ("aluminium", Self::ALUMINIUM)];

    /// Looks a preset up by name.
    pub fn preset(name: &str) -> Option<Self> {
        Self::PRESETS
            .iter()
            .find(|(preset, _)| *preset == name)
            .map(|(_, conductor)| *conductor)
    }
}

/// Lobe parameters of a material, as the seed named them (SPEC section 4).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lobes {
    /// Weight of the specular lobe.
    pub specular_rate: f32,
    /// Specular colour between white and the base colour.
    pub specular_tint: f32,
    /// Roughness of the specular lobe.
    pub specular_roughness: f32,
    /// Weight of the transmission lobe.
    pub refract_rate: f32,
    /// Transmitted colour between white and the base colour.
    pub refract_tint: f32,
    /// Index of refraction of the inside.
    pub ior: f32,
    /// Roughness of transmission.
    pub refract_roughness: f32,
}

impl Lobes {
    /// Pure Lambert (the default of a material without a preset).
    pub const DIFFUSE: Self = Self {
        specular_rate: 0.0,
        specular_tint: 0.0,
        specular_roughness: 0.0,
        refract_rate: 0.0,
        refract_tint: 0.0,
        ior: 1.5,
        refract_roughness: 0.0,
    };

    /// The seed's six materials: lobe parameters chosen to look like the real thing.
    pub const PRESETS: [(&'static str, Self); 6] = [
        // Polished metal: all specular, coloured by the base colour (Schlick F0 = colour).
        (
            "metal",
            Self {
                specular_rate: 1.0,
                specular_tint: 1.0,
                specular_roughness: 0.15,
                ..Self::DIFFUSE
            },
        ),
        // Plastic: a slightly rough white coat over the diffuse colour.
        (
            "plastic",
            Self {
                specular_rate: 0.1,
                specular_roughness: 0.25,
                ..Self::DIFFUSE
            },
        ),
        // Matte wall paint.
        ("wall", Self::DIFFUSE),
        // Clear glass: smooth dielectric, Fresnel decides reflection and refraction.
        (
            "glass",
            Self {
                refract_rate: 1.0,
                ..Self::DIFFUSE
            },
        ),
        // Smooth varnished wood: a weak, fairly rough gloss.
        (
            "wood",
            Self {
                specular_rate: 0.06,
                specular_roughness: 0.35,
                ..Self::DIFFUSE
            },
        ),
        // Smooth ceramic glaze: a stronger, sharper gloss.
        (
            "ceramic",
            Self {
                specular_rate: 0.2,
                specular_roughness: 0.08,
                ..Self::DIFFUSE
            },
        ),
    ];

    /// Looks a preset up by name.
    pub fn preset(name: &str) -> Option<Self> {
        Self::PRESETS
            .iter()
            .find(|(n, _)| *n == name)
            .map(|(_, l)| *l)
    }
}

/// A material in linear RGB with the seed's lobe weights.
#[derive(Debug, Clone, PartialEq)]
pub struct Material {
    /// Name in the scene file.
    pub name: String,
    /// Linear base colour (used when there is no texture).
    pub base_color: Vec3,
    /// Index into [`Scene::textures`] replacing the base colour.
    pub texture: Option<u32>,
    /// Emitted radiance on the front side.
    pub emission: Vec3,
    /// Lobe weights and parameters.
    pub lobes: Lobes,
    /// Complex-IOR Fresnel for the specular lobe, else Schlick from the specular colour.
    pub conductor: Option<Conductor>,
}

/// An sRGB-encoded 8-bit RGBA image.
#[derive(Debug, Clone, PartialEq)]
pub struct Texture {
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// Row-major texels, row 0 at the top, packed RGBA8 (red in the low byte).
    pub texels: Vec<u32>,
}

/// A triangle mesh in world space.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TriangleMesh {
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Vertex shading normals (one per position).
    pub normals: Vec<Vec3>,
    /// Vertex texture coordinates (one per position).
    pub uvs: Vec<Vec2>,
    /// Triangles as indices into the vertex arrays.
    pub indices: Vec<[u32; 3]>,
    /// Shade with the geometric normal instead of `normals`.
    pub flat: bool,
}

/// The geometry of one object.
#[derive(Debug, Clone, PartialEq)]
pub enum Shape {
    /// Parallelogram `origin + s edge_u + t edge_v`.
    Quad {
        /// Corner.
        origin: Vec3,
        /// First edge.
        edge_u: Vec3,
        /// Second edge.
        edge_v: Vec3,
    },
    /// Sphere.
    Sphere {
        /// Centre.
        center: Vec3,
        /// Radius.
        radius: f32,
        /// Rotation of the texture about +y, radians.
        texture_rotation: f32,
    },
    /// Cylinder from `p0` to `p1`.
    Cylinder {
        /// Axis start.
        p0: Vec3,
        /// Axis end.
        p1: Vec3,
        /// Radius.
        radius: f32,
        /// Closed by two disks.
        caps: bool,
    },
    /// Triangle mesh.
    Mesh(TriangleMesh),
}

/// One pickable model: a shape with a material.
#[derive(Debug, Clone, PartialEq)]
pub struct Object {
    /// Name from the file, or `<kind><index>` when the file gives none.
    pub name: String,
    /// Index into [`Scene::materials`].
    pub material: u32,
    /// Geometry.
    pub shape: Shape,
}

/// A scene ready to be uploaded and rendered.
#[derive(Debug, Clone, PartialEq)]
pub struct Scene {
    /// The camera.
    pub camera: Camera,
    /// Sampling settings.
    pub settings: RenderSettings,
    /// Constant environment radiance (black when there is none).
    pub environment: Vec3,
    /// Materials.
    pub materials: Vec<Material>,
    /// Textures referenced by materials.
    pub textures: Vec<Texture>,
    /// Objects.
    pub objects: Vec<Object>,
}
