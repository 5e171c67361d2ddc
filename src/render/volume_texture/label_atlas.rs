//! A segmentation that travels in the volume's bricks: a second atlas of the volume atlas's
//! extent in the labels' format, slot for slot with it, so that the rays' and the slices' page
//! tables find a voxel's labels where they find its sample (`volume_labels` in
//! shaders/shared/volume.wgsl). Each brick's labels are written beside its samples, from the
//! level the brick is held at: the coarser levels by the most frequent label
//! ([`crate::labels::levels`]), never a mean. A brick held as a constant reads label 0 (only
//! bricks no ray sees are constants).

use std::sync::Arc;

use super::VolumeTextureError;
use crate::accel::bricks::BrickLayout;
use crate::labels::LabelMap;
use crate::labels::levels::halved;
use crate::render::context::GpuContext;
use crate::render::labels::label_format;
use crate::volume::downsample::level_dims;

/// The labels of a bricked volume's resident bricks, in their slots.
pub(super) struct LabelAtlas {
    texture: wgpu::Texture,
    /// What the passes bind.
    pub(super) view: wgpu::TextureView,
    /// The labels (level 0).
    map: Arc<LabelMap>,
    /// Levels 1, 2, … of each layer.
    coarser: Vec<Vec<Vec<u16>>>,
    /// Channels of a texel (1, 2 or 4: a layer each).
    channels: u32,
    /// Edge of the volume's level-0 bricks.
    brick_vox: u32,
    /// The segmentation it holds (the `GpuLabels`' address).
    pub(super) owner: usize,
}

/// The texels of `brick`'s slot in `layout` (its apron and overhang repeating the nearest voxel)
/// from `layers` of the level `layout` holds, x fastest, `channels` a texel (layers past those
/// given read 0).
fn encode_slot(
    layers: &[Vec<u16>],
    layout: &BrickLayout,
    brick: [u32; 3],
    channels: u32,
) -> Vec<u16> {
    let [w, h, _] = layout.level_dims().map(|d| d as usize);
    let s = layout.slot_vox();
    let channels = channels as usize;
    let mut out = vec![0u16; (s * s * s) as usize * channels];
    for (t, texel) in out.chunks_exact_mut(channels).enumerate() {
        let t = t as u32;
        let [x, y, z] = layout
            .voxel_of(brick, [t % s, t / s % s, t / (s * s)])
            .map(|c| c as usize);
        let i = x + w * (y + h * z);
        for (c, layer) in texel.iter_mut().zip(layers) {
            *c = layer.get(i).copied().unwrap_or(0);
        }
    }
    out
}

impl LabelAtlas {
    /// An atlas of `extent` texels for `map`, its levels below the finest made for `levels`
    /// levels (all cores), no slot written yet.
    pub(super) fn new(
        ctx: &GpuContext,
        (extent, brick_vox, levels): ([u32; 3], u32, u32),
        map: Arc<LabelMap>,
        owner: usize,
    ) -> Result<Self, VolumeTextureError> {
        let (format, channels) = label_format(map.layers().len());
        let bytes = extent.iter().map(|&e| u64::from(e)).product::<u64>() * 2 * u64::from(channels);
        let texture = match super::allocate(ctx, extent, format) {
            Ok((texture, _)) => texture,
            Err(super::Allocation::OutOfMemory) => {
                return Err(VolumeTextureError::OutOfMemory {
                    name: format!("the labels {} (their atlas of bricks)", map.name()),
                    megabytes: bytes as f64 / 1e6,
                    adapter: ctx.adapter_info.name.clone(),
                });
            }
            Err(super::Allocation::Refused(e)) => return Err(VolumeTextureError::Gpu(e)),
        };
        let started = std::time::Instant::now();
        let mut coarser: Vec<Vec<Vec<u16>>> = Vec::new();
        for level in 1..levels {
            let finer = match coarser.last() {
                Some(layers) => layers.as_slice(),
                None => map.layers(),
            };
            let dims = level_dims(map.dims(), level - 1);
            coarser.push(finer.iter().map(|layer| halved(layer, dims)).collect());
        }
        log::debug!(
            "{} coarser label levels in {:.0} ms",
            coarser.len(),
            started.elapsed().as_secs_f64() * 1e3
        );
        Ok(Self {
            view: texture.create_view(&wgpu::TextureViewDescriptor::default()),
            texture,
            map,
            coarser,
            channels,
            brick_vox,
            owner,
        })
    }

    /// Bytes of its texture.
    pub(super) fn bytes(&self) -> u64 {
        let size = self.texture.size();
        u64::from(size.width)
            * u64::from(size.height)
            * u64::from(size.depth_or_array_layers)
            * 2
            * u64::from(self.channels)
    }

    /// The texels of brick `brick` of level `level`'s slot (its apron and overhang repeat the
    /// nearest voxel, as the volume's slot does), x fastest, a `u16` per channel.
    pub(super) fn encode(&self, level: u32, brick: [u32; 3]) -> Vec<u16> {
        let layout = BrickLayout::geometry(self.map.dims(), self.brick_vox, level);
        let layers: &[Vec<u16>] = match level {
            0 => self.map.layers(),
            l => self.coarser.get(l as usize - 1).map_or(&[], Vec::as_slice),
        };
        encode_slot(layers, &layout, brick, self.channels)
    }

    /// Writes `texels` ([`Self::encode`]) into the slot at atlas texel `origin`, `s` a side.
    pub(super) fn write(&self, ctx: &GpuContext, origin: [u32; 3], s: u32, texels: &[u16]) {
        ctx.queue.write_texture(
            wgpu::TexelCopyTextureInfo {
                texture: &self.texture,
                mip_level: 0,
                origin: wgpu::Origin3d {
                    x: origin[0],
                    y: origin[1],
                    z: origin[2],
                },
                aspect: wgpu::TextureAspect::All,
            },
            bytemuck::cast_slice(texels),
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(s * 2 * self.channels),
                rows_per_image: Some(s),
            },
            wgpu::Extent3d {
                width: s,
                height: s,
                depth_or_array_layers: s,
            },
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::{Aabb, Camera, ProjectionKind};
    use crate::labels::levels::halved;
    use crate::render::VolumeRenderer;
    use crate::render::labels::{GpuLabels, LabelPlacement};
    use crate::settings::effects::LabelView;
    use crate::settings::{Bricking, Mode, RenderPath, RenderSettings, Strategy, Upload};
    use crate::volume::{Samples, ValueMapping, Volume};
    use glam::DVec3;

    #[test]
    fn a_label_slot_holds_its_levels_voxels_and_repeats_the_edges() {
        let dims = [9u32, 6, 5];
        let n = (dims[0] * dims[1] * dims[2]) as usize;
        let first: Vec<u16> = (0..n as u16).collect();
        let second: Vec<u16> = (0..n as u16).map(|v| 1000 + v).collect();
        for level in [0, 1] {
            let layout = BrickLayout::geometry(dims, 4, level);
            let ld = layout.level_dims();
            let m = (ld[0] * ld[1] * ld[2]) as usize;
            let layers = [first[..m].to_vec(), second[..m].to_vec()];
            let s = layout.slot_vox();
            for b in 0..layout.bricks.iter().product::<u32>() {
                let brick = layout.brick_at(b);
                let slot = encode_slot(&layers, &layout, brick, 4);
                assert_eq!(slot.len(), (s * s * s * 4) as usize);
                for (t, texel) in slot.chunks_exact(4).enumerate() {
                    let t = t as u32;
                    let v = layout.voxel_of(brick, [t % s, t / s % s, t / (s * s)]);
                    let i = (v[0] + ld[0] * (v[1] + ld[1] * v[2])) as u16;
                    assert_eq!(texel, [i, 1000 + i, 0, 0], "level {level} brick {brick:?}");
                }
            }
        }
    }

    /// 70 × 45 × 38 (bricks of 32: seams on every axis) of noise and a brighter ball.
    fn scene() -> (Volume, LabelMap) {
        let dims = [70u32, 45, 38];
        let mut v = Vec::new();
        let mut labels = Vec::new();
        for z in 0..dims[2] {
            for y in 0..dims[1] {
                for x in 0..dims[0] {
                    let p = DVec3::new(f64::from(x), f64::from(y), f64::from(z));
                    let noise = 300.0 + 250.0 * (p.x * 0.3).sin() * (p.y * 0.23).cos();
                    let ball = (p - DVec3::new(35.0, 22.0, 19.0)).length();
                    v.push((noise + if ball < 15.0 { 600.0 } else { 0.0 }) as u16);
                    // Blocks of labels 1-4 in the ball, stripes of 5 across them: the level's
                    // most frequent label differs from a voxel's.
                    labels.push(match (x, y, z) {
                        _ if ball >= 17.0 => 0,
                        _ if x % 3 == 0 && y > 22 => 5,
                        _ => 1 + ((x / 5 + y / 7 + z / 6) % 4) as u16,
                    });
                }
            }
        }
        let volume = Volume::new(
            "labelled",
            dims,
            [1.0; 3],
            Samples::U16(v),
            ValueMapping::IDENTITY,
        )
        .expect("valid");
        (volume, LabelMap::bare(dims, vec![labels]))
    }

    /// Labels 1-5 in colours of their own, every one but 3 shown.
    fn table() -> Vec<[u8; 4]> {
        let mut table = vec![[0u8; 4]; 1 << 16];
        for (v, c) in table.iter_mut().enumerate().take(6).skip(1) {
            *c = [
                40 * v as u8,
                250 - 45 * v as u8,
                90,
                if v == 3 { 0 } else { 200 },
            ];
        }
        table
    }

    /// A perspective camera framing a grid of `dims` (1 mm voxels) obliquely.
    fn oblique(dims: [u32; 3]) -> Camera {
        let bounds = Aabb::of_volume(dims, [1.0; 3]);
        Camera::framing(
            &bounds,
            DVec3::new(0.6, -0.7, 0.4).normalize(),
            DVec3::Z,
            ProjectionKind::Perspective,
        )
    }

    /// A bricked renderer of `volume` within `budget`, with `map` placed as `placement` says,
    /// shown by [`table`].
    fn renderer(
        volume: &Volume,
        budget: Option<u64>,
        map: &LabelMap,
        placement: LabelPlacement,
    ) -> VolumeRenderer {
        let mut r = VolumeRenderer::new(GpuContext::headless().expect("a GPU")).expect("renderer");
        let upload = Upload {
            bricking: Bricking::On,
            gpu_budget: budget,
            ..Upload::default()
        };
        r.set_volume_with(&Arc::new(volume.clone()), &upload)
            .expect("upload");
        r.set_transfer_function(&crate::transfer::TransferFunction::grey_ramp());
        let ctx = r.context().clone();
        let gpu = GpuLabels::placed(&ctx.device, &ctx.queue, Arc::new(map.clone()), placement)
            .expect("labels");
        assert_eq!(gpu.in_bricks(), placement != LabelPlacement::Auto);
        let table = table();
        gpu.write_table_for_tests(&ctx.queue, &table);
        r.set_labels(Some(Arc::new(gpu)))
            .expect("labels over the volume");
        r
    }

    fn cases() -> Vec<RenderSettings> {
        let dvr = RenderSettings {
            step_vox: 0.5,
            path: RenderPath::Compute,
            background: [0.0; 3],
            ..RenderSettings::default()
        };
        let mip = RenderSettings {
            mode: Mode::Mip,
            window: Some([0.0, 1200.0]),
            ..dvr
        };
        let mut all = Vec::new();
        for (base, view) in [
            (dvr, LabelView::Colour),
            (dvr, LabelView::Inside),
            (mip, LabelView::ColourInside),
        ] {
            for strategy in [Strategy::RcT, Strategy::RcS] {
                all.push(RenderSettings {
                    labels: view,
                    strategy: strategy.for_mode(base.mode),
                    ..base
                });
            }
        }
        all.push(RenderSettings {
            path: RenderPath::Fragment,
            labels: LabelView::Colour,
            ..dvr
        });
        all
    }

    /// Labels that travel in the volume's bricks draw as labels in one texture do: at the
    /// volume's own level the same labels; where the budget holds a coarser level, each
    /// coarse voxel's most frequent label (one texture of those labels, upsampled, draws the
    /// same), leaping exact as RC-t; surfaces too, at the volume's own level.
    #[test]
    fn labels_in_bricks_draw_as_the_labels_of_their_level_in_one_texture() {
        let (volume, map) = scene();
        let dims = volume.dims();
        let camera = oblique(dims);
        let size = [48, 48];
        // Level 1 (2 bricks and the coarsest) fits 8 slots of 34³ 16-bit texels, level 0's 12
        // do not.
        let coarse_budget = 8 * 34u64.pow(3) * 2 * 16 / 10;
        let up = |layer: &[u16]| -> Vec<u16> {
            let half = halved(layer, dims);
            let hd = level_dims(dims, 1);
            (0..layer.len())
                .map(|i| {
                    let [x, y, z] = [i % 70 / 2, i / 70 % 45 / 2, i / (70 * 45) / 2];
                    half[x + hd[0] as usize * (y + hd[1] as usize * z)]
                })
                .collect()
        };
        let coarse_map = LabelMap::bare(dims, vec![up(&map.layers()[0])]);
        for (budget, whole_map, level) in [(None, &map, 0), (Some(coarse_budget), &coarse_map, 1)] {
            let mut bricks = renderer(&volume, budget, &map, LabelPlacement::Bricks);
            let mut whole = renderer(&volume, budget, whole_map, LabelPlacement::Auto);
            for settings in cases() {
                if level == 1 && settings.mode != Mode::Mip {
                    // DVR keeps the bricks it sees at level 0 (the rest are constants).
                    continue;
                }
                let got = bricks
                    .render_image(&camera, size, &settings)
                    .expect("frame");
                let status = bricks.volume_texture().and_then(|t| t.residency().cloned());
                let want = whole.render_image(&camera, size, &settings).expect("frame");
                assert_eq!(
                    status.map(|s| s.levels),
                    Some(1 << level),
                    "{settings:?} reads level {level} alone"
                );
                let diff = got.diff(&want).expect("same size");
                assert!(
                    diff.max_abs <= 1.0 / 255.0 + 1e-6,
                    "level {level}, {:?} {:?} {:?}: {diff:?}",
                    settings.mode,
                    settings.labels,
                    settings.strategy
                );
                // The labels' colours show (the grey ramp's pixels are grey).
                let coloured = (0..size[1])
                    .flat_map(|y| (0..size[0]).map(move |x| (x, y)))
                    .any(|(x, y)| {
                        let p = got.get(x, y);
                        (p[0] - p[1]).abs() > 0.05
                    });
                assert_eq!(coloured, settings.labels.colours(), "{settings:?}");
            }
        }
        // Surfaces: the mask smoothed from the labels' occupancy, written on the CPU (there is
        // no texture of them to read), draws as the one built from their texture.
        let mut bricks = renderer(&volume, None, &map, LabelPlacement::Bricks);
        let mut whole = renderer(&volume, None, &map, LabelPlacement::Auto);
        for (strategy, path) in [
            (Strategy::RcT, RenderPath::Compute),
            (Strategy::RcS, RenderPath::Compute),
            (Strategy::RcT, RenderPath::Fragment),
        ] {
            let surfaces = RenderSettings {
                labels: LabelView::Surfaces,
                strategy,
                path,
                ..RenderSettings::default()
            };
            let got = bricks
                .render_image(&camera, size, &surfaces)
                .expect("frame");
            let want = whole.render_image(&camera, size, &surfaces).expect("frame");
            let diff = got.diff(&want).expect("same size");
            assert!(diff.max_abs <= 1.0 / 255.0 + 1e-6, "{surfaces:?}: {diff:?}");
            let off = RenderSettings {
                labels: LabelView::Off,
                ..surfaces
            };
            let plain = whole.render_image(&camera, size, &off).expect("frame");
            assert!(want.diff(&plain).expect("same size").max_abs > 0.1);
        }
        assert!(
            bricks
                .volume_texture()
                .is_some_and(|t| t.label_atlas_bytes() > 0)
        );
    }

    /// Surfaces of labels in bricks on their grid reduced (forced: at most 36 or 18 voxels an
    /// axis, as a grid past the GPU's textures takes it) match the f64 reference, which smooths
    /// the same occupancy on the same reduced grid, on both paths, and leaping (RC-s) as RC-t.
    #[test]
    fn surfaces_on_a_halved_grid_match_the_reference() {
        use crate::reference::{Labelled, render_labelled_on};
        let (volume, _) = scene();
        let dims = volume.dims();
        // The ball's four quarters (label 3's hidden): surfaces large enough to outlive a
        // 4-fold reduction, and to move where its scale is wrong.
        let quarters: Vec<u16> = (0..dims[0] * dims[1] * dims[2])
            .map(|i| {
                let p = DVec3::new(
                    f64::from(i % 70),
                    f64::from(i / 70 % 45),
                    f64::from(i / 3150),
                );
                if (p - DVec3::new(35.0, 22.0, 19.0)).length() < 16.0 {
                    1 + u16::from(p.x >= 35.0) + 2 * u16::from(p.y >= 22.0)
                } else {
                    0
                }
            })
            .collect();
        let map = LabelMap::bare(dims, vec![quarters]);
        let camera = oblique(dims);
        let size = [48, 48];
        let table = table();
        let surfaces = RenderSettings {
            labels: LabelView::Surfaces,
            step_vox: 0.5,
            strategy: Strategy::RcT,
            ..RenderSettings::default()
        };
        let labelled = Labelled {
            map: &map,
            table: &table,
        };
        let tf = crate::transfer::TransferFunction::grey_ramp();
        let reference = |factor| {
            let frame = (size, &surfaces);
            render_labelled_on(&volume, &tf, &camera, frame, Some(&labelled), factor).image
        };
        let whole = reference(1);
        // Halved, and reduced 4-fold (where k·ceil(N / k) passes N by up to 3 voxels of 45).
        for (side, factor, grid) in [(36, 2, [35, 23, 19]), (18, 4, [18, 12, 10])] {
            let mut r = renderer(&volume, None, &map, LabelPlacement::BricksWithin(side));
            let want = reference(factor);
            // The reduced grid's surfaces are not the full grid's (lavapipe: 0.016 and 0.022
            // apart at most): the comparison sees the reduction.
            assert!(want.diff(&whole).expect("same size").max_abs > 0.01);
            for (strategy, path) in [
                (Strategy::RcT, RenderPath::Compute),
                (Strategy::RcT, RenderPath::Fragment),
                (Strategy::RcS, RenderPath::Compute),
            ] {
                let s = RenderSettings {
                    strategy,
                    path,
                    ..surfaces
                };
                let got = r.render_image(&camera, size, &s).expect("frame");
                let facts = r.label_surface_facts().expect("a mask");
                assert_eq!(facts.grid, (factor, grid));
                let diff = got.diff(&want).expect("same size");
                // Lavapipe: 5e-4 (halved) and 1.8e-3 (4-fold) at most; sampling the mask
                // without its scale moved pixels by 4.2e-3 and 1.3e-2.
                assert!(
                    diff.max_abs < 3e-3 && diff.share_over_1_255 == 0.0,
                    "{factor}-fold, {strategy:?} {path:?}: {diff:?}"
                );
            }
        }
    }
}
