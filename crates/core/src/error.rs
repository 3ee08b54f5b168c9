//! Errors of rendering, on either backend.

/// What can fail between choosing a device and reading the image back.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// No adapter at all, or none matching the requested name.
    #[error("{0}")]
    NoAdapter(String),
    /// The adapter refused to create a device.
    #[error("cannot open a device on {adapter}: {message}")]
    Device {
        /// The adapter's name.
        adapter: String,
        /// What wgpu said.
        message: String,
    },
    /// A shader or pipeline failed validation.
    #[error("pipeline {label}: {message}")]
    Pipeline {
        /// The pipeline's label.
        label: String,
        /// What wgpu said.
        message: String,
    },
    /// The scene or image does not fit the device's limits.
    #[error("{0}")]
    Limits(String),
    /// The GPU failed while rendering or reading back.
    #[error("GPU failure: {0}")]
    Gpu(String),
    /// Sums to resume from that do not fit the image.
    #[error("cannot resume: {0}")]
    Resume(String),
}

/// A scene whose geometry cannot be built into a BVH: a coordinate or a length that is not
/// finite or lies beyond [`pathlight_scene::settings::MAX_COORDINATE`] (where boxes and
/// areas would overflow). Scene files are checked when they load, with their line; this
/// guards every other way a scene is made.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("object {object:?}: {message}")]
pub struct GeometryError {
    /// The object's name.
    pub object: String,
    /// What is wrong, with the value.
    pub message: String,
}
