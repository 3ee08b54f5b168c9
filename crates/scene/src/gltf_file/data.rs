//! A glTF file's binary data: its buffers (the GLB chunk, files beside it, `data:` URIs),
//! its images' bytes, and checks that an accessor lies within them before it is read.

use std::path::{Path, PathBuf};

use base64::Engine;
use gltf::accessor::{DataType, Dimensions};

use crate::error::SceneError;

/// Where a glTF file's relative URIs start, and its path for errors.
pub(super) struct Files<'a> {
    /// The `.gltf` or `.glb` file.
    pub path: &'a Path,
    /// Its directory.
    pub base: PathBuf,
}

impl Files<'_> {
    /// An error about `element` of the file.
    pub fn error(&self, element: &str, message: impl std::fmt::Display) -> SceneError {
        SceneError::Asset {
            path: self.path.to_owned(),
            message: format!("{element}: {message}"),
        }
    }

    /// The bytes a URI names: a `data:` URI's payload, or a file relative to the glTF file.
    fn uri_bytes(&self, element: &str, uri: &str) -> Result<Vec<u8>, SceneError> {
        if let Some(rest) = uri.strip_prefix("data:") {
            let Some((header, payload)) = rest.split_once(',') else {
                return Err(self.error(element, "malformed data URI (no comma)"));
            };
            if !header.ends_with(";base64") {
                return Err(self.error(element, "data URI is not base64"));
            }
            return base64::engine::general_purpose::STANDARD
                .decode(payload)
                .map_err(|err| {
                    self.error(element, format!("data URI is not valid base64: {err}"))
                });
        }
        if uri.contains("://") {
            return Err(self.error(element, format!("URI {uri:?} is not a local file")));
        }
        let decoded = percent_encoding::percent_decode_str(uri).decode_utf8_lossy();
        let file = self.base.join(decoded.as_ref());
        std::fs::read(&file)
            .map_err(|err| self.error(element, format!("cannot read {}: {err}", file.display())))
    }

    /// Every buffer's bytes, each at least as long as the file says.
    pub fn buffers(
        &self,
        document: &gltf::Document,
        blob: Option<Vec<u8>>,
    ) -> Result<Vec<Vec<u8>>, SceneError> {
        let mut blob = blob;
        document
            .buffers()
            .map(|buffer| {
                let element = format!("buffer {}", buffer.index());
                let bytes = match buffer.source() {
                    gltf::buffer::Source::Bin => blob.take().ok_or_else(|| {
                        self.error(&element, "refers to a GLB binary chunk the file lacks")
                    })?,
                    gltf::buffer::Source::Uri(uri) => self.uri_bytes(&element, uri)?,
                };
                if bytes.len() < buffer.length() {
                    return Err(self.error(
                        &element,
                        format!(
                            "holds {} bytes; the file says {}",
                            bytes.len(),
                            buffer.length()
                        ),
                    ));
                }
                Ok(bytes)
            })
            .collect()
    }

    /// The encoded bytes of image `image` (PNG or JPEG).
    pub fn image_bytes(
        &self,
        image: &gltf::Image,
        buffers: &[Vec<u8>],
    ) -> Result<Vec<u8>, SceneError> {
        let element = format!("image {}", image.index());
        match image.source() {
            gltf::image::Source::Uri { uri, .. } => self.uri_bytes(&element, uri),
            gltf::image::Source::View { view, .. } => {
                let range = view_range(&view, buffers).ok_or_else(|| {
                    self.error(
                        &element,
                        format!("buffer view {} lies outside its buffer", view.index()),
                    )
                })?;
                Ok(buffers[view.buffer().index()][range].to_vec())
            }
        }
    }

    /// Checks that `accessor` holds `dimensions` of one of `types` and lies within its
    /// buffer view and buffer; `element` names its use for errors.
    pub fn check_accessor(
        &self,
        element: &str,
        accessor: &gltf::Accessor,
        buffers: &[Vec<u8>],
        dimensions: Dimensions,
        types: &[DataType],
    ) -> Result<(), SceneError> {
        let what = format!("{element} (accessor {})", accessor.index());
        if accessor.dimensions() != dimensions || !types.contains(&accessor.data_type()) {
            return Err(self.error(
                &what,
                format!(
                    "holds {:?} of {:?}; expected {dimensions:?} of {types:?}",
                    accessor.dimensions(),
                    accessor.data_type()
                ),
            ));
        }
        if accessor.sparse().is_some() {
            return Err(self.error(&what, "sparse accessors are not supported"));
        }
        if accessor.count() == 0 {
            return Err(self.error(&what, "holds no elements"));
        }
        let Some(view) = accessor.view() else {
            return Err(self.error(&what, "has no buffer view"));
        };
        let Some(range) = view_range(&view, buffers) else {
            return Err(self.error(
                &what,
                format!("buffer view {} lies outside its buffer", view.index()),
            ));
        };
        let size = accessor.size();
        let stride = view.stride().unwrap_or(size);
        let end = (accessor.count() - 1)
            .checked_mul(stride)
            .and_then(|n| n.checked_add(accessor.offset() + size));
        if stride < size || end.is_none_or(|end| end > range.len()) {
            return Err(self.error(
                &what,
                format!(
                    "{} elements of {size} bytes (stride {stride}, offset {}) overrun buffer view {} of {} bytes",
                    accessor.count(),
                    accessor.offset(),
                    view.index(),
                    range.len()
                ),
            ));
        }
        Ok(())
    }
}

/// The byte range of `view` in its buffer, if it lies within it.
fn view_range(view: &gltf::buffer::View, buffers: &[Vec<u8>]) -> Option<std::ops::Range<usize>> {
    let buffer = buffers.get(view.buffer().index())?;
    let end = view.offset().checked_add(view.length())?;
    (end <= buffer.len()).then_some(view.offset()..end)
}
