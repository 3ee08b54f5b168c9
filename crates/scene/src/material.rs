//! Materials: the seed's lobe parameters in linear RGB, and conductor presets.

use glam::Vec3;

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

/// Lobe parameters of a material, as the seed named them.
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
    /// The texture replacing the base colour (glTF: multiplying it).
    pub texture: Option<TextureRef>,
    /// Emitted radiance on the front side.
    pub emission: Vec3,
    /// Lobe weights and parameters.
    pub lobes: Lobes,
    /// Complex-IOR Fresnel for the specular lobe, else Schlick from the specular colour.
    pub conductor: Option<Conductor>,
    /// The glTF metal-rough model, which then replaces `lobes` and `conductor`.
    pub metal_rough: Option<MetalRough>,
}

/// How a texture's coordinates wrap outside [0, 1] (glTF's sampler modes).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Wrap {
    /// Tile.
    Repeat,
    /// Hold the edge texel.
    Clamp,
    /// Tile, every other copy mirrored.
    Mirror,
}

/// One use of a texture: which image, where its coordinates come from and how they wrap.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TextureRef {
    /// Index into [`crate::Scene::textures`].
    pub texture: u32,
    /// The 2x3 affine map from surface (u, v) to texture (u, v), rows first:
    /// `u' = m[0][0] u + m[0][1] v + m[0][2]` (glTF's `KHR_texture_transform`).
    pub transform: [[f32; 3]; 2],
    /// Wrapping of u and v.
    pub wrap: [Wrap; 2],
}

impl TextureRef {
    /// The identity coordinate map.
    pub const IDENTITY: [[f32; 3]; 2] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];

    /// A scene file's texture: untransformed, u tiling and v held at the edges.
    pub fn plain(texture: u32) -> Self {
        Self {
            texture,
            transform: Self::IDENTITY,
            wrap: [Wrap::Repeat, Wrap::Clamp],
        }
    }
}

/// How a glTF material's alpha (base colour alpha times its factor) is used.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum AlphaMode {
    /// Alpha is ignored.
    Opaque,
    /// Texels with alpha below the cutoff are holes: every ray passes through them.
    Mask(f32),
    /// Alpha is the probability that a ray stops (stochastic transparency).
    Blend,
}

/// glTF 2.0's metallic-roughness material (with the `KHR_materials_ior`, `_transmission`,
/// `_volume` and `_emissive_strength` extensions). The base colour, its texture and the
/// emission are [`Material`]'s own fields.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MetalRough {
    /// 0 dielectric, 1 metal.
    pub metallic: f32,
    /// Perceptual roughness; GGX alpha is its square.
    pub roughness: f32,
    /// Multiplies metallic by its blue channel and roughness by its green (linear).
    pub metal_rough_texture: Option<TextureRef>,
    /// Tangent-space normal map (linear, MikkTSpace).
    pub normal_texture: Option<TextureRef>,
    /// Scales the normal map's x and y.
    pub normal_scale: f32,
    /// Multiplies the emission (sRGB).
    pub emission_texture: Option<TextureRef>,
    /// Index of refraction of the dielectric (1.5 unless `KHR_materials_ior`).
    pub ior: f32,
    /// Fraction of the dielectric base that transmits instead of scattering diffusely.
    pub transmission: f32,
    /// Transmission through a thin wall (no volume): rays leave undeviated by refraction.
    pub thin: bool,
    /// Use of alpha.
    pub alpha: AlphaMode,
    /// Base colour alpha factor.
    pub alpha_factor: f32,
}

impl MetalRough {
    /// A white-based, fully rough dielectric with no textures (glTF's defaults but for
    /// metallic, which glTF defaults to 1).
    pub const DEFAULT: Self = Self {
        metallic: 0.0,
        roughness: 1.0,
        metal_rough_texture: None,
        normal_texture: None,
        normal_scale: 1.0,
        emission_texture: None,
        ior: 1.5,
        transmission: 0.0,
        thin: true,
        alpha: AlphaMode::Opaque,
        alpha_factor: 1.0,
    };
}
