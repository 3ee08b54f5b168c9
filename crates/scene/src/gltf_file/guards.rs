//! What the `gltf` crate (1.4.1) would panic on, refused first with an error naming the
//! element: a GLB header length below the header's size, a primitive's `POSITION` naming no
//! accessor (its validation looks it up unchecked), an image with neither a URI nor a
//! buffer view with a MIME type (`Image::source` unwraps them).

use gltf::json::Root;
use gltf::json::mesh::Semantic;
use gltf::json::validation::Checked;

use super::data::Files;
use crate::error::SceneError;

/// Refuses a GLB whose header gives a length shorter than the header itself (`binary.rs:252`
/// subtracts the header's size from it unchecked).
pub(super) fn check_glb_header(files: &Files, bytes: &[u8]) -> Result<(), SceneError> {
    if let Some(length) = bytes
        .strip_prefix(b"glTF")
        .and_then(|rest| rest.get(4..8))
        .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .filter(|&length| length < 12)
    {
        return Err(files.error(
            "GLB header",
            format!("its length {length} is shorter than the 12-byte header"),
        ));
    }
    Ok(())
}

/// Refuses, before the crate validates `root`, what its validation or its accessors would
/// panic on.
pub(super) fn check_json(files: &Files, root: &Root) -> Result<(), SceneError> {
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            let position = primitive
                .attributes
                .get(&Checked::Valid(Semantic::Positions));
            if let Some(index) = position.filter(|i| i.value() >= root.accessors.len()) {
                return Err(files.error(
                    &format!("mesh {m} primitive {p}"),
                    format!(
                        "POSITION names accessor {}, but the file has {}",
                        index.value(),
                        root.accessors.len()
                    ),
                ));
            }
        }
    }
    for (i, image) in root.images.iter().enumerate() {
        let from_view = image.buffer_view.is_some() && image.mime_type.is_some();
        if !from_view && image.uri.is_none() {
            return Err(files.error(
                &format!("image {i}"),
                "needs a uri, or a bufferView with a mimeType",
            ));
        }
    }
    Ok(())
}
