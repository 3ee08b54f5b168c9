//! glTF 2.0 import (`.gltf` with its buffers and images, `.glb`, `data:` URIs): the
//! triangles of every node of the default scene (in world space, or as instances of one copy
//! where nodes share a mesh), their metal-rough
//! materials and textures, the scene's perspective cameras and its punctual lights
//! (`KHR_lights_punctual`). Malformed files are refused
//! naming the element (mesh, primitive, accessor, buffer, image, node); points and lines
//! are skipped with a warning.

mod data;
mod guards;
mod materials;
mod primitives;

use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

use glam::{Affine3A, Mat4, Vec3};

use crate::desc::RenderDesc;
use crate::error::SceneError;
use crate::memory::SceneSize;
use crate::settings::MAX_COORDINATE;
use crate::{
    Camera, Cone, Environment, Instance, Light, LightKind, Material, Object, RenderSettings, Scene,
    Shape, Texture, TriangleMesh,
};
use data::Files;
use materials::Materials;

/// Deepest node nesting accepted.
const MAX_DEPTH: usize = 256;
/// Most mesh instances accepted (a node shared by many parents is placed once per path).
const MAX_INSTANCES: usize = 1 << 20;
/// Radiance of the grey sky that lights a glTF file opened on its own.
pub const GREY_SKY: f32 = 0.8;

/// A perspective camera of a glTF file, placed in the world.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GltfCamera {
    /// Eye position.
    pub position: Vec3,
    /// Unit view direction (the camera's -z).
    pub forward: Vec3,
    /// Unit up direction (the camera's +y).
    pub up: Vec3,
    /// Full vertical field of view, degrees.
    pub fov_y_deg: f32,
    /// Width over height, when the file gives it.
    pub aspect: Option<f32>,
}

/// What a glTF file adds to a scene. Material indices count from 0 within `materials`,
/// and texture indices within `textures`.
#[derive(Debug, Clone, PartialEq)]
pub struct GltfModel {
    /// One mesh object per placed primitive.
    pub objects: Vec<Object>,
    /// The materials the objects use.
    pub materials: Vec<Material>,
    /// The images the materials use.
    pub textures: Vec<Texture>,
    /// Perspective cameras in node order.
    pub cameras: Vec<GltfCamera>,
    /// Punctual lights in node order, their candela and lux read as W/sr and W/m^2 (one to
    /// one, as glTF viewers show them and as glTF emission is read).
    pub lights: Vec<Light>,
}

impl GltfModel {
    /// The box around every vertex: (min, max).
    pub fn bounds(&self) -> (Vec3, Vec3) {
        self.objects
            .iter()
            .filter_map(|o| match &o.shape {
                Shape::Mesh(m) => Some(m.bounds()),
                Shape::Instance(instance) => Some(instance.bounds()),
                _ => None,
            })
            .fold((Vec3::MAX, Vec3::MIN), |(lo, hi), (min, max)| {
                (lo.min(min), hi.max(max))
            })
    }
}

/// Reads the glTF file `path` and places its default scene (or its first) by `transform`.
pub fn load_gltf(path: &Path, transform: Mat4) -> Result<GltfModel, SceneError> {
    let bytes = std::fs::read(path).map_err(|source| SceneError::Io {
        path: path.to_owned(),
        source,
    })?;
    let files = Files {
        path,
        base: path.parent().map(Path::to_owned).unwrap_or_default(),
    };
    let invalid = |err: gltf::Error| SceneError::Asset {
        path: path.to_owned(),
        message: format!("not a valid glTF file: {err}"),
    };
    guards::check_glb_header(&files, &bytes)?;
    let gltf::Gltf { document, blob } =
        gltf::Gltf::from_slice_without_validation(&bytes).map_err(invalid)?;
    guards::check_json(&files, document.as_json())?;
    let document = gltf::Document::from_json(document.into_json()).map_err(invalid)?;
    warn_unsupported_extensions(path, &document);
    if document
        .extensions_used()
        .any(|e| e == "KHR_draco_mesh_compression")
    {
        return Err(files.error(
            "extensionsUsed",
            "Draco-compressed meshes are not supported",
        ));
    }
    let buffers = files.buffers(&document, blob)?;
    let scene = document
        .default_scene()
        .or_else(|| document.scenes().next())
        .ok_or_else(|| files.error("scenes", "the file holds no scene"))?;
    let mut walk = Walk {
        files: &files,
        buffers: &buffers,
        materials: Materials::new(&document),
        model: GltfModel {
            objects: Vec::new(),
            materials: Vec::new(),
            textures: Vec::new(),
            cameras: Vec::new(),
            lights: Vec::new(),
        },
        ancestors: Vec::new(),
        instances: 0,
        uses: HashMap::new(),
        shared: HashMap::new(),
        stem: path
            .file_stem()
            .map_or_else(|| "gltf".to_owned(), |s| s.to_string_lossy().into_owned()),
    };
    for node in scene.nodes() {
        count_uses(&node, &mut Vec::new(), &mut walk.uses);
    }
    check_memory(&files, &document, &scene, &walk.uses)?;
    for node in scene.nodes() {
        walk.node(&node, transform)?;
    }
    if walk.model.objects.is_empty() {
        return Err(files.error(
            &format!("scene {}", scene.index()),
            "holds no triangles to render",
        ));
    }
    walk.model.materials = walk.materials.materials;
    walk.model.textures = walk.materials.textures;
    Ok(walk.model)
}

/// The extensions pathlight reads (`KHR_draco_mesh_compression` is refused).
const SUPPORTED_EXTENSIONS: [&str; 9] = [
    "KHR_lights_punctual",
    "KHR_materials_clearcoat",
    "KHR_materials_emissive_strength",
    "KHR_materials_ior",
    "KHR_materials_sheen",
    "KHR_materials_specular",
    "KHR_materials_transmission",
    "KHR_materials_volume",
    "KHR_texture_transform",
];

/// Warns once, naming them, about the extensions the file uses that pathlight ignores (a
/// file that requires one is refused by the `gltf` crate's validation).
fn warn_unsupported_extensions(path: &Path, document: &gltf::Document) {
    let ignored: Vec<&str> = document
        .extensions_used()
        .filter(|e| !SUPPORTED_EXTENSIONS.contains(e))
        .collect();
    if !ignored.is_empty() {
        log::warn!(
            "{}: uses glTF extensions pathlight does not support, which are ignored: {}",
            path.display(),
            ignored.join(", ")
        );
    }
}

/// The depth-first walk over a scene's nodes.
struct Walk<'a> {
    files: &'a Files<'a>,
    buffers: &'a [Vec<u8>],
    materials: Materials<'a>,
    model: GltfModel,
    /// The nodes above the current one (a node among them again is a cycle).
    ancestors: Vec<usize>,
    instances: usize,
    /// The file's name without extension, prefixing object names.
    stem: String,
    /// Per mesh, how often the scene places it (from [`count_uses`]).
    uses: HashMap<usize, usize>,
    /// Per (mesh, primitive) of a mesh placed more than once, its triangles in the mesh's own
    /// space (`None`: skipped), read once and shared by its instances.
    shared: HashMap<(usize, usize), Option<Arc<TriangleMesh>>>,
}

/// Refuses a scene whose triangles and instances (`uses`: placements per mesh; a mesh placed
/// more than once is kept once and instanced) need more memory than this process may use
/// ([`crate::memory`]), before any is read.
fn check_memory(
    files: &Files,
    document: &gltf::Document,
    scene: &gltf::Scene,
    uses: &HashMap<usize, usize>,
) -> Result<(), SceneError> {
    let triangles_of = |mesh: gltf::Mesh| -> u64 {
        mesh.primitives()
            .map(|p| {
                let count = p
                    .indices()
                    .or_else(|| p.get(&gltf::Semantic::Positions))
                    .map_or(0, |a| a.count() as u64);
                match p.mode() {
                    gltf::mesh::Mode::Triangles => count / 3,
                    gltf::mesh::Mode::TriangleStrip | gltf::mesh::Mode::TriangleFan => {
                        count.saturating_sub(2)
                    }
                    _ => 0,
                }
            })
            .sum()
    };
    let mut size = SceneSize::default();
    for mesh in document.meshes() {
        let placed = uses.get(&mesh.index()).copied().unwrap_or(0) as u64;
        if placed > 0 {
            size.triangles = size.triangles.saturating_add(triangles_of(mesh));
        }
        if placed > 1 {
            size.instances = size.instances.saturating_add(placed);
        }
    }
    crate::memory::check_size(size).map_err(|message| {
        let placements: usize = uses.values().sum();
        files.error(
            &format!("scene {}", scene.index()),
            format!("places {} meshes {placements} times: {message}", uses.len()),
        )
    })
}

/// Counts into `uses` how often each mesh is placed under `node` (a node reached again
/// through its own descendants, or deeper than [`MAX_DEPTH`], ends the count there: the
/// walk refuses such files).
fn count_uses(node: &gltf::Node, ancestors: &mut Vec<usize>, uses: &mut HashMap<usize, usize>) {
    if ancestors.contains(&node.index()) || ancestors.len() >= MAX_DEPTH {
        return;
    }
    if let Some(mesh) = node.mesh() {
        let count = uses.entry(mesh.index()).or_default();
        if *count > MAX_INSTANCES {
            return;
        }
        *count += 1;
    }
    ancestors.push(node.index());
    for child in node.children() {
        count_uses(&child, ancestors, uses);
    }
    ancestors.pop();
}

impl Walk<'_> {
    fn node(&mut self, node: &gltf::Node, parent: Mat4) -> Result<(), SceneError> {
        let element = format!("node {}", node.index());
        if self.ancestors.contains(&node.index()) {
            return Err(self.files.error(
                &element,
                "is its own ancestor (the node hierarchy has a cycle)",
            ));
        }
        if self.ancestors.len() >= MAX_DEPTH {
            return Err(self
                .files
                .error(&element, format!("nodes nest deeper than {MAX_DEPTH}")));
        }
        let local = Mat4::from_cols_array_2d(&node.transform().matrix());
        let world = parent * local;
        if !world.is_finite()
            || world
                .abs()
                .to_cols_array()
                .iter()
                .any(|&v| v > MAX_COORDINATE)
        {
            return Err(self.files.error(&element, "its transform is not finite"));
        }
        if let Some(camera) = node.camera() {
            self.camera(&camera, world);
        }
        if let Some(light) = node.light() {
            self.light(&light, world, &element)?;
        }
        if let Some(mesh) = node.mesh() {
            self.instances += 1;
            if self.instances > MAX_INSTANCES {
                return Err(self.files.error(
                    &element,
                    format!("the scene places more than {MAX_INSTANCES} meshes"),
                ));
            }
            self.mesh(&mesh, world)?;
        }
        self.ancestors.push(node.index());
        for child in node.children() {
            self.node(&child, world)?;
        }
        self.ancestors.pop();
        Ok(())
    }

    fn camera(&mut self, camera: &gltf::Camera, world: Mat4) {
        let gltf::camera::Projection::Perspective(p) = camera.projection() else {
            log::warn!(
                "{}: camera {} is orthographic and is skipped",
                self.files.path.display(),
                camera.index()
            );
            return;
        };
        let forward = world.transform_vector3(Vec3::NEG_Z).normalize_or_zero();
        let up = world.transform_vector3(Vec3::Y).normalize_or_zero();
        let fov = p.yfov().to_degrees();
        if forward == Vec3::ZERO || up.cross(forward) == Vec3::ZERO || !(fov > 0.0 && fov < 180.0) {
            log::warn!(
                "{}: camera {} has a degenerate placement or field of view and is skipped",
                self.files.path.display(),
                camera.index()
            );
            return;
        }
        self.model.cameras.push(GltfCamera {
            position: world.transform_point3(Vec3::ZERO),
            forward,
            up,
            fov_y_deg: fov,
            aspect: p.aspect_ratio().filter(|a| a.is_finite() && *a > 0.0),
        });
    }

    /// Places punctual light `light` at `world`'s origin, shining along its -z.
    fn light(
        &mut self,
        light: &gltf::khr_lights_punctual::Light,
        world: Mat4,
        element: &str,
    ) -> Result<(), SceneError> {
        use gltf::khr_lights_punctual::Kind;
        let what = format!("{element}: light {}", light.index());
        let intensity = Vec3::from(light.color()) * light.intensity();
        if !(intensity.is_finite() && intensity.min_element() >= 0.0) {
            return Err(self.files.error(
                &what,
                format!(
                    "colour {:?} times intensity {} must be finite and >= 0",
                    light.color(),
                    light.intensity()
                ),
            ));
        }
        let direction = world.transform_vector3(Vec3::NEG_Z).normalize_or_zero();
        if direction == Vec3::ZERO && !matches!(light.kind(), Kind::Point) {
            return Err(self
                .files
                .error(&what, "its node's transform has no -z direction"));
        }
        let position = world.transform_point3(Vec3::ZERO);
        let kind = match light.kind() {
            Kind::Directional => LightKind::Sun {
                direction,
                angular_diameter_deg: 0.0,
            },
            Kind::Point => LightKind::Point {
                position,
                radius: 0.0,
                cone: None,
            },
            Kind::Spot {
                inner_cone_angle,
                outer_cone_angle,
            } => {
                let (inner, outer) = (inner_cone_angle.to_degrees(), outer_cone_angle.to_degrees());
                if !(outer > 0.0 && outer <= 90.0 && (0.0..=outer).contains(&inner)) {
                    return Err(self.files.error(
                        &what,
                        format!(
                            "cone angles {inner_cone_angle} and {outer_cone_angle} must satisfy \
                             0 <= inner <= outer, 0 < outer <= pi/2"
                        ),
                    ));
                }
                LightKind::Point {
                    position,
                    radius: 0.0,
                    cone: Some(Cone {
                        axis: direction,
                        inner_deg: inner,
                        outer_deg: outer,
                    }),
                }
            }
        };
        self.model.lights.push(Light {
            name: format!(
                "{}/{}",
                self.stem,
                light
                    .name()
                    .map_or_else(|| format!("light{}", light.index()), str::to_owned)
            ),
            intensity,
            kind,
        });
        Ok(())
    }

    /// Places `mesh` by `world`: a mesh the scene places once as world-space triangles, one
    /// placed more often as instances of its triangles (each primitive read, and warned
    /// about, once).
    fn mesh(&mut self, mesh: &gltf::Mesh, world: Mat4) -> Result<(), SceneError> {
        let instanced = self.uses.get(&mesh.index()).is_some_and(|&n| n > 1);
        for primitive in mesh.primitives() {
            let (material, needs) =
                self.materials
                    .get(self.files, self.buffers, &primitive.material())?;
            let key = (mesh.index(), primitive.index());
            let shape = if instanced {
                let triangles = match self.shared.get(&key) {
                    Some(triangles) => triangles.clone(),
                    None => {
                        let triangles = primitives::read_primitive(
                            self.files,
                            self.buffers,
                            mesh.index(),
                            &primitive,
                            needs,
                        )?
                        .map(Arc::new);
                        self.shared.insert(key, triangles.clone());
                        triangles
                    }
                };
                let Some(triangles) = triangles else {
                    continue;
                };
                Shape::Instance(Instance {
                    mesh: triangles,
                    to_world: Affine3A::from_mat4(world),
                })
            } else {
                let Some(mut triangles) = primitives::read_primitive(
                    self.files,
                    self.buffers,
                    mesh.index(),
                    &primitive,
                    needs,
                )?
                else {
                    continue;
                };
                triangles.place(world);
                Shape::Mesh(triangles)
            };
            let name = format!(
                "{}/{}#{}.{}",
                self.stem,
                mesh.name()
                    .map_or_else(|| format!("mesh{}", mesh.index()), str::to_owned),
                primitive.index(),
                self.instances
            );
            self.model.objects.push(Object {
                name,
                material,
                shape,
            });
        }
        Ok(())
    }
}

/// A scene of the glTF file `path` alone: its camera `camera` (else its first, else one
/// framing the model from the front and a little above), its emitters and punctual lights,
/// and, when it has no punctual lights, a uniform grey sky of radiance [`GREY_SKY`] (as glTF
/// viewers light a model, even one with emissive materials), and the default render
/// settings.
pub fn gltf_scene(path: &Path, camera: Option<usize>) -> Result<Scene, SceneError> {
    let model = load_gltf(path, Mat4::IDENTITY)?;
    let height = 720;
    let camera = match camera {
        Some(n) => {
            let c = model.cameras.get(n).ok_or_else(|| SceneError::Asset {
                path: path.to_owned(),
                message: format!(
                    "has no camera {n}: it has {} perspective camera(s), numbered from 0",
                    model.cameras.len()
                ),
            })?;
            file_camera(c, height)
        }
        None => match model.cameras.first() {
            Some(c) => file_camera(c, height),
            None => framing_camera(model.bounds(), height),
        },
    };
    Ok(Scene {
        camera,
        settings: RenderSettings::from(&RenderDesc::default()),
        environment: Environment::Constant(if model.lights.is_empty() {
            Vec3::splat(GREY_SKY)
        } else {
            Vec3::ZERO
        }),
        materials: model.materials,
        textures: model.textures,
        objects: model.objects,
        lights: model.lights,
    })
}

/// The camera of the file, its image `height` pixels high and as wide as its aspect ratio
/// (16:9 when it gives none).
fn file_camera(c: &GltfCamera, height: u32) -> Camera {
    let aspect = c.aspect.unwrap_or(16.0 / 9.0).clamp(0.1, 10.0);
    Camera {
        position: c.position,
        look_at: c.position + c.forward,
        up: c.up,
        fov_y_deg: c.fov_y_deg,
        width: ((height as f32 * aspect).round() as u32).max(1),
        height,
        aperture_radius: 0.0,
        focus_distance: 1.0,
    }
}

/// A 16:9 camera with a 40 degree vertical field of view looking at the centre of `bounds`
/// along -z from a little above, far enough that the box's bounding sphere fits the view.
pub fn framing_camera(bounds: (Vec3, Vec3), height: u32) -> Camera {
    let (lo, hi) = bounds;
    let center = 0.5 * (lo + hi);
    let radius = (0.5 * (hi - lo).length()).max(1e-3);
    let fov_y_deg = 40.0f32;
    let distance = radius / (0.5 * fov_y_deg.to_radians()).sin();
    let direction = Vec3::new(0.0, 0.35, 1.0).normalize();
    Camera {
        position: center + distance * direction,
        look_at: center,
        up: Vec3::Y,
        fov_y_deg,
        width: height * 16 / 9,
        height,
        aperture_radius: 0.0,
        focus_distance: distance,
    }
}
