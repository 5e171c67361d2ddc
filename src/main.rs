//! The `leapview` binary: the viewer window, or a command (`render`, `info`).

mod cli;

use std::process::ExitCode;

use clap::Parser;
use cli::{Cli, Failure};

fn main() -> ExitCode {
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("warn")).init();
    let cli = Cli::parse();
    let result = match cli.command {
        Some(command) => cli::run(command, &cli.raw),
        None => Err(Failure::Other(anyhow::anyhow!(
            "the window is not built yet"
        ))),
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
