//! What a frame counted: samples taken, samples that could change the pixel, rays, leaps, the
//! grid samples leapt and the leaping structure's lookups. Filled by the GPU's statistics
//! variants (`render::probe`) and by the CPU reference ray caster (`reference`), so the two are
//! compared in one type.

/// Per-frame sample statistics (a GPU statistics variant's, or the CPU reference's, which does
/// not leap and leaves `leaps`, `leapt_samples` and `lookups` at 0).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct FrameCounters {
    /// Samples taken (volume reads classified through the transfer function).
    pub samples: u64,
    /// Samples whose transfer-function opacity was non-zero.
    pub visible_samples: u64,
    /// Rays cast (pixels whose ray met the volume).
    pub rays: u64,
    /// Empty regions leapt over (RC-s).
    pub leaps: u64,
    /// Grid samples skipped by leaping (RC-s): with the samples taken, what RC-t takes (MIP and
    /// MinIP also take up to five samples per ray before the march, to prime their leaping).
    pub leapt_samples: u64,
    /// Questions the leaping loop asked of its structure (RC-s): one per leaf block, or cube of
    /// blocks with the distance field, entered; the octree's climb to a coarser empty node
    /// counts as one. What leaping pays for the samples it removes.
    pub lookups: u64,
    /// Shadow rays marched towards a directional light (one per lit sample with shadows on).
    pub shadow_rays: u64,
    /// Samples the shadow rays took (leapt ones not counted).
    pub shadow_samples: u64,
}

impl FrameCounters {
    /// Samples per pixel of a `size` image (frames' counters summed: per pixel and frame
    /// when `frames` > 1).
    pub fn samples_per_pixel(&self, size: [u32; 2], frames: usize) -> f64 {
        let pixels = size[0] as f64 * size[1] as f64 * frames.max(1) as f64;
        self.samples as f64 / pixels.max(1.0)
    }

    /// Samples taken over the samples with non-zero opacity (the oracle a perfect leaping
    /// scheme would take); 1 means no sample was wasted. `None` when nothing was visible.
    pub(crate) fn oracle_ratio(&self) -> Option<f64> {
        (self.visible_samples > 0).then(|| self.samples as f64 / self.visible_samples as f64)
    }

    /// Adds `other`'s counts (to total several frames).
    pub fn add(&mut self, other: &Self) {
        self.samples += other.samples;
        self.visible_samples += other.visible_samples;
        self.rays += other.rays;
        self.leaps += other.leaps;
        self.leapt_samples += other.leapt_samples;
        self.lookups += other.lookups;
        self.shadow_rays += other.shadow_rays;
        self.shadow_samples += other.shadow_samples;
    }

    /// Share of the grid samples before each ray's end that leaping skipped (0 without
    /// leaping); `None` when no ray had a sample.
    pub fn share_leapt(&self) -> Option<f64> {
        let grid = self.samples + self.leapt_samples;
        (grid > 0).then(|| self.leapt_samples as f64 / grid as f64)
    }
}
