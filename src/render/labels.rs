//! A segmentation on the GPU, one upload for the slice views and the ray caster: its layers of
//! labels (up to four, one per channel: `R16Uint`, `Rg16Uint` or `Rgba16Uint`) as a 3D texture
//! on the image's grid (read with `textureLoad`, nearest voxel: labels are never interpolated),
//! or, where the grid is past the GPU's 3D textures or its memory, in the bricked volume's label
//! atlas (`render::volume_texture::label_atlas`, slot for slot with the volume's bricks); and a
//! 256 × 256 table of each label value's colour, its alpha 0 where the label is hidden
//! ([`LabelMap::colour_table`]).

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};

use wgpu::util::DeviceExt;

use crate::accel::label_cells::{LabelCells, VoxelBox};
use crate::labels::LabelMap;
use crate::labels::classes::{self, Classes};

use super::texture::{full_view, texture_2d};

/// Edge of a table indexed by label value (the colours, the surfaces' classes): 256 × 256
/// texels hold every `u16`.
pub(crate) const TABLE_EDGE: u32 = 256;

/// Most layers of labels drawn: a texel's channels.
const MOST_LAYERS: usize = 4;

/// Words of the visibility bits: one bit per `u16` label value.
const SHOWN_WORDS: usize = (1 << 16) / 32;

/// A label map's textures, and what leaping over hidden labels reads: which labels each cell of
/// the grid holds ([`LabelCells`], as two storage buffers) and one visibility bit per label.
pub struct GpuLabels {
    /// The labels, a layer per channel, as one texture of the grid; `None` where they travel
    /// in the volume's bricks.
    whole: Option<wgpu::TextureView>,
    /// The labels (the volume's label atlas is filled from them where they travel in its
    /// bricks; the surfaces' neighbour graph is found in them on first use).
    map: Arc<LabelMap>,
    /// Whether they travel in the volume's bricks.
    in_bricks: bool,
    /// The volume's label atlas holding them, where they travel in its bricks and a volume
    /// took them ([`crate::render::volume_texture::VolumeTexture::attach_labels`]).
    atlas: Mutex<Option<wgpu::TextureView>>,
    /// Bumped each time [`Self::atlas`] changes: the slice views draw again.
    atlas_changes: AtomicU64,
    /// Each label value's colour (sRGB) and visibility (alpha).
    pub(crate) colours: wgpu::TextureView,
    colour_texture: wgpu::Texture,
    /// How many layers the texture holds.
    layers: u32,
    /// The grid they lie on (the image's).
    dims: [u32; 3],
    /// Cells per axis of the cell lists.
    pub(crate) cells: [u32; 3],
    /// Per cell, where its labels start in `cell_labels` (cells + 1 entries).
    pub(crate) cell_offsets: wgpu::Buffer,
    /// Every cell's labels.
    pub(crate) cell_labels: wgpu::Buffer,
    /// One bit per label value: shown.
    pub(crate) shown_bits: wgpu::Buffer,
    /// The most voxels an axis of the surfaces' grid may have where they travel in bricks, if
    /// less than the GPU's 3D textures ([`LabelPlacement::BricksWithin`]).
    surface_side: Option<u32>,
    /// Each label's box of voxels (to the cell): what a toggle of it can change.
    boxes: std::collections::BTreeMap<u16, VoxelBox>,
    /// Bumped by every [`GpuLabels::show`] that changes which labels are shown: what depends on
    /// the visibility is built again.
    generation: AtomicU64,
    /// The visibility bits last written.
    last_bits: Mutex<Vec<u32>>,
    /// Every pair of labels near enough for their smoothed surfaces to run together
    /// ([`classes::neighbours`]): the graph the surfaces' classes colour, found when surfaces
    /// first ask (1.5 s at 512³ on two cores: not for views that never draw them), and how
    /// long that took (ms, on the CPU).
    neighbours: std::sync::OnceLock<(Vec<(u16, u16)>, f64)>,
    /// The classes last found, with the generation they were found for.
    last_classes: Mutex<Option<(u64, Arc<Classes>)>>,
}

/// Where a segmentation's labels are held on the GPU.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LabelPlacement {
    /// One texture of the grid where it fits the GPU's 3D textures and memory, else in the
    /// volume's bricks.
    Auto,
    /// In the volume's bricks whatever the grid (the tests compare the two).
    Bricks,
    /// In the volume's bricks, their surfaces found on a grid of at most this many voxels an
    /// axis (the tests force the reduction a grid past the GPU's textures takes).
    BricksWithin(u32),
}

/// Why labels could not go to the GPU.
#[derive(Debug, thiserror::Error)]
pub enum LabelUploadError {
    /// More layers of overlapping segments than a texel holds.
    #[error("the segments overlap {0} deep; at most {MOST_LAYERS} overlapping layers are drawn")]
    TooManyLayers(usize),
}

impl GpuLabels {
    /// Uploads `labels` and its segments' colours, each visible: one texture where the grid
    /// fits, else kept to travel in the volume's bricks ([`LabelPlacement::Auto`]).
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        labels: impl Into<Arc<LabelMap>>,
    ) -> Result<Self, LabelUploadError> {
        Self::placed(device, queue, labels.into(), LabelPlacement::Auto)
    }

    /// [`Self::new`], the labels held where `placement` says.
    pub fn placed(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        map: Arc<LabelMap>,
        placement: LabelPlacement,
    ) -> Result<Self, LabelUploadError> {
        let labels = &*map;
        let dims = labels.dims();
        let layers = labels.layers();
        if layers.len() > MOST_LAYERS {
            return Err(LabelUploadError::TooManyLayers(layers.len()));
        }
        let fits = dims
            .iter()
            .all(|&d| d <= device.limits().max_texture_dimension_3d);
        let whole = match placement {
            LabelPlacement::Auto if fits => whole_texture(device, queue, labels),
            _ => None,
        };
        let colour_texture =
            table_texture(device, wgpu::TextureFormat::Rgba8Unorm, "label colours");
        let cells = LabelCells::of(labels);
        let storage = |label, words: &[u32]| {
            // A binding holds at least one word.
            let contents: &[u32] = if words.is_empty() { &[0] } else { words };
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents: bytemuck::cast_slice(contents),
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            })
        };
        let made = Self {
            in_bricks: whole.is_none(),
            atlas: Mutex::new(None),
            atlas_changes: AtomicU64::new(0),
            map: Arc::clone(&map),
            whole,
            colours: full_view(&colour_texture),
            colour_texture,
            layers: layers.len().max(1) as u32,
            dims,
            boxes: cells.boxes(dims),
            surface_side: match placement {
                LabelPlacement::BricksWithin(side) => Some(side.max(1)),
                _ => None,
            },
            cells: cells.cells,
            cell_offsets: storage("label cell offsets", &cells.offsets),
            cell_labels: storage("label cell labels", &cells.labels),
            shown_bits: storage("shown labels", &[0; SHOWN_WORDS]),
            generation: AtomicU64::new(0),
            last_bits: Mutex::new(vec![0; SHOWN_WORDS]),
            neighbours: std::sync::OnceLock::new(),
            last_classes: Mutex::new(None),
        };
        made.show(queue, labels, |_| true);
        Ok(made)
    }

    /// Counts the changes of which labels are shown.
    pub fn generation(&self) -> u64 {
        self.generation.load(Ordering::Relaxed)
    }

    /// Bytes on the GPU: the labels (where one texture holds them: the volume's label atlas
    /// counts those in bricks), the colour table, the cell lists and the visibility bits.
    pub fn gpu_bytes(&self) -> u64 {
        let voxels: u64 = self.dims.iter().map(|&d| u64::from(d)).product();
        let texel = 2 * u64::from(label_format(self.layers as usize).1);
        u64::from(self.whole.is_some()) * voxels * texel
            + u64::from(TABLE_EDGE * TABLE_EDGE * 4)
            + self.cell_offsets.size()
            + self.cell_labels.size()
            + self.shown_bits.size()
    }

    /// Whether the labels travel in the volume's bricks (its label atlas holds them) rather
    /// than in one texture of their own.
    pub fn in_bricks(&self) -> bool {
        self.in_bricks
    }

    /// The labels the volume's label atlas is filled from, where they travel in its bricks.
    pub(crate) fn brick_source(&self) -> Option<&Arc<LabelMap>> {
        self.in_bricks.then_some(&self.map)
    }

    /// The texture of one grid holding the labels, where one does.
    pub(crate) fn whole(&self) -> Option<&wgpu::TextureView> {
        self.whole.as_ref()
    }

    /// What a pass binds as the labels: their texture, else the label atlas of the bricked
    /// volume that took them (`None` where none has yet).
    pub(crate) fn texels(&self) -> Option<wgpu::TextureView> {
        let atlas = || self.atlas.lock().unwrap_or_else(|e| e.into_inner()).clone();
        self.whole.clone().or_else(atlas)
    }

    /// Records the label atlas holding them (`None`: none does).
    pub(crate) fn set_atlas(&self, view: Option<wgpu::TextureView>) {
        *self.atlas.lock().unwrap_or_else(|e| e.into_inner()) = view;
        self.atlas_changes.fetch_add(1, Ordering::Relaxed);
    }

    /// Counts the changes of the label atlas holding them (what a slice view drew with).
    pub(crate) fn atlas_changes(&self) -> u64 {
        self.atlas_changes.load(Ordering::Relaxed)
    }

    /// The voxel grid the labels lie on (the image's).
    pub fn dims(&self) -> [u32; 3] {
        self.dims
    }

    /// The shown labels' classes: the channels of the surfaces' mask, neighbours apart where
    /// [`classes::MOST_CLASSES`] allow.
    /// Found again only when the shown labels change (the window's panel asks every frame).
    pub fn classes(&self) -> Arc<Classes> {
        let mut cached = self.last_classes.lock().unwrap_or_else(|e| e.into_inner());
        let generation = self.generation();
        if let Some((g, c)) = cached.as_ref()
            && *g == generation
        {
            return Arc::clone(c);
        }
        let last = self.last_bits.lock().unwrap_or_else(|e| e.into_inner());
        let shown: Vec<bool> = (0..1usize << 16)
            .map(|v| last[v / 32] >> (v % 32) & 1 == 1)
            .collect();
        drop(last);
        let pairs = &self.neighbour_graph().0;
        // A toggle keeps the other labels' classes: their walls stay where they were.
        let found = Arc::new(match cached.as_ref() {
            Some((_, before)) => classes::classes_after(before, &shown, pairs),
            None => classes::classes(&shown, pairs),
        });
        *cached = Some((generation, Arc::clone(&found)));
        found
    }

    /// The neighbouring labels (pairs) and how long finding them took (ms): `None` until
    /// surfaces first asked for them.
    pub fn neighbour_facts(&self) -> Option<(usize, f64)> {
        (self.neighbours.get()).map(|(pairs, ms)| (pairs.len(), *ms))
    }

    /// The neighbour graph, found now where no one asked before.
    fn neighbour_graph(&self) -> &(Vec<(u16, u16)>, f64) {
        self.neighbours.get_or_init(|| {
            let started = std::time::Instant::now();
            let pairs = classes::neighbours(&self.map);
            (pairs, started.elapsed().as_secs_f64() * 1e3)
        })
    }

    /// The most voxels an axis of the surfaces' grid may have, if less than the GPU's textures.
    pub(crate) fn surface_side(&self) -> Option<u32> {
        self.surface_side
    }

    /// The box of voxels (to the cell) label `value` lies in; `None` where no voxel holds it.
    pub(crate) fn label_box(&self, value: u16) -> Option<VoxelBox> {
        self.boxes.get(&value).copied()
    }

    /// How many layers of labels the texture holds.
    pub fn layers(&self) -> u32 {
        self.layers
    }

    /// Writes the colour table: each segment in its colour, shown where `visible` says so
    /// (hidden labels have alpha 0).
    pub fn show(
        &self,
        queue: &wgpu::Queue,
        labels: &LabelMap,
        visible: impl Fn(&crate::labels::Segment) -> bool,
    ) {
        self.write_table(queue, &labels.colour_table(visible));
    }

    /// Writes the colour table: each segment in the colour and at the opacity `style` gives it
    /// (alpha 0: hidden).
    pub fn show_styled(
        &self,
        queue: &wgpu::Queue,
        labels: &LabelMap,
        style: impl Fn(&crate::labels::Segment) -> [u8; 4],
    ) {
        self.write_table(queue, &labels.styled_table(style));
    }

    /// [`Self::write_table`] for tests that make a table of their own.
    #[cfg(test)]
    pub(crate) fn write_table_for_tests(&self, queue: &wgpu::Queue, table: &[[u8; 4]]) {
        self.write_table(queue, table);
    }

    /// Uploads `table` (a colour and opacity per label value) and the visibility bits it implies.
    fn write_table(&self, queue: &wgpu::Queue, table: &[[u8; 4]]) {
        let mut bits = vec![0u32; SHOWN_WORDS];
        for (value, c) in table.iter().enumerate() {
            if c[3] > 0 {
                bits[value / 32] |= 1 << (value % 32);
            }
        }
        // Only a change of which labels are shown rebuilds what leaps by them (a colour or an
        // opacity does not).
        let mut last = self.last_bits.lock().unwrap_or_else(|e| e.into_inner());
        if *last != bits {
            queue.write_buffer(&self.shown_bits, 0, bytemuck::cast_slice(&bits));
            self.generation.fetch_add(1, Ordering::Relaxed);
            *last = bits;
        }
        drop(last);
        queue.write_texture(
            self.colour_texture.as_image_copy(),
            bytemuck::cast_slice(table),
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

/// The texture format of `layers` layers of labels, a channel each, and its channels (three
/// take four: there is no three-channel format).
pub(crate) fn label_format(layers: usize) -> (wgpu::TextureFormat, u32) {
    match layers {
        0 | 1 => (wgpu::TextureFormat::R16Uint, 1),
        2 => (wgpu::TextureFormat::Rg16Uint, 2),
        _ => (wgpu::TextureFormat::Rgba16Uint, 4),
    }
}

/// One texture of `labels`'s grid, a layer per channel, uploaded; `None` where the GPU has no
/// memory for it (the labels then travel in the volume's bricks).
fn whole_texture(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    labels: &LabelMap,
) -> Option<wgpu::TextureView> {
    let dims = labels.dims();
    let layers = labels.layers();
    let (format, channels) = label_format(layers.len());
    let channels = channels as usize;
    let size = wgpu::Extent3d {
        width: dims[0],
        height: dims[1],
        depth_or_array_layers: dims[2],
    };
    let oom = device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
    let texture = device.create_texture(&wgpu::TextureDescriptor {
        label: Some("labels"),
        size,
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D3,
        format,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    if let Some(e) = pollster::block_on(oom.pop()) {
        log::warn!("no GPU memory for the labels as one texture ({e}): they travel in bricks");
        texture.destroy();
        return None;
    }
    let voxels = dims.iter().map(|&d| d as usize).product::<usize>();
    // One layer goes as it is; several are interleaved, a channel each.
    let texels: std::borrow::Cow<'_, [u16]> = match layers {
        [one] => one.into(),
        _ => (0..voxels * channels)
            .map(|i| {
                layers
                    .get(i % channels)
                    .map_or(0, |layer| layer[i / channels])
            })
            .collect::<Vec<u16>>()
            .into(),
    };
    queue.write_texture(
        texture.as_image_copy(),
        bytemuck::cast_slice(&texels),
        wgpu::TexelCopyBufferLayout {
            offset: 0,
            bytes_per_row: Some(dims[0] * 2 * channels as u32),
            rows_per_image: Some(dims[1]),
        },
        size,
    );
    Some(full_view(&texture))
}

/// A [`TABLE_EDGE`]² table indexed by label value, written from the CPU.
pub(crate) fn table_texture(
    device: &wgpu::Device,
    format: wgpu::TextureFormat,
    label: &str,
) -> wgpu::Texture {
    let usage = wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST;
    texture_2d(device, [TABLE_EDGE; 2], format, usage, label)
}

/// Bound where a pass shows no labels: a 1³ texture of label 0, a 1 × 1 colour table, a 1³
/// surface mask and a 1 × 1 class table.
pub(crate) struct NoLabels {
    pub(crate) labels: wgpu::TextureView,
    pub(crate) colours: wgpu::TextureView,
    /// A 1³ label-surface mask of 0.
    pub(crate) mask: wgpu::TextureView,
    /// A 1 × 1 class table.
    pub(crate) classes: wgpu::TextureView,
}

impl NoLabels {
    pub(crate) fn new(device: &wgpu::Device) -> Self {
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
            mask: make(
                "no label surface",
                wgpu::TextureDimension::D3,
                wgpu::TextureFormat::R8Unorm,
            ),
            classes: make(
                "no label classes",
                wgpu::TextureDimension::D2,
                wgpu::TextureFormat::R8Uint,
            ),
        }
    }
}
