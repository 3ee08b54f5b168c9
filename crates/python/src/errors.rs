//! pathlight's Python exceptions, carrying the messages the command line prints.

use pyo3::PyErr;
use pyo3::create_exception;
use pyo3::exceptions::{PyRuntimeError, PyValueError};

create_exception!(
    pathlight,
    SceneError,
    PyValueError,
    "A scene that cannot be loaded or a value it refuses: the message names the file, line \
     or key."
);
create_exception!(
    pathlight,
    RenderError,
    PyRuntimeError,
    "Rendering failed: no device, a state file that does not fit, a denoiser not found."
);

/// `error` (with its causes) as a [`SceneError`].
pub fn scene_error(error: impl std::error::Error) -> PyErr {
    SceneError::new_err(message(&error))
}

/// `error` (with its causes) as a [`RenderError`].
pub fn render_error(error: impl std::error::Error) -> PyErr {
    RenderError::new_err(message(&error))
}

/// The error's message followed by its causes' (those it does not already say), as the
/// command line prints them.
fn message(error: &dyn std::error::Error) -> String {
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
