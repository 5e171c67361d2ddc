//! Recording one frame's ray-casting passes: on the fragment path the back faces into exit
//! points, then the front faces (and the near-plane cap) running the ray loop; on the compute
//! path one dispatch over the image, each invocation intersecting its ray with the box.

use crate::render::gpu_data::WORKGROUP;
use crate::render::probe::{ProbePool, ProbeSlot};

use super::pipelines::{FramePipelines, RaycastPipeline};
use super::targets::Targets;

/// Vertices of the proxy cube (12 triangles).
const CUBE_VERTICES: u32 = 36;
/// Vertices of the cube and the near-plane cap (one full-screen triangle).
const CUBE_AND_CAP_VERTICES: u32 = 39;

/// What one frame's passes bind and draw.
pub struct RaycastPasses<'a> {
    /// The frame's pipelines.
    pub pipelines: FramePipelines<'a>,
    /// Group 0: uniforms, volume and tables.
    pub frame_group: &'a wgpu::BindGroup,
    /// The frame's textures and group 1.
    pub targets: &'a Targets,
    /// Group 2, for statistics variants.
    pub stats_group: Option<&'a wgpu::BindGroup>,
    /// Group 3, for leaping variants.
    pub leap_group: Option<&'a wgpu::BindGroup>,
    /// Whether the near plane cuts the box, so the fragment path also draws the near-plane cap.
    pub near_cap: bool,
    /// Linear RGB behind the volume.
    pub background: [f64; 3],
    /// The image rows to render, `[first, end)`: all of them, or one band of a frame rendered
    /// in bands (the compute path's uniforms carry the first row).
    pub rows: [u32; 2],
    /// Pixel rows per workgroup of the compute path: `WORKGROUP`, or `SPLIT_GROUP_ROWS` where
    /// the variant splits rays (`PipelineKey::split`).
    pub group_rows: u32,
}

impl RaycastPasses<'_> {
    /// Records the passes into `encoder`, timed into `probe` when given.
    pub fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        probe: Option<(&ProbePool, &ProbeSlot)>,
    ) {
        match self.pipelines.raycast {
            RaycastPipeline::Fragment(raycast) => self.record_fragment(encoder, raycast, probe),
            RaycastPipeline::Compute(raycast) => {
                let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some("ray cast"),
                    timestamp_writes: probe.and_then(|(p, s)| p.compute_timestamps(s, true)),
                });
                pass.set_pipeline(raycast);
                pass.set_bind_group(0, self.frame_group, &[]);
                pass.set_bind_group(1, &self.targets.compute_io, &[]);
                self.set_optional_groups(|index, group| pass.set_bind_group(index, group, &[]));
                let width = self.targets.size[0];
                let height = self.rows[1] - self.rows[0];
                pass.dispatch_workgroups(
                    width.div_ceil(WORKGROUP),
                    height.div_ceil(self.group_rows),
                    1,
                );
            }
        }
    }

    /// Pass 1 (back faces → exit points), then pass 2 (front faces and cap run the ray loop),
    /// both cut to the band's rows. The output is cleared to the background by the first band
    /// only, so that later bands add to it; exit points are drawn anew for each band.
    fn record_fragment(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        raycast: &wgpu::RenderPipeline,
        probe: Option<(&ProbePool, &ProbeSlot)>,
    ) {
        let timestamps = |first, last| probe.and_then(|(p, s)| p.render_timestamps(s, first, last));
        let [width, _] = self.targets.size;
        let [first, end] = self.rows;
        {
            let mut pass = begin_pass(
                encoder,
                &self.targets.exit,
                Some(wgpu::Color::TRANSPARENT),
                timestamps(true, false),
                "exit points",
            );
            pass.set_scissor_rect(0, first, width, end - first);
            pass.set_pipeline(self.pipelines.exit);
            pass.set_bind_group(0, self.frame_group, &[]);
            pass.draw(0..CUBE_VERTICES, 0..1);
        }
        let [r, g, b] = self.background;
        let background = wgpu::Color { r, g, b, a: 1.0 };
        let mut pass = begin_pass(
            encoder,
            &self.targets.output_view,
            (first == 0).then_some(background),
            timestamps(false, true),
            "ray cast",
        );
        pass.set_scissor_rect(0, first, width, end - first);
        pass.set_pipeline(raycast);
        pass.set_bind_group(0, self.frame_group, &[]);
        pass.set_bind_group(1, &self.targets.fragment_io, &[]);
        self.set_optional_groups(|index, group| pass.set_bind_group(index, group, &[]));
        let vertices = if self.near_cap {
            CUBE_AND_CAP_VERTICES
        } else {
            CUBE_VERTICES
        };
        pass.draw(0..vertices, 0..1);
    }

    /// Binds groups 2 (statistics) and 3 (leaping) where the variant has them.
    fn set_optional_groups(&self, mut set: impl FnMut(u32, &wgpu::BindGroup)) {
        if let Some(group) = self.stats_group {
            set(2, group);
        }
        if let Some(group) = self.leap_group {
            set(3, group);
        }
    }
}

/// A render pass into `view`, cleared to `clear` first (kept as it is for `None`).
fn begin_pass<'e>(
    encoder: &'e mut wgpu::CommandEncoder,
    view: &wgpu::TextureView,
    clear: Option<wgpu::Color>,
    timestamps: Option<wgpu::RenderPassTimestampWrites<'_>>,
    label: &str,
) -> wgpu::RenderPass<'e> {
    encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some(label),
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations {
                load: clear.map_or(wgpu::LoadOp::Load, wgpu::LoadOp::Clear),
                store: wgpu::StoreOp::Store,
            },
        })],
        depth_stencil_attachment: None,
        timestamp_writes: timestamps,
        occlusion_query_set: None,
        multiview_mask: None,
    })
}
