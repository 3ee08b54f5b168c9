//! The geometry of the scene's objects.

use glam::{Vec2, Vec3, Vec4};

/// A triangle mesh in world space.
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
}

/// One pickable model: a shape with a material.
#[derive(Debug, Clone, PartialEq)]
pub struct Object {
    /// Name from the file, or `<kind><index>` when the file gives none.
    pub name: String,
    /// Index into [`Scene::materials`].
    pub material: u32,
    /// Geometry.
    pub shape: Shape,
}
