//! Materials: a common part (base colour, emission, their textures, a normal map, alpha)
//! and a material model, in linear RGB: the seed's lobe mixture ([`Lobes`], with conductor
//! presets) or glTF's metallic-roughness model ([`MetalRough`]).

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
    /// Complex-IOR Fresnel for the specular lobe, else Schlick from the specular colour.
    pub conductor: Option<Conductor>,
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
        conductor: None,
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

/// A material in linear RGB: what every model shares, and its model.
#[derive(Debug, Clone, PartialEq)]
pub struct Material {
    /// Name in the scene file.
    pub name: String,
    /// Linear base colour, multiplied by `texture` where there is one.
    pub base_color: Vec3,
    /// The base colour texture (sRGB; its alpha channel is the material's alpha).
    pub texture: Option<TextureRef>,
    /// Emitted radiance on the front side, multiplied by `emission_texture`.
    pub emission: Vec3,
    /// The emission texture (sRGB).
    pub emission_texture: Option<TextureRef>,
    /// Tangent-space normal map (linear, MikkTSpace), on meshes with tangents.
    pub normal_texture: Option<TextureRef>,
    /// Scales the normal map's x and y.
    pub normal_scale: f32,
    /// Use of alpha.
    pub alpha: AlphaMode,
    /// Base colour alpha factor.
    pub alpha_factor: f32,
    /// How the surface scatters light.
    pub model: Model,
}

impl Material {
    /// An opaque, untextured, non-emissive material of `model`.
    pub fn new(name: impl Into<String>, base_color: Vec3, model: Model) -> Self {
        Self {
            name: name.into(),
            base_color,
            texture: None,
            emission: Vec3::ZERO,
            emission_texture: None,
            normal_texture: None,
            normal_scale: 1.0,
            alpha: AlphaMode::Opaque,
            alpha_factor: 1.0,
            model,
        }
    }

    /// Every texture the material reads, its own and its model's.
    pub fn textures_mut(&mut self) -> impl Iterator<Item = &mut TextureRef> {
        let (model, layers) = match &mut self.model {
            Model::Lobes(_) => (None, None),
            Model::MetalRough(pbr) => (pbr.metal_rough_texture.as_mut(), Some(&mut pbr.textures)),
        };
        [
            self.texture.as_mut(),
            self.emission_texture.as_mut(),
            self.normal_texture.as_mut(),
            model,
        ]
        .into_iter()
        .flatten()
        .chain(layers.into_iter().flat_map(LayerTextures::iter_mut))
    }
}

/// A material model: how a surface scatters light. The kernels hold one BSDF per model
/// (ARCHITECTURE.md, "How to add a material model").
#[derive(Debug, Clone, Copy, PartialEq)]
// A scene holds a few materials, copied while it loads: their size does not matter, and
// boxing the metal-rough one would cost every use its `Copy`.
#[allow(clippy::large_enum_variant)]
pub enum Model {
    /// The seed's mixture of Lambert, specular and transmission lobes.
    Lobes(Lobes),
    /// glTF 2.0's metallic-roughness model.
    MetalRough(MetalRough),
}

impl Model {
    /// Its name in scene files (`model = "..."`).
    pub fn name(&self) -> &'static str {
        match self {
            Self::Lobes(_) => "lobes",
            Self::MetalRough(_) => "metal-rough",
        }
    }
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

/// glTF 2.0's metallic-roughness model (with the `KHR_materials_ior`, `_transmission` and
/// `_volume` extensions). The base colour, its texture, the emission, the normal map and
/// alpha are [`Material`]'s own.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MetalRough {
    /// 0 dielectric, 1 metal.
    pub metallic: f32,
    /// Perceptual roughness; GGX alpha is its square.
    pub roughness: f32,
    /// Multiplies metallic by its blue channel and roughness by its green (linear).
    pub metal_rough_texture: Option<TextureRef>,
    /// Index of refraction of the dielectric (1.5 unless `KHR_materials_ior`).
    pub ior: f32,
    /// Fraction of the dielectric base that transmits instead of scattering diffusely.
    pub transmission: f32,
    /// Transmission through a thin wall (no volume): rays leave undeviated by refraction.
    pub thin: bool,
    /// Strength of the dielectric's specular reflection, `KHR_materials_specular`'s
    /// `specularFactor` (1: glTF's plain dielectric; 0: none, the base alone).
    pub specular: f32,
    /// Linear colour multiplying the dielectric's F0 (`specularColorFactor`; white: glTF's
    /// plain dielectric).
    pub specular_color: Vec3,
    /// Strength of a clear coat over the whole material (`KHR_materials_clearcoat`'s
    /// `clearcoatFactor`; 0: none).
    pub clearcoat: f32,
    /// The coat's perceptual roughness (`clearcoatRoughnessFactor`).
    pub clearcoat_roughness: f32,
    /// Scale of the x and y of the coat's normal map (`clearcoatNormalTexture.scale`).
    pub clearcoat_normal_scale: f32,
    /// Absorption coefficient per unit length (linear RGB) inside a solid (not `thin`)
    /// material: light crossing it keeps `exp(-attenuation d)` over a distance d
    /// (`KHR_materials_volume`'s `-ln(attenuationColor) / attenuationDistance`); zero: clear.
    pub attenuation: Vec3,
    /// Linear colour of a sheen over the material (`KHR_materials_sheen`'s
    /// `sheenColorFactor`; black: none).
    pub sheen_color: Vec3,
    /// The sheen's perceptual roughness (`sheenRoughnessFactor`; read as at least 0.07).
    pub sheen_roughness: f32,
    /// The extensions' textures, each multiplying its factor.
    pub textures: LayerTextures,
}

/// The metal-rough extensions' textures (glTF's channels; each multiplies its factor).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct LayerTextures {
    /// `KHR_materials_transmission`: transmission in red.
    pub transmission: Option<TextureRef>,
    /// `KHR_materials_specular`: strength in alpha.
    pub specular: Option<TextureRef>,
    /// `KHR_materials_specular`: F0 colour (sRGB).
    pub specular_color: Option<TextureRef>,
    /// `KHR_materials_clearcoat`: strength in red.
    pub clearcoat: Option<TextureRef>,
    /// `KHR_materials_clearcoat`: roughness in green.
    pub clearcoat_roughness: Option<TextureRef>,
    /// `KHR_materials_clearcoat`: the coat's own tangent-space normal map.
    pub clearcoat_normal: Option<TextureRef>,
    /// `KHR_materials_sheen`: colour (sRGB).
    pub sheen_color: Option<TextureRef>,
    /// `KHR_materials_sheen`: roughness in alpha.
    pub sheen_roughness: Option<TextureRef>,
}

impl LayerTextures {
    /// No textures.
    pub const NONE: Self = Self {
        transmission: None,
        specular: None,
        specular_color: None,
        clearcoat: None,
        clearcoat_roughness: None,
        clearcoat_normal: None,
        sheen_color: None,
        sheen_roughness: None,
    };

    /// In the order of the kernels' texture slots (`TEXTURE_TRANSMISSION` onwards).
    pub fn in_slot_order(&self) -> [Option<TextureRef>; 8] {
        [
            self.transmission,
            self.specular,
            self.specular_color,
            self.clearcoat,
            self.clearcoat_roughness,
            self.sheen_color,
            self.sheen_roughness,
            self.clearcoat_normal,
        ]
    }

    /// The same, to be changed.
    fn iter_mut(&mut self) -> impl Iterator<Item = &mut TextureRef> {
        [
            self.transmission.as_mut(),
            self.specular.as_mut(),
            self.specular_color.as_mut(),
            self.clearcoat.as_mut(),
            self.clearcoat_roughness.as_mut(),
            self.clearcoat_normal.as_mut(),
            self.sheen_color.as_mut(),
            self.sheen_roughness.as_mut(),
        ]
        .into_iter()
        .flatten()
    }
}

impl MetalRough {
    /// A fully rough dielectric with no texture (glTF's defaults but for metallic, which
    /// glTF defaults to 1).
    pub const DEFAULT: Self = Self {
        metallic: 0.0,
        roughness: 1.0,
        metal_rough_texture: None,
        ior: 1.5,
        transmission: 0.0,
        thin: true,
        specular: 1.0,
        specular_color: Vec3::ONE,
        clearcoat: 0.0,
        clearcoat_roughness: 0.0,
        clearcoat_normal_scale: 1.0,
        attenuation: Vec3::ZERO,
        sheen_color: Vec3::ZERO,
        sheen_roughness: 0.0,
        textures: LayerTextures::NONE,
    };
}
