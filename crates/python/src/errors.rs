//! pathlight's Python exceptions, carrying the messages the command line prints.

use pathlight_core::error_message;
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
    SceneError::new_err(error_message(&error))
}

/// `error` (with its causes) as a [`RenderError`].
pub fn render_error(error: impl std::error::Error) -> PyErr {
    RenderError::new_err(error_message(&error))
}
