//! A glTF mesh primitive's triangles, read into a [`TriangleMesh`] in the mesh's own space.

use glam::{Vec2, Vec3, Vec4};
use gltf::accessor::{DataType, Dimensions};
use gltf::mesh::Mode;

use super::data::Files;
use crate::error::SceneError;
use crate::mesh::vertex_normals;
use crate::shape::TriangleMesh;
use crate::tangents::mikktspace_tangents;

/// The triangles of a list, strip or fan of vertex indices `indices`, as glTF orders them
/// (every triangle counter-clockwise from its front); `None` for points and lines.
pub(super) fn triangles(mode: Mode, indices: &[u32]) -> Option<Vec<[u32; 3]>> {
    let count = indices.len();
    let corners = |c: [usize; 3]| c.map(|k| indices[k]);
    let tris = match mode {
        Mode::Triangles => (0..count / 3)
            .map(|i| corners([3 * i, 3 * i + 1, 3 * i + 2]))
            .collect(),
        Mode::TriangleStrip => (0..count.saturating_sub(2))
            .map(|i| corners([i, i + 1 + i % 2, i + 2 - i % 2]))
            .collect(),
        Mode::TriangleFan => (1..count.saturating_sub(1))
            .map(|i| corners([i, i + 1, 0]))
            .collect(),
        Mode::Points | Mode::Lines | Mode::LineLoop | Mode::LineStrip => return None,
    };
    Some(tris)
}

/// What a primitive needs from its material: the texture coordinate set its textures read
/// and whether it is normal-mapped (which needs tangents).
#[derive(Debug, Clone, Copy)]
pub(super) struct Needs {
    /// `TEXCOORD_n` to read.
    pub uv_set: u32,
    /// Tangents are needed.
    pub tangents: bool,
}

/// Reads `primitive` of mesh `mesh_index`; `Ok(None)` (with a warning) when it draws
/// points or lines or no triangle with area.
pub(super) fn read_primitive(
    files: &Files,
    buffers: &[Vec<u8>],
    mesh_index: usize,
    primitive: &gltf::Primitive,
    needs: Needs,
) -> Result<Option<TriangleMesh>, SceneError> {
    let element = format!("mesh {mesh_index} primitive {}", primitive.index());
    let reader = primitive.reader(|b| buffers.get(b.index()).map(Vec::as_slice));
    let Some(position_accessor) = primitive.get(&gltf::Semantic::Positions) else {
        return Err(files.error(&element, "has no POSITION attribute"));
    };
    let check = |what: &str, accessor: &gltf::Accessor, dims, types: &[DataType]| {
        files.check_accessor(&format!("{element} {what}"), accessor, buffers, dims, types)
    };
    check(
        "POSITION",
        &position_accessor,
        Dimensions::Vec3,
        &[DataType::F32],
    )?;
    let positions: Vec<Vec3> = reader
        .read_positions()
        .ok_or_else(|| files.error(&element, "cannot read POSITION"))?
        .map(Vec3::from)
        .collect();
    if let Some(i) = positions.iter().position(|p| !p.is_finite()) {
        return Err(files.error(
            &element,
            format!("vertex {i} has position {} (not finite)", positions[i]),
        ));
    }
    let count = positions.len();
    let normals = match primitive.get(&gltf::Semantic::Normals) {
        Some(accessor) => {
            check("NORMAL", &accessor, Dimensions::Vec3, &[DataType::F32])?;
            let normals: Vec<Vec3> = reader
                .read_normals()
                .ok_or_else(|| files.error(&element, "cannot read NORMAL"))?
                .map(|n| Vec3::from(n).normalize_or_zero())
                .collect();
            (normals.len() == count).then_some(normals)
        }
        None => None,
    };
    let uvs = match primitive.get(&gltf::Semantic::TexCoords(needs.uv_set)) {
        Some(accessor) => {
            let types = [DataType::F32, DataType::U8, DataType::U16];
            check("TEXCOORD", &accessor, Dimensions::Vec2, &types)?;
            let uvs: Vec<Vec2> = reader
                .read_tex_coords(needs.uv_set)
                .ok_or_else(|| files.error(&element, "cannot read TEXCOORD"))?
                .into_f32()
                .map(Vec2::from)
                .collect();
            if uvs.iter().any(|uv| !uv.is_finite()) {
                return Err(files.error(&element, "a texture coordinate is not finite"));
            }
            (uvs.len() == count).then_some(uvs)
        }
        None => None,
    };
    let indices: Vec<u32> = match primitive.indices() {
        Some(accessor) => {
            let types = [DataType::U8, DataType::U16, DataType::U32];
            check("indices", &accessor, Dimensions::Scalar, &types)?;
            let indices: Vec<u32> = reader
                .read_indices()
                .ok_or_else(|| files.error(&element, "cannot read its indices"))?
                .into_u32()
                .collect();
            if let Some(&bad) = indices.iter().find(|&&i| i as usize >= count) {
                return Err(files.error(
                    &element,
                    format!("index {bad} is out of range: the primitive has {count} vertices"),
                ));
            }
            indices
        }
        None => (0..count as u32).collect(),
    };
    let Some(mut kept) = triangles(primitive.mode(), &indices) else {
        log::warn!(
            "{}: {element} draws {:?}, which is skipped (only triangles render)",
            files.path.display(),
            primitive.mode()
        );
        return Ok(None);
    };
    drop(indices);
    let all = kept.len();
    kept.retain(|t| {
        let [a, b, c] = t.map(|i| positions[i as usize]);
        (b - a).cross(c - a).length_squared() > 0.0
    });
    if kept.len() < all {
        log::warn!(
            "{}: {element}: {} of its {all} triangles have no area and are skipped",
            files.path.display(),
            all - kept.len(),
        );
    }
    if kept.is_empty() {
        return Ok(None);
    }
    let flat = normals.is_none();
    let mut mesh = TriangleMesh {
        normals: normals.unwrap_or_else(|| vertex_normals(&positions, &kept)),
        uvs: uvs.unwrap_or_else(|| vec![Vec2::ZERO; count]),
        positions,
        indices: kept,
        tangents: Vec::new(),
        colors: match primitive.get(&gltf::Semantic::Colors(0)) {
            Some(accessor) => {
                let types = [DataType::F32, DataType::U8, DataType::U16];
                if !matches!(accessor.dimensions(), Dimensions::Vec3 | Dimensions::Vec4) {
                    return Err(files.error(&element, "COLOR_0 is neither VEC3 nor VEC4"));
                }
                check("COLOR_0", &accessor, accessor.dimensions(), &types)?;
                let colors: Vec<Vec4> = reader
                    .read_colors(0)
                    .ok_or_else(|| files.error(&element, "cannot read COLOR_0"))?
                    .into_rgba_f32()
                    .map(Vec4::from)
                    .collect();
                if colors.len() != count || colors.iter().any(|c| !c.is_finite()) {
                    return Err(
                        files.error(&element, "COLOR_0 does not give a finite colour per vertex")
                    );
                }
                colors
            }
            None => Vec::new(),
        },
        flat,
    };
    if needs.tangents {
        mesh.tangents = match primitive.get(&gltf::Semantic::Tangents) {
            Some(accessor) if !flat => {
                check("TANGENT", &accessor, Dimensions::Vec4, &[DataType::F32])?;
                let tangents: Vec<Vec4> = reader
                    .read_tangents()
                    .ok_or_else(|| files.error(&element, "cannot read TANGENT"))?
                    .map(Vec4::from)
                    .collect();
                if tangents.len() != count || tangents.iter().any(|t| !t.is_finite()) {
                    return Err(files.error(
                        &element,
                        "TANGENT does not give a finite tangent per vertex",
                    ));
                }
                mesh.indices
                    .iter()
                    .flat_map(|t| t.map(|i| tangents[i as usize]))
                    .collect()
            }
            _ => mikktspace_tangents(&mesh),
        };
    }
    Ok(Some(mesh))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn strips_and_fans_follow_the_gltf_orders() {
        // glTF 2.0, 3.7.2.1: strip p_i = {v_i, v_{i+(1+i%2)}, v_{i+(2-i%2)}};
        // fan p_i = {v_{i+1}, v_{i+2}, v_0}.
        // Indices 10, 11, ... name vertices 10, 11, ...: the triples are indices, not slots.
        let first = |n: u32| (10..10 + n).collect::<Vec<u32>>();
        assert_eq!(
            triangles(Mode::TriangleStrip, &first(5)).unwrap(),
            vec![[10, 11, 12], [11, 13, 12], [12, 13, 14]]
        );
        assert_eq!(
            triangles(Mode::TriangleFan, &first(5)).unwrap(),
            vec![[11, 12, 10], [12, 13, 10], [13, 14, 10]]
        );
        assert_eq!(
            triangles(Mode::Triangles, &first(7)).unwrap(),
            vec![[10, 11, 12], [13, 14, 15]]
        );
        assert!(triangles(Mode::LineStrip, &first(5)).is_none());
        assert_eq!(
            triangles(Mode::TriangleStrip, &first(2)).unwrap(),
            Vec::<[u32; 3]>::new()
        );
    }

    #[test]
    fn a_mirroring_node_keeps_the_front_side_and_flips_the_bitangent() {
        let mut mesh = TriangleMesh {
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y],
            normals: vec![Vec3::Z; 3],
            uvs: vec![Vec2::ZERO, Vec2::X, Vec2::Y],
            indices: vec![[0, 1, 2]],
            // Bitangent cross(z, x) * w = -y, towards -v: up in the image.
            tangents: vec![Vec4::new(1.0, 0.0, 0.0, -1.0); 3],
            colors: Vec::new(),
            flat: false,
        };
        // Mirror x and move: the triangle's front (+z) must still be counter-clockwise.
        mesh.place(glam::Mat4::from_scale(Vec3::new(-2.0, 1.0, 1.0)));
        let [a, b, c] = mesh.indices[0].map(|i| mesh.positions[i as usize]);
        let face = (b - a).cross(c - a).normalize();
        assert!(
            face.distance(mesh.normals[0]) < 1e-6,
            "{face} vs {}",
            mesh.normals[0]
        );
        assert_eq!(mesh.indices[0], [0, 2, 1]);
        for t in &mesh.tangents {
            assert_eq!(*t, Vec4::new(-1.0, 0.0, 0.0, 1.0));
        }
        // -v (still -y, the mirror being in x) = cross(n, t) * w.
        let bitangent = mesh.normals[0].cross(mesh.tangents[0].truncate()) * mesh.tangents[0].w;
        assert!(bitangent.distance(Vec3::NEG_Y) < 1e-6, "{bitangent}");
    }
}
