//! GPU time of the slice pass, from timestamp queries around each of `repeats` passes (the
//! median), for `leapview slice --repeat` and the cost figures of the slice views. A timed pass
//! may hold several slices: its time over their number is what one more slice adds to a
//! command buffer, without the fixed cost of a pass between two timestamps.

use super::{Output, SliceError, SliceRenderer, SliceSource};
use crate::render::context::GpuContext;
use crate::render::gpu_data::SliceParams;
use crate::render::readback::read_buffer;

impl SliceRenderer {
    /// Runs `repeats` passes between two timestamps each, every pass drawing the slice of
    /// `params` from `source` into `output` `per_pass` times; the median GPU time of a pass
    /// over `per_pass`, in milliseconds, `None` when the adapter has no timestamp queries.
    pub fn median_gpu_ms(
        &self,
        ctx: &GpuContext,
        source: SliceSource<'_>,
        output: Output<'_>,
        params: &SliceParams,
        repeats: u32,
        per_pass: u32,
    ) -> Result<Option<f64>, SliceError> {
        if !ctx.has_timestamps() || repeats == 0 || per_pass == 0 {
            return Ok(None);
        }
        let count = repeats.min(1024) * 2;
        let queries = ctx.device.create_query_set(&wgpu::QuerySetDescriptor {
            label: Some("slice timestamps"),
            ty: wgpu::QueryType::Timestamp,
            count,
        });
        let bytes = u64::from(count) * 8;
        let resolve = ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("slice timestamps"),
            size: bytes,
            usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let (pipeline, group) = self.prepare(&ctx.device, &ctx.queue, source, output, params);
        let mut encoder = ctx
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("slice timing"),
            });
        for r in 0..count / 2 {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("slice"),
                timestamp_writes: Some(wgpu::ComputePassTimestampWrites {
                    query_set: &queries,
                    beginning_of_pass_write_index: Some(2 * r),
                    end_of_pass_write_index: Some(2 * r + 1),
                }),
            });
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, &group, &[]);
            let [x, y] = super::dispatch(params);
            for _ in 0..per_pass {
                pass.dispatch_workgroups(x, y, 1);
            }
        }
        encoder.resolve_query_set(&queries, 0..count, &resolve, 0);
        ctx.queue.submit([encoder.finish()]);
        let raw = read_buffer(ctx, &resolve, bytes).map_err(SliceError::Readback)?;
        let ticks: Vec<u64> = raw
            .chunks_exact(8)
            .map(|b| u64::from_le_bytes([b[0], b[1], b[2], b[3], b[4], b[5], b[6], b[7]]))
            .collect();
        let period_ns = f64::from(ctx.queue.get_timestamp_period());
        let mut ms: Vec<f64> = ticks
            .chunks_exact(2)
            .map(|t| t[1].saturating_sub(t[0]) as f64 * period_ns / 1e6 / f64::from(per_pass))
            .collect();
        ms.sort_by(f64::total_cmp);
        Ok(ms.get(ms.len() / 2).copied())
    }
}
