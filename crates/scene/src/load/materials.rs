//! The materials of a scene file: the keys every model shares (`color`, `texture`,
//! `emission`), the `model` key that chooses the material model, and each model's own keys,
//! validated with the file's line. A key of another model is refused, saying which `model`
//! it belongs to.

use std::ops::Range;

use glam::Vec3;

use super::Builder;
use crate::desc::{ColorSpace, MaterialDesc, ModelDesc};
use crate::error::SceneError;
use crate::{Conductor, Lobes, Material, MetalRough, Model, TextureRef};

/// Every model-specific key with the model it belongs to, and whether `m` gives it (`ior`
/// belongs to both models and is not listed).
fn model_keys(m: &MaterialDesc) -> [(ModelDesc, &'static str, bool); 17] {
    use ModelDesc::{Lobes, MetalRough};
    [
        (Lobes, "preset", m.preset.is_some()),
        (Lobes, "specular_rate", m.specular_rate.is_some()),
        (Lobes, "specular_tint", m.specular_tint.is_some()),
        (Lobes, "specular_roughness", m.specular_roughness.is_some()),
        (Lobes, "refract_rate", m.refract_rate.is_some()),
        (Lobes, "refract_tint", m.refract_tint.is_some()),
        (Lobes, "refract_roughness", m.refract_roughness.is_some()),
        (
            Lobes,
            "conductor",
            m.conductor.is_some() || m.eta.is_some() || m.k.is_some(),
        ),
        (MetalRough, "metallic", m.metallic.is_some()),
        (MetalRough, "roughness", m.roughness.is_some()),
        (MetalRough, "transmission", m.transmission.is_some()),
        (MetalRough, "specular", m.specular.is_some()),
        (MetalRough, "specular_color", m.specular_color.is_some()),
        (MetalRough, "clearcoat", m.clearcoat.is_some()),
        (
            MetalRough,
            "clearcoat_roughness",
            m.clearcoat_roughness.is_some(),
        ),
        (MetalRough, "sheen_color", m.sheen_color.is_some()),
        (MetalRough, "sheen_roughness", m.sheen_roughness.is_some()),
    ]
}

impl Builder<'_, '_> {
    /// Material `name` of the file.
    pub(super) fn material(
        &mut self,
        name: &str,
        desc: &toml::Spanned<MaterialDesc>,
        color_space: ColorSpace,
    ) -> Result<Material, SceneError> {
        let span = desc.span();
        let m = desc.get_ref();
        let key = |field: &str| format!("materials.{name}.{field}");
        let base_color = self.color(span.clone(), &key("color"), m.color, color_space)?;
        let emission = match m.emission {
            Some(e) => self.radiance(span.clone(), &key("emission"), e)?,
            None => Vec3::ZERO,
        };
        let chosen = m.model.unwrap_or(ModelDesc::Lobes);
        if let Some((owner, other_key, _)) = model_keys(m)
            .into_iter()
            .find(|(owner, _, given)| *given && *owner != chosen)
        {
            let why = match m.model {
                Some(_) => format!("this material's model is {:?}", chosen.name()),
                None => format!("without `model` a material is {:?}", chosen.name()),
            };
            return Err(self.invalid(
                span,
                format!(
                    "{}: a key of the {:?} model; {why}: write model = {:?} to use it",
                    key(other_key),
                    owner.name(),
                    owner.name()
                ),
            ));
        }
        let model = match chosen {
            ModelDesc::Lobes => Model::Lobes(self.lobes(name, m, span.clone())?),
            ModelDesc::MetalRough => Model::MetalRough(self.metal_rough(name, m, span.clone())?),
        };
        let texture = match &m.texture {
            Some(path) => Some(TextureRef::plain(self.texture(
                span,
                &key("texture"),
                path,
            )?)),
            None => None,
        };
        // Under the lobes a texture replaces `color`; under metal-rough it multiplies it.
        let base_color = match (model, texture) {
            (Model::Lobes(_), Some(_)) => Vec3::ONE,
            _ => base_color,
        };
        Ok(Material {
            texture,
            emission,
            ..Material::new(name, base_color, model)
        })
    }

    /// The lobe model's keys: a preset's lobes with the keys given over them.
    fn lobes(&self, name: &str, m: &MaterialDesc, span: Range<usize>) -> Result<Lobes, SceneError> {
        let key = |field: &str| format!("materials.{name}.{field}");
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
        Ok(Lobes {
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
            conductor,
        })
    }

    /// The metal-rough model's keys.
    fn metal_rough(
        &self,
        name: &str,
        m: &MaterialDesc,
        span: Range<usize>,
    ) -> Result<MetalRough, SceneError> {
        let key = |k: &str| format!("materials.{name}.{k}");
        let ior = m.ior.unwrap_or(1.5);
        if !(ior.is_finite() && ior >= 1.0) {
            return Err(self.invalid(span, format!("{} = {ior} must be >= 1", key("ior"))));
        }
        Ok(MetalRough {
            metallic: self.unit(span.clone(), &key("metallic"), m.metallic.unwrap_or(0.0))?,
            roughness: self.unit(span.clone(), &key("roughness"), m.roughness.unwrap_or(1.0))?,
            transmission: self.unit(
                span.clone(),
                &key("transmission"),
                m.transmission.unwrap_or(0.0),
            )?,
            specular: self.unit(span.clone(), &key("specular"), m.specular.unwrap_or(1.0))?,
            clearcoat: self.unit(span.clone(), &key("clearcoat"), m.clearcoat.unwrap_or(0.0))?,
            clearcoat_roughness: self.unit(
                span.clone(),
                &key("clearcoat_roughness"),
                m.clearcoat_roughness.unwrap_or(0.0),
            )?,
            specular_color: match m.specular_color {
                Some(c) => self.radiance(span.clone(), &key("specular_color"), c)?,
                None => Vec3::ONE,
            },
            sheen_color: match m.sheen_color {
                Some(c) => {
                    let key = key("sheen_color");
                    let c = self.radiance(span.clone(), &key, c)?;
                    if c.max_element() > 1.0 {
                        return Err(self.invalid(span, format!("{key} = {c}: must lie in [0, 1]")));
                    }
                    c
                }
                None => Vec3::ZERO,
            },
            sheen_roughness: self.unit(
                span.clone(),
                &key("sheen_roughness"),
                m.sheen_roughness.unwrap_or(0.0),
            )?,
            ior,
            ..MetalRough::DEFAULT
        })
    }
}
