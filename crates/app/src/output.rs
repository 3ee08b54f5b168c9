//! Writing the film: PNG (sRGB curve, clamped) or EXR (linear float RGB), by extension.
//!
//! An existing file is replaced only by a complete image: the image is encoded in memory,
//! written to a temporary file beside the target, flushed to the disk, and renamed over the
//! target. A full disk, a crash or a kill before the rename leaves the target as it was.

use std::io::Write as _;
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

/// The folder a file at `path` lies in.
fn folder_of(path: &Path) -> &Path {
    match path.parent() {
        Some(parent) if !parent.as_os_str().is_empty() => parent,
        _ => Path::new("."),
    }
}

/// Checks before rendering that an image can be written to `path`: a known format, not a
/// folder, and a folder that accepts a new file (a temporary file is created there and
/// removed). Nothing is written at `path` itself.
pub fn check_writable(path: &Path) -> anyhow::Result<()> {
    format_of(path)?;
    if path.is_dir() {
        bail!("output {} is not writable: it is a folder", path.display());
    }
    tempfile::NamedTempFile::new_in(folder_of(path))
        .with_context(|| format!("output {} is not writable", path.display()))?;
    Ok(())
}

/// The film encoded in `format`.
fn encode(film: &Film, format: Format) -> anyhow::Result<Vec<u8>> {
    match format {
        Format::Png => {
            use image::ImageEncoder as _;
            let pixels: Vec<u8> = film
                .pixels
                .iter()
                .flat_map(|p| p.map(|c| (linear_to_srgb(c) * 255.0 + 0.5) as u8))
                .collect();
            let mut bytes = Vec::new();
            image::codecs::png::PngEncoder::new(&mut bytes).write_image(
                &pixels,
                film.width,
                film.height,
                image::ExtendedColorType::Rgb8,
            )?;
            Ok(bytes)
        }
        Format::Exr => Ok(film.encode_exr()?),
    }
}

/// Replaces (or creates) `path` with `bytes` atomically: a temporary file beside it is
/// written, flushed to the disk and renamed over it.
fn replace_file(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let mut file = tempfile::NamedTempFile::new_in(folder_of(path))?;
    file.write_all(bytes)?;
    file.as_file().sync_all()?;
    file.persist(path)?;
    Ok(())
}

/// Writes `film` to `path` in the format its extension names, replacing a file there only
/// once the whole image is on the disk.
pub fn write(film: &Film, path: &Path) -> anyhow::Result<()> {
    let bytes = encode(film, format_of(path)?)
        .with_context(|| format!("cannot encode {}", path.display()))?;
    replace_file(path, &bytes).with_context(|| format!("cannot write {}", path.display()))
}
