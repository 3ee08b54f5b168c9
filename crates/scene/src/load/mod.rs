//! Building a [`Scene`] from scene-file text: validation, name resolution, asset loading.
//! The camera, settings and environment are read here, the materials in `materials`, the
//! shapes and placed glTF files in `objects`, the lights in `lights` (its private modules).

mod lights;
mod materials;
mod objects;

use std::collections::HashMap;
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::Vec3;
use toml::Spanned;

use crate::desc::{ColorSpace, EnvironmentDesc, RenderDesc, SamplerDesc, SceneDesc};
use crate::error::RangeError;
use crate::error::SceneError;
use crate::settings::{
    MAX_COORDINATE, check_aperture, check_env_rotation, check_env_strength, check_length,
    check_max_depth, check_resolution, check_spp, check_view,
};
use crate::texture::srgb_to_linear;
use crate::{Camera, Environment, HdrImage, Material, RenderSettings, Sampler, Scene, Texture};

/// Where a scene's text and assets come from.
#[derive(Debug, Clone)]
pub struct SceneSource<'a> {
    /// Name used in error messages (usually the file path).
    pub name: String,
    /// The TOML text.
    pub text: &'a str,
    /// Directory that relative asset paths start from.
    pub base_dir: PathBuf,
    /// Assets compiled into the binary, by the path the scene names them with.
    pub embedded: &'a [(&'a str, &'a [u8])],
}

/// Reads and builds the scene in `path`.
pub fn load_scene_file(path: &Path) -> Result<Scene, SceneError> {
    let text = std::fs::read_to_string(path).map_err(|source| SceneError::Io {
        path: path.to_owned(),
        source,
    })?;
    load_scene(&SceneSource {
        name: path.display().to_string(),
        text: &text,
        base_dir: path.parent().map(Path::to_owned).unwrap_or_default(),
        embedded: &[],
    })
}

/// Parses and builds a scene.
pub fn load_scene(source: &SceneSource) -> Result<Scene, SceneError> {
    Builder::new(source).build(parse(source)?)
}

/// The materials of a scene's text alone, built as [`load_scene`] builds them: in the same
/// order, with the same texture ids where the texture paths are the same. For changing the
/// materials of a loaded scene without reading its shapes again (the materials placed glTF
/// files bring are not among them).
pub fn load_materials(source: &SceneSource) -> Result<Vec<Material>, SceneError> {
    let desc = parse(source)?;
    let mut builder = Builder::new(source);
    desc.materials
        .iter()
        .map(|(name, material)| builder.material(name, material, desc.color_space))
        .collect()
}

/// The scene description of a scene's text, or the syntax error with its line and column.
fn parse(source: &SceneSource) -> Result<SceneDesc, SceneError> {
    toml::from_str(source.text).map_err(|err| {
        let (line, column) = err
            .span()
            .map(|span| line_column(source.text, span.start))
            .unwrap_or((1, 1));
        SceneError::Syntax {
            file: source.name.clone(),
            line,
            column,
            message: err.message().trim().to_owned(),
        }
    })
}

/// 1-based line and column of a byte offset.
fn line_column(text: &str, offset: usize) -> (usize, usize) {
    let before = &text[..offset.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let column = before.len() - before.rfind('\n').map_or(0, |i| i + 1) + 1;
    (line, column)
}

struct Builder<'a, 'b> {
    source: &'a SceneSource<'b>,
    textures: Vec<Texture>,
    texture_ids: HashMap<String, u32>,
}

impl<'a, 'b> Builder<'a, 'b> {
    fn new(source: &'a SceneSource<'b>) -> Self {
        Self {
            source,
            textures: Vec::new(),
            texture_ids: HashMap::new(),
        }
    }
}

impl Builder<'_, '_> {
    fn invalid(&self, span: Range<usize>, message: String) -> SceneError {
        SceneError::Invalid {
            file: self.source.name.clone(),
            line: line_column(self.source.text, span.start).0,
            message,
        }
    }

    fn build(mut self, desc: SceneDesc) -> Result<Scene, SceneError> {
        let camera = self.camera(&desc)?;
        let settings = self.settings(&desc)?;
        let environment = match &desc.environment {
            None => Environment::default(),
            Some(env) => self.environment(env)?,
        };
        let mut materials = Vec::new();
        let mut material_ids = HashMap::new();
        for (name, material) in &desc.materials {
            material_ids.insert(name.clone(), materials.len() as u32);
            materials.push(self.material(name, material, desc.color_space)?);
        }
        let mut objects = self.objects(&desc, &material_ids)?;
        let mut lights = self.lights(&desc.light, desc.color_space)?;
        for gltf in &desc.gltf {
            self.place_gltf(gltf, &mut materials, &mut objects, &mut lights)?;
        }
        Ok(Scene {
            camera,
            settings,
            environment,
            materials,
            textures: self.textures,
            objects,
            lights,
        })
    }

    fn camera(&self, desc: &SceneDesc) -> Result<Camera, SceneError> {
        let span = desc.camera.span();
        let c = desc.camera.get_ref();
        let position = self.point(span.clone(), "camera.position", c.position)?;
        let look_at = self.point(span.clone(), "camera.look_at", c.look_at)?;
        let up = self.point(span.clone(), "camera.up", c.up)?;
        check_view("camera.", position, look_at, up, c.fov_y)
            .map_err(|e| self.invalid(span.clone(), e.to_string()))?;
        let [width, height] = c.resolution;
        check_resolution(width, height).map_err(|e| self.invalid(span.clone(), e.to_string()))?;
        let range = |result: Result<f32, RangeError>| {
            result.map_err(|e| self.invalid(span.clone(), e.to_string()))
        };
        let aperture_radius = range(check_aperture("camera.aperture_radius", c.aperture_radius))?;
        let focus_distance = match c.focus_distance {
            Some(d) => self.length(span, "camera.focus_distance", d)?,
            None => position.distance(look_at),
        };
        Ok(Camera {
            position,
            look_at,
            up,
            fov_y_deg: c.fov_y,
            width,
            height,
            aperture_radius,
            focus_distance,
        })
    }

    /// `[environment]`: a constant `radiance` or a `map` with its `strength` and `rotation`.
    fn environment(&self, env: &Spanned<EnvironmentDesc>) -> Result<Environment, SceneError> {
        let (span, e) = (env.span(), env.get_ref());
        let key = |k: &str| format!("environment.{k}");
        match (&e.radiance, &e.map) {
            (Some(radiance), None) => {
                if e.strength.is_some() || e.rotation.is_some() {
                    return Err(self.invalid(
                        span,
                        "environment.strength and environment.rotation apply to a `map`".into(),
                    ));
                }
                Ok(Environment::Constant(self.radiance(
                    span,
                    &key("radiance"),
                    *radiance,
                )?))
            }
            (None, Some(path)) => {
                let range = |result: Result<f32, RangeError>| {
                    result.map_err(|e| self.invalid(span.clone(), e.to_string()))
                };
                let strength = range(check_env_strength(
                    &key("strength"),
                    e.strength.unwrap_or(1.0),
                ))?;
                let rotation = range(check_env_rotation(
                    &key("rotation"),
                    e.rotation.unwrap_or(0.0),
                ))?;
                let (full, bytes) = self.asset_bytes(path).map_err(|err| match err {
                    SceneError::Io { path, source } => self.invalid(
                        span.clone(),
                        format!("{}: cannot read {}: {source}", key("map"), path.display()),
                    ),
                    other => other,
                })?;
                let image = HdrImage::decode(&bytes, &full)?;
                Ok(Environment::from_map(Arc::new(image), strength, rotation))
            }
            _ => Err(self.invalid(
                span,
                "[environment] needs exactly one of `radiance` (a constant) and `map` (an image)"
                    .into(),
            )),
        }
    }

    fn settings(&self, desc: &SceneDesc) -> Result<RenderSettings, SceneError> {
        let Some(render) = &desc.render else {
            return Ok(RenderSettings::from(&RenderDesc::default()));
        };
        let span = render.span();
        let r = render.get_ref();
        check_spp(r.spp).map_err(|e| self.invalid(span.clone(), e.to_string()))?;
        check_max_depth(r.max_depth).map_err(|e| self.invalid(span, e.to_string()))?;
        Ok(RenderSettings::from(r))
    }

    fn point(&self, span: Range<usize>, key: &str, v: [f32; 3]) -> Result<Vec3, SceneError> {
        if v.iter().all(|c| c.abs() <= MAX_COORDINATE) {
            Ok(Vec3::from(v))
        } else {
            Err(self.invalid(
                span,
                format!(
                    "{key} = {v:?}: coordinates must be finite and within +-{MAX_COORDINATE:e}"
                ),
            ))
        }
    }

    /// A length (a radius): finite, above zero and within the coordinate limit.
    fn length(&self, span: Range<usize>, key: &str, value: f32) -> Result<f32, SceneError> {
        check_length(key, value).map_err(|e| self.invalid(span, e.to_string()))
    }

    fn radiance(&self, span: Range<usize>, key: &str, v: [f32; 3]) -> Result<Vec3, SceneError> {
        if v.iter().all(|c| c.is_finite() && *c >= 0.0) {
            Ok(Vec3::from(v))
        } else {
            Err(self.invalid(span, format!("{key} = {v:?} must be finite and >= 0")))
        }
    }

    /// A colour in the file's `color_space`, as linear RGB (sRGB values must lie in [0, 1]).
    fn color(
        &self,
        span: Range<usize>,
        key: &str,
        v: [f32; 3],
        color_space: ColorSpace,
    ) -> Result<Vec3, SceneError> {
        let color = self.radiance(span.clone(), key, v)?;
        match color_space {
            ColorSpace::Linear => Ok(color),
            ColorSpace::Srgb if color.max_element() > 1.0 => {
                Err(self.invalid(span, format!("{key} = {v:?}: sRGB colours lie in [0, 1]")))
            }
            ColorSpace::Srgb => Ok(color.to_array().map(srgb_to_linear).into()),
        }
    }

    fn unit(&self, span: Range<usize>, key: &str, value: f32) -> Result<f32, SceneError> {
        if (0.0..=1.0).contains(&value) {
            Ok(value)
        } else {
            Err(self.invalid(span, format!("{key} = {value} must lie in [0, 1]")))
        }
    }

    /// Reads an asset named in the file: embedded first, else relative to the scene.
    fn asset_bytes(&self, path: &str) -> Result<(PathBuf, Vec<u8>), SceneError> {
        if let Some((_, bytes)) = self.source.embedded.iter().find(|(name, _)| *name == path) {
            return Ok((PathBuf::from(path), bytes.to_vec()));
        }
        let full = self.source.base_dir.join(path);
        let bytes = std::fs::read(&full).map_err(|source| SceneError::Io {
            path: full.clone(),
            source,
        })?;
        Ok((full, bytes))
    }

    fn texture(&mut self, span: Range<usize>, key: &str, path: &str) -> Result<u32, SceneError> {
        if let Some(&id) = self.texture_ids.get(path) {
            return Ok(id);
        }
        let (full, bytes) = self.asset_bytes(path).map_err(|err| match err {
            SceneError::Io { path, source } => self.invalid(
                span,
                format!("{key}: cannot read {}: {source}", path.display()),
            ),
            other => other,
        })?;
        let texture = Texture::decode(&bytes, &full)?;
        let id = self.textures.len() as u32;
        self.textures.push(texture);
        self.texture_ids.insert(path.to_owned(), id);
        Ok(id)
    }
}

impl From<&RenderDesc> for RenderSettings {
    fn from(r: &RenderDesc) -> Self {
        Self {
            spp: r.spp,
            max_depth: r.max_depth,
            rr_depth: r.rr_depth,
            seed: r.seed,
            sampler: match r.sampler {
                SamplerDesc::Sobol => Sampler::Sobol,
                SamplerDesc::Independent => Sampler::Independent,
            },
            aovs: false,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::line_column;

    #[test]
    fn line_column_counts_from_one() {
        let text = "a\nbc\nd";
        assert_eq!(line_column(text, 0), (1, 1));
        assert_eq!(line_column(text, 3), (2, 2));
        assert_eq!(line_column(text, 5), (3, 1));
    }
}
