//! The frames' measurements: the probes that carry GPU timestamps and sample counters back, the
//! statistics variants' bind group, and the count of what the renderer did.

use crate::render::context::GpuContext;
use crate::render::probe::{ProbePool, ProbeSlot};

use super::leap::Builds;
use super::request::WorkCounts;

/// The frames' measurements: GPU timestamps and counters, the statistics variants' group, and
/// what was done so far.
pub(super) struct Measurements {
    pub(super) probes: ProbePool,
    pub(super) stats_group: wgpu::BindGroup,
    pub(super) frames_submitted: u64,
    pub(super) work: WorkCounts,
}

impl Measurements {
    /// Counts a new submission and takes a probe for it (none when all are in flight); clears
    /// the counters of a statistics frame when `first` (the first band of a frame rendered in
    /// bands: the counters add up over its bands). The `last` band of a statistics frame
    /// carries the frame's counters, so it waits for a probe rather than go without.
    pub(super) fn begin(
        &mut self,
        device: &wgpu::Device,
        stats: bool,
        [first, last]: [bool; 2],
        encoder: &mut wgpu::CommandEncoder,
    ) -> Option<ProbeSlot> {
        self.frames_submitted += 1;
        self.work.frames += 1;
        if stats && first {
            self.probes.clear_counters(encoder);
        }
        if stats && last {
            self.probes
                .acquire_or_wait(device, self.frames_submitted, stats)
        } else {
            self.probes.acquire(self.frames_submitted, stats)
        }
    }

    /// Counts what the leaping structures' preparation built.
    pub(super) fn count_builds(&mut self, builds: Builds) {
        self.work.minmax_builds += u64::from(builds.minmax);
        self.work.minmax_brick_builds += u64::from(builds.minmax_bricks);
        self.work.flag_builds += u64::from(builds.flags);
        self.work.distance_builds += u64::from(builds.distance);
        self.work.label_flag_builds += u64::from(builds.labels);
    }

    /// Resolves the frame's probe into its read-back buffer, submits, and starts the read-back.
    pub(super) fn submit(
        &mut self,
        ctx: &GpuContext,
        mut encoder: wgpu::CommandEncoder,
        slot: Option<ProbeSlot>,
    ) {
        if let Some(s) = &slot {
            self.probes.finish(s, &mut encoder);
        }
        ctx.queue.submit([encoder.finish()]);
        if let Some(s) = slot {
            self.probes.submitted(s);
        }
    }
}
