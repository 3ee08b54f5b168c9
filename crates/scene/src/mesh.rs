//! Triangle meshes: OBJ import, placement and vertex normals.

use std::path::Path;

use glam::{EulerRot, Mat4, Quat, Vec2, Vec3};

use crate::desc::{ScaleDesc, TransformDesc};
use crate::error::SceneError;
use crate::shape::TriangleMesh;

impl TransformDesc {
    /// The object-to-world matrix: scale, then rotate x, y, z (degrees), then translate.
    pub fn to_matrix(&self) -> Mat4 {
        let scale = match self.scale {
            None => Vec3::ONE,
            Some(ScaleDesc::Uniform(s)) => Vec3::splat(s),
            Some(ScaleDesc::PerAxis(s)) => Vec3::from(s),
        };
        let [rx, ry, rz] = self.rotate.map(f32::to_radians);
        let rotation = Quat::from_euler(EulerRot::ZYX, rz, ry, rx);
        Mat4::from_scale_rotation_translation(scale, rotation, Vec3::from(self.translate))
    }
}

/// Refuses a vertex position, normal or texture coordinate of the OBJ text `text` that is
/// not a finite number (`1e300` overflows f32: infinite), naming its line.
fn check_obj_numbers(path: &Path, text: &str) -> Result<(), SceneError> {
    for (index, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        let what = match words.next() {
            Some("v") => "vertex position",
            Some("vn") => "vertex normal",
            Some("vt") => "texture coordinate",
            _ => continue,
        };
        // Malformed numbers are left to the OBJ parser, which reports them.
        if words.any(|w| w.parse::<f32>().is_ok_and(|v| !v.is_finite())) {
            return Err(SceneError::AssetLine {
                path: path.to_owned(),
                line: index + 1,
                message: format!("{what} {:?} is not a finite number", line.trim()),
            });
        }
    }
    Ok(())
}

/// Reads an OBJ file (all its models, triangulated) into one mesh in object space.
pub fn load_obj(path: &Path) -> Result<TriangleMesh, SceneError> {
    if let Ok(bytes) = std::fs::read(path) {
        check_obj_numbers(path, &String::from_utf8_lossy(&bytes))?;
    }
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ..Default::default()
    };
    let (models, _materials) = tobj::load_obj(path, &options).map_err(|err| match err {
        tobj::LoadError::OpenFileFailed => SceneError::Io {
            path: path.to_owned(),
            source: std::io::Error::new(std::io::ErrorKind::NotFound, "cannot open mesh file"),
        },
        other => SceneError::Asset {
            path: path.to_owned(),
            message: format!("not a valid OBJ file: {other}"),
        },
    })?;
    let mut mesh = TriangleMesh::default();
    let mut all_have_normals = true;
    for model in &models {
        let m = &model.mesh;
        let base = mesh.positions.len() as u32;
        let count = m.positions.len() / 3;
        mesh.positions.extend(
            m.positions
                .chunks_exact(3)
                .map(|p| Vec3::new(p[0], p[1], p[2])),
        );
        if m.normals.len() == m.positions.len() {
            mesh.normals.extend(
                m.normals
                    .chunks_exact(3)
                    .map(|n| Vec3::new(n[0], n[1], n[2])),
            );
        } else {
            all_have_normals = false;
            mesh.normals.extend(std::iter::repeat_n(Vec3::ZERO, count));
        }
        if m.texcoords.len() / 2 == count {
            // OBJ puts v = 0 at the bottom of the image; ours is at the top.
            mesh.uvs.extend(
                m.texcoords
                    .chunks_exact(2)
                    .map(|t| Vec2::new(t[0], 1.0 - t[1])),
            );
        } else {
            mesh.uvs.extend(std::iter::repeat_n(Vec2::ZERO, count));
        }
        mesh.indices.extend(
            m.indices
                .chunks_exact(3)
                .map(|t| [base + t[0], base + t[1], base + t[2]]),
        );
    }
    if mesh.indices.is_empty() {
        return Err(SceneError::Asset {
            path: path.to_owned(),
            message: "the OBJ file holds no faces".into(),
        });
    }
    if !all_have_normals {
        mesh.normals = vertex_normals(&mesh.positions, &mesh.indices);
    }
    Ok(mesh)
}

/// Area-weighted average of the face normals around each vertex.
pub fn vertex_normals(positions: &[Vec3], indices: &[[u32; 3]]) -> Vec<Vec3> {
    let mut normals = vec![Vec3::ZERO; positions.len()];
    for tri in indices {
        let [a, b, c] = tri.map(|i| positions[i as usize]);
        let face = (b - a).cross(c - a);
        for &i in tri {
            normals[i as usize] += face;
        }
    }
    normals.iter().map(|n| n.normalize_or_zero()).collect()
}

impl TriangleMesh {
    /// Moves the mesh by `object_to_world`, normals by its inverse transpose.
    pub fn transform(&mut self, object_to_world: Mat4) {
        let normal_matrix = object_to_world.inverse().transpose();
        for p in &mut self.positions {
            *p = object_to_world.transform_point3(*p);
        }
        for n in &mut self.normals {
            *n = normal_matrix.transform_vector3(*n).normalize_or_zero();
        }
    }

    /// Moves the mesh by `world` as a glTF node or an instance places it: as
    /// [`Self::transform`], tangents by the matrix; a mirroring matrix (negative
    /// determinant) reverses every triangle, so that counter-clockwise stays the front, and
    /// flips the bitangent signs.
    pub fn place(&mut self, world: Mat4) {
        self.transform(world);
        let linear = glam::Mat3::from_mat4(world);
        let mirrored = linear.determinant() < 0.0;
        for t in &mut self.tangents {
            let direction = (linear * t.truncate()).normalize_or_zero();
            *t = direction.extend(if mirrored { -t.w } else { t.w });
        }
        if mirrored {
            for tri in &mut self.indices {
                tri.swap(1, 2);
            }
            for corners in self.tangents.chunks_exact_mut(3) {
                corners.swap(1, 2);
            }
        }
    }
}
