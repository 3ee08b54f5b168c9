//! `pathlight`: a progressive GPU path tracer. See `pathlight --help`.

#[macro_use]
mod note;
mod backend;
mod bench;
mod cli;
mod denoise;
mod merge;
mod output;
mod progress;
mod render;
mod shard;
mod view;

use std::process::ExitCode;

use clap::Parser;

fn main() -> ExitCode {
    env_logger::Builder::from_env(
        env_logger::Env::default().default_filter_or("warn,wgpu_hal::gles::egl=off"),
    )
    .init();
    let cli = cli::Cli::parse();
    let result = match cli.command {
        Some(cli::Command::Render(args)) => render::run(&args),
        Some(cli::Command::View(args)) => view::run(&args),
        Some(cli::Command::Bench(args)) => bench::run(&args),
        Some(cli::Command::Merge(args)) => merge::run(&args),
        Some(cli::Command::Denoise(args)) => denoise::run(&args),
        None => view::run(&cli::ViewArgs::defaults()),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        // The render has said what it kept.
        Err(err) if err.is::<render::Interrupted>() => {
            ExitCode::from(render::Interrupted::EXIT_CODE)
        }
        Err(err) => {
            note!("error: {}", pathlight_core::error_message(err.as_ref()));
            ExitCode::FAILURE
        }
    }
}
