//! pathlight's denoiser: Intel Open Image Denoise 2 (OIDN), its `RT` filter on a film with
//! the albedo and shading normal images (`pathlight_core::Film::aovs_from_accumulation`).
//!
//! OIDN is loaded when it is first wanted, not linked: a build of pathlight needs no OIDN,
//! and the same binary denoises as soon as the library is on the machine
//! (`tools/get-oidn.sh` puts it in `~/.local/share/pathlight/oidn`). Where it is looked for
//! is [`Denoiser::load`]'s; without it, [`DenoiseError::NotFound`] says how to get it.
//! ARCHITECTURE.md ("Denoising") says why it is loaded this way.

mod oidn;
mod search;

use pathlight_core::Film;

pub use search::{LIBRARY, candidates};

/// Why a film could not be denoised.
#[derive(Debug, thiserror::Error)]
pub enum DenoiseError {
    /// OIDN is on none of the paths looked at; the message says how to get it.
    #[error(
        "Open Image Denoise 2 was not found (looked for {looked}): run `tools/get-oidn.sh` in \
         pathlight's source folder (it fetches OIDN 2.5.1's CPU libraries from PyPI into \
         ~/.local/share/pathlight/oidn), or set PATHLIGHT_OIDN to a folder holding \
         lib/{LIBRARY}"
    )]
    NotFound {
        /// The paths looked at, comma-separated.
        looked: String,
    },
    /// A library was found but could not be used (not OIDN 2, or a missing part).
    #[error("{path}: {message}")]
    Load {
        /// The library.
        path: String,
        /// What went wrong.
        message: String,
    },
    /// OIDN reported an error while denoising.
    #[error("Open Image Denoise: {0}")]
    Oidn(String),
    /// The images do not have one size.
    #[error("the auxiliary images are {aux}, the image {color}: they must be the same size")]
    Size {
        /// The film's size.
        color: String,
        /// The auxiliary images' size.
        aux: String,
    },
}

/// How hard to work on a film.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    /// For final images: the auxiliary images are denoised first (OIDN's prefiltering),
    /// then the film with them as clean guides, every filter at OIDN's high quality (its
    /// larger network where the guides are clean). About seven times `Fast`'s time; the
    /// lowest error of the variants measured (BENCHMARKS.md).
    Final,
    /// For previews and the viewer: the film with the auxiliary images as they are, at
    /// OIDN's balanced quality.
    Fast,
}

/// The albedo and shading normal images that guide the denoiser (the same size as the film;
/// the albedo in [0, 1], the normal in [-1, 1]).
#[derive(Debug, Clone, Copy)]
pub struct Aux<'a> {
    /// The albedo of the first surface that is not a perfect mirror or glass.
    pub albedo: &'a Film,
    /// Its shading normal.
    pub normal: &'a Film,
}

/// OIDN, loaded, with a CPU device.
pub struct Denoiser {
    device: oidn::Device,
    /// The library file it was loaded from.
    library: String,
}

impl std::fmt::Debug for Denoiser {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Denoiser")
            .field("library", &self.library)
            .finish()
    }
}

impl Denoiser {
    /// OIDN from the first of [`candidates`] that loads.
    pub fn load() -> Result<Self, DenoiseError> {
        let candidates = candidates();
        for path in &candidates {
            match oidn::Device::open(path) {
                Ok(device) => {
                    return Ok(Self {
                        device,
                        library: path.display().to_string(),
                    });
                }
                // A file that is there but does not load is an error worth seeing; a name the
                // loader does not find is just the next place to look.
                Err(message) if path.is_file() => {
                    return Err(DenoiseError::Load {
                        path: path.display().to_string(),
                        message,
                    });
                }
                Err(_) => {}
            }
        }
        Err(DenoiseError::NotFound {
            looked: candidates
                .iter()
                .map(|p| p.display().to_string())
                .collect::<Vec<_>>()
                .join(", "),
        })
    }

    /// The library file it was loaded from, and OIDN's version (`2.5.1`).
    pub fn describe(&self) -> String {
        format!(
            "Open Image Denoise {} ({})",
            self.device.version(),
            self.library
        )
    }

    /// `color` (linear HDR radiance) denoised, guided by `aux` where given.
    pub fn denoise(
        &self,
        color: &Film,
        aux: Option<Aux>,
        mode: Mode,
    ) -> Result<Film, DenoiseError> {
        if let Some(aux) = aux {
            for image in [aux.albedo, aux.normal] {
                if (image.width, image.height) != (color.width, color.height) {
                    return Err(DenoiseError::Size {
                        color: format!("{}x{}", color.width, color.height),
                        aux: format!("{}x{}", image.width, image.height),
                    });
                }
            }
        }
        let mut output = color.clone();
        let (width, height) = (color.width as usize, color.height as usize);
        let run =
            |inputs: &[(&str, &[[f32; 3]])], output: &mut [[f32; 3]], options: oidn::Options| {
                self.device
                    .filter(width, height, inputs, output, options)
                    .map_err(DenoiseError::Oidn)
            };
        match (aux, mode) {
            (None, _) => run(
                &[("color", &color.pixels)],
                &mut output.pixels,
                oidn::Options::beauty(false, quality(mode)),
            )?,
            (Some(aux), Mode::Fast) => run(
                &[
                    ("color", &color.pixels),
                    ("albedo", &aux.albedo.pixels),
                    ("normal", &aux.normal.pixels),
                ],
                &mut output.pixels,
                oidn::Options::beauty(false, quality(mode)),
            )?,
            (Some(aux), Mode::Final) => {
                // OIDN's prefiltering: each auxiliary image denoised on its own, then used
                // as a clean guide.
                let mut albedo = aux.albedo.pixels.clone();
                run(
                    &[("albedo", &aux.albedo.pixels)],
                    &mut albedo,
                    oidn::Options::auxiliary(quality(mode)),
                )?;
                let mut normal = aux.normal.pixels.clone();
                run(
                    &[("normal", &aux.normal.pixels)],
                    &mut normal,
                    oidn::Options::auxiliary(quality(mode)),
                )?;
                run(
                    &[
                        ("color", &color.pixels),
                        ("albedo", &albedo),
                        ("normal", &normal),
                    ],
                    &mut output.pixels,
                    oidn::Options::beauty(true, quality(mode)),
                )?;
            }
        }
        Ok(output)
    }
}

/// OIDN's quality for `mode`.
fn quality(mode: Mode) -> oidn::Quality {
    match mode {
        Mode::Final => oidn::Quality::High,
        Mode::Fast => oidn::Quality::Balanced,
    }
}
