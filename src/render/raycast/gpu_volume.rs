//! What lives as long as one volume: its 3D texture and geometry, the segmentation shown over
//! it, group 0 (which binds both beside the renderer's uniforms, sampler and tables), and the
//! leaping structures with their group 3.

use std::sync::Arc;

use crate::render::context::GpuContext;
use crate::render::label_surface::{SurfaceMask, SurfacePipelines, channels_for};
use crate::render::labels::{GpuLabels, NoLabels};
use crate::render::probe::{ProbePool, ProbeSlot};
use crate::render::volume_texture::{VolumeTexture, VolumeTextureError};
use crate::settings::{RenderSettings, Upload};
use crate::volume::{ValueRange, Volume};

use crate::render::gpu_data::FrameUniforms;

use super::layouts::{FrameResources, Layouts};
use super::leap::LeapStructures;
use super::transfer_tables::TransferTables;
use super::uniforms::{FrameGeometry, LeapLevels, SampleDecoding, frame_uniforms};

/// The resources group 0 binds that outlive any one volume.
pub struct FrameShared<'a> {
    /// The frame uniforms.
    pub uniforms: &'a wgpu::Buffer,
    /// The linear clamp-to-edge sampler.
    pub sampler: &'a wgpu::Sampler,
    /// The transfer function's tables.
    pub tables: &'a TransferTables,
    /// Bound where the volume has no segmentation.
    pub(crate) no_labels: &'a NoLabels,
}

/// A volume on the GPU, ready to be ray-cast.
pub struct GpuVolume {
    /// The 3D texture (shared with any other kind of drawing of the same volume).
    pub texture: VolumeTexture,
    /// Samples along x, y, z.
    pub dims: [u32; 3],
    /// Voxel spacing in millimetres.
    pub spacing_mm: [f64; 3],
    /// The value range normalised values run over.
    pub range: ValueRange,
    /// Whether every voxel is finite (`Volume::non_finite_count` is 0).
    pub all_finite: bool,
    /// Whether the volume is a colour one (its texels: luminance, red, green, blue).
    pub colour: bool,
    /// The segmentation shown over it (shared with the slices), if any.
    pub labels: Option<Arc<GpuLabels>>,
    /// Its shown labels' smoothed mask, made on the first frame that draws them as surfaces.
    pub(crate) surface: Option<SurfaceMask>,
    /// Group 0 of every ray-casting pipeline.
    pub frame_group: wgpu::BindGroup,
    /// The min/max pyramid, node flags and distance field (built lazily).
    pub leap: LeapStructures,
    /// Group 3 of the leaping variants.
    pub leap_group: wgpu::BindGroup,
}

impl GpuVolume {
    /// Uploads `volume` as `upload` asks (precision, layout, budget) and builds its groups; a
    /// bricked volume's first bricks for at most `first_upload` (all without).
    pub fn new(
        ctx: &GpuContext,
        layouts: &Layouts,
        shared: &FrameShared<'_>,
        volume: &std::sync::Arc<Volume>,
        (upload, first_upload): (&Upload, Option<std::time::Duration>),
    ) -> Result<Self, VolumeTextureError> {
        let texture = VolumeTexture::upload_streaming(ctx, volume, upload, first_upload)?;
        let frame_group = frame_group(ctx, layouts, shared, &texture, (None, None));
        let leap = LeapStructures::new(
            ctx,
            volume.dims(),
            (texture.encoding.scale, texture.encoding.bias),
            texture.view.brick_vox,
            texture.leap_most,
        );
        let leap_group = layouts.leap_group(&ctx.device, &leap.resources());
        Ok(Self {
            texture,
            dims: volume.dims(),
            spacing_mm: volume.spacing_mm(),
            range: volume.normalization_range(),
            all_finite: !volume.may_be_non_finite(),
            colour: volume.colour().is_some(),
            labels: None,
            surface: None,
            frame_group,
            leap,
            leap_group,
        })
    }
}

/// Group 0 of `texture` with `labels` and their surface mask (none: the dummies).
fn frame_group(
    ctx: &GpuContext,
    layouts: &Layouts,
    shared: &FrameShared<'_>,
    texture: &VolumeTexture,
    (labels, surface): (Option<&GpuLabels>, Option<&SurfaceMask>),
) -> wgpu::BindGroup {
    let none = shared.no_labels;
    let mask = surface.map_or((&none.mask, &none.classes), |s| (&s.view, &s.classes));
    let texels = labels.and_then(GpuLabels::texels);
    let labels = labels.map_or((&none.labels, &none.colours, mask.0, mask.1), |l| {
        let texels = texels.as_ref().unwrap_or(&none.labels);
        (texels, &l.colours, mask.0, mask.1)
    });
    layouts.frame_group(
        &ctx.device,
        &FrameResources {
            uniforms: shared.uniforms,
            volume: &texture.view,
            sampler: shared.sampler,
            lut: &shared.tables.lut().view,
            integrals: &shared.tables.integrals().view,
            labels,
        },
    )
}

impl GpuVolume {
    /// Shows `labels` (on this volume's grid) over it, or none.
    pub(crate) fn set_labels(
        &mut self,
        ctx: &GpuContext,
        layouts: &Layouts,
        shared: &FrameShared<'_>,
        labels: Option<Arc<GpuLabels>>,
    ) {
        self.surface = None;
        let group = (labels.as_deref(), None);
        self.frame_group = frame_group(ctx, layouts, shared, &self.texture, group);
        self.labels = labels;
    }

    /// Records the build of the shown labels' surface mask at `smoothing` (voxels) where it does
    /// not hold them yet, making it (and group 0 again) on first use; returns whether it
    /// recorded a build (timed into `probe` where given). Nothing without labels.
    pub(crate) fn prepare_surfaces(
        &mut self,
        ctx: &GpuContext,
        (layouts, pipelines): (&Layouts, &SurfacePipelines),
        shared: &FrameShared<'_>,
        smoothing: f32,
        (encoder, probe): (
            &mut wgpu::CommandEncoder,
            Option<(&mut ProbePool, &ProbeSlot)>,
        ),
    ) -> bool {
        let Some(labels) = self.labels.as_deref() else {
            return false;
        };
        if self
            .surface
            .as_ref()
            .is_some_and(|s| s.holds(labels, smoothing))
        {
            return false;
        }
        let classes = labels.classes();
        let channels = channels_for(classes.used);
        if !self
            .surface
            .as_ref()
            .is_some_and(|s| s.fits(labels, channels))
        {
            // A new mask (and group 0 again) for a new grid or another number of classes.
            self.surface = None;
            let mask = SurfaceMask::new(ctx, labels, channels);
            let group = (Some(labels), Some(&mask));
            self.frame_group = frame_group(ctx, layouts, shared, &self.texture, group);
            self.surface = Some(mask);
        }
        self.surface.as_mut().is_some_and(|s| {
            s.build(
                ctx,
                pipelines,
                (labels, &classes),
                smoothing,
                encoder,
                probe,
            )
        })
    }

    /// The uniforms of a frame of this volume of `size` pixels seen through `geometry`, for a
    /// lookup table of `lut_entries` whose stored depths are in units of `lut_depth_unit`
    /// (leaping levels still unset).
    pub(crate) fn uniforms(
        &self,
        (size, settings): ([u32; 2], &RenderSettings),
        geometry: &FrameGeometry,
        (lut_entries, lut_depth_unit): (u32, f32),
    ) -> FrameUniforms {
        let decoding = SampleDecoding {
            texel_scale: self.texture.encoding.scale,
            texel_bias: self.texture.encoding.bias,
            lut_size: lut_entries,
            lut_depth_unit,
            range: self.range,
            all_finite: self.all_finite,
            colour: self.colour,
        };
        let mut uniforms = frame_uniforms(
            geometry,
            size,
            self.dims,
            self.spacing_mm,
            settings,
            decoding,
            LeapLevels::default(),
        );
        uniforms.label_layers = self.labels.as_ref().map_or(0, |l| l.layers());
        uniforms.label_bricks = u32::from(self.labels.as_ref().is_some_and(|l| l.in_bricks()));
        uniforms
    }
}
