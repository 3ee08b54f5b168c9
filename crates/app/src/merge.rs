//! `pathlight merge`: sums render states (shards, checkpoints) exactly into one image or
//! state, after checking that they are parts of one render and do not overlap.

use anyhow::bail;
use pathlight_core::state::merge;

use crate::cli::MergeArgs;
use crate::{denoise, output};

/// Runs the command.
pub fn run(args: &MergeArgs) -> anyhow::Result<()> {
    output::check_writable(&args.output)?;
    let parts = args
        .parts
        .iter()
        .map(|path| Ok((path.display().to_string(), output::read_state(path)?)))
        .collect::<anyhow::Result<Vec<_>>>()?;
    let merged = merge(&parts)?;
    let target = &merged.state.target;
    if !merged.missing.is_empty() {
        let height = merged.state.fingerprint.height;
        let gaps: Vec<String> = merged
            .missing
            .iter()
            .map(|(rows, samples)| {
                let rows = if rows.len() as u32 == height {
                    "every row".to_string()
                } else {
                    format!("rows {}..{}", rows.start, rows.end)
                };
                format!("samples {}..{} of {rows}", samples.start, samples.end)
            })
            .collect();
        let gaps = gaps.join("; ");
        if !args.allow_gaps {
            bail!(
                "the parts lack {gaps} of samples {}..{}; --allow-gaps writes the image of \
                 the samples they hold",
                target.start,
                target.end
            );
        }
        note!("warning: the parts lack {gaps}");
    }
    let film = merged.film();
    let is_state = output::format_of(&args.output)? == output::Format::State;
    if is_state {
        output::write_render(&merged.into_state()?, &args.output)?;
    } else {
        let images = denoise::images(film.clone(), merged.aov_films(), None, &args.aov)?;
        output::write_images(&images, &args.output)?;
    }
    note!(
        "merged {} parts into {}: {}x{}, {} spp",
        args.parts.len(),
        args.output.display(),
        film.width,
        film.height,
        film.spp
    );
    Ok(())
}
