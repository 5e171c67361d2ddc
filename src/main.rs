//! The `leapview` binary: the viewer window, or a command (`render`, `info`).

mod cli;

use std::process::ExitCode;

use clap::Parser;
use cli::{Cli, Failure};
use leapview::ui::app::{AppError, AppOptions};

fn main() -> ExitCode {
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("warn")).init();
    let cli = Cli::parse();
    let result = match cli.command {
        Some(command) => cli::run(command, &cli.raw),
        None => cli::load_options(&cli.raw).and_then(|load_options| {
            let options = AppOptions {
                file: cli.file,
                load_options,
            };
            leapview::ui::app::run(options).map_err(|e| match e {
                AppError::Automation(_) => Failure::BadInput(e.into()),
                other => Failure::Other(other.into()),
            })
        }),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(Failure::BadInput(e)) => {
            eprintln!("leapview: {e:#}");
            ExitCode::from(2)
        }
        Err(Failure::Other(e)) => {
            eprintln!("leapview: {e:#}");
            ExitCode::FAILURE
        }
    }
}
