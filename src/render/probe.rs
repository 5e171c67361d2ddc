//! What a frame measured on the GPU: timestamps around its passes and, for statistics variants,
//! its sample counters. Read back asynchronously through a small pool of buffers so that the
//! window never waits for the GPU, or synchronously for the command line and benchmarks.

use std::sync::Arc;
use std::sync::atomic::{AtomicU8, Ordering};

use crate::counters::FrameCounters;

use super::gpu_data::COUNTERS;

const FREE: u8 = 0;
const IN_FLIGHT: u8 = 1;
const MAPPED: u8 = 2;
const FAILED: u8 = 3;

/// Timestamps per frame: start and end of the frame's passes, of the transfer-function rebuild
/// (leaping structures) when the frame did one, and of the label surfaces' mask build when the
/// frame did one.
const TIMESTAMPS: u32 = 6;
/// Bytes of the timestamps.
const TIMESTAMP_BYTES: u64 = TIMESTAMPS as u64 * 8;
/// Each pair of timestamps resolves to its own offset: resolves start at multiples of this.
const RESOLVE_STRIDE: u64 = wgpu::QUERY_RESOLVE_BUFFER_ALIGNMENT;
/// Bytes of the counters (a low and a high u32 each).
const COUNTER_BYTES: u64 = COUNTERS as u64 * 8;

/// What came back for one frame.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FrameResults {
    /// Frame number the results belong to.
    pub frame: u64,
    /// GPU time from the start of the first pass to the end of the last, milliseconds (when the
    /// adapter has timestamp queries).
    pub gpu_ms: Option<f64>,
    /// Sample counters (statistics variants only).
    pub counters: Option<FrameCounters>,
    /// GPU time of the leaping structures' rebuild this frame recorded (after a transfer-function
    /// or block-size change), milliseconds.
    pub rebuild_ms: Option<f64>,
    /// GPU time of the label surfaces' mask build this frame recorded (after a toggle of the
    /// shown labels or a change of their smoothing), milliseconds.
    pub mask_ms: Option<f64>,
}

/// One set of query and read-back resources.
struct Probe {
    queries: Option<wgpu::QuerySet>,
    resolve: wgpu::Buffer,
    readback: wgpu::Buffer,
    state: Arc<AtomicU8>,
    frame: u64,
    has_counters: bool,
    has_rebuild: bool,
    has_mask: bool,
}

/// A pool of probes; the counters buffer is shared (frames using statistics are serialised by
/// the queue).
pub struct ProbePool {
    probes: Vec<Probe>,
    /// Results collected while waiting for a free probe ([`Self::acquire_or_wait`]), handed
    /// out by the next [`Self::collect`].
    ready: Vec<FrameResults>,
    /// Storage buffer the statistics variants add to.
    pub counters: wgpu::Buffer,
    timestamp_period_ns: f64,
}

/// The probe a frame records into.
pub struct ProbeSlot(usize);

/// Most frames in flight at once before the window skips measuring one.
const POOL_SIZE: usize = 4;

impl ProbePool {
    /// Creates the pool; timestamps only where `timestamps` is true.
    pub fn new(device: &wgpu::Device, queue: &wgpu::Queue, timestamps: bool) -> Self {
        let probes = (0..POOL_SIZE)
            .map(|i| Probe {
                queries: timestamps.then(|| {
                    device.create_query_set(&wgpu::QuerySetDescriptor {
                        label: Some("frame timestamps"),
                        ty: wgpu::QueryType::Timestamp,
                        count: TIMESTAMPS,
                    })
                }),
                resolve: device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("timestamp resolve"),
                    size: RESOLVE_STRIDE * u64::from(TIMESTAMPS / 2),
                    usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                    mapped_at_creation: false,
                }),
                readback: device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some(&format!("probe readback {i}")),
                    size: TIMESTAMP_BYTES + COUNTER_BYTES,
                    usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                }),
                state: Arc::new(AtomicU8::new(FREE)),
                frame: 0,
                has_counters: false,
                has_rebuild: false,
                has_mask: false,
            })
            .collect();
        let counters = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("sample counters"),
            size: COUNTER_BYTES,
            usage: wgpu::BufferUsages::STORAGE
                | wgpu::BufferUsages::COPY_SRC
                | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        Self {
            probes,
            ready: Vec::new(),
            counters,
            timestamp_period_ns: queue.get_timestamp_period() as f64,
        }
    }

    /// Takes a free probe for frame `frame`, or `None` when all are still in flight.
    pub(crate) fn acquire(&mut self, frame: u64, has_counters: bool) -> Option<ProbeSlot> {
        let index = self
            .probes
            .iter()
            .position(|p| p.state.load(Ordering::Acquire) == FREE)?;
        let probe = &mut self.probes[index];
        probe.frame = frame;
        probe.has_counters = has_counters;
        probe.has_rebuild = false;
        probe.has_mask = false;
        Some(ProbeSlot(index))
    }

    /// Takes a free probe for frame `frame`, waiting for the GPU to finish the frames in flight
    /// when none is free (their results are kept for the next [`Self::collect`]): for a frame
    /// whose measurements must not be skipped, such as the last band of a statistics frame,
    /// which alone carries the frame's counters.
    pub(crate) fn acquire_or_wait(
        &mut self,
        device: &wgpu::Device,
        frame: u64,
        has_counters: bool,
    ) -> Option<ProbeSlot> {
        if let Some(slot) = self.acquire(frame, has_counters) {
            return Some(slot);
        }
        let done = self.collect(device, true);
        self.ready.extend(done);
        self.acquire(frame, has_counters)
    }

    /// Timestamp writes for a render pass: `first` writes the start, `last` the end.
    pub(crate) fn render_timestamps(
        &self,
        slot: &ProbeSlot,
        first: bool,
        last: bool,
    ) -> Option<wgpu::RenderPassTimestampWrites<'_>> {
        let q = self.probes[slot.0].queries.as_ref()?;
        (first || last).then_some(wgpu::RenderPassTimestampWrites {
            query_set: q,
            beginning_of_pass_write_index: first.then_some(0),
            end_of_pass_write_index: last.then_some(1),
        })
    }

    /// Timestamp writes for a compute pass (always the last pass of a frame); `first` also
    /// writes the start (when it is the only pass).
    pub(crate) fn compute_timestamps(
        &self,
        slot: &ProbeSlot,
        first: bool,
    ) -> Option<wgpu::ComputePassTimestampWrites<'_>> {
        let q = self.probes[slot.0].queries.as_ref()?;
        Some(wgpu::ComputePassTimestampWrites {
            query_set: q,
            beginning_of_pass_write_index: first.then_some(0),
            end_of_pass_write_index: Some(1),
        })
    }

    /// Timestamp writes for the rebuild's compute passes: `first` writes its start, `last` its end.
    pub(crate) fn rebuild_timestamps(
        &mut self,
        slot: &ProbeSlot,
        first: bool,
        last: bool,
    ) -> Option<wgpu::ComputePassTimestampWrites<'_>> {
        self.probes[slot.0].has_rebuild = true;
        self.span_timestamps(slot, 1, (first, last))
    }

    /// Timestamp writes for the label mask build's compute passes: `first` writes its start,
    /// `last` its end.
    pub(crate) fn mask_timestamps(
        &mut self,
        slot: &ProbeSlot,
        first: bool,
        last: bool,
    ) -> Option<wgpu::ComputePassTimestampWrites<'_>> {
        self.probes[slot.0].has_mask = true;
        self.span_timestamps(slot, 2, (first, last))
    }

    /// The writes of timestamp pair `pair` (1: the rebuild's, 2: the mask's) for a pass that
    /// begins the span (`first`) or ends it (`last`).
    fn span_timestamps(
        &self,
        slot: &ProbeSlot,
        pair: u32,
        (first, last): (bool, bool),
    ) -> Option<wgpu::ComputePassTimestampWrites<'_>> {
        // A pass inside the span writes no timestamp (wgpu refuses a pass that writes neither).
        let q = self.probes[slot.0]
            .queries
            .as_ref()
            .filter(|_| first || last)?;
        Some(wgpu::ComputePassTimestampWrites {
            query_set: q,
            beginning_of_pass_write_index: first.then_some(2 * pair),
            end_of_pass_write_index: last.then_some(2 * pair + 1),
        })
    }

    /// Clears the counters before a statistics frame.
    pub(crate) fn clear_counters(&self, encoder: &mut wgpu::CommandEncoder) {
        encoder.clear_buffer(&self.counters, 0, None);
    }

    /// After the frame's passes: resolve timestamps and copy results to the read-back buffer.
    pub fn finish(&self, slot: &ProbeSlot, encoder: &mut wgpu::CommandEncoder) {
        let probe = &self.probes[slot.0];
        if let Some(q) = &probe.queries {
            // Only the pairs this frame wrote: the frame's, the rebuild's, the mask's.
            let pairs = [true, probe.has_rebuild, probe.has_mask];
            for (pair, _) in pairs.iter().enumerate().filter(|(_, w)| **w) {
                let (first, at) = (2 * pair as u32, RESOLVE_STRIDE * pair as u64);
                encoder.resolve_query_set(q, first..first + 2, &probe.resolve, at);
                encoder.copy_buffer_to_buffer(
                    &probe.resolve,
                    at,
                    &probe.readback,
                    16 * pair as u64,
                    16,
                );
            }
        }
        if probe.has_counters {
            encoder.copy_buffer_to_buffer(
                &self.counters,
                0,
                &probe.readback,
                TIMESTAMP_BYTES,
                COUNTER_BYTES,
            );
        }
    }

    /// After submission: start mapping the read-back buffer.
    pub fn submitted(&self, slot: ProbeSlot) {
        let probe = &self.probes[slot.0];
        probe.state.store(IN_FLIGHT, Ordering::Release);
        let state = probe.state.clone();
        probe
            .readback
            .map_async(wgpu::MapMode::Read, .., move |result| {
                state.store(
                    if result.is_ok() { MAPPED } else { FAILED },
                    Ordering::Release,
                );
            });
    }

    /// Whether any frame's results are still on their way.
    pub(crate) fn any_in_flight(&self) -> bool {
        self.probes
            .iter()
            .any(|p| p.state.load(Ordering::Acquire) == IN_FLIGHT)
    }

    /// Collects the results of every frame whose read-back has completed, oldest first. With
    /// `wait`, first blocks until all submitted work is done.
    pub fn collect(&mut self, device: &wgpu::Device, wait: bool) -> Vec<FrameResults> {
        let poll = if wait {
            wgpu::PollType::wait_indefinitely()
        } else {
            wgpu::PollType::Poll
        };
        if let Err(e) = device.poll(poll) {
            log::warn!("waiting for the GPU failed: {e}");
        }
        let mut results = std::mem::take(&mut self.ready);
        for probe in &mut self.probes {
            match probe.state.load(Ordering::Acquire) {
                MAPPED => {
                    let Ok(data) = probe.readback.get_mapped_range(..) else {
                        probe.readback.unmap();
                        probe.state.store(FREE, Ordering::Release);
                        continue;
                    };
                    let words: &[u32] = bytemuck::cast_slice(&data);
                    let ticks = |i: usize| words[2 * i] as u64 | (words[2 * i + 1] as u64) << 32;
                    let ms = |a: usize, b: usize| {
                        ticks(b).saturating_sub(ticks(a)) as f64 * self.timestamp_period_ns * 1e-6
                    };
                    let gpu_ms = probe.queries.as_ref().map(|_| ms(0, 1));
                    let rebuild_ms =
                        (probe.queries.is_some() && probe.has_rebuild).then(|| ms(2, 3));
                    let mask_ms = (probe.queries.is_some() && probe.has_mask).then(|| ms(4, 5));
                    let c = TIMESTAMPS as usize;
                    let counters = probe.has_counters.then(|| FrameCounters {
                        samples: ticks(c),
                        visible_samples: ticks(c + 1),
                        rays: ticks(c + 2),
                        leaps: ticks(c + 3),
                        leapt_samples: ticks(c + 4),
                        lookups: ticks(c + 5),
                        shadow_rays: ticks(c + 6),
                        shadow_samples: ticks(c + 7),
                    });
                    drop(data);
                    probe.readback.unmap();
                    probe.state.store(FREE, Ordering::Release);
                    results.push(FrameResults {
                        frame: probe.frame,
                        gpu_ms,
                        counters,
                        rebuild_ms,
                        mask_ms,
                    });
                }
                FAILED => {
                    probe.state.store(FREE, Ordering::Release);
                }
                _ => {}
            }
        }
        results.sort_by_key(|r| r.frame);
        results
    }
}
