//! The `leapview` binary: the viewer window, or a command (`render`, `info`, `bench`,
//! `accuracy`).

mod cli;

use std::process::ExitCode;

use clap::Parser;
use cli::{Cli, Failure};
use leapview::ui::app::{AppError, AppOptions};

fn main() -> ExitCode {
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("warn"))
        .format_timestamp_millis()
        .init();
    let cli = Cli::parse();
    if cli.command.is_some() {
        quiet_device_selection();
    }
    let result = match cli.command {
        Some(command) => cli::run(command, &cli.raw),
        None => cli::load_options(&cli.raw).and_then(|load_options| {
            let options = AppOptions {
                file: cli.file,
                load_options,
                gpu_budget: cli.gpu.gpu_budget,
                labels: cli.labels,
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

/// Headless commands pick their adapter themselves: Mesa's implicit device-selection layer would
/// only connect to a Wayland display to rank them, and print "error: XDG_RUNTIME_DIR is invalid"
/// twice where there is none (a server, CI). It stays off unless the user set it either way.
fn quiet_device_selection() {
    if std::env::var_os("NODEVICE_SELECT").is_none() {
        // SAFETY: called at the start of `main`, before any thread exists that could read the
        // environment concurrently.
        unsafe { std::env::set_var("NODEVICE_SELECT", "1") };
    }
}
