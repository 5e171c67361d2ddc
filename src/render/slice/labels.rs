//! A segmentation on the GPU for the slice views: its first layer of labels as a 3D `R16Uint`
//! texture on the image's grid (read with `textureLoad`, nearest voxel: labels are never
//! interpolated) and a 256 × 256 table of each label value's colour, its alpha 0 where the label
//! is hidden.

use crate::labels::LabelMap;

use super::super::texture::full_view;

/// Label values a colour table holds: every `u16`.
const TABLE_EDGE: u32 = 256;

/// A label map's textures.
pub struct SliceLabels {
    /// The first layer's labels.
    pub(super) labels: wgpu::TextureView,
    /// Each label value's colour (sRGB) and visibility (alpha).
    pub(super) colours: wgpu::TextureView,
    colour_texture: wgpu::Texture,
}

/// Why labels could not go to the GPU.
#[derive(Debug, thiserror::Error)]
pub enum LabelUploadError {
    /// The label grid is larger than this GPU's 3D textures.
    #[error(
        "the labels' grid {0:?} is larger than this GPU's 3D textures ({1} a side): labels over \
         a bricked volume are not shown yet"
    )]
    TooLarge([u32; 3], u32),
}

impl SliceLabels {
    /// Uploads `labels`'s first layer and its segments' colours, each visible.
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        labels: &LabelMap,
    ) -> Result<Self, LabelUploadError> {
        let dims = labels.dims();
        let limit = device.limits().max_texture_dimension_3d;
        if dims.iter().any(|&d| d > limit) {
            return Err(LabelUploadError::TooLarge(dims, limit));
        }
        let size = wgpu::Extent3d {
            width: dims[0],
            height: dims[1],
            depth_or_array_layers: dims[2],
        };
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("slice labels"),
            size,
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D3,
            format: wgpu::TextureFormat::R16Uint,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        let empty = vec![0u16; dims.iter().map(|&d| d as usize).product()];
        let layer = labels.layers().first().unwrap_or(&empty);
        queue.write_texture(
            texture.as_image_copy(),
            bytemuck::cast_slice(layer),
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(dims[0] * 2),
                rows_per_image: Some(dims[1]),
            },
            size,
        );
        let colour_texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("label colours"),
            size: wgpu::Extent3d {
                width: TABLE_EDGE,
                height: TABLE_EDGE,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba8Unorm,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        let made = Self {
            labels: full_view(&texture),
            colours: full_view(&colour_texture),
            colour_texture,
        };
        made.show(queue, labels, |_| true);
        Ok(made)
    }

    /// Writes the colour table: each segment of layer 0 in its colour, shown where `visible`
    /// says so (hidden labels have alpha 0).
    pub fn show(
        &self,
        queue: &wgpu::Queue,
        labels: &LabelMap,
        visible: impl Fn(&crate::labels::Segment) -> bool,
    ) {
        let mut table = vec![[0u8; 4]; (TABLE_EDGE * TABLE_EDGE) as usize];
        for s in labels.segments().iter().filter(|s| s.layer == 0) {
            let [r, g, b] = s.colour;
            table[usize::from(s.value)] = [r, g, b, if visible(s) { 255 } else { 0 }];
        }
        queue.write_texture(
            self.colour_texture.as_image_copy(),
            bytemuck::cast_slice(&table),
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(TABLE_EDGE * 4),
                rows_per_image: Some(TABLE_EDGE),
            },
            wgpu::Extent3d {
                width: TABLE_EDGE,
                height: TABLE_EDGE,
                depth_or_array_layers: 1,
            },
        );
    }
}

/// Bound where a pass shows no labels: a 1³ texture of label 0 and a 1 × 1 colour table.
pub(super) struct NoLabels {
    pub(super) labels: wgpu::TextureView,
    pub(super) colours: wgpu::TextureView,
}

impl NoLabels {
    pub(super) fn new(device: &wgpu::Device) -> Self {
        let make = |label, dimension, format| {
            full_view(&device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size: wgpu::Extent3d {
                    width: 1,
                    height: 1,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension,
                format,
                usage: wgpu::TextureUsages::TEXTURE_BINDING,
                view_formats: &[],
            }))
        };
        Self {
            labels: make(
                "no labels",
                wgpu::TextureDimension::D3,
                wgpu::TextureFormat::R16Uint,
            ),
            colours: make(
                "no label colours",
                wgpu::TextureDimension::D2,
                wgpu::TextureFormat::Rgba8Unorm,
            ),
        }
    }
}
