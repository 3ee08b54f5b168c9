//! The shapes of a scene file (quads, spheres, cylinders, OBJ meshes, surfaces of
//! revolution) and the glTF files it places, with their materials resolved by name.

use std::collections::HashMap;
use std::ops::Range;

use std::sync::Arc;

use glam::{Affine3A, Vec2, Vec3};
use toml::Spanned;

use super::{Builder, line_column};
use crate::desc::{GltfDesc, SceneDesc, Shading};
use crate::error::SceneError;
use crate::gltf_file::load_gltf;
use crate::revolve::Revolution;
use crate::settings::MAX_COORDINATE;
use crate::{Instance, Light, Material, Object, Shape, TriangleMesh};

impl Builder<'_, '_> {
    pub(super) fn objects(
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
            let mesh_material = material(span.clone(), &d.material)?;
            let path = self.source.base_dir.join(&d.file);
            if !path.is_file() {
                return Err(self.invalid(
                    span,
                    format!("file = {:?}: no such file {}", d.file, path.display()),
                ));
            }
            let mut mesh = crate::mesh::load_obj(&path)?;
            mesh.flat = d.shading == Shading::Flat;
            let name = named(&d.name, "mesh", i);
            if d.instances.is_empty() {
                mesh.transform(d.transform.to_matrix());
                let what = format!("file = {:?} placed by its transform", d.file);
                let mesh = self.checked_mesh(span, &what, mesh)?;
                objects.push(Object {
                    name,
                    material: mesh_material,
                    shape: Shape::Mesh(mesh),
                });
                continue;
            }
            let mesh = Arc::new(mesh);
            let placements = std::iter::once((name.clone(), mesh_material, &d.transform));
            let mut more = Vec::with_capacity(d.instances.len());
            for (k, instance) in d.instances.iter().enumerate() {
                let material = match &instance.material {
                    Some(m) => material(span.clone(), m)?,
                    None => mesh_material,
                };
                let name = instance
                    .name
                    .clone()
                    .unwrap_or_else(|| format!("{name}#{}", k + 1));
                more.push((name, material, &instance.transform));
                spans.push(span.clone());
            }
            for (k, (name, material, transform)) in placements.chain(more).enumerate() {
                let to_world = Affine3A::from_mat4(transform.to_matrix());
                let instance = Instance {
                    mesh: mesh.clone(),
                    to_world,
                };
                let (min, max) = instance.bounds();
                if !(min.abs().max(max.abs()))
                    .cmple(Vec3::splat(MAX_COORDINATE))
                    .all()
                {
                    let what = if k == 0 {
                        "its transform".to_owned()
                    } else {
                        format!("instances[{}]", k - 1)
                    };
                    return Err(self.invalid(
                        span,
                        format!(
                            "file = {:?} placed by {what} reaches {min} .. {max}, beyond +-{MAX_COORDINATE:e}",
                            d.file
                        ),
                    ));
                }
                objects.push(Object {
                    name,
                    material,
                    shape: Shape::Instance(instance),
                });
            }
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

    /// Adds the objects, materials, textures and lights of a `[[gltf]]` entry.
    pub(super) fn place_gltf(
        &mut self,
        desc: &Spanned<GltfDesc>,
        materials: &mut Vec<Material>,
        objects: &mut Vec<Object>,
        lights: &mut Vec<Light>,
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
        for mut material in model.materials {
            for r in material.textures_mut() {
                r.texture += first_texture;
            }
            materials.push(material);
        }
        self.textures.extend(model.textures);
        objects.extend(model.objects.into_iter().map(|o| Object {
            material: o.material + first_material,
            ..o
        }));
        lights.extend(model.lights);
        Ok(())
    }
}
