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
    /// Index into [`Scene::textures`] replacing the base colour.
    pub texture: Option<u32>,
    /// Emitted radiance on the front side.
    pub emission: Vec3,
    /// Lobe weights and parameters.
    pub lobes: Lobes,
    /// Complex-IOR Fresnel for the specular lobe, else Schlick from the specular colour.
    pub conductor: Option<Conductor>,
}
