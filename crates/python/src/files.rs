//! Files the module reads and writes: state files, and images written as the command line
//! writes them (a file replaced only once the new one is whole on the disk).

use std::io::Write as _;
use std::path::Path;

use pathlight_core::Film;
use pathlight_core::state::RenderState;
use pathlight_scene::texture::linear_to_srgb;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use crate::errors::RenderError;

/// The state file at `path`.
pub fn read_state(path: &Path) -> PyResult<RenderState> {
    let bytes = std::fs::read(path)
        .map_err(|e| RenderError::new_err(format!("cannot read {}: {e}", path.display())))?;
    RenderState::decode(&bytes)
        .map_err(|e| RenderError::new_err(format!("{}: {e}", path.display())))
}

/// Writes `state` to `path`.
pub fn write_state(state: &RenderState, path: &Path) -> PyResult<()> {
    replace_file(path, &state.encode())
}

/// Writes `film` to `path` as its extension says: `.png` (8-bit sRGB, clamped) or `.exr`
/// (32-bit float linear RGB), the bytes `pathlight render` writes for the same image.
pub fn write_image(film: &Film, path: &Path) -> PyResult<()> {
    let extension = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let cannot = |e: &dyn std::fmt::Display| {
        RenderError::new_err(format!("cannot encode {}: {e}", path.display()))
    };
    let bytes = match extension.as_deref() {
        Some("png") => film.encode_png(linear_to_srgb).map_err(|e| cannot(&e))?,
        Some("exr") => film.encode_exr().map_err(|e| cannot(&e))?,
        _ => {
            return Err(PyValueError::new_err(format!(
                "{}: unknown image format; use a .png or .exr extension",
                path.display()
            )));
        }
    };
    replace_file(path, &bytes)
}

/// Replaces (or creates) `path` with `bytes`: a temporary file beside it is written, flushed
/// to the disk and renamed over it.
fn replace_file(path: &Path, bytes: &[u8]) -> PyResult<()> {
    let folder = match path.parent() {
        Some(parent) if !parent.as_os_str().is_empty() => parent,
        _ => Path::new("."),
    };
    let write = || -> std::io::Result<()> {
        let mut file = tempfile::NamedTempFile::new_in(folder)?;
        file.write_all(bytes)?;
        file.as_file().sync_all()?;
        file.persist(path)?;
        Ok(())
    };
    write().map_err(|e| RenderError::new_err(format!("cannot write {}: {e}", path.display())))
}
