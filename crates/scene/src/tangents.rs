//! MikkTSpace tangents, the frame glTF normal maps are baked in (`bevy_mikktspace`).
//!
//! glTF's texture coordinate v grows downwards in the image, while its normal textures hold
//! +Y up in the image (glTF 2.0, 3.9.3); Blender, which bakes most of them, generates its
//! tangents with v pointing up. MikkTSpace is therefore given (u, 1 - v), so that the
//! bitangent `cross(normal, tangent) * w` points up in the image as in files that ship their
//! `TANGENT`.

use glam::Vec4;

use crate::shape::TriangleMesh;

/// The mesh as `bevy_mikktspace` reads it, and the tangents it writes, per corner.
struct MikkMesh<'a> {
    mesh: &'a TriangleMesh,
    tangents: Vec<Vec4>,
}

impl bevy_mikktspace::Geometry for MikkMesh<'_> {
    fn num_faces(&self) -> usize {
        self.mesh.indices.len()
    }

    fn num_vertices_of_face(&self, _face: usize) -> usize {
        3
    }

    fn position(&self, face: usize, vert: usize) -> [f32; 3] {
        self.mesh.positions[self.mesh.indices[face][vert] as usize].to_array()
    }

    fn normal(&self, face: usize, vert: usize) -> [f32; 3] {
        self.mesh.normals[self.mesh.indices[face][vert] as usize].to_array()
    }

    fn tex_coord(&self, face: usize, vert: usize) -> [f32; 2] {
        let uv = self.mesh.uvs[self.mesh.indices[face][vert] as usize];
        [uv.x, 1.0 - uv.y]
    }

    fn set_tangent(
        &mut self,
        tangent_space: Option<bevy_mikktspace::TangentSpace>,
        face: usize,
        vert: usize,
    ) {
        if let Some(space) = tangent_space {
            self.tangents[3 * face + vert] = Vec4::from_array(space.tangent_encoded());
        }
    }
}

/// MikkTSpace tangents of `mesh` (which has normals and texture coordinates), per triangle
/// corner. Corners MikkTSpace leaves without a frame (degenerate texture coordinates) get
/// a tangent perpendicular to their normal.
pub fn mikktspace_tangents(mesh: &TriangleMesh) -> Vec<Vec4> {
    let mut mikk = MikkMesh {
        mesh,
        tangents: vec![Vec4::ZERO; 3 * mesh.indices.len()],
    };
    // The crate's error type has no variants: generation cannot fail.
    let _ = bevy_mikktspace::generate_tangents(&mut mikk);
    for (i, tangent) in mikk.tangents.iter_mut().enumerate() {
        if tangent.truncate().length_squared() == 0.0 {
            let normal = mesh.normals[mesh.indices[i / 3][i % 3] as usize];
            *tangent = normal.any_orthonormal_vector().extend(1.0);
        }
    }
    mikk.tangents
}

#[cfg(test)]
mod tests {
    use glam::{Vec2, Vec3};

    use super::*;

    /// The direction of +u in a triangle's plane, from its corners and texture coordinates.
    fn plane_tangent(corners: [Vec3; 3], uvs: [Vec2; 3]) -> Vec3 {
        let [p0, p1, p2] = corners;
        let [t0, t1, t2] = uvs;
        let (e1, e2) = (p1 - p0, p2 - p0);
        let (d1, d2) = (t1 - t0, t2 - t0);
        let r = 1.0 / (d1.x * d2.y - d2.x * d1.y);
        ((e1 * d2.y - e2 * d1.y) * r).normalize()
    }

    #[test]
    fn a_flat_quad_gets_the_direction_of_u_and_a_bitangent_up_the_image() {
        // A quad in the xy plane facing +z, u along a rotated axis, v mirrored: the image's
        // up (-v) is cross(z, tangent), w = 1.
        let angle = 0.6f32;
        let (s, c) = angle.sin_cos();
        let positions = vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(2.0, 1.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        ];
        // uv = R(angle) (x, -y), so that position = (c u - s v, -s u - c v, 0).
        let uvs: Vec<Vec2> = positions
            .iter()
            .map(|p| Vec2::new(c * p.x + s * -p.y, -s * p.x + c * -p.y))
            .collect();
        let mesh = TriangleMesh {
            normals: vec![Vec3::Z; 4],
            positions,
            uvs,
            indices: vec![[0, 1, 2], [0, 2, 3]],
            ..TriangleMesh::default()
        };
        let tangents = mikktspace_tangents(&mesh);
        assert_eq!(tangents.len(), 6);
        for (i, t) in tangents.iter().enumerate() {
            let tri = mesh.indices[i / 3];
            let expected = plane_tangent(
                tri.map(|v| mesh.positions[v as usize]),
                tri.map(|v| mesh.uvs[v as usize]),
            );
            assert!(
                t.truncate().distance(expected) < 1e-5,
                "corner {i}: {t} vs {expected}"
            );
            // d(position)/d(-v) = (s, c, 0) = cross(z, tangent): w = 1.
            assert_eq!(t.w, 1.0, "corner {i}");
        }
        // The hand-computed tangent itself: d(position)/du = (c, -s, 0).
        assert!(
            tangents[0].truncate().distance(Vec3::new(c, -s, 0.0)) < 1e-5,
            "{}",
            tangents[0]
        );
    }
}
