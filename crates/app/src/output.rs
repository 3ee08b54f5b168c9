//! Writing the film: PNG (sRGB curve, clamped) or EXR (linear float RGB, with the auxiliary
//! images and a denoised image's raw one as layers), or the render's state (its exact sums,
//! `docs/state-format.md`), by extension.
//!
//! An existing file is replaced only by a complete image: the image is encoded in memory,
//! written to a temporary file beside the target, flushed to the disk, and renamed over the
//! target. A full disk, a crash or a kill before the rename leaves the target as it was.

use std::io::Write as _;
use std::path::Path;

use anyhow::{Context, bail};
use pathlight_core::Film;
use pathlight_core::film::ExrLayer;
use pathlight_core::state::RenderState;
use pathlight_scene::texture::linear_to_srgb;

use crate::cli::Aov;

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
        Format::Png => Ok(film.encode_png(linear_to_srgb)?),
        Format::Exr => Ok(film.encode_exr()?),
    }
}

/// Replaces (or creates) `path` with `bytes` atomically: a temporary file beside it is
/// written, flushed to the disk and renamed over it. The file keeps the permissions of the
/// one it replaces; a new one gets what any program's new file gets (read and write for
/// all, less the umask), not the temporary file's owner-only ones.
fn replace_file(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let mut builder = tempfile::Builder::new();
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let permissions = match std::fs::metadata(path) {
            Ok(existing) => existing.permissions(),
            Err(_) => std::fs::Permissions::from_mode(0o666),
        };
        builder.permissions(permissions);
    }
    let mut file = builder.tempfile_in(folder_of(path))?;
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
        Format::State => {
            anyhow::ensure!(
                state.fingerprint.is_hashed(),
                "cannot write {}: the render did not hash its scene (a bug in pathlight)",
                path.display()
            );
            state.encode()
        }
        format => encode(&state.film(), format)
            .with_context(|| format!("cannot encode {}", path.display()))?,
    };
    replace_file(path, &bytes).with_context(|| format!("cannot write {}", path.display()))
}

/// A finished picture and the images written with it.
#[derive(Debug, Clone)]
pub struct Images {
    /// The picture (denoised where asked).
    pub image: Film,
    /// The raw picture when `image` is denoised: an EXR keeps it as the layer `noisy`.
    pub noisy: Option<Film>,
    /// Auxiliary images to write beside it.
    pub aovs: Vec<(Aov, Film)>,
}

impl Images {
    /// The picture alone.
    pub fn plain(image: Film) -> Self {
        Self {
            image,
            noisy: None,
            aovs: Vec::new(),
        }
    }
}

/// Writes `images` to `path` (`.png` or `.exr`): an EXR holds them all as layers (`noisy.R`,
/// `albedo.R`, `normal.X`, ...); a PNG holds the picture, each auxiliary image going to a
/// PNG beside it (`out.albedo.png`: the albedo sRGB-encoded, the normal as `(n + 1) / 2`),
/// the raw picture nowhere. Every file is replaced only once it is whole on the disk.
pub fn write_images(images: &Images, path: &Path) -> anyhow::Result<()> {
    let format = format_of(path)?;
    let cannot_encode = || format!("cannot encode {}", path.display());
    match format {
        Format::State => bail!(
            "output {}: a state holds a render's sums, not an image",
            path.display()
        ),
        Format::Exr => {
            let mut layers = Vec::new();
            if let Some(noisy) = &images.noisy {
                layers.push(ExrLayer {
                    name: "noisy",
                    channels: ["R", "G", "B"],
                    film: noisy,
                });
            }
            for (aov, film) in &images.aovs {
                layers.push(ExrLayer {
                    name: aov.name(),
                    channels: match aov {
                        Aov::Albedo => ["R", "G", "B"],
                        Aov::Normal => ["X", "Y", "Z"],
                    },
                    film,
                });
            }
            let bytes = images
                .image
                .encode_exr_layers(&layers)
                .with_context(cannot_encode)?;
            replace_file(path, &bytes).with_context(|| format!("cannot write {}", path.display()))
        }
        Format::Png => {
            for (aov, film) in &images.aovs {
                let sibling = sibling_path(path, aov.name());
                let bytes = match aov {
                    Aov::Albedo => film.encode_png(linear_to_srgb),
                    Aov::Normal => film.encode_png(|n| (n + 1.0) * 0.5),
                }
                .with_context(|| format!("cannot encode {}", sibling.display()))?;
                replace_file(&sibling, &bytes)
                    .with_context(|| format!("cannot write {}", sibling.display()))?;
            }
            write(&images.image, path)
        }
    }
}

/// `out.png` with `name` before its extension: `out.albedo.png`.
pub fn sibling_path(path: &Path, name: &str) -> std::path::PathBuf {
    let stem = path.file_stem().unwrap_or_default().to_string_lossy();
    let extension = path.extension().unwrap_or_default().to_string_lossy();
    path.with_file_name(format!("{stem}.{name}.{extension}"))
}

/// Reads the render state in `path`, naming the file in every error.
pub fn read_state(path: &Path) -> anyhow::Result<RenderState> {
    let bytes = std::fs::read(path).with_context(|| format!("cannot read {}", path.display()))?;
    RenderState::decode(&bytes).with_context(|| format!("{}", path.display()))
}

#[cfg(test)]
mod tests {
    use pathlight_core::Accumulation;
    use pathlight_core::state::Fingerprint;
    use pathlight_scene::{Camera, RenderSettings};

    use super::*;

    /// A state whose fingerprint lacks the scene's hash is not written: it would merge with
    /// a render of any scene.
    #[test]
    fn a_state_without_the_scene_hash_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let camera = Camera {
            width: 2,
            height: 2,
            ..pathlight_scene::default_scene::load().unwrap().camera
        };
        let settings = RenderSettings::from(&pathlight_scene::desc::RenderDesc::default());
        let state = RenderState::new(
            Fingerprint::unhashed(&camera, &settings),
            0..1,
            "test".into(),
            Accumulation::empty(2, 2, 0, false),
        );
        let path = dir.path().join("a.state");
        let err = write_render(&state, &path).unwrap_err().to_string();
        assert!(err.contains("did not hash its scene"), "{err}");
        assert!(!path.exists());
    }
}

#[cfg(all(test, unix))]
mod permission_tests {
    use std::os::unix::fs::PermissionsExt;

    use super::*;

    fn mode(path: &Path) -> u32 {
        std::fs::metadata(path).unwrap().permissions().mode() & 0o777
    }

    /// A new output gets the mode any new file gets here (0o666 less the umask, as
    /// `File::create` shows), not the temporary file's 0o600; a replaced one keeps its own.
    #[test]
    fn outputs_get_the_usual_permissions_and_replacements_keep_theirs() {
        let dir = tempfile::tempdir().unwrap();
        let usual = dir.path().join("usual");
        std::fs::File::create(&usual).unwrap();
        let new = dir.path().join("new.png");
        replace_file(&new, b"one").unwrap();
        assert_eq!(mode(&new), mode(&usual));
        assert_ne!(
            mode(&new),
            0o600,
            "a umask of 0o177 would hide the difference"
        );
        std::fs::set_permissions(&new, std::fs::Permissions::from_mode(0o640)).unwrap();
        replace_file(&new, b"two").unwrap();
        assert_eq!(mode(&new), 0o640);
        assert_eq!(std::fs::read(&new).unwrap(), b"two");
    }
}
