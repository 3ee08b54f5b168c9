//! `pathlight denoise`, and the denoising `render --denoise` does: a film, guided by its
//! albedo and normal images when there are some, through Open Image Denoise.

use std::time::Instant;

use anyhow::{Context, bail};
use pathlight_core::Film;
use pathlight_denoise::{Aux, Denoiser, Mode};

use crate::cli::{Aov, DenoiseArgs, DenoiseMode};
use crate::output::{self, Format, Images};

/// OIDN, or the error that says how to get it; says which library it uses.
pub fn load() -> anyhow::Result<Denoiser> {
    let denoiser = Denoiser::load()?;
    note!("denoiser: {}", denoiser.describe());
    Ok(denoiser)
}

/// The mode of the denoiser `mode` asks for.
pub fn mode(mode: DenoiseMode) -> Mode {
    match mode {
        DenoiseMode::Final => Mode::Final,
        DenoiseMode::Fast => Mode::Fast,
    }
}

/// The images to write of a render's `color` and its auxiliary images `aovs` (albedo,
/// normal): `color` denoised by `denoiser` when given (keeping the raw one), and the
/// auxiliary images `write` names.
pub fn images(
    color: Film,
    aovs: Option<(Film, Film)>,
    denoiser: Option<(&Denoiser, Mode)>,
    write: &[Aov],
) -> anyhow::Result<Images> {
    let mut images = Images::plain(color);
    if let Some((denoiser, mode)) = denoiser {
        let aux = aovs.as_ref().map(|(albedo, normal)| Aux { albedo, normal });
        if aux.is_none() {
            note!("no albedo and normal images: denoising the colour alone");
        }
        let started = Instant::now();
        let denoised = denoiser.denoise(&images.image, aux, mode)?;
        note!(
            "denoised {}x{} in {:.2} s",
            denoised.width,
            denoised.height,
            started.elapsed().as_secs_f64()
        );
        images.noisy = Some(std::mem::replace(&mut images.image, denoised));
    }
    if !write.is_empty() {
        let Some((albedo, normal)) = aovs else {
            bail!("the render has no auxiliary images to write");
        };
        for &aov in write {
            let film = match aov {
                Aov::Albedo => albedo.clone(),
                Aov::Normal => normal.clone(),
            };
            images.aovs.push((aov, film));
        }
    }
    Ok(images)
}

/// Runs the command.
pub fn run(args: &DenoiseArgs) -> anyhow::Result<()> {
    output::check_writable(&args.output)?;
    if output::format_of(&args.output)? == Format::State {
        bail!(
            "output {}: a denoised image is an image; write a .png or .exr",
            args.output.display()
        );
    }
    let input = &args.input;
    let (color, aovs) = match output::format_of(input) {
        Ok(Format::State) => {
            let state = output::read_state(input)?;
            (state.film(), state.aov_films())
        }
        Ok(Format::Exr) => {
            let wanted = [("albedo", ["R", "G", "B"]), ("normal", ["X", "Y", "Z"])];
            let (color, mut layers) = Film::read_exr_layers(input, &wanted)
                .with_context(|| format!("cannot read {}", input.display()))?;
            let normal = layers.pop().flatten();
            let albedo = layers.pop().flatten();
            (color, albedo.zip(normal))
        }
        _ => bail!(
            "{}: pathlight denoise reads an .exr (its R, G, B and, if there, albedo and \
             normal layers) or a .state",
            input.display()
        ),
    };
    let denoiser = load()?;
    let images = images(color, aovs, Some((&denoiser, mode(args.mode))), &args.aov)?;
    output::write_images(&images, &args.output)?;
    note!(
        "wrote {}: {}x{}",
        args.output.display(),
        images.image.width,
        images.image.height
    );
    Ok(())
}
