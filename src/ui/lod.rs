//! Interaction level of detail: while the user drags, a frame that would miss the frame budget is
//! rendered at a lower resolution (and shown stretched), chosen from the GPU time per pixel of
//! the frames before; once the pointer has been still for [`STILL_AFTER`], the view is rendered
//! again at full resolution. The image left on screen is therefore always full quality, and
//! saved images and screenshots never use a reduced frame.
//!
//! The cost model is the simplest that holds for a ray caster: GPU time proportional to the
//! pixels rendered (each pixel is one ray), measured from the last frames' timestamp queries.

use std::collections::VecDeque;
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

/// Frames remembered while their GPU times are on their way.
const PENDING: usize = 16;

/// The cost per pixel, learnt from frames as their GPU times arrive.
#[derive(Clone, Debug, Default)]
pub struct Lod {
    /// Frames submitted and not yet measured: (frame number, pixels).
    pending: VecDeque<(u64, u64)>,
    /// GPU milliseconds per megapixel of the last measured frame.
    ms_per_megapixel: Option<f64>,
}

impl Lod {
    /// Remembers that `frame` renders `pixels` pixels.
    pub fn submitted(&mut self, frame: u64, pixels: u64) {
        self.pending.push_back((frame, pixels));
        while self.pending.len() > PENDING {
            self.pending.pop_front();
        }
    }

    /// Takes the GPU time of `frame`.
    pub fn measured(&mut self, frame: u64, gpu_ms: f64) {
        while let Some(&(f, pixels)) = self.pending.front() {
            if f > frame {
                break;
            }
            self.pending.pop_front();
            if f == frame && pixels > 0 && gpu_ms.is_finite() && gpu_ms >= 0.0 {
                self.ms_per_megapixel = Some(gpu_ms / (pixels as f64 * 1e-6));
            }
        }
    }

    /// Forgets the cost (a new volume or other settings make the old one meaningless).
    pub fn forget(&mut self) {
        self.ms_per_megapixel = None;
    }

    /// Predicted GPU milliseconds of a frame of `size` pixels, once a frame was measured.
    pub fn predicted_ms(&self, size: [u32; 2]) -> Option<f64> {
        let megapixels = f64::from(size[0]) * f64::from(size[1]) * 1e-6;
        self.ms_per_megapixel.map(|c| c * megapixels)
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
        ((ideal / SCALE_QUANTUM).floor() * SCALE_QUANTUM).clamp(MIN_SCALE, 1.0)
    }
}

/// `size` scaled by `scale` per axis, at least one pixel.
pub fn scaled_size(size: [u32; 2], scale: f64) -> [u32; 2] {
    size.map(|s| ((f64::from(s) * scale).round() as u32).clamp(1, s.max(1)))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn measured(ms_per_frame: f64, size: [u32; 2]) -> Lod {
        let mut lod = Lod::default();
        lod.submitted(1, u64::from(size[0]) * u64::from(size[1]));
        lod.measured(1, ms_per_frame);
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
    fn results_match_their_frames() {
        let mut lod = Lod::default();
        lod.submitted(1, 1_000_000);
        lod.submitted(2, 250_000);
        // Frame 1's result never came; frame 2's says 4 ms for a quarter megapixel.
        lod.measured(2, 4.0);
        assert_eq!(lod.predicted_ms([1000, 1000]), Some(16.0));
        // A late or unknown frame changes nothing.
        lod.measured(1, 1000.0);
        lod.measured(7, f64::NAN);
        assert_eq!(lod.predicted_ms([1000, 1000]), Some(16.0));
    }

    #[test]
    fn scaled_sizes_stay_positive() {
        assert_eq!(scaled_size([801, 601], 0.5), [401, 301]);
        assert_eq!(scaled_size([3, 1], 0.25), [1, 1]);
        assert_eq!(scaled_size([640, 480], 1.0), [640, 480]);
    }
}
