//! Building a [`Scene`] from scene-file text: validation, name resolution, asset loading.

use std::collections::HashMap;
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::{Vec2, Vec3};
use toml::Spanned;

use crate::desc::{
    ColorSpace, EnvironmentDesc, GltfDesc, MaterialDesc, RenderDesc, SamplerDesc, SceneDesc,
    Shading,
};
use crate::error::SceneError;
use crate::gltf_file::load_gltf;
use crate::revolve::Revolution;
use crate::settings::{MAX_COORDINATE, check_max_depth, check_resolution, check_spp};
use crate::texture::srgb_to_linear;
use crate::{
    Camera, Conductor, Environment, HdrImage, Lobes, Material, MetalRough, Object, RenderSettings,
    Sampler, Scene, Shape, Texture, TextureRef, TriangleMesh,
};

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
    let desc: SceneDesc = toml::from_str(source.text).map_err(|err| {
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
    })?;
    Builder {
        source,
        textures: Vec::new(),
        texture_ids: HashMap::new(),
    }
    .build(desc)
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
        for gltf in &desc.gltf {
            self.place_gltf(gltf, &mut materials, &mut objects)?;
        }
        Ok(Scene {
            camera,
            settings,
            environment,
            materials,
            textures: self.textures,
            objects,
        })
    }

    fn camera(&self, desc: &SceneDesc) -> Result<Camera, SceneError> {
        let span = desc.camera.span();
        let c = desc.camera.get_ref();
        let position = self.point(span.clone(), "camera.position", c.position)?;
        let look_at = self.point(span.clone(), "camera.look_at", c.look_at)?;
        let up = self.point(span.clone(), "camera.up", c.up)?;
        if position.distance(look_at) <= 0.0 {
            return Err(self.invalid(span, "camera.look_at equals camera.position".into()));
        }
        if up.cross(look_at - position).length_squared() <= 0.0 {
            return Err(self.invalid(span, "camera.up is parallel to the view direction".into()));
        }
        if !(c.fov_y > 0.0 && c.fov_y < 180.0) {
            return Err(self.invalid(
                span,
                format!(
                    "camera.fov_y = {} must lie strictly between 0 and 180 degrees",
                    c.fov_y
                ),
            ));
        }
        let [width, height] = c.resolution;
        check_resolution(width, height).map_err(|e| self.invalid(span.clone(), e.to_string()))?;
        if !(c.aperture_radius >= 0.0 && c.aperture_radius <= MAX_COORDINATE) {
            return Err(self.invalid(
                span,
                format!(
                    "camera.aperture_radius = {} must be >= 0 and at most {MAX_COORDINATE:e}",
                    c.aperture_radius
                ),
            ));
        }
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
            aperture_radius: c.aperture_radius,
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
                let strength = e.strength.unwrap_or(1.0);
                if !(strength.is_finite() && strength >= 0.0) {
                    return Err(self.invalid(
                        span,
                        format!("{} = {strength} must be finite and >= 0", key("strength")),
                    ));
                }
                let rotation = e.rotation.unwrap_or(0.0);
                if !rotation.is_finite() {
                    return Err(self.invalid(
                        span,
                        format!("{} = {rotation} must be finite", key("rotation")),
                    ));
                }
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
        if value > 0.0 && value <= MAX_COORDINATE {
            Ok(value)
        } else {
            Err(self.invalid(
                span,
                format!("{key} = {value} must be > 0 and at most {MAX_COORDINATE:e}"),
            ))
        }
    }

    /// A mesh made from the file's values (an OBJ placed by its transform, a revolved
    /// profile) whose vertices must all be finite and within the coordinate limit.
    fn checked_mesh(
        &self,
        span: Range<usize>,
        what: &str,
        mesh: TriangleMesh,
    ) -> Result<TriangleMesh, SceneError> {
        match mesh.positions.iter().position(|p| !p.abs().cmple(Vec3::splat(MAX_COORDINATE)).all()) {
            None => Ok(mesh),
            Some(i) => Err(self.invalid(
                span,
                format!(
                    "{what}: vertex {i} lies at {}; coordinates must be finite and within +-{MAX_COORDINATE:e}",
                    mesh.positions[i]
                ),
            )),
        }
    }

    fn radiance(&self, span: Range<usize>, key: &str, v: [f32; 3]) -> Result<Vec3, SceneError> {
        if v.iter().all(|c| c.is_finite() && *c >= 0.0) {
            Ok(Vec3::from(v))
        } else {
            Err(self.invalid(span, format!("{key} = {v:?} must be finite and >= 0")))
        }
    }

    fn unit(&self, span: Range<usize>, key: &str, value: f32) -> Result<f32, SceneError> {
        if (0.0..=1.0).contains(&value) {
            Ok(value)
        } else {
            Err(self.invalid(span, format!("{key} = {value} must lie in [0, 1]")))
        }
    }

    fn material(
        &mut self,
        name: &str,
        desc: &Spanned<MaterialDesc>,
        color_space: ColorSpace,
    ) -> Result<Material, SceneError> {
        let span = desc.span();
        let m = desc.get_ref();
        let key = |field: &str| format!("materials.{name}.{field}");
        let color = self.radiance(span.clone(), &key("color"), m.color)?;
        let base_color = match color_space {
            ColorSpace::Linear => color,
            ColorSpace::Srgb => {
                if color.max_element() > 1.0 {
                    return Err(self.invalid(
                        span,
                        format!(
                            "{} = {:?}: sRGB colours lie in [0, 1]",
                            key("color"),
                            m.color
                        ),
                    ));
                }
                color.to_array().map(srgb_to_linear).into()
            }
        };
        let emission = match m.emission {
            Some(e) => self.radiance(span.clone(), &key("emission"), e)?,
            None => Vec3::ZERO,
        };
        if m.metallic.is_some() || m.roughness.is_some() || m.transmission.is_some() {
            return self.metal_rough_material(name, m, base_color, emission, span);
        }
        let conductor = match (&m.conductor, m.eta, m.k) {
            (None, None, None) => None,
            (Some(preset), None, None) => Some(Conductor::preset(preset).ok_or_else(|| {
                let names: Vec<_> = Conductor::PRESETS.iter().map(|(n, _)| *n).collect();
                self.invalid(
                    span.clone(),
                    format!("{} = {preset:?} is not one of {names:?}", key("conductor")),
                )
            })?),
            (None, Some(eta), Some(k)) => Some(Conductor {
                eta: self.radiance(span.clone(), &key("eta"), eta)?,
                k: self.radiance(span.clone(), &key("k"), k)?,
            }),
            _ => {
                return Err(self.invalid(
                    span,
                    format!(
                        "{}: give either `conductor` (a preset) or both `eta` and `k`",
                        key("conductor")
                    ),
                ));
            }
        };
        let base = match &m.preset {
            None => Lobes::DIFFUSE,
            Some(name) => Lobes::preset(name).ok_or_else(|| {
                let names: Vec<_> = Lobes::PRESETS.iter().map(|(n, _)| *n).collect();
                self.invalid(
                    span.clone(),
                    format!("{} = {name:?} is not one of {names:?}", key("preset")),
                )
            })?,
        };
        // A conductor is all specular unless the file says otherwise.
        let default_specular = if conductor.is_some() {
            1.0
        } else {
            base.specular_rate
        };
        let specular_rate = self.unit(
            span.clone(),
            &key("specular_rate"),
            m.specular_rate.unwrap_or(default_specular),
        )?;
        let refract_rate = self.unit(
            span.clone(),
            &key("refract_rate"),
            m.refract_rate.unwrap_or(base.refract_rate),
        )?;
        if specular_rate + refract_rate > 1.0 + 1e-6 {
            return Err(self.invalid(
                span,
                format!(
                    "materials.{name}: specular_rate + refract_rate = {} exceeds 1",
                    specular_rate + refract_rate
                ),
            ));
        }
        let ior = m.ior.unwrap_or(base.ior);
        if !(ior.is_finite() && ior > 0.0) {
            return Err(self.invalid(span, format!("{} = {ior} must be > 0", key("ior"))));
        }
        let texture = self.base_texture(span.clone(), name, m)?;
        let lobes = Lobes {
            specular_rate,
            specular_tint: self.unit(
                span.clone(),
                &key("specular_tint"),
                m.specular_tint.unwrap_or(base.specular_tint),
            )?,
            specular_roughness: self.unit(
                span.clone(),
                &key("specular_roughness"),
                m.specular_roughness.unwrap_or(base.specular_roughness),
            )?,
            refract_rate,
            refract_tint: self.unit(
                span.clone(),
                &key("refract_tint"),
                m.refract_tint.unwrap_or(base.refract_tint),
            )?,
            ior,
            refract_roughness: self.unit(
                span,
                &key("refract_roughness"),
                m.refract_roughness.unwrap_or(base.refract_roughness),
            )?,
        };
        Ok(Material {
            name: name.to_owned(),
            base_color,
            texture,
            emission,
            lobes,
            conductor,
            metal_rough: None,
        })
    }

    /// A material with `metallic`, `roughness` or `transmission`: glTF's metal-rough model,
    /// which takes none of the lobe keys.
    fn metal_rough_material(
        &mut self,
        name: &str,
        m: &MaterialDesc,
        base_color: Vec3,
        emission: Vec3,
        span: Range<usize>,
    ) -> Result<Material, SceneError> {
        let key = |k: &str| format!("materials.{name}.{k}");
        let lobe_keys = [
            ("preset", m.preset.is_some()),
            ("specular_rate", m.specular_rate.is_some()),
            ("specular_tint", m.specular_tint.is_some()),
            ("specular_roughness", m.specular_roughness.is_some()),
            ("refract_rate", m.refract_rate.is_some()),
            ("refract_tint", m.refract_tint.is_some()),
            ("refract_roughness", m.refract_roughness.is_some()),
            (
                "conductor",
                m.conductor.is_some() || m.eta.is_some() || m.k.is_some(),
            ),
        ];
        if let Some((lobe_key, _)) = lobe_keys.iter().find(|(_, given)| *given) {
            return Err(self.invalid(
                span,
                format!(
                    "{}: the metal-rough model (metallic, roughness, transmission) takes no `{lobe_key}`",
                    key(lobe_key)
                ),
            ));
        }
        let ior = m.ior.unwrap_or(1.5);
        if !(ior.is_finite() && ior >= 1.0) {
            return Err(self.invalid(span, format!("{} = {ior} must be >= 1", key("ior"))));
        }
        let texture = self.base_texture(span.clone(), name, m)?;
        Ok(Material {
            name: name.to_owned(),
            base_color,
            texture,
            emission,
            lobes: Lobes::DIFFUSE,
            conductor: None,
            metal_rough: Some(MetalRough {
                metallic: self.unit(span.clone(), &key("metallic"), m.metallic.unwrap_or(0.0))?,
                roughness: self.unit(
                    span.clone(),
                    &key("roughness"),
                    m.roughness.unwrap_or(1.0),
                )?,
                transmission: self.unit(
                    span,
                    &key("transmission"),
                    m.transmission.unwrap_or(0.0),
                )?,
                ior,
                ..MetalRough::DEFAULT
            }),
        })
    }

    /// The texture a material's `texture` key names, placed as scene files place it.
    fn base_texture(
        &mut self,
        span: Range<usize>,
        name: &str,
        m: &MaterialDesc,
    ) -> Result<Option<TextureRef>, SceneError> {
        let Some(path) = &m.texture else {
            return Ok(None);
        };
        let key = format!("materials.{name}.texture");
        Ok(Some(TextureRef::plain(self.texture(span, &key, path)?)))
    }

    /// Adds the objects, materials and textures of a `[[gltf]]` entry.
    fn place_gltf(
        &mut self,
        desc: &Spanned<GltfDesc>,
        materials: &mut Vec<Material>,
        objects: &mut Vec<Object>,
    ) -> Result<(), SceneError> {
        let d = desc.get_ref();
        let path = self.source.base_dir.join(&d.file);
        let model = load_gltf(&path, d.transform.to_matrix()).map_err(|err| match err {
            SceneError::Io { path, source } => self.invalid(
                desc.span(),
                format!("gltf.file: cannot read {}: {source}", path.display()),
            ),
            other => other,
        })?;
        let (first_material, first_texture) = (materials.len() as u32, self.textures.len() as u32);
        let shift = |r: &mut Option<TextureRef>| {
            if let Some(r) = r {
                r.texture += first_texture;
            }
        };
        for mut material in model.materials {
            shift(&mut material.texture);
            if let Some(pbr) = &mut material.metal_rough {
                shift(&mut pbr.metal_rough_texture);
                shift(&mut pbr.normal_texture);
                shift(&mut pbr.emission_texture);
            }
            materials.push(material);
        }
        self.textures.extend(model.textures);
        objects.extend(model.objects.into_iter().map(|o| Object {
            material: o.material + first_material,
            ..o
        }));
        Ok(())
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

    fn objects(
        &self,
        desc: &SceneDesc,
        material_ids: &HashMap<String, u32>,
    ) -> Result<Vec<Object>, SceneError> {
        let mut objects = Vec::new();
        // Where each object was declared, for errors about it.
        let mut spans: Vec<Range<usize>> = Vec::new();
        let material = |span: Range<usize>, name: &str| {
            material_ids.get(name).copied().ok_or_else(|| {
                let known: Vec<_> = material_ids.keys().collect();
                self.invalid(
                    span,
                    format!("material = {name:?} is not defined (defined: {known:?})"),
                )
            })
        };
        let named = |name: &Option<String>, kind: &str, index: usize| {
            name.clone().unwrap_or_else(|| format!("{kind}{index}"))
        };
        for (i, q) in desc.quad.iter().enumerate() {
            let (span, d) = (q.span(), q.get_ref());
            spans.push(span.clone());
            let edge_u = self.point(span.clone(), "edge_u", d.edge_u)?;
            let edge_v = self.point(span.clone(), "edge_v", d.edge_v)?;
            objects.push(Object {
                name: named(&d.name, "quad", i),
                material: material(span.clone(), &d.material)?,
                shape: Shape::Quad {
                    origin: self.point(span, "origin", d.origin)?,
                    edge_u,
                    edge_v,
                },
            });
        }
        for (i, s) in desc.sphere.iter().enumerate() {
            let (span, d) = (s.span(), s.get_ref());
            spans.push(span.clone());
            let radius = self.length(span.clone(), "radius", d.radius)?;
            if !d.texture_rotation.is_finite() {
                return Err(self.invalid(
                    span,
                    format!("texture_rotation = {} must be finite", d.texture_rotation),
                ));
            }
            objects.push(Object {
                name: named(&d.name, "sphere", i),
                material: material(span.clone(), &d.material)?,
                shape: Shape::Sphere {
                    center: self.point(span, "center", d.center)?,
                    radius,
                    texture_rotation: d.texture_rotation.to_radians(),
                },
            });
        }
        for (i, c) in desc.cylinder.iter().enumerate() {
            let (span, d) = (c.span(), c.get_ref());
            spans.push(span.clone());
            let radius = self.length(span.clone(), "radius", d.radius)?;
            let p0 = self.point(span.clone(), "p0", d.p0)?;
            let p1 = self.point(span.clone(), "p1", d.p1)?;
            if p0 == p1 {
                return Err(self.invalid(span, "p0 and p1 must differ".into()));
            }
            objects.push(Object {
                name: named(&d.name, "cylinder", i),
                material: material(span, &d.material)?,
                shape: Shape::Cylinder {
                    p0,
                    p1,
                    radius,
                    caps: d.caps,
                },
            });
        }
        for (i, m) in desc.mesh.iter().enumerate() {
            let (span, d) = (m.span(), m.get_ref());
            spans.push(span.clone());
            let material = material(span.clone(), &d.material)?;
            let path = self.source.base_dir.join(&d.file);
            if !path.is_file() {
                return Err(self.invalid(
                    span,
                    format!("file = {:?}: no such file {}", d.file, path.display()),
                ));
            }
            let mut mesh = crate::mesh::load_obj(&path)?;
            mesh.transform(d.transform.to_matrix());
            mesh.flat = d.shading == Shading::Flat;
            let what = format!("file = {:?} placed by its transform", d.file);
            let mesh = self.checked_mesh(span, &what, mesh)?;
            objects.push(Object {
                name: named(&d.name, "mesh", i),
                material,
                shape: Shape::Mesh(mesh),
            });
        }
        for (i, r) in desc.revolve.iter().enumerate() {
            let (span, d) = (r.span(), r.get_ref());
            spans.push(span.clone());
            let material = material(span.clone(), &d.material)?;
            let axis = self.point(span.clone(), "axis", d.axis)?;
            let in_range = |v: &f32| v.abs() <= MAX_COORDINATE;
            if d.profile.len() < 2 || !d.profile.iter().flatten().all(in_range) {
                return Err(self.invalid(
                    span,
                    format!(
                        "profile needs at least two [radius, height] points, finite and within \
                         +-{MAX_COORDINATE:e}"
                    ),
                ));
            }
            if !(3..=4096).contains(&d.segments) || !(1..=4096).contains(&d.rings) {
                return Err(self.invalid(
                    span,
                    format!(
                        "segments = {} must lie in 3..=4096 and rings = {} in 1..=4096",
                        d.segments, d.rings
                    ),
                ));
            }
            if axis.length_squared() <= 0.0 {
                return Err(self.invalid(span, "axis must not be zero".into()));
            }
            let revolution = Revolution {
                base: self.point(span.clone(), "base", d.base)?,
                axis: axis.normalize(),
                profile: d.profile.iter().map(|&p| Vec2::from(p)).collect(),
                segments: d.segments,
                rings: d.rings,
                cap_bottom: d.cap_bottom,
            };
            let mesh = self.checked_mesh(span, "the revolved profile", revolution.to_mesh())?;
            objects.push(Object {
                name: named(&d.name, "revolve", i),
                material,
                shape: Shape::Mesh(mesh),
            });
        }
        // Names pick objects out (the viewer's messages, `bench --without`): each must be one.
        let mut seen: HashMap<&str, usize> = HashMap::new();
        for (i, object) in objects.iter().enumerate() {
            if let Some(&first) = seen.get(object.name.as_str()) {
                let first_line = line_column(self.source.text, spans[first].start).0;
                return Err(self.invalid(
                    spans[i].clone(),
                    format!(
                        "name = {:?} is already the name of the object on line {first_line}",
                        object.name
                    ),
                ));
            }
            seen.insert(&object.name, i);
        }
        Ok(objects)
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
