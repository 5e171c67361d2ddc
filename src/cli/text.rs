//! Text for a terminal: numbers without float noise, and standard output that a closed pipe
//! (`leapview info FILE | head -1`) ends quietly instead of with a panic.

use std::io::Write;

/// `writeln!` into a `String`, which cannot fail.
macro_rules! outln {
    ($out:expr, $($arg:tt)*) => {{
        use std::fmt::Write as _;
        let _ = writeln!($out, $($arg)*);
    }};
}
pub(crate) use outln;

/// `v` as a person would write it: integers as integers, others to six significant digits
/// without trailing zeros, very large or small magnitudes in scientific notation
/// (`203.19372632000002` → `203.194`, `1.7976931348623157e308` → `1.79769e308`).
pub fn number(v: f64) -> String {
    if !v.is_finite() {
        return format!("{v}");
    }
    let magnitude = v.abs();
    if magnitude != 0.0 && !(1e-4..1e9).contains(&magnitude) {
        let s = format!("{v:.5e}");
        let (mantissa, exponent) = s.split_once('e').unwrap_or((&s, "0"));
        return format!("{}e{exponent}", trim_zeros(mantissa));
    }
    if v.fract() == 0.0 {
        return format!("{v:.0}");
    }
    let decimals = (5 - magnitude.log10().floor() as i32).clamp(0, 9) as usize;
    trim_zeros(&format!("{v:.decimals$}")).to_string()
}

fn trim_zeros(s: &str) -> &str {
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.')
    } else {
        s
    }
}

/// Writes `text` to standard output. A reader that went away (a closed pipe) is not an error:
/// the command has nothing left to tell anyone.
pub fn print_stdout(text: &str) -> std::io::Result<()> {
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(()),
        other => other,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_lose_their_noise_but_not_their_sense() {
        assert_eq!(number(203.19372632000002), "203.194");
        assert_eq!(number(-1024.0), "-1024");
        assert_eq!(number(0.5), "0.5");
        assert_eq!(number(0.000123456789), "0.000123457");
        assert_eq!(number(f64::MAX), "1.79769e308");
        assert_eq!(number(-3.5e-7), "-3.5e-7");
        assert_eq!(number(0.0), "0");
        assert_eq!(number(2.0e9), "2e9");
        assert_eq!(number(f64::NAN), "NaN");
    }
}
