//! Slice views on the GPU: one compute pass samples the volume texture (the ray caster's own,
//! `VolumeRenderer::volume_texture`) at each pixel's voxel coordinates. Its exact variant writes
//! the value (data units, f32, trilinear with exact weights) and its grey through the window to
//! buffers ([`SliceTarget`]); its display variant, what the window shows and `leapview slice`
//! writes, samples with the texture unit's filter (as the ray caster does) and writes only the
//! grey, into a texture ([`DisplayTarget`]). Thick slabs leap over the [`SliceBricks`] that
//! cannot change them. The pixel grid is the pure `mpr::SliceView::voxel_grid`; the f64 twin
//! is `reference::slice`.

mod bricks;
mod targets;
mod timing;

pub use bricks::SliceBricks;
pub use targets::{DisplayTarget, SliceTarget};

use crate::mpr::{PatientFrame, Slab, SlabMode, SliceView};
use crate::transfer::TransferFunction;
use crate::transfer::lut::{LUT_SIZE, slice_colours};
use crate::volume::Volume;

use super::context::GpuContext;
use super::gpu_data::{SLAB_MEAN, SLAB_MINIP, SLAB_MIP, SliceParams, WORKGROUP};
use super::labels::GpuLabels;
use super::shader::{ShaderError, compose, compute_pipeline, shader_module};
use super::table_texture::TableTexture;
use super::volume_texture::{PerLayout, VolumeTexture, VolumeView, texel_units};

/// How a view is sampled and shown.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SliceLook {
    /// The window (data units): grey 0 at the low end, 255 at the high end.
    pub window: [f64; 2],
    /// The nearest voxel instead of trilinear interpolation.
    pub nearest: bool,
    /// A thick slab instead of a thin slice.
    pub slab: Option<Slab>,
    /// Whether a slab skips the bricks that cannot change it (it does where the pass is given
    /// bricks; off, it takes every sample: the comparison the cost figures make).
    pub leap: bool,
    /// Blend the transfer function's colour over the grey by its opacity (the display variant,
    /// where the pass is given a colour table; the exact one writes grey).
    pub colour: bool,
    /// Grey from white at the window's low end to black at its high end (DICOM MONOCHROME1,
    /// `Provenance::invert_grey`, or the user's choice).
    pub invert: bool,
    /// How labels are drawn over the image, where the pass is given them (the display variant).
    pub labels: LabelLook,
}

/// How a slice shows labels: filled at an opacity, with or without their outlines.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LabelLook {
    /// How opaque the fill is, 0…1 (0: outlines only, where on).
    pub opacity: f32,
    /// Each label's outline drawn opaque.
    pub outline: bool,
}

impl Default for LabelLook {
    /// Half opaque, with outlines: the image shows through, the boundaries stay sharp.
    fn default() -> Self {
        Self {
            opacity: 0.5,
            outline: true,
        }
    }
}

/// The parameters of one view's pass: the view's pixel grid in `frame`'s voxel coordinates, the
/// texels' encoding and the window. `pitch`: u32 words per image row of a [`SliceTarget`]
/// (unused by a [`DisplayTarget`]).
pub fn slice_params(
    view: &SliceView,
    frame: &PatientFrame,
    volume: &Volume,
    format: wgpu::TextureFormat,
    look: SliceLook,
    pitch: u32,
) -> SliceParams {
    let grid = view.voxel_grid(frame);
    let v4 = |v: glam::DVec3| [v.x as f32, v.y as f32, v.z as f32, 0.0];
    let (texel_max, unit_scale, unit_bias) = texel_units(volume, format);
    let normal = view.plane.normal();
    let (slab_count, slab_step_mm) = look.slab.map_or((1, 0.0), |s| s.samples(frame, normal));
    let slab_step = frame.axes().inverse() * (normal * slab_step_mm);
    let slab_mode = match look.slab.map(|s| s.mode) {
        Some(SlabMode::MinIp) => SLAB_MINIP,
        Some(SlabMode::Mean) => SLAB_MEAN,
        _ => SLAB_MIP,
    };
    SliceParams {
        first: v4(grid.first),
        step_x: v4(grid.step_x),
        step_y: v4(grid.step_y),
        slab_step: v4(slab_step),
        width: view.size[0],
        height: view.size[1],
        nearest: u32::from(look.nearest),
        pitch,
        texel_max: texel_max as f32,
        unit_scale: unit_scale as f32,
        unit_bias: unit_bias as f32,
        window_lo: look.window[0] as f32,
        window_hi: look.window[1] as f32,
        slab_count,
        slab_mode,
        leap: u32::from(look.leap && look.slab.is_some()),
        colour: u32::from(look.colour),
        colour_lo: volume.normalization_range().min as f32,
        colour_hi: volume.normalization_range().max as f32,
        invert: u32::from(look.invert),
        volume_colour: u32::from(volume.colour().is_some()),
        // Set by the pass from the labels it is given.
        labels: 0,
        label_opacity: look.labels.opacity.clamp(0.0, 1.0),
        label_outline: u32::from(look.labels.outline),
        // Set by the pass from the labels it is given.
        label_bricks: 0,
        _pad0: 0,
        _pad1: 0,
        _pad2: 0,
    }
}

/// A slice read back to the CPU.
#[derive(Clone, Debug, PartialEq)]
pub struct SliceImage {
    /// Width and height in pixels.
    pub size: [u32; 2],
    /// The value of each pixel (data units, f32; NaN outside the volume or where a sample is
    /// missing), row-major, row 0 at the top.
    pub values: Vec<f32>,
    /// The grey level of each pixel through the window.
    pub grey: Vec<u8>,
}

/// Rows of pixels each invocation of a thin slice shades: four measured about twice as fast as
/// one at 1080p, while a slab's samples keep one row per invocation busy and four made it slower
/// (docs/benchmarks/README.md, "Figures moved from code comments").
const THIN_ROWS_PER_INVOCATION: u32 = 4;

/// The workgroups of the pass of `params`: one invocation per column and band of rows.
pub(crate) fn dispatch(params: &SliceParams) -> [u32; 2] {
    let rows = if params.slab_count > 1 {
        1
    } else {
        THIN_ROWS_PER_INVOCATION
    };
    [
        params.width.div_ceil(WORKGROUP),
        params.height.div_ceil(WORKGROUP * rows),
    ]
}

/// What a pass samples: the volume texture and, for a leaping slab, its bricks.
#[derive(Clone, Copy)]
pub struct SliceSource<'a> {
    /// The volume (the ray caster's: one filterable texture or bricks).
    pub texture: &'a VolumeView,
    /// The volume's bricks; without them a slab takes every sample.
    pub bricks: Option<&'a SliceBricks>,
    /// The transfer function's colours over the volume's value range
    /// ([`SliceRenderer::colour_table`]); without them the display variant writes grey.
    pub colours: Option<&'a TableTexture>,
    /// Labels over the image (the display variant); without them, none.
    pub labels: Option<&'a GpuLabels>,
}

/// Where a pass writes, which also picks its variant.
#[derive(Clone, Copy)]
pub enum Output<'a> {
    /// Values and grey to buffers; trilinear with exact weights.
    Exact(&'a SliceTarget),
    /// Grey into a texture; trilinear by the texture unit.
    Display(&'a DisplayTarget),
}

impl Output<'_> {
    fn params(&self) -> &wgpu::Buffer {
        match self {
            Output::Exact(t) => &t.params,
            Output::Display(t) => &t.params,
        }
    }
}

/// The sampling pass's two variants and the bricks' builder, compiled once per device.
pub struct SliceRenderer {
    exact: PerLayout<wgpu::ComputePipeline>,
    display: PerLayout<wgpu::ComputePipeline>,
    bricks_pipeline: PerLayout<wgpu::ComputePipeline>,
    /// The display variant's trilinear sampler (clamp to edge).
    linear: wgpu::Sampler,
    /// Bound in place of bricks where there are none (the pass then takes every sample).
    no_bricks: wgpu::Buffer,
    /// Bound in place of a colour table where there is none.
    no_colours: TableTexture,
    /// Bound in place of labels where there are none.
    no_labels: super::labels::NoLabels,
}

/// Why a slice could not be drawn.
#[derive(Debug, thiserror::Error)]
pub enum SliceError {
    /// The slice shader does not compose (a bug in `shaders/`).
    #[error(transparent)]
    Shader(#[from] ShaderError),
    /// The image is larger than the device's buffers or dispatches allow.
    #[error("a {0} x {1} slice image is larger than this GPU allows")]
    TooLarge(u32, u32),
    /// Reading the result back failed.
    #[error("reading the slice back from the GPU failed: {0}")]
    Readback(String),
}

impl SliceRenderer {
    /// Compiles the pass's variants and the bricks' builder.
    pub fn new(device: &wgpu::Device) -> Result<Self, SliceError> {
        // One pipeline per layout of the volume, from `file` with `defines` and the layout's.
        let variant = |label: &str, file: &str, defines: &[&str], entry: &str| {
            PerLayout::new(|layout| -> Result<_, ShaderError> {
                let all: Vec<&str> = defines.iter().chain(layout).copied().collect();
                let module = shader_module(device, label, compose(file, &all)?);
                Ok(compute_pipeline(device, &module, entry))
            })
        };
        Ok(Self {
            exact: variant("slice", "entry/slice.wgsl", &[], "slice")?,
            display: variant("slice display", "entry/slice.wgsl", &["DISPLAY"], "slice")?,
            bricks_pipeline: variant("slab bricks", "build/minmax.wgsl", &[], "build_base")?,
            linear: device.create_sampler(&wgpu::SamplerDescriptor {
                label: Some("slice trilinear"),
                mag_filter: wgpu::FilterMode::Linear,
                min_filter: wgpu::FilterMode::Linear,
                ..Default::default()
            }),
            no_bricks: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("no slab bricks"),
                size: 16,
                usage: wgpu::BufferUsages::STORAGE,
                mapped_at_creation: false,
            }),
            no_colours: TableTexture::slice_colours(device, 1),
            no_labels: super::labels::NoLabels::new(device),
        })
    }

    /// The colour table of `tf` over `volume`'s value range, for [`SliceSource::colours`].
    pub fn colour_table(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        tf: &TransferFunction,
        volume: &Volume,
    ) -> TableTexture {
        let table = TableTexture::slice_colours(device, LUT_SIZE as u32);
        table.write(queue, &slice_colours(tf, volume.normalization_range()));
        table
    }

    /// Writes `params` for `output` (leaping only where `source` has bricks) and returns the
    /// pipeline and bind group of its pass.
    fn prepare(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        source: SliceSource<'_>,
        output: Output<'_>,
        params: &SliceParams,
    ) -> (&wgpu::ComputePipeline, wgpu::BindGroup) {
        let mut params = *params;
        if source.bricks.is_none() {
            params.leap = 0;
        }
        if source.colours.is_none() {
            params.colour = 0;
        }
        params.labels = source.labels.map_or(0, GpuLabels::layers);
        params.label_bricks = u32::from(source.labels.is_some_and(GpuLabels::in_bricks));
        queue.write_buffer(output.params(), 0, bytemuck::bytes_of(&params));
        let pipeline = match output {
            Output::Exact(_) => self.exact.pick(source.texture),
            Output::Display(_) => self.display.pick(source.texture),
        };
        let bricks = source.bricks.map_or(&self.no_bricks, |b| &b.buffer);
        let mut entries = source.texture.entries([0, 6, 7]);
        entries.extend([
            wgpu::BindGroupEntry {
                binding: 1,
                resource: output.params().as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 4,
                resource: bricks.as_entire_binding(),
            },
        ]);
        // Owned here: the entries borrow it.
        let label_texels = source.labels.and_then(GpuLabels::texels);
        match output {
            Output::Exact(t) => {
                entries.push(wgpu::BindGroupEntry {
                    binding: 2,
                    resource: t.values.as_entire_binding(),
                });
                entries.push(wgpu::BindGroupEntry {
                    binding: 3,
                    resource: t.image.as_entire_binding(),
                });
            }
            Output::Display(t) => {
                let colours = source.colours.unwrap_or(&self.no_colours);
                entries.push(wgpu::BindGroupEntry {
                    binding: 5,
                    resource: wgpu::BindingResource::TextureView(&colours.view),
                });
                let labels = label_texels.as_ref().unwrap_or(&self.no_labels.labels);
                let label_colours = (source.labels).map_or(&self.no_labels.colours, |l| &l.colours);
                entries.push(wgpu::BindGroupEntry {
                    binding: 8,
                    resource: wgpu::BindingResource::TextureView(labels),
                });
                entries.push(wgpu::BindGroupEntry {
                    binding: 9,
                    resource: wgpu::BindingResource::TextureView(label_colours),
                });
                entries.push(wgpu::BindGroupEntry {
                    binding: 2,
                    resource: wgpu::BindingResource::Sampler(&self.linear),
                });
                entries.push(wgpu::BindGroupEntry {
                    binding: 3,
                    resource: wgpu::BindingResource::TextureView(&t.view),
                });
            }
        }
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("slice"),
            layout: &pipeline.get_bind_group_layout(0),
            entries: &entries,
        });
        (pipeline, group)
    }

    /// Records the pass of `params` from `source` into `output` (the parameters are written
    /// now, so each view needs its own target within one submission).
    pub(crate) fn encode(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        source: SliceSource<'_>,
        output: Output<'_>,
        params: &SliceParams,
    ) {
        let (pipeline, group) = self.prepare(device, queue, source, output, params);
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("slice"),
            timestamp_writes: None,
        });
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, &group, &[]);
        let [x, y] = dispatch(params);
        pass.dispatch_workgroups(x, y, 1);
    }

    /// The bricks of `volume` in `texture`, for leaping slabs (see [`Self::build_bricks`]).
    pub fn bricks_of(
        &self,
        ctx: &GpuContext,
        volume: &Volume,
        texture: &VolumeTexture,
    ) -> Option<SliceBricks> {
        let (texel_max, _, _) = texel_units(volume, texture.encoding.format);
        self.build_bricks(
            &ctx.device,
            &ctx.queue,
            &texture.slice_view(),
            volume.dims(),
            texel_max,
        )
    }

    /// Draws `view` of `volume` (already in `texture`, with its `bricks` for a leaping slab)
    /// by the exact variant and reads it back: the tests and `leapview slice --exact`.
    pub fn render(
        &self,
        ctx: &GpuContext,
        volume: &Volume,
        texture: &VolumeTexture,
        bricks: Option<&SliceBricks>,
        view: &SliceView,
        look: SliceLook,
    ) -> Result<SliceImage, SliceError> {
        let target = SliceTarget::new(&ctx.device, view.size)?;
        let params = slice_params(
            view,
            &PatientFrame::of(volume),
            volume,
            texture.encoding.format,
            look,
            target.pitch,
        );
        let view_of = texture.slice_view();
        let source = SliceSource {
            texture: &view_of,
            bricks,
            colours: None,
            labels: None,
        };
        self.submit(ctx, source, Output::Exact(&target), &params);
        let (values, grey) = target.read(ctx)?;
        Ok(SliceImage {
            size: view.size,
            values,
            grey,
        })
    }

    /// Draws `view` as the window shows it (the display variant; coloured by `colours` where
    /// `look` asks, with `labels` over it) and reads its pixels back, RGB, row-major:
    /// `leapview slice` and the tests that compare the two variants.
    #[allow(clippy::too_many_arguments)]
    pub fn render_display(
        &self,
        ctx: &GpuContext,
        volume: &Volume,
        texture: &VolumeTexture,
        bricks: Option<&SliceBricks>,
        colours: Option<&TableTexture>,
        labels: Option<&GpuLabels>,
        view: &SliceView,
        look: SliceLook,
    ) -> Result<Vec<[u8; 3]>, SliceError> {
        let target = DisplayTarget::new(&ctx.device, view.size)?;
        let params = slice_params(
            view,
            &PatientFrame::of(volume),
            volume,
            texture.encoding.format,
            look,
            view.size[0],
        );
        let view_of = texture.slice_view();
        let source = SliceSource {
            texture: &view_of,
            bricks,
            colours,
            labels,
        };
        self.submit(ctx, source, Output::Display(&target), &params);
        target.read(ctx)
    }

    /// Records and submits one pass.
    fn submit(
        &self,
        ctx: &GpuContext,
        source: SliceSource<'_>,
        output: Output<'_>,
        params: &SliceParams,
    ) {
        let mut encoder = ctx
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("slice"),
            });
        self.encode(
            &ctx.device,
            &ctx.queue,
            &mut encoder,
            source,
            output,
            params,
        );
        ctx.queue.submit([encoder.finish()]);
    }
}
