//! Parsers of the flags' value lists: `X,Y,Z` vectors, dimensions, `WxH` sizes and `LO,HI`
//! windows.

/// `N` values separated by commas or `x`.
fn parse_list<const N: usize, T: std::str::FromStr>(s: &str, what: &str) -> Result<[T; N], String> {
    let parts: Vec<&str> = s.split([',', 'x', 'X']).map(str::trim).collect();
    if parts.len() != N {
        return Err(format!(
            "expected {N} {what} separated by commas, got {s:?}"
        ));
    }
    let mut values = Vec::with_capacity(N);
    for p in parts {
        values.push(
            p.parse::<T>()
                .map_err(|_| format!("{p:?} is not a valid number in {s:?}"))?,
        );
    }
    values
        .try_into()
        .map_err(|_| format!("expected {N} {what}"))
}

/// `X,Y,Z`: three finite numbers.
pub fn parse_vec3(s: &str) -> Result<[f64; 3], String> {
    let v: [f64; 3] = parse_list(s, "numbers")?;
    if v.iter().any(|x| !x.is_finite()) {
        return Err(format!("{s:?} holds a value that is not finite"));
    }
    Ok(v)
}

/// `X,Y,Z` dimensions.
pub fn parse_dims(s: &str) -> Result<[u32; 3], String> {
    parse_list(s, "dimensions")
}

/// `WxH` (or `W,H`), both sides non-zero.
pub fn parse_size(s: &str) -> Result<[u32; 2], String> {
    let v: [u32; 2] = parse_list(s, "sizes (WxH)")?;
    if v.contains(&0) {
        return Err(format!("image size {s:?} has a zero side"));
    }
    Ok(v)
}

/// `LO,HI`: a window in data units, its top above its bottom.
pub fn parse_window(s: &str) -> Result<[f64; 2], String> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    let [lo, hi] = parts.as_slice() else {
        return Err(format!("expected LO,HI, got {s:?}"));
    };
    let parse = |p: &str| {
        p.parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| format!("{p:?} is not a finite number in {s:?}"))
    };
    let (lo, hi) = (parse(lo)?, parse(hi)?);
    if hi <= lo {
        return Err(format!(
            "the window's top must exceed its bottom, got {s:?}"
        ));
    }
    Ok([lo, hi])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lists_parse_and_reject() {
        assert_eq!(parse_size("640x480"), Ok([640, 480]));
        assert!(parse_size("640x0").is_err());
        assert_eq!(parse_vec3("1,-2.5,3"), Ok([1.0, -2.5, 3.0]));
        assert!(parse_vec3("1,2").is_err());
        assert!(parse_vec3("1,nan,2").is_err());
        assert_eq!(parse_dims("4,5,6"), Ok([4, 5, 6]));
    }
}
