//! The scene file's `[[light]]` entries: point, spot and sun lights, each key checked
//! against its type.

use std::ops::Range;

use glam::Vec3;
use toml::Spanned;

use super::Builder;
use crate::desc::{ColorSpace, LightDesc, LightType};
use crate::error::SceneError;
use crate::{Cone, Light, LightKind};

/// Largest sun disk accepted, degrees (the real sun's is 0.53).
const MAX_SUN_DIAMETER: f32 = 60.0;

impl Builder<'_, '_> {
    /// The `[[light]]` entries, named `light<index>` when the file gives no name.
    pub(super) fn lights(
        &self,
        descs: &[Spanned<LightDesc>],
        color_space: ColorSpace,
    ) -> Result<Vec<Light>, SceneError> {
        descs
            .iter()
            .enumerate()
            .map(|(i, desc)| self.light(i, desc, color_space))
            .collect()
    }

    fn light(
        &self,
        index: usize,
        desc: &Spanned<LightDesc>,
        color_space: ColorSpace,
    ) -> Result<Light, SceneError> {
        let (span, d) = (desc.span(), desc.get_ref());
        let type_name = match d.kind {
            LightType::Point => "point",
            LightType::Spot => "spot",
            LightType::Sun => "sun",
        };
        let key = |k: &str| format!("light.{k}");
        // Keys that only some types take.
        let given = [
            ("position", d.position.is_some(), d.kind != LightType::Sun),
            (
                "direction",
                d.direction.is_some(),
                d.kind != LightType::Point,
            ),
            ("look_at", d.look_at.is_some(), d.kind == LightType::Spot),
            ("radius", d.radius.is_some(), d.kind != LightType::Sun),
            (
                "inner_angle",
                d.inner_angle.is_some(),
                d.kind == LightType::Spot,
            ),
            (
                "outer_angle",
                d.outer_angle.is_some(),
                d.kind == LightType::Spot,
            ),
            (
                "angular_diameter",
                d.angular_diameter.is_some(),
                d.kind == LightType::Sun,
            ),
        ];
        if let Some((name, _, _)) = given.iter().find(|(_, given, allowed)| *given && !allowed) {
            return Err(self.invalid(
                span,
                format!("light.{name} does not apply to a {type_name} light"),
            ));
        }
        let color = self.color(span.clone(), &key("color"), d.color, color_space)?;
        if !(d.intensity.is_finite() && d.intensity >= 0.0) {
            return Err(self.invalid(
                span,
                format!("light.intensity = {} must be finite and >= 0", d.intensity),
            ));
        }
        let intensity = self.radiance(
            span.clone(),
            "light.color x light.intensity",
            (color * d.intensity).to_array(),
        )?;
        let kind = match d.kind {
            LightType::Sun => LightKind::Sun {
                direction: self.direction(span.clone(), d)?,
                angular_diameter_deg: self.angle(
                    span,
                    "light.angular_diameter",
                    d.angular_diameter.unwrap_or(0.0),
                    0.0..=MAX_SUN_DIAMETER,
                )?,
            },
            LightType::Point | LightType::Spot => {
                let Some(position) = d.position else {
                    return Err(
                        self.invalid(span, format!("a {type_name} light needs light.position"))
                    );
                };
                let position = self.point(span.clone(), &key("position"), position)?;
                let radius = match d.radius {
                    Some(0.0) | None => 0.0,
                    Some(r) => self.length(span.clone(), &key("radius"), r)?,
                };
                let cone = match d.kind {
                    LightType::Spot => Some(self.cone(span, d, position)?),
                    _ => None,
                };
                LightKind::Point {
                    position,
                    radius,
                    cone,
                }
            }
        };
        Ok(Light {
            name: d.name.clone().unwrap_or_else(|| format!("light{index}")),
            intensity,
            kind,
        })
    }

    /// A spot light's cone: its axis from `direction` or `look_at`, its angles checked.
    fn cone(&self, span: Range<usize>, d: &LightDesc, position: Vec3) -> Result<Cone, SceneError> {
        let axis = match d.look_at {
            Some(target) => {
                if d.direction.is_some() {
                    return Err(self.invalid(
                        span,
                        "a spot light takes one of light.direction and light.look_at".into(),
                    ));
                }
                let target = self.point(span.clone(), "light.look_at", target)?;
                let axis = (target - position).normalize_or_zero();
                if axis == Vec3::ZERO {
                    return Err(self.invalid(span, "light.look_at equals light.position".into()));
                }
                axis
            }
            None => self.direction(span.clone(), d)?,
        };
        let outer_deg = self.angle(
            span.clone(),
            "light.outer_angle",
            d.outer_angle.unwrap_or(45.0),
            0.0..=90.0,
        )?;
        if outer_deg <= 0.0 {
            return Err(self.invalid(span, "light.outer_angle must be above 0".into()));
        }
        let inner_deg = self.angle(
            span.clone(),
            "light.inner_angle",
            d.inner_angle.unwrap_or(0.0),
            0.0..=outer_deg,
        )?;
        Ok(Cone {
            axis,
            inner_deg,
            outer_deg,
        })
    }

    /// `light.direction`, required, not zero, made unit length.
    fn direction(&self, span: Range<usize>, d: &LightDesc) -> Result<Vec3, SceneError> {
        let what = if d.kind == LightType::Spot {
            "a spot light needs light.direction or light.look_at"
        } else {
            "a sun light needs light.direction (the way its light travels)"
        };
        let Some(direction) = d.direction else {
            return Err(self.invalid(span, what.into()));
        };
        let direction = self.point(span.clone(), "light.direction", direction)?;
        let unit = direction.normalize_or_zero();
        if unit == Vec3::ZERO {
            return Err(self.invalid(span, "light.direction must not be zero".into()));
        }
        Ok(unit)
    }

    /// An angle in degrees within `range`.
    fn angle(
        &self,
        span: Range<usize>,
        key: &str,
        degrees: f32,
        range: std::ops::RangeInclusive<f32>,
    ) -> Result<f32, SceneError> {
        if range.contains(&degrees) {
            Ok(degrees)
        } else {
            Err(self.invalid(
                span,
                format!(
                    "{key} = {degrees} must lie in [{}, {}] degrees",
                    range.start(),
                    range.end()
                ),
            ))
        }
    }
}
