//! Writing the film: PNG (sRGB curve, clamped) or EXR (linear float RGB), or the render's
//! state (its exact sums, `docs/state-format.md`), by extension.
//!
//! An existing file is replaced only by a complete image: the image is encoded in memory,
//! written to a temporary file beside the target, flushed to the disk, and renamed over the
//! target. A full disk, a crash or a kill before the rename leaves the target as it was.

use std::io::Write as _;
use std::path::Path;

use anyhow::{Context, bail};
use pathlight_core::Film;
use pathlight_core::state::RenderState;
use pathlight_scene::texture::linear_to_srgb;

/// File formats pathlight writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// 8-bit sRGB PNG.
    Png,
    /// 32-bit float linear OpenEXR.
    Exr,
    /// The render's state: its exact sums and samples.
    State,
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
        Some("state") => Ok(Format::State),
        _ => bail!(
            "output {}: unknown format; use a .png or .exr extension (an image) or .state \
             (the render's exact sums)",
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

/// The film encoded in `format` (an image format).
fn encode(film: &Film, format: Format) -> anyhow::Result<Vec<u8>> {
    match format {
        Format::State => bail!("a film has no state: only a render's sums make one"),
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

/// Writes `film` to `path` in the image format its extension names, replacing a file
/// there only once the whole image is on the disk.
pub fn write(film: &Film, path: &Path) -> anyhow::Result<()> {
    let bytes = encode(film, format_of(path)?)
        .with_context(|| format!("cannot encode {}", path.display()))?;
    replace_file(path, &bytes).with_context(|| format!("cannot write {}", path.display()))
}

/// Writes a render's `state` to `path`: the state itself (`.state`), or its image, replacing
/// a file there only once all of it is on the disk.
pub fn write_render(state: &RenderState, path: &Path) -> anyhow::Result<()> {
    let bytes = match format_of(path)? {
        Format::State => state.encode(),
        format => encode(&state.film(), format)
            .with_context(|| format!("cannot encode {}", path.display()))?,
    };
    replace_file(path, &bytes).with_context(|| format!("cannot write {}", path.display()))
}

/// Reads the render state in `path`, naming the file in every error.
pub fn read_state(path: &Path) -> anyhow::Result<RenderState> {
    let bytes = std::fs::read(path).with_context(|| format!("cannot read {}", path.display()))?;
    RenderState::decode(&bytes).with_context(|| format!("{}", path.display()))
}
