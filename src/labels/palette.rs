//! Colours for labels the file gives none: consecutive values far apart in hue (the golden
//! angle) and alternating in lightness, so that neighbouring labels, usually consecutive
//! values, stay apart.

/// The colour of label `value` (sRGB).
pub(super) fn colour(value: u16) -> [u8; 3] {
    // The golden ratio's fraction: successive hues 222.5° apart, never repeating exactly.
    let hue = (f64::from(value) * 0.618_033_988_749_895).fract();
    let lightness = [0.95, 0.75, 0.85][usize::from(value) % 3];
    hsv(hue, 0.65, lightness)
}

/// sRGB of hue `h` (0…1), saturation `s` and value `v`.
fn hsv(h: f64, s: f64, v: f64) -> [u8; 3] {
    let sector = h * 6.0;
    let f = sector.fract();
    let (p, q, t) = (v * (1.0 - s), v * (1.0 - s * f), v * (1.0 - s * (1.0 - f)));
    // The sector is 0…5 (h < 1), so the cast loses nothing.
    let (r, g, b) = match sector as u32 {
        0 => (v, t, p),
        1 => (q, v, p),
        2 => (p, v, t),
        3 => (p, q, v),
        4 => (t, p, v),
        _ => (v, p, q),
    };
    [r, g, b].map(|c| (c * 255.0).round().clamp(0.0, 255.0) as u8)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Distance between two colours, in 0…255 per channel (Euclidean).
    fn apart(a: [u8; 3], b: [u8; 3]) -> f64 {
        a.iter()
            .zip(b)
            .map(|(&x, y)| (f64::from(x) - f64::from(y)).powi(2))
            .sum::<f64>()
            .sqrt()
    }

    #[test]
    fn neighbouring_labels_are_far_apart_and_none_is_black() {
        for v in 1..2000u16 {
            let (a, b) = (colour(v), colour(v + 1));
            assert!(apart(a, b) > 60.0, "{v}: {a:?} {b:?}");
            assert!(a.iter().any(|&c| c > 150), "{v}: {a:?} is dark");
        }
    }

    #[test]
    fn hues_cover_the_wheel() {
        assert_eq!(hsv(0.0, 1.0, 1.0), [255, 0, 0]);
        assert_eq!(hsv(1.0 / 3.0, 1.0, 1.0), [0, 255, 0]);
        assert_eq!(hsv(2.0 / 3.0, 1.0, 1.0), [0, 0, 255]);
    }
}
