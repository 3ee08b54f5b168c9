//! Writing the film: PNG (sRGB curve, clamped) or EXR (linear float RGB), by extension.

use std::fs::OpenOptions;
use std::path::Path;

use anyhow::{Context, bail};
use pathlight_core::Film;
use pathlight_scene::texture::linear_to_srgb;

/// Image file formats pathlight writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// 8-bit sRGB PNG.
    Png,
    /// 32-bit float linear OpenEXR.
    Exr,
}

/// The format named by `path`'s extension.
pub fn format_of(path: &Path) -> anyhow::Result<Format> {
    match path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .as_deref()
    {
        Some("png") => Ok(Format::Png),
        Some("exr") => Ok(Format::Exr),
        _ => bail!(
            "output {}: unknown image format; use a .png or .exr extension",
            path.display()
        ),
    }
}

/// Checks before rendering that `path` can be written; returns whether this check created
/// the file (so a failed render can remove it again).
pub fn check_writable(path: &Path) -> anyhow::Result<bool> {
    format_of(path)?;
    let existed = path.exists();
    OpenOptions::new()
        .append(true)
        .create(true)
        .open(path)
        .with_context(|| format!("output {} is not writable", path.display()))?;
    Ok(!existed)
}

/// Writes `film` to `path` in the format its extension names.
pub fn write(film: &Film, path: &Path) -> anyhow::Result<()> {
    match format_of(path)? {
        Format::Png => {
            let bytes: Vec<u8> = film
                .pixels
                .iter()
                .flat_map(|p| p.map(|c| (linear_to_srgb(c) * 255.0 + 0.5) as u8))
                .collect();
            image::save_buffer(
                path,
                &bytes,
                film.width,
                film.height,
                image::ColorType::Rgb8,
            )
            .with_context(|| format!("cannot write {}", path.display()))
        }
        Format::Exr => film
            .write_exr(path)
            .with_context(|| format!("cannot write {}", path.display())),
    }
}
