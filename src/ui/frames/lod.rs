//! Interaction level of detail: while the user drags, a frame that would miss the frame budget is
//! rendered at a lower resolution (and shown stretched), chosen from the time per pixel of the
//! frames before; once the pointer has been still for [`STILL_AFTER`], the view is rendered
//! again at full resolution. The image left on screen is therefore always full quality, and
//! saved images and screenshots never use a reduced frame.
//!
//! The cost model is the simplest that holds for a ray caster: time proportional to the pixels
//! rendered (each pixel is one ray). The time is the wall-clock time from a band's submission to
//! its completion as the window sees it, not the GPU's timestamps: what the user waits for is
//! the whole frame, including what the timestamps do not see (the queue, the window's own
//! drawing, a CPU driver's scheduling). The same model sizes the bands a frame is rendered in
//! ([`crate::ui::frames::frame_job`]).

use std::time::Duration;

/// Frame time to stay under while interacting: one 60 Hz refresh.
pub const BUDGET_MS: f64 = 16.0;

/// Pointer stillness after which the view is refined to full resolution.
pub const STILL_AFTER: Duration = Duration::from_millis(120);

/// Smallest resolution scale (per axis): below a quarter, the preview no longer shows what the
/// user is adjusting.
pub const MIN_SCALE: f64 = 0.25;

/// Scales are multiples of this (per axis), so the output texture is not reallocated for every
/// small change of the measured cost.
const SCALE_QUANTUM: f64 = 0.125;

/// How much a new measurement counts against the ones before (an exponential average: one
/// slow band, a pass the system delayed, does not halve the resolution at once).
const NEW_WEIGHT: f64 = 0.5;

/// Horizontal strips of the view the cost is learnt for: a ray caster's cost per pixel varies
/// from row to row by a factor of 50 and more (empty background against a head), so one number
/// for the whole view sizes bands badly (seen on lavapipe: after cheap rows, a band of 296 rows
/// of the head was predicted at 16 ms and took 1050).
pub const STRIPS: usize = 128;

/// Rows of a band when nothing is known of the rows it covers.
pub const UNKNOWN_BAND_ROWS: u32 = 64;

/// The cost per pixel of each horizontal strip of the view, learnt from bands as they complete,
/// in milliseconds from submission to completion.
#[derive(Clone, Debug)]
pub struct Lod {
    /// Milliseconds per pixel of each strip (top to bottom), where measured.
    strips: Vec<Option<f64>>,
}

impl Default for Lod {
    fn default() -> Self {
        Self {
            strips: vec![None; STRIPS],
        }
    }
}

/// The strips a row range covers in an image `height` rows high.
fn strips_of(rows: [u32; 2], height: u32) -> std::ops::Range<usize> {
    let h = f64::from(height.max(1));
    let first = (f64::from(rows[0]) / h * STRIPS as f64).floor() as usize;
    let end = (f64::from(rows[1]) / h * STRIPS as f64).ceil() as usize;
    first.min(STRIPS - 1)..end.clamp(first + 1, STRIPS)
}

impl Lod {
    /// Takes a measurement: rows `rows` of a frame of `size` pixels took `ms` milliseconds from
    /// submission to completion.
    pub(crate) fn observe(&mut self, size: [u32; 2], rows: [u32; 2], ms: f64) {
        let pixels = f64::from(size[0]) * f64::from(rows[1].saturating_sub(rows[0]));
        if pixels == 0.0 || !ms.is_finite() || ms < 0.0 {
            return;
        }
        let cost = ms / pixels;
        for strip in &mut self.strips[strips_of(rows, size[1])] {
            *strip = Some(match *strip {
                Some(old) => old + NEW_WEIGHT * (cost - old),
                None => cost,
            });
        }
    }

    /// The cost per pixel of row `row` of an image `height` rows high: its strip's, or, where
    /// that was never measured, the dearest strip's (a band is never sized on hope).
    fn row_cost(&self, row: u32, height: u32) -> Option<f64> {
        let strip = strips_of([row, row + 1], height).start;
        self.strips[strip].or_else(|| self.strips.iter().flatten().copied().reduce(f64::max))
    }

    /// The end of a band starting at row `first` of a frame of `size` pixels that takes about
    /// `budget_ms`, by the costs learnt (whole multiples of `quantum` rows, at least one; at
    /// most the image; [`UNKNOWN_BAND_ROWS`] when nothing was measured).
    pub fn band_end(&self, size: [u32; 2], first: u32, budget_ms: f64, quantum: u32) -> u32 {
        let [width, height] = size;
        let quantum = quantum.max(1);
        let mut end = first;
        let mut ms = 0.0;
        while end < height {
            let Some(cost) = self.row_cost(end, height) else {
                return (first + UNKNOWN_BAND_ROWS).min(height);
            };
            let next = (end + quantum).min(height);
            let more = cost * f64::from(width) * f64::from(next - end);
            // (A relative 1e-9 forgives the rounding of the sum.)
            if end > first && ms + more > budget_ms * (1.0 + 1e-9) {
                break;
            }
            ms += more;
            end = next;
        }
        end.max((first + 1).min(height))
    }

    /// Forgets the cost (a new volume or other settings make the old one meaningless).
    pub(crate) fn forget(&mut self) {
        self.strips.fill(None);
    }

    /// Predicted milliseconds of a frame of `size` pixels, once a band was measured.
    pub(crate) fn predicted_ms(&self, size: [u32; 2]) -> Option<f64> {
        let [width, height] = size;
        (0..height)
            .map(|row| self.row_cost(row, height).map(|c| c * f64::from(width)))
            .sum()
    }

    /// Resolution scale (per axis) for a frame of `size` pixels: 1 when still or when the frame
    /// fits the budget (or nothing was measured yet), else the largest quantised scale whose
    /// predicted time fits it, at least [`MIN_SCALE`].
    pub fn scale(&self, size: [u32; 2], interacting: bool) -> f64 {
        let Some(ms) = self.predicted_ms(size).filter(|_| interacting) else {
            return 1.0;
        };
        if ms <= BUDGET_MS {
            return 1.0;
        }
        let ideal = (BUDGET_MS / ms).sqrt();
        // (1e-9 forgives the rounding of the predicted sum.)
        ((ideal / SCALE_QUANTUM + 1e-9).floor() * SCALE_QUANTUM).clamp(MIN_SCALE, 1.0)
    }
}

/// `size` scaled by `scale` per axis, at least one pixel.
pub(crate) fn scaled_size(size: [u32; 2], scale: f64) -> [u32; 2] {
    size.map(|s| ((f64::from(s) * scale).round() as u32).clamp(1, s.max(1)))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn measured(ms_per_frame: f64, size: [u32; 2]) -> Lod {
        let mut lod = Lod::default();
        lod.observe(size, [0, size[1]], ms_per_frame);
        lod
    }

    #[test]
    fn fast_frames_and_still_views_keep_full_resolution() {
        let lod = measured(5.0, [1000, 1000]);
        assert_eq!(lod.scale([1000, 1000], true), 1.0);
        let slow = measured(400.0, [1000, 1000]);
        assert_eq!(slow.scale([1000, 1000], false), 1.0, "still: full quality");
        assert_eq!(
            Lod::default().scale([1000, 1000], true),
            1.0,
            "nothing measured"
        );
    }

    #[test]
    fn slow_frames_drop_to_the_budget_and_not_below_a_quarter() {
        // 64 ms at full size: a quarter of the pixels (scale ½) takes 16 ms.
        let lod = measured(64.0, [800, 600]);
        assert_eq!(lod.scale([800, 600], true), 0.5);
        let predicted = lod
            .predicted_ms(scaled_size([800, 600], 0.5))
            .expect("measured");
        assert!(predicted <= BUDGET_MS + 1e-9, "{predicted}");
        // 40 ms: ideal 0.632, quantised down to 0.625.
        assert_eq!(measured(40.0, [800, 600]).scale([800, 600], true), 0.625);
        // Far too slow: the floor.
        assert_eq!(
            measured(5000.0, [800, 600]).scale([800, 600], true),
            MIN_SCALE
        );
    }

    #[test]
    fn the_cost_learnt_from_a_reduced_frame_predicts_the_full_one() {
        // A reduced frame (400×300) took 16 ms: the full 800×600 frame would take 64.
        let lod = measured(16.0, [400, 300]);
        let full = lod.predicted_ms([800, 600]).expect("measured");
        assert!((full - 64.0).abs() < 1e-9, "{full}");
        assert_eq!(lod.scale([800, 600], true), 0.5);
    }

    #[test]
    fn measurements_are_averaged_and_nonsense_is_ignored() {
        let mut lod = Lod::default();
        // A quarter megapixel in 4 ms: 16 ms per megapixel.
        lod.observe([1000, 250], [0, 250], 4.0);
        assert_close(lod.predicted_ms([1000, 1000]), 16.0);
        // One frame at 48 ms per megapixel moves the estimate halfway.
        lod.observe([1000, 1000], [0, 1000], 48.0);
        assert_close(lod.predicted_ms([1000, 1000]), 32.0);
        lod.observe([1000, 1000], [5, 5], 5.0);
        lod.observe([1000, 1000], [0, 10], f64::NAN);
        lod.observe([1000, 1000], [0, 10], -1.0);
        assert_close(lod.predicted_ms([1000, 1000]), 32.0);
    }

    fn assert_close(got: Option<f64>, want: f64) {
        let got = got.expect("measured");
        assert!(
            (got - want).abs() < 1e-9 * want.max(1.0),
            "{got} against {want}"
        );
    }

    #[test]
    fn bands_follow_the_cost_of_their_rows() {
        // 800×800: the top half is empty (0.1 µs a pixel), the bottom half a head (4 µs).
        let mut lod = Lod::default();
        lod.observe([800, 800], [0, 400], 0.0001 * 800.0 * 400.0);
        lod.observe([800, 800], [400, 800], 0.004 * 800.0 * 400.0);
        // A 16 ms band of head rows: 16 / (0.004 × 800) = 5 rows, one workgroup of 8 at least.
        assert_eq!(lod.band_end([800, 800], 400, 16.0, 8), 408);
        // From the empty top: 0.08 ms a row, 200 rows in 16 ms.
        assert_eq!(lod.band_end([800, 800], 0, 16.0, 8), 200);
        // With 40 ms it reaches the head (32 ms) and stops there: its first 8 rows would add 26.
        assert_eq!(lod.band_end([800, 800], 0, 40.0, 8), 400);
        // The same strips predict a preview at half the size: a quarter of the time.
        let full = lod.predicted_ms([800, 800]).expect("measured");
        let half = lod.predicted_ms([400, 400]).expect("measured");
        assert!((half - full / 4.0).abs() < 1e-6 * full, "{half} {full}");
    }

    #[test]
    fn rows_never_measured_cost_what_the_dearest_strip_costs() {
        let mut lod = Lod::default();
        assert_eq!(lod.band_end([640, 480], 0, 16.0, 8), UNKNOWN_BAND_ROWS);
        assert_eq!(lod.band_end([640, 40], 0, 16.0, 8), 40);
        // Only the top rows measured, cheap: the unknown rest is taken as dear as they are.
        lod.observe([640, 480], [0, 60], 0.001 * 640.0 * 60.0);
        assert_eq!(lod.band_end([640, 480], 240, 16.0, 8), 264);
        // Nothing beyond the image, and never an empty band.
        assert_eq!(lod.band_end([640, 480], 476, 1000.0, 8), 480);
        assert_eq!(lod.band_end([640, 480], 0, 0.0, 8), 8);
        lod.forget();
        assert_eq!(lod.predicted_ms([640, 480]), None);
    }

    #[test]
    fn scaled_sizes_stay_positive() {
        assert_eq!(scaled_size([801, 601], 0.5), [401, 301]);
        assert_eq!(scaled_size([3, 1], 0.25), [1, 1]);
        assert_eq!(scaled_size([640, 480], 1.0), [640, 480]);
    }
}
