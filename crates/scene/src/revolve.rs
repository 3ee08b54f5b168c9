//! Surfaces of revolution: a profile curve revolved about an axis into a triangle mesh.

use glam::{Vec2, Vec3};

use crate::shape::TriangleMesh;

/// A profile revolved about an axis.
#[derive(Debug, Clone)]
pub struct Revolution {
    /// Point on the axis at profile height 0.
    pub base: Vec3,
    /// Unit axis direction.
    pub axis: Vec3,
    /// Control points `(radius, height)`, bottom to top.
    pub profile: Vec<Vec2>,
    /// Segments around the axis (at least 3).
    pub segments: u32,
    /// Rings along the profile (at least 1).
    pub rings: u32,
    /// Close the bottom with a fan of triangles.
    pub cap_bottom: bool,
}

/// Point on the centripetal-free (uniform) Catmull-Rom spline through `points`, `t` in [0, 1].
fn catmull_rom(points: &[Vec2], t: f32) -> Vec2 {
    let spans = points.len() - 1;
    let x = t.clamp(0.0, 1.0) * spans as f32;
    let i = (x.floor() as usize).min(spans - 1);
    let u = x - i as f32;
    let p1 = points[i];
    let p2 = points[i + 1];
    // Reflect the end points so the curve starts and ends at the first and last control points.
    let p0 = if i == 0 { 2.0 * p1 - p2 } else { points[i - 1] };
    let p3 = if i + 2 < points.len() {
        points[i + 2]
    } else {
        2.0 * p2 - p1
    };
    let u2 = u * u;
    let u3 = u2 * u;
    0.5 * ((2.0 * p1)
        + (p2 - p0) * u
        + (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3) * u2
        + (3.0 * p1 - p0 - 3.0 * p2 + p3) * u3)
}

impl Revolution {
    /// Builds the mesh: `rings + 1` profile samples times `segments + 1` columns (the seam is
    /// duplicated so texture coordinates wrap), u around the axis, v down the profile.
    pub fn to_mesh(&self) -> TriangleMesh {
        let axis = self.axis.normalize();
        let (tangent, bitangent) = axis.any_orthonormal_pair();
        let columns = self.segments + 1;
        let mut mesh = TriangleMesh::default();
        for ring in 0..=self.rings {
            let t = ring as f32 / self.rings as f32;
            let Vec2 {
                x: radius,
                y: height,
            } = catmull_rom(&self.profile, t);
            for column in 0..columns {
                // The seam's last column is the first one again, exactly: cos and sin of 2 pi
                // in f32 are not 1 and 0, and the gap between them would let rays through.
                let phi =
                    std::f32::consts::TAU * (column % self.segments) as f32 / self.segments as f32;
                let radial = tangent * phi.cos() + bitangent * phi.sin();
                mesh.positions
                    .push(self.base + axis * height + radial * radius.max(0.0));
                mesh.uvs
                    .push(Vec2::new(column as f32 / self.segments as f32, 1.0 - t));
            }
        }
        for ring in 0..self.rings {
            for column in 0..self.segments {
                let a = ring * columns + column;
                let b = a + 1;
                let c = a + columns;
                let d = c + 1;
                mesh.indices.push([a, b, d]);
                mesh.indices.push([a, d, c]);
            }
        }
        if self.cap_bottom {
            let center = mesh.positions.len() as u32;
            let Vec2 { y: height, .. } = catmull_rom(&self.profile, 0.0);
            mesh.positions.push(self.base + axis * height);
            mesh.uvs.push(Vec2::new(0.5, 1.0));
            for column in 0..self.segments {
                mesh.indices.push([center, column + 1, column]);
            }
        }
        mesh.normals = crate::mesh::vertex_normals(&mesh.positions, &mesh.indices);
        // The seam's duplicated columns must share one normal, or it shows as a crease.
        for ring in 0..=self.rings {
            let first = (ring * columns) as usize;
            let last = first + self.segments as usize;
            let shared = (mesh.normals[first] + mesh.normals[last]).normalize_or_zero();
            mesh.normals[first] = shared;
            mesh.normals[last] = shared;
        }
        mesh
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spline_passes_through_control_points() {
        let points = [
            Vec2::new(0.3, 0.0),
            Vec2::new(0.5, 0.4),
            Vec2::new(0.2, 1.0),
        ];
        assert!(catmull_rom(&points, 0.0).distance(points[0]) < 1e-6);
        assert!(catmull_rom(&points, 0.5).distance(points[1]) < 1e-6);
        assert!(catmull_rom(&points, 1.0).distance(points[2]) < 1e-6);
    }

    #[test]
    fn the_seam_columns_are_the_same_points() {
        let mesh = Revolution {
            base: Vec3::ZERO,
            axis: Vec3::new(0.3, 1.0, 0.2).normalize(),
            profile: vec![
                Vec2::new(0.5, 0.0),
                Vec2::new(0.7, 0.5),
                Vec2::new(0.3, 1.0),
            ],
            segments: 37,
            rings: 9,
            cap_bottom: true,
        }
        .to_mesh();
        for ring in 0..=9 {
            let first = ring * 38;
            assert_eq!(
                mesh.positions[first],
                mesh.positions[first + 37],
                "ring {ring}"
            );
        }
    }

    #[test]
    fn cylinder_profile_gives_outward_normals_and_exact_radius() {
        let revolution = Revolution {
            base: Vec3::new(1.0, 0.0, 0.0),
            axis: Vec3::Y,
            profile: vec![Vec2::new(0.5, 0.0), Vec2::new(0.5, 1.0)],
            segments: 16,
            rings: 4,
            cap_bottom: false,
        };
        let mesh = revolution.to_mesh();
        assert_eq!(mesh.indices.len(), 16 * 4 * 2);
        for (p, n) in mesh.positions.iter().zip(&mesh.normals) {
            let radial = Vec3::new(p.x - 1.0, 0.0, p.z);
            assert!((radial.length() - 0.5).abs() < 1e-5);
            assert!(n.dot(radial.normalize()) > 0.99, "normal {n} at {p}");
        }
    }
}
