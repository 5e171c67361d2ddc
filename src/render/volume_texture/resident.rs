//! The bricked volume's residency on the GPU (`accel::residency` decides, this carries it out):
//! the levels' samples on the CPU, each brick of level 0's value range in texels as the shaders
//! decode them, the bricks encoded and written into their slots a batch at a time (within a
//! time budget where one is given), and the two page tables (the rays' and the slices').

use std::sync::Arc;
use std::time::{Duration, Instant};

use super::atlas::encode_brick;
use super::encoding::{TexelEncoding, TexelSource, bytes_per_texel, encode_texels};
use crate::accel::bricks::BrickLayout;
use crate::accel::emptiness::OpacityIndex;
use crate::accel::residency::{BrickKey, CONSTANT_F16, Residency, Wanted, dilate};
use crate::parallel::parallel;
use crate::render::context::GpuContext;
use crate::volume::Volume;
use crate::volume::downsample::Level;

/// Bricks encoded and written per batch (about 5 MB of 16-bit slots).
const BATCH: usize = 64;

/// Voxels around a brick whose values its range includes. A brick is served by a constant only
/// where those values are all unseen (transparent, or on one side of the iso value); then any
/// sample within `REACH - ½` voxels of the brick is unseen too, and no seen sample reads the
/// brick: a gradient reads two voxels on (fourth order), a pre-integrated segment or an
/// isosurface's refinement one step, and the gradient at an isosurface's hit two voxels past
/// that step. Four voxels cover steps up to 1.5 voxels; a frame with longer steps keeps every
/// brick beside a seen one too.
pub const REACH: u32 = 4;

/// The longest step (voxels) [`REACH`] covers.
pub const REACH_STEP_VOX: f64 = 1.0;

/// Which bricks of level 0 a frame's rays cannot see, and so may read a constant.
#[derive(Clone, Debug)]
pub enum Cull {
    /// Every brick's data (MIP, MinIP, X-ray, slices).
    Nothing,
    /// DVR: bricks whose every value the transfer function makes transparent (the index of
    /// its baked table, and the table's generation, which names it).
    Transparent(Arc<OpacityIndex>, u64),
    /// Isosurfaces: bricks whose values all lie on one side of the iso value (normalised).
    OneSide(f32),
}

/// What a frame's rays leave unread: the rule, and whether its step is longer than
/// [`REACH_STEP_VOX`] (every brick beside a seen one is then kept too).
#[derive(Clone, Debug)]
pub struct Unseen {
    /// Which bricks the rule empties.
    pub cull: Cull,
    /// Whether the frame's step is longer than [`REACH`] covers.
    pub long_steps: bool,
    /// The eye in continuous voxel coordinates (voxel `i`'s centre at `i + ½`): missing
    /// bricks nearest it are uploaded first.
    pub eye: Option<[f64; 3]>,
    /// Slice planes shown beside the rays: the bricks they cross hold data, whatever the rays
    /// leave unseen.
    pub slices: Vec<SlicePlane>,
    /// Continuous voxel coordinates → clip space of the frame (wgpu's: depth 0…1): bricks
    /// outside the view frustum (by more than [`REACH`]) are seen by no ray. `None`: all are in
    /// view.
    pub frustum: Option<glam::DMat4>,
}

/// A slice (or slab) through the volume, in continuous voxel coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SlicePlane {
    /// A point on the plane.
    pub point: [f64; 3],
    /// Its unit normal.
    pub normal: [f64; 3],
    /// How far the slab reaches either side of the plane (0 for a thin slice).
    pub half_thickness: f64,
}

/// Whether the box `[lo, hi]` (continuous voxel coordinates) may be in the view of `clip`: not
/// all its corners outside one of the frustum's six planes (exact for a convex box, whatever
/// the corners' w).
fn in_frustum(clip: &glam::DMat4, lo: [f64; 3], hi: [f64; 3]) -> bool {
    let corners: [glam::DVec4; 8] = std::array::from_fn(|i| {
        let pick = |a: usize| if i >> a & 1 == 1 { hi[a] } else { lo[a] };
        *clip * glam::DVec4::new(pick(0), pick(1), pick(2), 1.0)
    });
    let outside = |f: &dyn Fn(&glam::DVec4) -> f64| corners.iter().all(|c| f(c) < 0.0);
    !(outside(&|c| c.x + c.w)
        || outside(&|c| c.w - c.x)
        || outside(&|c| c.y + c.w)
        || outside(&|c| c.w - c.y)
        || outside(&|c| c.z)
        || outside(&|c| c.w - c.z))
}

impl SlicePlane {
    /// Whether the plane (its slab) comes within `margin` voxels of the box `[lo, hi]`.
    fn meets(&self, lo: [f64; 3], hi: [f64; 3], margin: f64) -> bool {
        let mut distance = 0.0;
        let mut extent = 0.0;
        for a in 0..3 {
            let centre = 0.5 * (lo[a] + hi[a]);
            distance += self.normal[a] * (centre - self.point[a]);
            extent += self.normal[a].abs() * (0.5 * (hi[a] - lo[a]) + margin);
        }
        distance.abs() <= extent + self.half_thickness
    }
}

impl Unseen {
    /// Nothing unseen: every brick's data, in brick order.
    pub const NOTHING: Self = Self {
        cull: Cull::Nothing,
        long_steps: false,
        eye: None,
        slices: Vec::new(),
        frustum: None,
    };
}

impl Cull {
    /// What the decision depends on, to tell whether it must be made again.
    fn key(&self) -> (u8, u64) {
        match self {
            Self::Nothing => (0, 0),
            Self::Transparent(_, generation) => (1, *generation),
            Self::OneSide(iso) => (2, u64::from(iso.to_bits())),
        }
    }

    /// Whether it empties nothing.
    fn is_nothing(&self) -> bool {
        matches!(self, Self::Nothing)
    }

    /// Whether a brick whose samples (normalised) lie in `[lo, hi]` contributes nothing.
    fn is_empty(&self, lo: f32, hi: f32) -> bool {
        match self {
            Self::Nothing => false,
            Self::Transparent(index, _) => index.is_empty(lo, hi),
            Self::OneSide(iso) => lo > *iso || hi < *iso,
        }
    }
}

/// What a decision was made for: the rule's key, the slice planes, the frustum.
type Decided = ((u8, u64), Vec<SlicePlane>, Option<[f64; 16]>);

/// A brick of level 0's texels and those within [`REACH`] of it, as the shaders decode them.
#[derive(Clone, Copy, Debug, PartialEq)]
struct BrickRange {
    /// Lowest normalised value.
    lo: f32,
    /// Highest normalised value.
    hi: f32,
    /// The lowest texel as a page-table constant (`accel::residency::CONSTANT`'s low bits),
    /// where one holds it exactly.
    constant: Option<u32>,
}

/// What one [`Resident::update`] did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Update {
    /// Whether the page tables changed (the leaping pyramid, built through them, is stale).
    pub changed: bool,
    /// Whether every wanted brick is resident.
    pub complete: bool,
}

/// How far residency is, for the overlay: one line.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ResidencyStatus {
    /// The level data bricks are wanted at.
    pub level: u32,
    /// Levels the rays read (bit `k`: level `k`).
    pub levels: u32,
    /// Bricks resident.
    pub resident: usize,
    /// Bricks wanted.
    pub wanted: usize,
    /// Bricks wanted and not yet resident.
    pub missing: usize,
    /// Bricks of level 0 served by a constant.
    pub constant: usize,
    /// Bytes the resident bricks take.
    pub bytes: u64,
}

/// A bricked volume's residency: what the atlas holds and how to fill it.
pub struct Resident {
    volume: Arc<Volume>,
    levels: Vec<Level>,
    encoding: TexelEncoding,
    brick_vox: u32,
    residency: Residency,
    ranges: Option<Vec<BrickRange>>,
    rays: wgpu::Texture,
    slices: wgpu::Texture,
    decided_for: Option<Decided>,
    wanted: Option<Wanted>,
    status: ResidencyStatus,
}

impl Resident {
    /// The residency of `volume` in an atlas of `slots` per axis, `capacity` of them used,
    /// bricks of `brick_vox`; the levels below the volume's own are halved here (all cores).
    /// Nothing is resident until the first [`Self::update`].
    pub fn new(
        ctx: &GpuContext,
        volume: Arc<Volume>,
        encoding: TexelEncoding,
        (brick_vox, slots, capacity): (u32, [u32; 3], u32),
    ) -> Self {
        let residency = Residency::new(volume.dims(), brick_vox, slots, capacity);
        let mut levels: Vec<Level> = Vec::new();
        for _ in 1..residency.levels() {
            let next = match levels.last() {
                Some(l) => l.halved(),
                None => Level::half_of(volume.samples(), volume.colour(), volume.dims()),
            };
            levels.push(next);
        }
        let pages = residency.grid(0);
        // Ranges only matter where not every brick of level 0 fits.
        let all = residency.page_count() as u64 + u64::from(residency.levels() > 1);
        let ranges = (all > u64::from(capacity) && volume.colour().is_none())
            .then(|| brick_ranges(&volume, &encoding, brick_vox))
            .flatten();
        Self {
            rays: page_texture(ctx, pages, "volume page table (rays)"),
            slices: page_texture(ctx, pages, "volume page table (slices)"),
            volume,
            levels,
            encoding,
            brick_vox,
            residency,
            ranges,
            decided_for: None,
            wanted: None,
            status: ResidencyStatus::default(),
        }
    }

    /// The rays' page table.
    pub fn rays_pages(&self) -> &wgpu::Texture {
        &self.rays
    }

    /// The slices' page table.
    pub fn slice_pages(&self) -> &wgpu::Texture {
        &self.slices
    }

    /// Brick edge in voxels.
    pub fn brick_vox(&self) -> u32 {
        self.brick_vox
    }

    /// The volume's voxels per axis.
    pub fn dims(&self) -> [u32; 3] {
        self.volume.dims()
    }

    /// How far residency is.
    pub fn status(&self) -> &ResidencyStatus {
        &self.status
    }

    /// The geometry of level `level`'s bricks (its slot arrangement unused).
    fn level_layout(&self, level: u32) -> BrickLayout {
        BrickLayout::geometry(self.volume.dims(), self.brick_vox, level)
    }

    /// Decides what `cull` lets the rays go without (again, only when it changed), then
    /// uploads missing bricks, coarsest first, until none is missing or `time` has passed (at
    /// least one batch), and rewrites the page tables where anything changed.
    pub fn update(
        &mut self,
        ctx: &GpuContext,
        atlas: &wgpu::Texture,
        unseen: &Unseen,
        time: Option<Duration>,
    ) -> Update {
        let start = Instant::now();
        let key = match &self.ranges {
            Some(_) if !unseen.cull.is_nothing() => {
                let (kind, value) = unseen.cull.key();
                (kind + 3 * u8::from(unseen.long_steps), value)
            }
            _ => Cull::Nothing.key(),
        };
        let mut changed = false;
        // The view decides only where not every brick fits.
        let frustum = unseen
            .frustum
            .filter(|_| !self.residency.holds_everything())
            .map(|m| m.to_cols_array());
        // Slices matter only where the rays leave bricks out.
        let slices = if key == Cull::Nothing.key() && frustum.is_none() {
            Vec::new()
        } else {
            unseen.slices.clone()
        };
        let key = (key, slices, frustum);
        if self.decided_for.as_ref() != Some(&key) {
            let (rays, slices) = self.needs_data(unseen);
            let wanted = self.residency.decide(&rays, &slices);
            if self.wanted.as_ref() != Some(&wanted) {
                self.residency.want(&wanted);
                self.wanted = Some(wanted);
                changed = true;
            }
            self.decided_for = Some(key);
        }
        let Some(mut wanted) = self.wanted.take() else {
            return Update::default();
        };
        if let Some(eye) = unseen.eye
            && self.residency.missing(&wanted) > 0
        {
            // The coarsest stays first; the rest nearest the eye first.
            let b = f64::from(self.brick_vox);
            let distance = |k: &BrickKey| {
                let size = b * f64::from(1u32 << k.level);
                (0..3)
                    .map(|a| ((f64::from(k.brick[a]) + 0.5) * size - eye[a]).powi(2))
                    .sum::<f64>()
            };
            wanted.bricks[1..].sort_by(|p, q| distance(p).total_cmp(&distance(q)));
        }
        loop {
            let given = self.residency.admit(&wanted, BATCH);
            if given.is_empty() {
                break;
            }
            self.upload(ctx, atlas, &given);
            changed = true;
            if time.is_some_and(|t| start.elapsed() >= t) {
                break;
            }
        }
        let missing = self.residency.missing(&wanted);
        self.status.missing = missing;
        if changed {
            self.write_pages(ctx, &wanted);
            self.status.resident = self.residency.resident_count();
            self.status.wanted = wanted.bricks.len();
            self.status.level = wanted.level;
            self.status.bytes = self.status.resident as u64
                * u64::from(self.brick_vox + 2).pow(3)
                * bytes_per_texel(self.encoding.format) as u64;
        }
        self.wanted = Some(wanted);
        Update {
            changed,
            complete: missing == 0,
        }
    }

    /// Which bricks of level 0 the rays need the data of: those `unseen` does not empty (over
    /// the brick and [`REACH`] around it), with their neighbours where steps are longer than
    /// that covers, and any without a constant; and which the slices show (within [`REACH`] of
    /// a plane or its slab).
    fn needs_data(&self, unseen: &Unseen) -> (Vec<bool>, Vec<bool>) {
        let n = self.residency.page_count();
        let grid = self.residency.grid(0);
        let mut rays = match &self.ranges {
            Some(ranges) => {
                let seen: Vec<bool> = ranges
                    .iter()
                    .map(|r| !unseen.cull.is_empty(r.lo, r.hi))
                    .collect();
                let mut rays = if unseen.long_steps {
                    dilate(&seen, grid)
                } else {
                    seen
                };
                for (need, range) in rays.iter_mut().zip(ranges) {
                    *need |= range.constant.is_none();
                }
                rays
            }
            None => vec![true; n],
        };
        let b = f64::from(self.brick_vox);
        if let Some(clip) = &unseen.frustum {
            let reach = f64::from(REACH);
            for (i, need) in rays.iter_mut().enumerate().filter(|(_, n)| **n) {
                let at = [
                    i as u32 % grid[0],
                    (i as u32 / grid[0]) % grid[1],
                    i as u32 / (grid[0] * grid[1]),
                ];
                let lo = at.map(|v| f64::from(v) * b - reach);
                let hi = at.map(|v| f64::from(v + 1) * b + reach);
                *need = in_frustum(clip, lo, hi);
            }
        }
        let slices = (0..n)
            .map(|i| {
                let at = [
                    i as u32 % grid[0],
                    (i as u32 / grid[0]) % grid[1],
                    i as u32 / (grid[0] * grid[1]),
                ];
                let lo = at.map(|v| f64::from(v) * b);
                let hi = lo.map(|v| v + b);
                unseen
                    .slices
                    .iter()
                    .any(|s| s.meets(lo, hi, f64::from(REACH)))
            })
            .collect();
        (rays, slices)
    }

    /// Encodes `given` (on all cores) and writes each into its slot.
    fn upload(&self, ctx: &GpuContext, atlas: &wgpu::Texture, given: &[(BrickKey, u32)]) {
        let s = self.brick_vox + 2;
        let bpt = bytes_per_texel(self.encoding.format) as u32;
        let encoded = parallel(given.len(), &|| false, &|k| {
            let (key, _) = given[k];
            let layout = self.level_layout(key.level);
            let source = match key.level {
                0 => TexelSource::of(&self.volume),
                l => TexelSource::level(&self.volume, &self.levels[l as usize - 1]),
            };
            let mut out = Vec::new();
            encode_brick(&source, &self.encoding, &layout, key.brick, &mut out);
            out
        });
        for ((_, slot), bytes) in given.iter().zip(encoded) {
            let Some(bytes) = bytes else { continue };
            let at = self.residency.slot_coords(*slot);
            ctx.queue.write_texture(
                wgpu::TexelCopyTextureInfo {
                    texture: atlas,
                    mip_level: 0,
                    origin: wgpu::Origin3d {
                        x: at[0] * s,
                        y: at[1] * s,
                        z: at[2] * s,
                    },
                    aspect: wgpu::TextureAspect::All,
                },
                &bytes,
                wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(s * bpt),
                    rows_per_image: Some(s),
                },
                wgpu::Extent3d {
                    width: s,
                    height: s,
                    depth_or_array_layers: s,
                },
            );
        }
        // As the whole upload: wgpu lets go of the batch's staging copy before the next.
        ctx.queue.submit([]);
        let _ = ctx.device.poll(wgpu::PollType::wait_indefinitely());
    }

    /// Writes both page tables for `wanted` as residency stands.
    fn write_pages(&mut self, ctx: &GpuContext, wanted: &Wanted) {
        let constants: Vec<Option<u32>> = match &self.ranges {
            Some(r) => r.iter().map(|r| r.constant).collect(),
            None => Vec::new(),
        };
        let tables = self.residency.page_tables(wanted, &constants);
        self.status.levels = tables.levels;
        self.status.constant = tables
            .rays
            .iter()
            .filter(|&&e| e & crate::accel::residency::CONSTANT != 0)
            .count();
        let pages = self.residency.grid(0);
        write_page_texture(ctx, &self.rays, pages, &tables.rays);
        write_page_texture(ctx, &self.slices, pages, &tables.slices);
    }
}

/// An empty page table of `pages` entries per axis.
fn page_texture(ctx: &GpuContext, pages: [u32; 3], label: &str) -> wgpu::Texture {
    ctx.device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d {
            width: pages[0],
            height: pages[1],
            depth_or_array_layers: pages[2],
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D3,
        format: wgpu::TextureFormat::R32Uint,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    })
}

/// Writes `entries` (x fastest) into the page table `texture` of `pages` per axis.
fn write_page_texture(ctx: &GpuContext, texture: &wgpu::Texture, pages: [u32; 3], entries: &[u32]) {
    ctx.queue.write_texture(
        wgpu::TexelCopyTextureInfo {
            texture,
            mip_level: 0,
            origin: wgpu::Origin3d::ZERO,
            aspect: wgpu::TextureAspect::All,
        },
        bytemuck::cast_slice(entries),
        wgpu::TexelCopyBufferLayout {
            offset: 0,
            bytes_per_row: Some(pages[0] * 4),
            rows_per_image: Some(pages[1]),
        },
        wgpu::Extent3d {
            width: pages[0],
            height: pages[1],
            depth_or_array_layers: pages[2],
        },
    );
}

/// Each brick of level 0's range over its texels and those within [`REACH`] of it (clamped to
/// the volume), decoded as the shaders decode them (`s = texel * scale + bias`), and a constant
/// within it, on all cores; `None` for a colour format or a volume with non-finite samples
/// (their marker is no value a constant may stand for).
fn brick_ranges(
    volume: &Volume,
    encoding: &TexelEncoding,
    brick_vox: u32,
) -> Option<Vec<BrickRange>> {
    use wgpu::TextureFormat as F;
    if volume.non_finite_count() > 0
        || !matches!(
            encoding.format,
            F::R8Unorm | F::R16Unorm | F::R16Float | F::R32Float
        )
    {
        return None;
    }
    let layout = BrickLayout::geometry(volume.dims(), brick_vox, 0);
    let source = TexelSource::of(volume);
    let format = encoding.format;
    let dims = volume.dims();
    let ranges = parallel(layout.count() as usize, &|| false, &|i| {
        let brick = layout.brick_at(i as u32);
        // Voxels [first, last] of each axis.
        let span: [(usize, usize); 3] = std::array::from_fn(|a| {
            let first = (brick[a] * brick_vox).saturating_sub(REACH);
            let last = ((brick[a] + 1) * brick_vox + REACH - 1).min(dims[a] - 1);
            (first as usize, last as usize)
        });
        let (row, plane) = (dims[0] as usize, dims[0] as usize * dims[1] as usize);
        let mut out = Vec::new();
        let mut lo = (f32::INFINITY, None);
        let mut hi = f32::NEG_INFINITY;
        for z in span[2].0..=span[2].1 {
            for y in span[1].0..=span[1].1 {
                let base = z * plane + y * row;
                out.clear();
                encode_texels(
                    &source,
                    encoding,
                    base + span[0].0..base + span[0].1 + 1,
                    &mut out,
                );
                for texel in out.chunks_exact(bytes_per_texel(format)) {
                    let (t, constant) = decode_texel(format, texel);
                    if t < lo.0 {
                        lo = (t, constant);
                    }
                    hi = hi.max(t);
                }
            }
        }
        // An f32 texel becomes the first f16 at or above the lowest, if the range reaches it.
        let constant = match format {
            F::R32Float => f16_at_least(lo.0)
                .filter(|h| h.to_f32() <= hi)
                .map(|h| u32::from(h.to_bits()) | CONSTANT_F16),
            _ => lo.1,
        };
        let decode = |t: f32| t * encoding.scale + encoding.bias;
        BrickRange {
            lo: decode(lo.0).min(decode(hi)),
            hi: decode(lo.0).max(decode(hi)),
            constant,
        }
    });
    ranges.into_iter().collect()
}

/// The smallest finite f16 at or above `t`.
fn f16_at_least(t: f32) -> Option<half::f16> {
    let h = half::f16::from_f32(t);
    if h.to_f32() >= t {
        return h.is_finite().then_some(h);
    }
    let bits = h.to_bits();
    let up = match bits {
        0x8000 => 1,
        b if b & 0x8000 == 0 => b + 1,
        b => b - 1,
    };
    let u = half::f16::from_bits(up);
    (u.is_finite() && u.to_f32() >= t).then_some(u)
}

/// A texel's value as the texture unit returns it, and its page-table constant (unorm16 bits,
/// or f16 bits with [`CONSTANT_F16`]) where one holds it exactly.
fn decode_texel(format: wgpu::TextureFormat, b: &[u8]) -> (f32, Option<u32>) {
    use wgpu::TextureFormat as F;
    match format {
        F::R8Unorm => (f32::from(b[0]) / 255.0, Some(u32::from(b[0]) * 257)),
        F::R16Unorm => {
            let v = u16::from_le_bytes([b[0], b[1]]);
            (f32::from(v) / 65535.0, Some(u32::from(v)))
        }
        F::R16Float => {
            let v = half::f16::from_le_bytes([b[0], b[1]]);
            (v.to_f32(), Some(u32::from(v.to_bits()) | CONSTANT_F16))
        }
        _ => (f32::from_le_bytes([b[0], b[1], b[2], b[3]]), None),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_plane_meets_the_bricks_it_crosses_and_a_slab_those_it_reaches() {
        let axial = SlicePlane {
            point: [0.0, 0.0, 40.0],
            normal: [0.0, 0.0, 1.0],
            half_thickness: 0.0,
        };
        let brick = |z: f64| ([0.0, 0.0, z], [32.0, 32.0, z + 32.0]);
        let (lo, hi) = brick(32.0);
        assert!(axial.meets(lo, hi, 0.0));
        let (lo, hi) = brick(64.0);
        assert!(!axial.meets(lo, hi, 4.0));
        let slab = SlicePlane {
            half_thickness: 30.0,
            ..axial
        };
        assert!(slab.meets(lo, hi, 0.0));
        let (lo, hi) = brick(0.0);
        assert!(!axial.meets(lo, hi, 4.0) && axial.meets(lo, hi, 8.0));
        let oblique = SlicePlane {
            point: [16.0, 16.0, 16.0],
            normal: [0.0, 0.6, 0.8],
            half_thickness: 0.0,
        };
        // The box (0, 0, 32)…(32, 32, 64): its nearest corner (0, 0, 32) is 3.2 voxels off
        // the plane (0.6·(0 − 16) + 0.8·(32 − 16)).
        let (lo, hi) = brick(32.0);
        assert!(!oblique.meets(lo, hi, 0.0) && oblique.meets(lo, hi, 4.0));
    }

    #[test]
    fn texels_decode_as_the_texture_unit_returns_them_and_constants_hold_them_exactly() {
        use wgpu::TextureFormat as F;
        let (v, c) = decode_texel(F::R8Unorm, &[51]);
        assert_eq!(v, 0.2);
        assert_eq!(c, Some(51 * 257));
        // unorm16 of the constant: 51·257 / 65535 = 51 / 255.
        assert_eq!((51.0f32 * 257.0) / 65535.0, 0.2);
        let (v, c) = decode_texel(F::R16Float, &half::f16::from_f32(0.75).to_le_bytes());
        assert_eq!(v, 0.75);
        assert_eq!(
            c,
            Some(u32::from(half::f16::from_f32(0.75).to_bits()) | CONSTANT_F16)
        );
        // An f32 texel's constant is the first f16 at or above it.
        for t in [0.1f32, -0.1, 0.5, 1e-9, -1e-9, 0.0] {
            let h = f16_at_least(t).expect("finite").to_f32();
            assert!(
                h >= t && f64::from(h - t) <= f64::from(t.abs()) / 1024.0 + 6e-8,
                "{t}: {h}"
            );
        }
        assert_eq!(f16_at_least(1e6), None);
    }
}
