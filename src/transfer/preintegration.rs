//! Pre-integrated classification (Engel, Kraus, Ertl 2001): the colour and opacity of a whole
//! segment between two samples, from the transfer function integrated over the values between
//! the segment's ends, assuming the value changes linearly along it.
//!
//! With extinction `τ(s) = −ln(1 − α(s))` per `d₀` (so a slab one `d₀` thick of value `s` has
//! opacity `α(s)`), a segment of `D` units of `d₀` from value `s_f` to `s_b` has
//!
//! - optical depth `D · τ̄`, with `τ̄ = ∫_{s_f}^{s_b} τ ds / (s_b − s_f)`, so opacity
//!   `1 − exp(−D · τ̄)`;
//! - colour `∫ c τ ds / ∫ τ ds`: the mean colour weighted by extinction. This ignores the
//!   attenuation inside the segment (exact for one colour, as in Engel et al.'s "no
//!   self-attenuation" tables, but bounded: never brighter than the brightest colour in the
//!   interval).
//!
//! The GPU evaluates the two integrals as differences of running integrals `T(s) = ∫₀ˢ τ` and
//! `K(s) = ∫₀ˢ c τ` over the lookup table's entries, which costs O(N) to build (no N² table) and
//! keeps the full table resolution. Each running integral is stored as two f32 (`hi + lo`) plus
//! the increment of its cell, so the difference of two nearby values keeps full precision after
//! a large opaque stretch (see [`integral_table`]). Values closer than one table cell are widened
//! to one cell around their midpoint.

use glam::DVec3;

use super::TransferFunction;
use super::lut::LUT_SIZE;
use crate::volume::ValueRange;

/// Largest extinction per `d₀`, for an opacity of exactly 1: a segment of 1/8 voxel still reaches
/// `1 − e^−8` (> 1 − 1/255), and `T` stays small enough for f32.
pub const TAU_MAX: f64 = 64.0;

/// Rows of the integral table, each [`LUT_SIZE`] texels of RGBA f32: `(T_hi, T_lo, ΔT, 0)`,
/// `(K_hi, 0)`, `(K_lo, 0)`, `(ΔK, 0)`, where `ΔX` at entry `i` is `X(i + 1) − X(i)`.
pub const INTEGRAL_ROWS: usize = 4;

/// Extinction per `d₀` of an opacity per `d₀`, capped at [`TAU_MAX`].
pub(crate) fn extinction(alpha: f64) -> f64 {
    crate::sampling::extinction(alpha).min(TAU_MAX)
}

/// The running-integral table for `tf` over `range`, row by row ([`INTEGRAL_ROWS`] ×
/// [`LUT_SIZE`] texels). Entry `i` is the value `i / (N − 1)`; between entries `τ` and `cτ` are
/// taken as linear (the trapezoid rule), matching the linear filtering of the ordinary table.
pub(crate) fn integral_table(tf: &TransferFunction, range: ValueRange) -> Vec<[f32; 4]> {
    let n = LUT_SIZE;
    let h = 1.0 / (n - 1) as f64;
    let entry = |i: usize| {
        let value = range.denormalize(i as f64 * h);
        let tau = extinction(tf.opacity_at(value, range));
        (tau, DVec3::from_array(tf.color_at(value, range)) * tau)
    };
    let (mut t, mut k) = (vec![0.0f64; n], vec![DVec3::ZERO; n]);
    let mut prev = entry(0);
    for i in 1..n {
        let next = entry(i);
        t[i] = t[i - 1] + 0.5 * h * (prev.0 + next.0);
        k[i] = k[i - 1] + 0.5 * h * (prev.1 + next.1);
        prev = next;
    }
    let split = |x: f64| {
        let hi = x as f32;
        (hi, (x - f64::from(hi)) as f32)
    };
    let mut rows = vec![[0.0f32; 4]; INTEGRAL_ROWS * n];
    for i in 0..n {
        let (dt, dk) = if i + 1 < n {
            (t[i + 1] - t[i], k[i + 1] - k[i])
        } else {
            (0.0, DVec3::ZERO)
        };
        let (t_hi, t_lo) = split(t[i]);
        let (kr, kg, kb) = (split(k[i].x), split(k[i].y), split(k[i].z));
        rows[i] = [t_hi, t_lo, dt as f32, 0.0];
        rows[n + i] = [kr.0, kg.0, kb.0, 0.0];
        rows[2 * n + i] = [kr.1, kg.1, kb.1, 0.0];
        rows[3 * n + i] = [dk.x as f32, dk.y as f32, dk.z as f32, 0.0];
    }
    rows
}

/// Colour (straight) and opacity of a segment `depth` units of `d₀` long whose normalised value
/// runs linearly from `s_front` to `s_back`, integrating the transfer function itself in f64
/// (Gauss–Legendre on each piece between its points): the CPU reference's pre-integration,
/// independent of the GPU's table.
pub fn segment(
    tf: &TransferFunction,
    range: ValueRange,
    s_front: f64,
    s_back: f64,
    depth: f64,
) -> (DVec3, f64) {
    let (lo, hi) = (s_front.min(s_back), s_front.max(s_back));
    let at = |s: f64| {
        let value = range.denormalize(s);
        let tau = extinction(tf.opacity_at(value, range));
        (tau, DVec3::from_array(tf.color_at(value, range)))
    };
    if hi - lo < 1e-12 {
        let (tau, c) = at(0.5 * (lo + hi));
        return (c, 1.0 - (-depth * tau).exp());
    }
    // Breakpoints of both curves inside (lo, hi), as normalised values.
    let mut cuts: Vec<f64> = tf
        .opacity
        .iter()
        .map(|p| p[0])
        .chain(tf.color.iter().map(|p| p[0]))
        .map(|v| range.normalize(tf.to_data(v, range)))
        .filter(|&s| s > lo && s < hi)
        .collect();
    cuts.push(lo);
    cuts.push(hi);
    cuts.sort_by(f64::total_cmp);
    let (mut t, mut k) = (0.0, DVec3::ZERO);
    for w in cuts.windows(2) {
        let (a, b) = (w[0], w[1]);
        for (x, weight) in GAUSS_8 {
            let s = 0.5 * (a + b) + 0.5 * (b - a) * x;
            let (tau, c) = at(s);
            t += 0.5 * (b - a) * weight * tau;
            k += 0.5 * (b - a) * weight * tau * c;
        }
    }
    if t <= 0.0 {
        return (DVec3::ZERO, 0.0);
    }
    (k / t, 1.0 - (-depth * t / (hi - lo)).exp())
}

/// Eight-point Gauss–Legendre nodes and weights on [−1, 1].
const GAUSS_8: [(f64, f64); 8] = [
    (-0.960_289_856_497_536_3, 0.101_228_536_290_376_26),
    (-0.796_666_477_413_626_7, 0.222_381_034_453_374_47),
    (-0.525_532_409_916_329, 0.313_706_645_877_887_3),
    (-0.183_434_642_495_649_8, 0.362_683_783_378_362),
    (0.183_434_642_495_649_8, 0.362_683_783_378_362),
    (0.525_532_409_916_329, 0.313_706_645_877_887_3),
    (0.796_666_477_413_626_7, 0.222_381_034_453_374_47),
    (0.960_289_856_497_536_3, 0.101_228_536_290_376_26),
];

#[cfg(test)]
mod tests {
    use super::*;

    fn range() -> ValueRange {
        ValueRange {
            min: 0.0,
            max: 100.0,
        }
    }

    /// A spike of opacity 0.8 one value wide at 50, red; transparent elsewhere.
    fn spike() -> TransferFunction {
        TransferFunction {
            opacity: vec![[0.0, 0.0], [49.5, 0.0], [50.0, 0.8], [50.5, 0.0]],
            color: vec![[0.0, 1.0, 0.0, 0.0]],
            space: crate::transfer::ValueSpace::Data,
        }
    }

    /// T(b) − T(a) as the shader computes it from the table.
    fn table_integral(rows: &[[f32; 4]], a: f64, b: f64) -> f64 {
        let n = LUT_SIZE;
        let at = |s: f64| {
            let x = s.clamp(0.0, 1.0) * (n - 1) as f64;
            let i = (x.floor() as usize).min(n - 2);
            let f = x - i as f64;
            let r = rows[i];
            (f64::from(r[0]), f64::from(r[1]), f64::from(r[2]) * f)
        };
        let (ha, la, pa) = at(a);
        let (hb, lb, pb) = at(b);
        (hb - ha) + (lb - la) + (pb - pa)
    }

    #[test]
    fn a_segment_across_a_thin_spike_keeps_its_optical_depth() {
        // Crossing the whole spike: ∫τ over the triangle of half-width 0.5 value = 0.005 in
        // normalised units, peak −ln(0.2); the mean over a segment from 0.2 to 0.8 is tiny but
        // the depth of a 4-voxel step carries it.
        let (c, a) = segment(&spike(), range(), 0.2, 0.8, 4.0);
        let peak = -(0.2f64).ln();
        // ∫ of −ln(1 − α) over a linear ramp of α is not the triangle's area; bound it by the
        // areas of α (below) and of the peak extinction (above).
        let (lo, hi) = (0.8 * 0.005, peak * 0.005);
        let depth = -(1.0 - a).ln() * 0.6 / 4.0;
        assert!(depth > lo && depth < hi, "{depth} not in ({lo}, {hi})");
        assert_eq!(c, DVec3::new(1.0, 0.0, 0.0));
        // Sampling at the segment's ends would see nothing at all.
        assert_eq!(spike().opacity_at(20.0, range()), 0.0);
    }

    #[test]
    fn the_table_integrates_as_the_reference_does() {
        let tf = spike();
        let rows = integral_table(&tf, range());
        for (a, b) in [(0.2, 0.8), (0.49, 0.51), (0.0, 1.0), (0.6, 0.9)] {
            let (_, alpha) = segment(&tf, range(), a, b, 1.0);
            let exact = -(1.0 - alpha).ln() * (b - a);
            let table = table_integral(&rows, a, b);
            // The table samples the TF every 1/4095 of the range (0.024 values here): its
            // trapezoids cut the spike's 1-value-wide triangle's tip by up to a few per cent.
            assert!(
                (table - exact).abs() <= 0.03 * exact.max(1e-9) + 1e-9,
                "[{a}, {b}]: table {table} vs exact {exact}"
            );
        }
    }

    #[test]
    fn nearby_values_after_an_opaque_stretch_keep_their_precision() {
        // Opaque (τ = TAU_MAX) below 0.5, faint (α = 1e-4) above: T is ~32 there, the faint
        // cell increments are ~2.4e-8, far below one f32 ulp of 32 (3.8e-6).
        let tf = TransferFunction {
            opacity: vec![[0.0, 1.0], [49.99, 1.0], [50.0, 1e-4], [100.0, 1e-4]],
            color: vec![[0.0, 1.0, 1.0, 1.0]],
            space: crate::transfer::ValueSpace::Data,
        };
        let rows = integral_table(&tf, range());
        let (a, b) = (0.7, 0.7 + 1e-3);
        let table = table_integral(&rows, a, b);
        let exact = -(1.0f64 - 1e-4).ln() * 1e-3;
        // hi + lo carries ~48 bits: the relative error stays at f32's per-cell rounding.
        assert!((table - exact).abs() < 1e-4 * exact, "{table} vs {exact}");
    }

    #[test]
    fn opacity_one_is_finite_and_nearly_opaque_at_the_smallest_correction_step() {
        assert_eq!(extinction(1.0), TAU_MAX);
        assert_eq!(extinction(0.0), 0.0);
        let (_, a) = segment(&TransferFunction::grey_ramp(), range(), 1.0, 1.0, 0.125);
        assert!(a > 1.0 - 1.0 / 255.0);
    }
}
