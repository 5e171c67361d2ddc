//! Running the `leapview` binary the way a user does.

use std::process::{Command, Output};

/// Runs `leapview ARGS` to completion (with a runtime dir, so Mesa's WSI layer stays quiet).
pub fn leapview(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_leapview"))
        .args(args)
        .env("XDG_RUNTIME_DIR", std::env::temp_dir())
        .output()
        .expect("run the binary")
}

/// The command's standard error as text.
pub fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}
