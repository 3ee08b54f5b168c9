//! glTF materials and their textures as pathlight's [`Material`]s and [`TextureRef`]s.

use std::collections::HashMap;

use glam::Vec3;
use gltf::texture::WrappingMode;

use super::data::Files;
use super::primitives::Needs;
use crate::error::SceneError;
use crate::material::{AlphaMode, Material, MetalRough, Model, TextureRef, Wrap};
use crate::texture::Texture;

/// A glTF file's materials, converted once each, and the images they decode.
pub(super) struct Materials {
    /// Converted materials, in the order first used.
    pub materials: Vec<Material>,
    /// Decoded images, in the order first used.
    pub textures: Vec<Texture>,
    /// Per glTF material (`None`: the default material), its index and needs.
    converted: HashMap<Option<usize>, (u32, Needs)>,
    /// Per glTF image, its index in `textures`.
    images: HashMap<usize, u32>,
}

impl Materials {
    /// No materials yet.
    pub fn new() -> Self {
        Self {
            materials: Vec::new(),
            textures: Vec::new(),
            converted: HashMap::new(),
            images: HashMap::new(),
        }
    }

    /// The index and needs of `material`, converting it (and decoding its images) the
    /// first time.
    pub fn get(
        &mut self,
        files: &Files,
        buffers: &[Vec<u8>],
        material: &gltf::Material,
    ) -> Result<(u32, Needs), SceneError> {
        if let Some(&done) = self.converted.get(&material.index()) {
            return Ok(done);
        }
        let converted = self.convert(files, buffers, material)?;
        let index = self.materials.len() as u32;
        self.materials.push(converted.0);
        self.converted
            .insert(material.index(), (index, converted.1));
        Ok((index, converted.1))
    }

    fn convert(
        &mut self,
        files: &Files,
        buffers: &[Vec<u8>],
        material: &gltf::Material,
    ) -> Result<(Material, Needs), SceneError> {
        let element = match material.index() {
            Some(i) => format!("material {i}"),
            None => "the default material".to_owned(),
        };
        let pbr = material.pbr_metallic_roughness();
        let [r, g, b, alpha_factor] = pbr.base_color_factor();
        let mut uv_sets = Vec::new();
        let mut reference = |this: &mut Self, info: Option<TextureUse>| {
            info.map(|(texture, tex_coord, transform)| {
                let set = transform
                    .as_ref()
                    .and_then(|t| t.tex_coord())
                    .unwrap_or(tex_coord);
                uv_sets.push(set);
                this.texture_ref(files, buffers, &texture, transform.as_ref())
            })
            .transpose()
        };
        let base_texture = reference(self, pbr.base_color_texture().map(info))?;
        let metal_rough_texture = reference(self, pbr.metallic_roughness_texture().map(info))?;
        let emission_texture = reference(self, material.emissive_texture().map(info))?;
        let normal = material.normal_texture();
        let normal_scale = normal.as_ref().map_or(1.0, |n| n.scale());
        let normal_texture = reference(self, normal.map(|n| (n.texture(), n.tex_coord(), None)))?;
        let uv_set = uv_sets.first().copied().unwrap_or(0);
        if uv_sets.iter().any(|&s| s != uv_set) {
            log::warn!(
                "{}: {element}: its textures read several texture coordinate sets; all read TEXCOORD_{uv_set}",
                files.path.display()
            );
        }
        let strength = material.emissive_strength().unwrap_or(1.0);
        let emission = Vec3::from(material.emissive_factor()) * strength;
        let transmission = material.transmission();
        if transmission
            .as_ref()
            .is_some_and(|t| t.transmission_texture().is_some())
        {
            log::warn!(
                "{}: {element}: the transmission texture is ignored (its factor is used)",
                files.path.display()
            );
        }
        let (clearcoat, clearcoat_roughness) = clearcoat(files, &element, material);
        let specular = material.specular();
        if specular
            .as_ref()
            .is_some_and(|s| s.specular_texture().is_some() || s.specular_color_texture().is_some())
        {
            log::warn!(
                "{}: {element}: the specular textures are ignored (their factors are used)",
                files.path.display()
            );
        }
        let volume = material.volume();
        let thickness = volume.as_ref().map_or(0.0, |v| v.thickness_factor());
        // Beer-Lambert: -ln(colour) / distance per channel (a black channel absorbs all, a
        // colour above 1 is clamped to 1, an infinite distance absorbs nothing).
        let attenuation = volume.as_ref().map_or(Vec3::ZERO, |v| {
            let distance = v.attenuation_distance();
            Vec3::from(v.attenuation_color()).map(|c| {
                if distance.is_finite() && distance > 0.0 && c < 1.0 {
                    (-c.max(0.0).ln() / distance).min(1e30)
                } else {
                    0.0
                }
            })
        });
        let alpha = match material.alpha_mode() {
            gltf::material::AlphaMode::Opaque => AlphaMode::Opaque,
            gltf::material::AlphaMode::Mask => {
                AlphaMode::Mask(material.alpha_cutoff().unwrap_or(0.5))
            }
            gltf::material::AlphaMode::Blend => AlphaMode::Blend,
        };
        let metal_rough = MetalRough {
            metallic: pbr.metallic_factor(),
            roughness: pbr.roughness_factor(),
            metal_rough_texture,
            ior: material.ior().unwrap_or(1.5),
            transmission: transmission.map_or(0.0, |t| t.transmission_factor()),
            thin: thickness <= 0.0,
            specular: specular.as_ref().map_or(1.0, |s| s.specular_factor()),
            specular_color: specular
                .as_ref()
                .map_or(Vec3::ONE, |s| Vec3::from(s.specular_color_factor())),
            clearcoat,
            clearcoat_roughness,
            attenuation,
        };
        let numbers = [
            r,
            g,
            b,
            alpha_factor,
            metal_rough.metallic,
            metal_rough.roughness,
            normal_scale,
            metal_rough.ior,
            metal_rough.transmission,
            emission.x,
            emission.y,
            emission.z,
            metal_rough.specular,
            metal_rough.specular_color.x,
            metal_rough.specular_color.y,
            metal_rough.specular_color.z,
            metal_rough.clearcoat,
            metal_rough.clearcoat_roughness,
        ];
        if numbers.iter().any(|v| !v.is_finite() || *v < 0.0) || metal_rough.ior < 1.0 {
            return Err(files.error(
                &element,
                format!("a factor is negative or not finite: {numbers:?}"),
            ));
        }
        let needs = Needs {
            uv_set,
            tangents: normal_texture.is_some(),
        };
        let material = Material {
            name: material
                .name()
                .map_or_else(|| element.clone(), str::to_owned),
            base_color: Vec3::new(r, g, b).min(Vec3::ONE),
            texture: base_texture,
            emission,
            emission_texture,
            normal_texture,
            normal_scale,
            alpha,
            alpha_factor: alpha_factor.min(1.0),
            model: Model::MetalRough(MetalRough {
                metallic: metal_rough.metallic.min(1.0),
                roughness: metal_rough.roughness.min(1.0),
                transmission: metal_rough.transmission.min(1.0),
                specular: metal_rough.specular.min(1.0),
                clearcoat: metal_rough.clearcoat.min(1.0),
                clearcoat_roughness: metal_rough.clearcoat_roughness.min(1.0),
                ..metal_rough
            }),
        };
        Ok((material, needs))
    }

    /// A use of `texture` with its sampler's wrapping and the `KHR_texture_transform`.
    fn texture_ref(
        &mut self,
        files: &Files,
        buffers: &[Vec<u8>],
        texture: &gltf::Texture,
        transform: Option<&gltf::texture::TextureTransform>,
    ) -> Result<TextureRef, SceneError> {
        let image = texture.source();
        let index = match self.images.get(&image.index()) {
            Some(&i) => i,
            None => {
                let bytes = files.image_bytes(&image, buffers)?;
                let name = files.path.with_file_name(format!(
                    "{}#image{}",
                    file_name(files),
                    image.index()
                ));
                let decoded = Texture::decode(&bytes, &name)?;
                let i = self.textures.len() as u32;
                self.textures.push(decoded);
                self.images.insert(image.index(), i);
                i
            }
        };
        let wrap = |mode: WrappingMode| match mode {
            WrappingMode::Repeat => Wrap::Repeat,
            WrappingMode::ClampToEdge => Wrap::Clamp,
            WrappingMode::MirroredRepeat => Wrap::Mirror,
        };
        let sampler = texture.sampler();
        Ok(TextureRef {
            texture: index,
            transform: transform.map_or(TextureRef::IDENTITY, uv_matrix),
            wrap: [wrap(sampler.wrap_s()), wrap(sampler.wrap_t())],
        })
    }
}

/// A texture reference's parts: the texture, its coordinate set and its transform.
fn info(i: gltf::texture::Info<'_>) -> TextureUse<'_> {
    (i.texture(), i.tex_coord(), i.texture_transform())
}

/// A texture, the coordinate set it reads and its `KHR_texture_transform`.
type TextureUse<'a> = (
    gltf::Texture<'a>,
    u32,
    Option<gltf::texture::TextureTransform<'a>>,
);

/// The glTF file's name, for naming its embedded images.
fn file_name(files: &Files) -> String {
    files
        .path
        .file_name()
        .map_or_else(String::new, |n| n.to_string_lossy().into_owned())
}

/// `KHR_texture_transform`'s translation * rotation * scale, as the 2x3 rows of
/// [`TextureRef::transform`].
pub(super) fn uv_matrix(t: &gltf::texture::TextureTransform) -> [[f32; 3]; 2] {
    let [ox, oy] = t.offset();
    let [sx, sy] = t.scale();
    let (s, c) = t.rotation().sin_cos();
    [[c * sx, s * sy, ox], [-s * sx, c * sy, oy]]
}

/// `KHR_materials_clearcoat`'s factors (the `gltf` crate does not read it): strength and
/// roughness, 0 and 0 without it (NaN for a value that is not a number, refused with the
/// other factors); its textures are ignored with a warning.
fn clearcoat(files: &Files, element: &str, material: &gltf::Material) -> (f32, f32) {
    let Some(coat) = material.extension_value("KHR_materials_clearcoat") else {
        return (0.0, 0.0);
    };
    let textures = [
        "clearcoatTexture",
        "clearcoatRoughnessTexture",
        "clearcoatNormalTexture",
    ];
    if textures.iter().any(|k| coat.get(k).is_some()) {
        log::warn!(
            "{}: {element}: the clear coat's textures are ignored (its factors are used)",
            files.path.display()
        );
    }
    let factor = |key: &str| match coat.get(key) {
        None => 0.0,
        Some(v) => v.as_f64().map_or(f32::NAN, |f| f as f32),
    };
    (
        factor("clearcoatFactor"),
        factor("clearcoatRoughnessFactor"),
    )
}
