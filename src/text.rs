//! Numbers as a person writes them, for every message, line of `info` and label: no float noise
//! (`203.19372632000002` → `203.194`), integers as integers, huge or tiny magnitudes in scientific
//! notation.

/// `v` to six significant digits (see [`number_to`]).
pub fn number(v: f64) -> String {
    number_to(v, 6)
}

/// `v` to `significant` digits, without trailing zeros: integers as integers, magnitudes below
/// 1e-4 or from 1e9 on in scientific notation (`1.7976931348623157e308` → `1.79769e308` at six).
pub(crate) fn number_to(v: f64, significant: u32) -> String {
    if !v.is_finite() {
        return format!("{v}");
    }
    let magnitude = v.abs();
    let significant = significant.max(1);
    if magnitude != 0.0 && !(1e-4..1e9).contains(&magnitude) {
        let decimals = (significant - 1) as usize;
        let s = format!("{v:.decimals$e}");
        let (mantissa, exponent) = s.split_once('e').unwrap_or((&s, "0"));
        return format!("{}e{exponent}", trim_zeros(mantissa));
    }
    if v.fract() == 0.0 {
        return format!("{v:.0}");
    }
    let decimals = (significant as i32 - 1 - magnitude.log10().floor() as i32).clamp(0, 9);
    let s = trim_zeros(&format!("{v:.*}", decimals as usize)).to_string();
    if s == "-0" { "0".into() } else { s }
}

fn trim_zeros(s: &str) -> &str {
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.')
    } else {
        s
    }
}

/// A byte count in decimal units a person reads at a glance: `512 bytes`, `1.2 kB`, `14.8 MB`.
pub fn bytes(bytes: u64) -> String {
    const UNITS: [&str; 5] = ["kB", "MB", "GB", "TB", "PB"];
    if bytes < 1000 {
        return format!("{bytes} bytes");
    }
    let mut value = bytes as f64 / 1000.0;
    let mut unit = 0;
    while value >= 999.95 && unit + 1 < UNITS.len() {
        value /= 1000.0;
        unit += 1;
    }
    format!("{value:.1} {}", UNITS[unit])
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

    #[test]
    fn fewer_digits_where_asked() {
        assert_eq!(number_to(27.578125, 3), "27.6");
        assert_eq!(number_to(1077.234375, 3), "1077");
        assert_eq!(number_to(0.9912345, 3), "0.991");
        assert_eq!(number_to(-0.00001, 3), "-1e-5");
        assert_eq!(number_to(-0.0004, 1), "-0.0004");
    }
}
