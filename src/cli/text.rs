//! Text for a terminal: numbers without float noise (the library's [`leapview::text`]), and
//! standard output that a closed pipe (`leapview info FILE | head -1`) ends quietly instead of
//! with a panic.

use std::io::Write;

/// `writeln!` into a `String`, which cannot fail.
macro_rules! outln {
    ($out:expr, $($arg:tt)*) => {{
        use std::fmt::Write as _;
        let _ = writeln!($out, $($arg)*);
    }};
}
pub(crate) use outln;

pub use leapview::text::number;

/// Writes `text` to standard output. A reader that went away (a closed pipe) is not an error:
/// the command has nothing left to tell anyone.
pub fn print_stdout(text: &str) -> std::io::Result<()> {
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(()),
        other => other,
    }
}
