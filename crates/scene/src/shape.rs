//! The geometry of the scene's objects.

use std::sync::Arc;

use glam::{Affine3A, Mat4, Vec2, Vec3, Vec4};

/// A triangle mesh: in world space as [`Shape::Mesh`], in its own space as an
/// [`Instance`]'s.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TriangleMesh {
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Vertex shading normals (one per position).
    pub normals: Vec<Vec3>,
    /// Vertex texture coordinates (one per position).
    pub uvs: Vec<Vec2>,
    /// Triangles as indices into the vertex arrays.
    pub indices: Vec<[u32; 3]>,
    /// Per triangle corner (three per triangle, in `indices` order), the tangent along
    /// +u and in `w` the sign of the bitangent (`cross(normal, tangent) * w` points along
    /// -v, up in the image, glTF's convention); empty when no material of the mesh needs
    /// them (normal maps do).
    pub tangents: Vec<Vec4>,
    /// Vertex colours (linear RGBA, one per position; glTF's `COLOR_0`), multiplying the
    /// base colour and its alpha; empty for none.
    pub colors: Vec<Vec4>,
    /// Shade with the geometric normal instead of `normals`.
    pub flat: bool,
}

/// The geometry of one object.
#[derive(Debug, Clone, PartialEq)]
pub enum Shape {
    /// Parallelogram `origin + s edge_u + t edge_v`.
    Quad {
        /// Corner.
        origin: Vec3,
        /// First edge.
        edge_u: Vec3,
        /// Second edge.
        edge_v: Vec3,
    },
    /// Sphere.
    Sphere {
        /// Centre.
        center: Vec3,
        /// Radius.
        radius: f32,
        /// Rotation of the texture about +y, radians.
        texture_rotation: f32,
    },
    /// Cylinder from `p0` to `p1`.
    Cylinder {
        /// Axis start.
        p0: Vec3,
        /// Axis end.
        p1: Vec3,
        /// Radius.
        radius: f32,
        /// Closed by two disks.
        caps: bool,
    },
    /// Triangle mesh.
    Mesh(TriangleMesh),
    /// A mesh shared with other objects, placed by a transform.
    Instance(Instance),
}

/// One placement of a shared mesh: the backends keep one copy of its triangles (and of its
/// tree) however many objects place it.
#[derive(Debug, Clone, PartialEq)]
pub struct Instance {
    /// The mesh in its own space.
    pub mesh: Arc<TriangleMesh>,
    /// Its placement: object space to world.
    pub to_world: Affine3A,
}

impl Instance {
    /// The mesh placed in the world as one mesh of its own (what the instance looks like):
    /// positions moved, normals by the inverse transpose, tangents by the matrix, and a
    /// mirroring placement's triangles reversed so that counter-clockwise stays the front.
    pub fn flattened(&self) -> TriangleMesh {
        let mut mesh = (*self.mesh).clone();
        mesh.place(Mat4::from(self.to_world));
        mesh
    }

    /// The box around the placed mesh (the placed box of the mesh's own): (min, max).
    pub fn bounds(&self) -> (Vec3, Vec3) {
        let (min, max) = self.mesh.bounds();
        (0..8)
            .map(|corner| {
                let pick =
                    |bit: u32, lo: f32, hi: f32| if corner >> bit & 1 == 0 { lo } else { hi };
                let p = Vec3::new(
                    pick(0, min.x, max.x),
                    pick(1, min.y, max.y),
                    pick(2, min.z, max.z),
                );
                self.to_world.transform_point3(p)
            })
            .fold((Vec3::MAX, Vec3::MIN), |(lo, hi), p| (lo.min(p), hi.max(p)))
    }
}

impl TriangleMesh {
    /// The box around its vertices: (min, max); inverted (MAX, MIN) without any.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        self.positions
            .iter()
            .fold((Vec3::MAX, Vec3::MIN), |(lo, hi), &p| {
                (lo.min(p), hi.max(p))
            })
    }
}

/// One pickable model: a shape with a material.
#[derive(Debug, Clone, PartialEq)]
pub struct Object {
    /// Name from the file, or `<kind><index>` when the file gives none.
    pub name: String,
    /// Index into [`crate::Scene::materials`].
    pub material: u32,
    /// Geometry.
    pub shape: Shape,
}
