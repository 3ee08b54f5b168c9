//! glTF materials and their textures as pathlight's [`Material`]s and [`TextureRef`]s.

use std::collections::HashMap;

use glam::Vec3;
use gltf::json::Value;
use gltf::texture::WrappingMode;

use super::data::Files;
use super::primitives::Needs;
use crate::error::SceneError;
use crate::material::{AlphaMode, LayerTextures, Material, MetalRough, Model, TextureRef, Wrap};
use crate::texture::Texture;

/// A glTF file's materials, converted once each, and the images they decode.
pub(super) struct Materials<'a> {
    /// The file's textures, which extensions the `gltf` crate does not read name by index.
    file_textures: Vec<gltf::Texture<'a>>,
    /// Converted materials, in the order first used.
    pub materials: Vec<Material>,
    /// Decoded images, in the order first used.
    pub textures: Vec<Texture>,
    /// Per glTF material (`None`: the default material), its index and needs.
    converted: HashMap<Option<usize>, (u32, Needs)>,
    /// Per glTF image, its index in `textures`.
    images: HashMap<usize, u32>,
}

impl<'a> Materials<'a> {
    /// No materials yet, for the file `document`.
    pub fn new(document: &'a gltf::Document) -> Self {
        Self {
            file_textures: document.textures().collect(),
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
        let mut reference = |this: &mut Self, used: Option<TextureUse>| {
            used.map(|(texture, set, matrix)| {
                uv_sets.push(set);
                this.texture_ref(files, buffers, &texture, matrix)
            })
            .transpose()
        };
        let base_texture = reference(self, pbr.base_color_texture().map(info))?;
        let metal_rough_texture = reference(self, pbr.metallic_roughness_texture().map(info))?;
        let emission_texture = reference(self, material.emissive_texture().map(info))?;
        let normal = material.normal_texture();
        let normal_scale = normal.as_ref().map_or(1.0, |n| n.scale());
        let normal_texture = reference(
            self,
            normal.map(|n| (n.texture(), n.tex_coord(), TextureRef::IDENTITY)),
        )?;
        let transmission = material.transmission();
        let specular = material.specular();
        let coat = Layer::read(files, &element, material, "KHR_materials_clearcoat")?;
        let sheen = Layer::read(files, &element, material, "KHR_materials_sheen")?;
        let file_textures = &self.file_textures;
        let [
            coat_texture,
            coat_roughness_texture,
            coat_normal_texture,
            sheen_color_texture,
            sheen_roughness_texture,
        ] = [
            (&coat, "clearcoatTexture"),
            (&coat, "clearcoatRoughnessTexture"),
            (&coat, "clearcoatNormalTexture"),
            (&sheen, "sheenColorTexture"),
            (&sheen, "sheenRoughnessTexture"),
        ]
        .map(|(layer, key)| layer.texture(file_textures, key));
        let textures = LayerTextures {
            transmission: reference(
                self,
                transmission
                    .as_ref()
                    .and_then(|t| t.transmission_texture())
                    .map(info),
            )?,
            specular: reference(
                self,
                specular
                    .as_ref()
                    .and_then(|s| s.specular_texture())
                    .map(info),
            )?,
            specular_color: reference(
                self,
                specular
                    .as_ref()
                    .and_then(|s| s.specular_color_texture())
                    .map(info),
            )?,
            clearcoat: reference(self, coat_texture?)?,
            clearcoat_roughness: reference(self, coat_roughness_texture?)?,
            clearcoat_normal: reference(self, coat_normal_texture?)?,
            sheen_color: reference(self, sheen_color_texture?)?,
            sheen_roughness: reference(self, sheen_roughness_texture?)?,
        };
        let uv_set = uv_sets.first().copied().unwrap_or(0);
        if uv_sets.iter().any(|&s| s != uv_set) {
            log::warn!(
                "{}: {element}: its textures read several texture coordinate sets; all read TEXCOORD_{uv_set}",
                files.path.display()
            );
        }
        let strength = material.emissive_strength().unwrap_or(1.0);
        let emission = Vec3::from(material.emissive_factor()) * strength;
        let sheen_color = sheen.color("sheenColorFactor");
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
            clearcoat: coat.number("clearcoatFactor", 0.0),
            clearcoat_roughness: coat.number("clearcoatRoughnessFactor", 0.0),
            clearcoat_normal_scale: coat.number("clearcoatNormalTexture/scale", 1.0),
            attenuation,
            sheen_color,
            sheen_roughness: sheen.number("sheenRoughnessFactor", 0.0),
            textures,
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
            metal_rough.clearcoat_normal_scale.abs(),
            metal_rough.sheen_color.x,
            metal_rough.sheen_color.y,
            metal_rough.sheen_color.z,
            metal_rough.sheen_roughness,
        ];
        if numbers.iter().any(|v| !v.is_finite() || *v < 0.0) || metal_rough.ior < 1.0 {
            return Err(files.error(
                &element,
                format!("a factor is negative or not finite: {numbers:?}"),
            ));
        }
        let needs = Needs {
            uv_set,
            tangents: normal_texture.is_some() || textures.clearcoat_normal.is_some(),
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
                sheen_color: metal_rough.sheen_color.min(Vec3::ONE),
                sheen_roughness: metal_rough.sheen_roughness.min(1.0),
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
        transform: [[f32; 3]; 2],
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
            transform,
            wrap: [wrap(sampler.wrap_s()), wrap(sampler.wrap_t())],
        })
    }
}

/// A texture reference's parts: the texture, its coordinate set and its transform.
fn info(i: gltf::texture::Info<'_>) -> TextureUse<'_> {
    let transform = i.texture_transform();
    let set = transform
        .as_ref()
        .and_then(|t| t.tex_coord())
        .unwrap_or(i.tex_coord());
    let matrix = transform.as_ref().map_or(TextureRef::IDENTITY, |t| {
        uv_matrix(t.offset(), t.rotation(), t.scale())
    });
    (i.texture(), set, matrix)
}

/// A texture, the coordinate set it reads and its `KHR_texture_transform` as a matrix.
type TextureUse<'a> = (gltf::Texture<'a>, u32, [[f32; 3]; 2]);

/// The glTF file's name, for naming its embedded images.
fn file_name(files: &Files) -> String {
    files
        .path
        .file_name()
        .map_or_else(String::new, |n| n.to_string_lossy().into_owned())
}

/// `KHR_texture_transform`'s translation * rotation * scale, as the 2x3 rows of
/// [`TextureRef::transform`].
pub(super) fn uv_matrix([ox, oy]: [f32; 2], rotation: f32, [sx, sy]: [f32; 2]) -> [[f32; 3]; 2] {
    let (s, c) = rotation.sin_cos();
    [[c * sx, s * sy, ox], [-s * sx, c * sy, oy]]
}

/// A material extension the `gltf` crate does not read (`KHR_materials_clearcoat`,
/// `KHR_materials_sheen`): its JSON object, empty when the material lacks it.
struct Layer<'f> {
    /// The extension's object, if the material has it.
    value: Option<&'f Value>,
    /// The file, for errors.
    files: &'f Files<'f>,
    /// "material N: KHR_materials_...", for errors.
    element: String,
}

impl<'f> Layer<'f> {
    /// Extension `name` of `material`.
    fn read(
        files: &'f Files<'f>,
        element: &str,
        material: &'f gltf::Material,
        name: &str,
    ) -> Result<Self, SceneError> {
        let value = material.extension_value(name);
        if value.is_some_and(|v| !v.is_object()) {
            return Err(files.error(&format!("{element}: {name}"), "is not an object"));
        }
        Ok(Self {
            value,
            files,
            element: format!("{element}: {name}"),
        })
    }

    /// Number `key` (a path below the extension's object: `a/b`), `default` when absent; NaN
    /// (refused with the other factors) when it is not a number.
    fn number(&self, key: &str, default: f32) -> f32 {
        match self.value.and_then(|v| v.pointer(&format!("/{key}"))) {
            None => default,
            Some(v) => v.as_f64().map_or(f32::NAN, |f| f as f32),
        }
    }

    /// Colour `key`, black when absent; NaN when it is not three numbers.
    fn color(&self, key: &str) -> Vec3 {
        match self.value.and_then(|v| v.get(key)) {
            None => Vec3::ZERO,
            Some(v) => match v.as_array().map(Vec::as_slice) {
                Some([r, g, b]) => {
                    Vec3::from([r, g, b].map(|c| c.as_f64().map_or(f32::NAN, |f| f as f32)))
                }
                _ => Vec3::NAN,
            },
        }
    }

    /// Texture info `key` (`index` into `textures`, `texCoord` and `KHR_texture_transform`),
    /// if present.
    fn texture<'a>(
        &self,
        textures: &[gltf::Texture<'a>],
        key: &str,
    ) -> Result<Option<TextureUse<'a>>, SceneError> {
        let Some(info) = self.value.and_then(|v| v.get(key)) else {
            return Ok(None);
        };
        let bad = |what: &str| self.files.error(&format!("{}.{key}", self.element), what);
        let index = info.get("index").and_then(Value::as_u64);
        let texture = index
            .and_then(|i| textures.get(usize::try_from(i).ok()?))
            .ok_or_else(|| bad("names no texture of the file"))?;
        let set = |v: Option<&Value>| {
            v.map_or(Some(0), |v| v.as_u64().and_then(|s| u32::try_from(s).ok()))
        };
        let mut tex_coord = set(info.get("texCoord")).ok_or_else(|| bad("bad texCoord"))?;
        let mut matrix = TextureRef::IDENTITY;
        if let Some(t) = info.pointer("/extensions/KHR_texture_transform") {
            let numbers = |key: &str, default: &[f32]| -> Option<Vec<f32>> {
                match t.get(key) {
                    None => Some(default.to_vec()),
                    Some(Value::Array(a)) => a
                        .iter()
                        .map(|x| x.as_f64().map(|f| f as f32).filter(|f| f.is_finite()))
                        .collect(),
                    Some(x) => x
                        .as_f64()
                        .map(|f| vec![f as f32])
                        .filter(|v| v[0].is_finite()),
                }
            };
            let (Some(offset), Some(rotation), Some(scale)) = (
                numbers("offset", &[0.0, 0.0]),
                numbers("rotation", &[0.0]),
                numbers("scale", &[1.0, 1.0]),
            ) else {
                return Err(bad("bad KHR_texture_transform"));
            };
            let (&[ox, oy], &[r], &[sx, sy]) = (&offset[..], &rotation[..], &scale[..]) else {
                return Err(bad("bad KHR_texture_transform"));
            };
            matrix = uv_matrix([ox, oy], r, [sx, sy]);
            if t.get("texCoord").is_some() {
                tex_coord = set(t.get("texCoord")).ok_or_else(|| bad("bad texCoord"))?;
            }
        }
        Ok(Some((texture.clone(), tex_coord, matrix)))
    }
}
