//! Errors of rendering, on either backend, and how every front end words an error.

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

/// `error`'s message followed by its causes' messages, each after ": ", leaving out a cause
/// whose message the text already holds (an error that names its cause, as a file's I/O
/// error does, would otherwise say it twice). How the command line and the Python package
/// word every error.
pub fn error_message(error: &dyn std::error::Error) -> String {
    let mut text = error.to_string();
    let mut source = error.source();
    while let Some(cause) = source {
        let said = cause.to_string();
        if !text.contains(&said) {
            text.push_str(": ");
            text.push_str(&said);
        }
        source = cause.source();
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An error of message `text` caused by `cause`.
    #[derive(Debug, thiserror::Error)]
    #[error("{text}")]
    struct Caused {
        text: String,
        source: Option<Box<Caused>>,
    }

    fn caused(text: &str, cause: Option<Caused>) -> Caused {
        Caused {
            text: text.to_owned(),
            source: cause.map(Box::new),
        }
    }

    #[test]
    fn messages_name_each_cause_once() {
        let io = || caused("No such file or directory (os error 2)", None);
        // A file's error that names its cause, and one that does not.
        let named = caused(
            "scene.toml: No such file or directory (os error 2)",
            Some(io()),
        );
        assert_eq!(
            error_message(&named),
            "scene.toml: No such file or directory (os error 2)"
        );
        let wrapped = caused(
            "cannot load the scene",
            Some(caused("scene.toml", Some(io()))),
        );
        assert_eq!(
            error_message(&wrapped),
            "cannot load the scene: scene.toml: No such file or directory (os error 2)"
        );
        assert_eq!(
            error_message(&io()),
            "No such file or directory (os error 2)"
        );
    }
}
