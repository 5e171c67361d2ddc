//! The bricked volume's residency on the GPU (`accel::residency` decides, this carries it out):
//! the levels' samples on the CPU, each brick of level 0's value range (`ranges`), what each
//! frame leaves unseen (`unseen`), the bricks encoded and written into their slots a batch at a
//! time (within a time budget where one is given), and the two page tables (the rays' and the
//! slices').

use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use super::atlas::{HeldBox, encode_brick, gpu_page};
use super::encoding::{TexelEncoding, TexelSource, bytes_per_texel};
use super::fetch::Fetcher;
use super::label_atlas::LabelAtlas;
use super::ranges::{BrickRange, brick_ranges};
use super::unseen::{REACH, Unseen, brick_box, footprint_levels, in_view};
use crate::accel::bricks::BrickLayout;
use crate::accel::residency::{
    BrickKey, NOT_NEEDED, PageTables, Residency, Wanted, at_level_0, dilate, index_to_brick,
};
use crate::parallel::parallel;
use crate::render::context::GpuContext;
use crate::volume::Volume;
use crate::volume::downsample::Level;
use rayon::prelude::*;

/// Bricks encoded and written per batch (about 1.3 MB of 16-bit slots): small enough that a
/// frame's upload time is kept to within a batch (64 took 7 ms on the H100 machine's host).
const BATCH: usize = 16;

/// Missing bricks a frame puts in order before uploading (the nearest of them; the rest wait):
/// more than a frame's time budget uploads on the H100 machine (about 300 at 8 ms).
const ORDERED: usize = 1024;

/// Which bricks of level 0 a frame needs: the finest level the rays need each at
/// ([`NOT_NEEDED`]: its constant), and whether the slices show it. A frame whose needs are
/// those residency was last decided for decides nothing.
#[derive(Clone, Debug, PartialEq, Eq)]
struct Needs {
    rays: Vec<u8>,
    slices: Vec<bool>,
}

/// The rays' needs under the rule alone (before the view): what they were computed for (the
/// rule's key and whether steps are long) and the answer; made again when the rule changes or
/// the value ranges arrive.
type RuleNeeds = (((u8, u64), bool), Vec<bool>);

/// How much one [`Resident::update`] may upload.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Pace {
    /// Time for the uploads (`None`: until nothing is missing).
    pub time: Option<Duration>,
    /// Level-0 page entries the bricks sent may stand for, at most (each update sends one
    /// brick at least).
    pub entries: usize,
    /// What a later update's bricks may stand for: where this one's are unbounded (the leaping
    /// pyramid is built whole this frame), the bricks that stand for more are sent past `time`
    /// (up to [`COARSE_TIME`] times it), as a later frame could only send each alone.
    pub later: usize,
}

impl Pace {
    /// Everything, at once.
    pub const ALL: Self = Self {
        time: None,
        entries: usize::MAX,
        later: usize::MAX,
    };
}

/// How many times its time budget a frame whose pyramid is built whole may spend sending the
/// bricks that a later frame could only send alone (a 2048 × 2048 × 1024 volume's 33 level-4
/// preview bricks: one sent alone took a 10-19 ms rebuild on the H100, §13-§14).
const COARSE_TIME: u32 = 4;

/// What one [`Resident::update`] did.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Update {
    /// Whether the page tables changed (the leaping pyramid, built through them, is stale).
    pub changed: bool,
    /// The level-0 bricks whose rays' page entry changed, where the page table was written
    /// before (else every brick is new).
    pub bricks: Option<Vec<[u32; 3]>>,
    /// Whether every wanted brick is resident.
    pub complete: bool,
}

/// How far residency is, for the overlay: one line.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ResidencyStatus {
    /// The finest level any data brick is wanted at (coarser ones where footprints allow).
    pub level: u32,
    /// The finest level at which every brick the rays need fits the budget (`level` is coarser
    /// where the footprints on screen ask for no finer).
    pub fits: u32,
    /// Levels the rays read (bit `k`: level `k`).
    pub levels: u32,
    /// Bricks resident.
    pub resident: usize,
    /// Bricks wanted.
    pub wanted: usize,
    /// Bricks wanted at the wanted level (the others: the coarsest and a preview).
    pub wanted_at_level: usize,
    /// Bricks wanted and not yet resident.
    pub missing: usize,
    /// Bricks of a streamed volume being read from its store.
    pub reading: usize,
    /// Whether residency is final: no wanted brick missing, and the bricks' value ranges in
    /// (until they are, every brick counts as needing data).
    pub complete: bool,
    /// Bricks of level 0 served by a constant.
    pub constant: usize,
    /// Bytes the resident bricks take.
    pub bytes: u64,
}

impl ResidencyStatus {
    /// The levels the rays read, as a list ("0, 2").
    pub fn levels_read(&self) -> String {
        let levels: Vec<String> = (0..u32::BITS)
            .filter(|l| self.levels & (1 << l) != 0)
            .map(|l| l.to_string())
            .collect();
        levels.join(", ")
    }
}

/// A bricked volume's residency: what the atlas holds and how to fill it.
pub struct Resident {
    volume: Arc<Volume>,
    levels: Vec<Level>,
    encoding: TexelEncoding,
    brick_vox: u32,
    residency: Residency,
    ranges: Option<Vec<BrickRange>>,
    /// The ranges while a worker still computes them: until then every brick needs data, and
    /// the first picture need not wait for a pass over the whole volume.
    ranges_coming: Option<JoinHandle<Option<Vec<BrickRange>>>>,
    rays: wgpu::Buffer,
    /// What the page tables were last written with (`None` before the first write).
    written: Option<Written>,
    /// The page tables are to be written whole in the next update: the frame the ranges
    /// arrived in decided residency with them, the next writes the tables (each took 3.7-6.8 ms at
    /// 2048 × 2048 × 1024 on the H100 machine's CPU, docs/benchmarks/nvidia-h100-bricks-stream
    /// §15); neither sends bricks.
    pages_due: bool,
    slices: wgpu::Buffer,
    decided_for: Option<Needs>,
    by_rule: Option<RuleNeeds>,
    wanted: Option<Wanted>,
    status: ResidencyStatus,
    /// How long the last page-table write took.
    pages_took: Duration,
    /// Bytes of bricks an update sends before it waits for the GPU to take them (what wgpu's
    /// staging copies hold at most, besides the batch being written).
    staging_most: u64,
    /// A streamed volume's readers: under a time budget, bricks are read off the frame's
    /// thread and sent once read.
    fetcher: Option<Fetcher>,
    /// A segmentation travelling in the bricks: each brick's labels go into the same slot of
    /// this atlas.
    labels: Option<LabelAtlas>,
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
        staging_most: u64,
    ) -> Self {
        let residency = Residency::new(volume.dims(), brick_vox, slots, capacity);
        let started = Instant::now();
        let mut levels: Vec<Level> = Vec::new();
        // A streamed volume's store holds its levels: they are read brick by brick.
        if let Some(samples) = volume.samples() {
            for _ in 1..residency.levels() {
                let next = match levels.last() {
                    Some(l) => l.halved(),
                    None => Level::half_of(samples, volume.colour(), volume.dims()),
                };
                levels.push(next);
            }
        }
        log::debug!(
            "{} coarser levels halved in {:.0} ms",
            levels.len(),
            started.elapsed().as_secs_f64() * 1e3
        );
        let pages = residency.grid(0);
        // Ranges only matter where not every brick of level 0 fits.
        let all = residency.page_count() as u64 + u64::from(residency.levels() > 1);
        // A streamed volume's ranges would read the whole store: every brick needs data.
        let whole = volume.samples().is_some() && volume.colour().is_none();
        let (ranges, ranges_coming) = if all > u64::from(capacity) && whole {
            match ranges_worker(Arc::clone(&volume), encoding, brick_vox) {
                Ok(worker) => (None, Some(worker)),
                Err(e) => {
                    log::warn!("no thread for the bricks' value ranges ({e}): computed first");
                    let cores = crate::parallel::cores();
                    (brick_ranges(&volume, &encoding, brick_vox, cores), None)
                }
            }
        } else {
            (None, None)
        };
        let fetcher = volume.streaming().and_then(|streamed| {
            let threads = streamed.readers();
            let (volume, encoding) = (Arc::clone(&volume), encoding);
            let encode: super::fetch::Encode =
                Arc::new(move |key| encode_streamed(&volume, &encoding, brick_vox, key));
            Fetcher::new(threads, encode)
                .map_err(|e| log::warn!("no threads to read bricks on ({e}): frames read them"))
                .ok()
        });
        Self {
            fetcher,
            labels: None,
            rays: page_table(ctx, pages, "volume page table (rays)"),
            slices: page_table(ctx, pages, "volume page table (slices)"),
            written: None,
            pages_due: false,
            volume,
            levels,
            encoding,
            brick_vox,
            residency,
            ranges,
            ranges_coming,
            decided_for: None,
            by_rule: None,
            wanted: None,
            status: ResidencyStatus::default(),
            pages_took: Duration::ZERO,
            staging_most,
        }
    }

    /// The rays' page table.
    pub fn rays_pages(&self) -> &wgpu::Buffer {
        &self.rays
    }

    /// The slices' page table.
    pub fn slice_pages(&self) -> &wgpu::Buffer {
        &self.slices
    }

    /// Levels of the volume the bricks may be held at.
    pub(super) fn levels(&self) -> u32 {
        self.residency.levels()
    }

    /// The label atlas, where a segmentation travels in the bricks.
    pub(super) fn labels(&self) -> Option<&LabelAtlas> {
        self.labels.as_ref()
    }

    /// Takes `atlas` as the bricks' labels (`None`: none), writing every resident brick's
    /// labels into it at once (all cores encode).
    pub(super) fn set_labels(&mut self, ctx: &GpuContext, atlas: Option<LabelAtlas>) {
        self.labels = atlas;
        if self.labels.is_none() {
            return;
        }
        let held: Vec<(BrickKey, u32)> = (self.residency.held_slots())
            .map(|(slot, key)| (key, slot))
            .collect();
        for batch in held.chunks(BATCH * 4) {
            self.upload_labels(ctx, batch);
            // One batch's staging copies in memory at a time.
            ctx.queue.submit([]);
        }
    }

    /// Encodes the labels of the bricks `given` (on all cores) and writes each into its slot
    /// of the label atlas, where there is one.
    fn upload_labels(&self, ctx: &GpuContext, given: &[(BrickKey, u32)]) {
        let Some(atlas) = &self.labels else {
            return;
        };
        let s = self.brick_vox + 2;
        let encoded = parallel(given.len(), &|| false, &|k| {
            let (key, _) = given[k];
            atlas.encode(key.level, key.brick)
        });
        for ((_, slot), texels) in given.iter().zip(encoded) {
            let Some(texels) = texels else { continue };
            let at = self.residency.slot_coords(*slot);
            atlas.write(ctx, at.map(|a| a * s), s, &texels);
        }
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

    /// Decides what `cull` lets the rays go without (again, only when it changed), then
    /// uploads missing bricks, coarsest first, until none is missing, `time` has passed or the
    /// bricks sent stand for `entries` level-0 page entries (each at least one brick), and
    /// rewrites the page tables where anything changed.
    pub fn update(
        &mut self,
        ctx: &GpuContext,
        atlas: &wgpu::Texture,
        unseen: &Unseen,
        pace: Pace,
    ) -> Update {
        let Pace { time, entries, .. } = pace;
        let start = Instant::now();
        let drawn = self.written.is_some();
        // Under a time budget, after the first frame, the ranges' arrival is spread over two
        // frames that send no bricks: this one decides, the next writes the tables whole.
        let arrived = self.receive_ranges(time.is_none()) && drawn && time.is_some();
        let writes_whole = std::mem::take(&mut self.pages_due);
        self.pages_due = arrived;
        let needs = self.needs_data(unseen);
        let decided_at = start.elapsed();
        let mut changed = writes_whole;
        // An orbit changes the frustum every frame, mostly not the bricks it needs.
        if self.decided_for.as_ref() != Some(&needs) {
            let wanted = self.residency.decide_levels(&needs.rays, &needs.slices);
            log::debug!(
                "residency decided in {:.2} ms ({:.2} the needs): {} bricks wanted at level {}",
                start.elapsed().as_secs_f64() * 1e3,
                decided_at.as_secs_f64() * 1e3,
                wanted.bricks.len(),
                wanted.level
            );
            if self.wanted.as_ref() != Some(&wanted) {
                self.residency.want(&wanted);
                self.wanted = Some(wanted);
                changed = true;
            }
            self.decided_for = Some(needs);
        }
        let decided = start.elapsed();
        let Some(wanted) = self.wanted.take() else {
            return Update::default();
        };
        let mut queue = self.upload_order(&wanted, unseen.eye, time.is_some());
        if let (Some(fetcher), Some(_)) = (&mut self.fetcher, time) {
            // The coarsest level is read here (a brick or a few: the first picture); the rest
            // is sent once the readers have it.
            let coarsest = self.residency.levels() - 1;
            let asked: Vec<BrickKey> = (queue.iter().take(ORDERED))
                .filter(|k| k.level != coarsest)
                .copied()
                .collect();
            fetcher.ask(&asked);
            queue.retain(|k| k.level == coarsest || fetcher.is_ready(k));
        }
        let sorted = start.elapsed();
        let mut rest = &queue[..];
        let (mut sent, mut encoding) = (0, Duration::ZERO);
        let (mut staged, mut covered) = (0, 0);
        let grid = self.residency.grid(0);
        // (An update without a time budget sends as usual, the whole write due or not.)
        let sends = !(arrived || (writes_whole && time.is_some()));
        while sends && !rest.is_empty() {
            let fit = fitting(rest, grid, entries.saturating_sub(covered), sent == 0);
            let given = self.residency.admit(rest, fit);
            if given.is_empty() {
                break;
            }
            covered += given.iter().map(|(k, _)| covers(grid, k)).sum::<usize>();
            if let (Some(fetcher), None) = (&mut self.fetcher, time) {
                // Without a time budget the frame waits for its bricks: read by all readers
                // at once (a remote store's round trips overlap), those after them asked for
                // meanwhile.
                let keys: Vec<BrickKey> = given.iter().map(|(k, _)| *k).collect();
                let ahead =
                    &rest[given.len()..rest.len().min(given.len() + super::fetch::IN_FLIGHT)];
                fetcher.wait_for(&keys, ahead);
            }
            rest = &rest[given.len()..];
            sent += given.len();
            let (took, bytes, submitted) = self.upload(ctx, atlas, &given);
            encoding += took;
            // The staging copies wgpu holds until the GPU has taken them: bounded, and no
            // wait for the GPU (nor the frame it is drawing) below that bound.
            staged += bytes;
            if staged > self.staging_most {
                let _ = ctx.device.poll(wgpu::PollType::Wait {
                    submission_index: Some(submitted),
                    timeout: None,
                });
                staged = 0;
            }
            changed = true;
            // The page tables are written after the uploads: their last time is kept back.
            let next = rest.first().map(|k| covers(grid, k));
            if !goes_on(&pace, start.elapsed() + self.pages_took, next) {
                break;
            }
        }
        let uploaded = start.elapsed();
        let missing = self.residency.missing(&wanted);
        self.status.missing = missing;
        self.status.reading = self.fetcher.as_ref().map_or(0, Fetcher::in_flight);
        self.status.complete = missing == 0 && self.ranges_coming.is_none() && !self.pages_due;
        let mut bricks = None;
        if arrived {
            // The tables as written still hold what they point at: nothing was evicted.
            changed = false;
        } else if changed {
            bricks = self.write_pages(ctx, &wanted);
            self.pages_took = start.elapsed() - uploaded;
            self.status.resident = self.residency.resident_count();
            self.status.wanted = wanted.bricks.len();
            self.status.wanted_at_level = wanted
                .bricks
                .iter()
                .filter(|k| k.level == wanted.level)
                .count();
            self.status.level = wanted.level;
            self.status.fits = wanted.fits;
            self.status.bytes = self.status.resident as u64
                * u64::from(self.brick_vox + 2).pow(3)
                * bytes_per_texel(self.encoding.format) as u64;
        }
        self.wanted = Some(wanted);
        log::debug!(
            "residency update: decided {:.2} ms, sorted {:.2}, uploaded {:.2} ({sent} bricks, \
             encoding {:.2}), pages {:.2}",
            decided.as_secs_f64() * 1e3,
            (sorted - decided).as_secs_f64() * 1e3,
            (uploaded - sorted).as_secs_f64() * 1e3,
            encoding.as_secs_f64() * 1e3,
            (start.elapsed() - uploaded).as_secs_f64() * 1e3,
        );
        Update {
            changed,
            bricks,
            complete: self.status.complete,
        }
    }

    /// Takes the bricks' value ranges once the worker has them (`wait`: waits for them), and
    /// has residency decided again with them; returns whether they arrived now.
    fn receive_ranges(&mut self, wait: bool) -> bool {
        if !self
            .ranges_coming
            .as_ref()
            .is_some_and(|w| wait || w.is_finished())
        {
            return false;
        }
        let Some(worker) = self.ranges_coming.take() else {
            return false;
        };
        // A worker that panicked leaves every brick needing data, as without ranges.
        self.ranges = worker.join().ok().flatten();
        self.decided_for = None;
        self.by_rule = None;
        // Every brick may now read a constant: the page tables are written whole.
        self.written = None;
        log::debug!("brick value ranges arrived");
        true
    }

    /// The wanted bricks that are missing, in the order they are uploaded: the coarsest
    /// first, then coarser levels (the preview) before finer, each nearest `eye` first; where
    /// the upload has a time budget (`budgeted`), only the first [`ORDERED`] are put in order.
    fn upload_order(
        &self,
        wanted: &Wanted,
        eye: Option<[f64; 3]>,
        budgeted: bool,
    ) -> Vec<BrickKey> {
        let mut missing: Vec<BrickKey> = (wanted.bricks.iter())
            .filter(|k| !self.residency.is_resident(k))
            .copied()
            .collect();
        let (Some(eye), Some((first, _))) = (eye, wanted.bricks.split_first()) else {
            return missing;
        };
        let b = f64::from(self.brick_vox);
        let distance = |k: &BrickKey| {
            let size = b * f64::from(1u32 << k.level);
            (0..3)
                .map(|a| ((f64::from(k.brick[a]) + 0.5) * size - eye[a]).powi(2))
                .sum::<f64>()
        };
        let coarsest = missing.first() == Some(first);
        let from = usize::from(coarsest);
        // Each brick's distance once, not once per comparison.
        let mut order: Vec<(u32, f64, BrickKey)> = missing[from..]
            .iter()
            .map(|k| (k.level, distance(k), *k))
            .collect();
        let before = |p: &(u32, f64, BrickKey), q: &(u32, f64, BrickKey)| {
            q.0.cmp(&p.0).then(p.1.total_cmp(&q.1))
        };
        if budgeted && order.len() > ORDERED {
            order.select_nth_unstable_by(ORDERED, before);
            order[..ORDERED].sort_by(before);
        } else {
            order.sort_by(before);
        }
        missing.truncate(from);
        missing.extend(order.into_iter().map(|(_, _, k)| k));
        missing
    }

    /// Which bricks of level 0 the rays need the data of: those `unseen` does not empty (over
    /// the brick and [`REACH`] around it), with their neighbours where steps are longer than
    /// that covers, and any without a constant, in the view frustum, each at the level its
    /// footprint needs where `unseen` asks for that (else level 0); and which the slices show
    /// (within [`REACH`] of a plane or its slab), where the rays leave some out or coarser.
    fn needs_data(&mut self, unseen: &Unseen) -> Needs {
        let n = self.residency.page_count();
        let grid = self.residency.grid(0);
        let rule = (unseen.cull.key(), unseen.long_steps);
        let by_rule = match &self.by_rule {
            Some((made_for, rays)) if *made_for == rule => rays,
            _ => {
                let rays = self.needs_by_rule(unseen);
                &self.by_rule.insert((rule, rays)).1
            }
        };
        let mut rays = at_level_0(by_rule);
        let b = f64::from(self.brick_vox);
        // The view decides only where not every brick fits.
        if let Some(clip) = unseen.frustum
            && !self.residency.holds_everything()
        {
            let in_view = in_view(&clip, grid, b, f64::from(REACH));
            for (need, seen) in rays.iter_mut().zip(in_view) {
                if !seen {
                    *need = NOT_NEEDED;
                }
            }
            if let Some(size) = unseen.footprint {
                let levels = self.residency.levels();
                let needed = footprint_levels(&clip, size, grid, b, levels);
                for (need, level) in rays.iter_mut().zip(needed) {
                    if *need != NOT_NEEDED {
                        *need = level;
                    }
                }
            }
        }
        // Slices matter only where the rays leave bricks out, or hold them coarser.
        let slices = if unseen.slices.is_empty() || rays.iter().all(|&r| r == 0) {
            Vec::new()
        } else {
            (0..n)
                .map(|i| {
                    let (lo, hi) = brick_box(i, grid, b);
                    (unseen.slices.iter()).any(|s| s.meets(lo, hi, f64::from(REACH)))
                })
                .collect()
        };
        Needs { rays, slices }
    }

    /// The rays' needs under the mode's rule alone (see [`Self::needs_data`]).
    fn needs_by_rule(&self, unseen: &Unseen) -> Vec<bool> {
        let Some(ranges) = &self.ranges else {
            return vec![true; self.residency.page_count()];
        };
        let seen: Vec<bool> = ranges
            .par_iter()
            .map(|r| !unseen.cull.is_empty(r.lo, r.hi))
            .collect();
        let mut rays = if unseen.long_steps {
            dilate(&seen, self.residency.grid(0))
        } else {
            seen
        };
        for (need, range) in rays.iter_mut().zip(ranges) {
            *need |= range.constant.is_none();
        }
        rays
    }

    /// Encodes `given` (on all cores) and writes each into its slot; returns how long the
    /// encoding took, the bytes sent and the submission that sends them.
    fn upload(
        &mut self,
        ctx: &GpuContext,
        atlas: &wgpu::Texture,
        given: &[(BrickKey, u32)],
    ) -> (Duration, u64, wgpu::SubmissionIndex) {
        let start = Instant::now();
        let s = self.brick_vox + 2;
        let bpt = bytes_per_texel(self.encoding.format) as u32;
        // What the readers have read already.
        let read: Vec<Option<Vec<u8>>> = match &mut self.fetcher {
            Some(f) => given.iter().map(|(k, _)| f.take(k)).collect(),
            None => vec![None; given.len()],
        };
        let encoded = parallel(given.len(), &|| false, &|k| {
            let (key, _) = given[k];
            if let Some(bytes) = &read[k] {
                return bytes.clone();
            }
            if self.volume.streaming().is_some() {
                return encode_streamed(&self.volume, &self.encoding, self.brick_vox, key);
            }
            let layout = BrickLayout::geometry(self.volume.dims(), self.brick_vox, key.level);
            let mut out = Vec::new();
            let source = match key.level {
                0 => TexelSource::of(&self.volume),
                l => TexelSource::level(&self.volume, &self.levels[l as usize - 1]),
            };
            let held = HeldBox::whole(&layout);
            encode_brick(
                &source,
                &self.encoding,
                (&layout, held),
                key.brick,
                &mut out,
            );
            out
        });
        let encoded_in = start.elapsed();
        let mut sent = 0;
        for ((_, slot), bytes) in given.iter().zip(encoded) {
            let Some(bytes) = bytes else { continue };
            sent += bytes.len() as u64;
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
        self.upload_labels(ctx, given);
        (encoded_in, sent, ctx.queue.submit([]))
    }

    /// Writes both page tables for `wanted` as residency stands (the entries that may have
    /// changed converted again and sent); returns the level-0 bricks whose rays' entry changed
    /// (`None` where the tables are new).
    fn write_pages(&mut self, ctx: &GpuContext, wanted: &Wanted) -> Option<Vec<[u32; 3]>> {
        let constants: Vec<Option<u32>> = match &self.ranges {
            Some(r) => r.iter().map(|r| r.constant).collect(),
            None => Vec::new(),
        };
        let mut written = self.written.take().unwrap_or_default();
        let refreshed = self.residency.refresh_page_tables(
            &mut written.tables,
            &written.constant,
            wanted,
            &constants,
        );
        written.constant.clone_from(&wanted.constant);
        let tables = &written.tables;
        self.status.levels = tables.levels;
        self.status.constant = tables
            .rays
            .iter()
            .filter(|&&e| e & crate::accel::residency::CONSTANT != 0)
            .count();
        let pages = self.residency.grid(0);
        let n = tables.rays.len();
        written.rays.resize(n, [0; 4]);
        written.slices.resize(n, [0; 4]);
        let every: Vec<usize>;
        let looked_at = match &refreshed.looked_at {
            Some(some) => some,
            None => {
                every = (0..n).collect();
                &every
            }
        };
        let convert = |i: usize| {
            let brick = index_to_brick(i as u32, pages);
            (
                gpu_page(tables.rays[i], brick, self.brick_vox),
                gpu_page(tables.slices[i], brick, self.brick_vox),
            )
        };
        if refreshed.looked_at.is_none() {
            // The whole table (131 072 entries at 2048 × 2048 × 1024) on all cores.
            (written.rays, written.slices) = (0..n).into_par_iter().map(convert).unzip();
        } else {
            for &i in looked_at {
                (written.rays[i], written.slices[i]) = convert(i);
            }
        }
        write_page_table(ctx, &self.rays, &written.rays, looked_at);
        write_page_table(ctx, &self.slices, &written.slices, looked_at);
        let changed = (refreshed.rays_changed).map(|c| {
            c.into_iter()
                .map(|i| index_to_brick(i as u32, pages))
                .collect()
        });
        self.written = Some(written);
        changed
    }
}

/// How many of `queue`'s first bricks (at most a batch) stand for no more than `room` level-0
/// page entries of a volume of `grid` level-0 bricks; at least one where `first`.
fn fitting(queue: &[BrickKey], grid: [u32; 3], room: usize, first: bool) -> usize {
    let mut used = 0;
    let fit = (queue.iter().take(BATCH))
        .take_while(|k| {
            used += covers(grid, k);
            used <= room
        })
        .count();
    fit.max(usize::from(first))
}

/// Whether an update that has `spent` this long goes on sending, the next brick standing for
/// `next` level-0 entries (`None`: none is left).
fn goes_on(pace: &Pace, spent: Duration, next: Option<usize>) -> bool {
    let Some(time) = pace.time else {
        return true;
    };
    let coarse = pace.entries == usize::MAX
        && next.is_some_and(|n| n > pace.later)
        && spent < time * COARSE_TIME;
    coarse || spent < time
}

/// The level-0 page entries (of a volume of `grid` level-0 bricks) that a brick stands in for.
fn covers(grid: [u32; 3], key: &BrickKey) -> usize {
    let edge = 1u32 << key.level;
    (0..3)
        .map(|a| grid[a].saturating_sub(key.brick[a] * edge).min(edge) as usize)
        .product()
}

/// The page tables as last written: for the residency's refresh, and as the GPU holds them.
#[derive(Default)]
struct Written {
    /// Both tables as the residency gives them.
    tables: PageTables,
    /// The constant flags they were made with.
    constant: Vec<bool>,
    /// The GPU's copies (`gpu_page`).
    rays: Vec<[u32; 4]>,
    slices: Vec<[u32; 4]>,
}

/// An empty page table of `pages` entries per axis.
fn page_table(ctx: &GpuContext, pages: [u32; 3], label: &str) -> wgpu::Buffer {
    let n = pages.iter().map(|&p| u64::from(p)).product();
    super::atlas::page_buffer(ctx, n, label)
}

/// Writes the runs of `entries` (x fastest) that `looked_at` (ascending) touches into the page
/// table `table`: a refresh sends what it changed, not the whole table.
fn write_page_table(
    ctx: &GpuContext,
    table: &wgpu::Buffer,
    entries: &[[u32; 4]],
    looked_at: &[usize],
) {
    for (first, last) in write_runs(looked_at) {
        ctx.queue.write_buffer(
            table,
            first as u64 * super::atlas::PAGE_BYTES,
            bytemuck::cast_slice(&entries[first..=last]),
        );
    }
}

/// Entries closer than this are sent in one write: each write costs a staging allocation of
/// its own, more than sending a few kilobytes between two runs.
const RUN_GAP: usize = 256;
/// Writes per refresh past which the span from the first entry to the last goes as one (a
/// preview brick of level 3 touches 512 entries of level 0 in 8 planes, its 32 a frame
/// hundreds of runs; the whole span is at most 2 MB at 2048 × 2048 × 1024).
const MOST_RUNS: usize = 16;

/// The runs (first, last entry) that [`write_page_table`] writes for `looked_at` (ascending).
fn write_runs(looked_at: &[usize]) -> Vec<(usize, usize)> {
    let mut runs: Vec<(usize, usize)> = Vec::new();
    for &i in looked_at {
        match runs.last_mut() {
            Some((_, last)) if i <= *last + RUN_GAP => *last = i,
            _ => runs.push((i, i)),
        }
    }
    if runs.len() > MOST_RUNS
        && let (Some(&(first, _)), Some(&(_, last))) = (runs.first(), runs.last())
    {
        return vec![(first, last)];
    }
    runs
}

/// The slot of brick `key` of a streamed volume (bricks of `brick_vox`), read from its store
/// and encoded.
fn encode_streamed(
    volume: &Volume,
    encoding: &TexelEncoding,
    brick_vox: u32,
    key: BrickKey,
) -> Vec<u8> {
    let mut out = Vec::new();
    let Some(streamed) = volume.streaming() else {
        return out;
    };
    let layout = BrickLayout::geometry(volume.dims(), brick_vox, key.level);
    let held = HeldBox::slot(&layout, key.brick);
    let samples = read_slot(streamed, key.level, held);
    let source = TexelSource::of(volume).with_samples(&samples);
    encode_brick(&source, encoding, (&layout, held), key.brick, &mut out);
    out
}

/// The samples of box `held` of `level` of a streamed volume, as its store gives them; where
/// the store fails, the preview's voxels that cover it (said in the log; the store's reader
/// says which of its chunks failed).
fn read_slot(
    streamed: &crate::volume::streamed::Streamed,
    level: u32,
    held: HeldBox,
) -> crate::volume::Samples {
    let hi = std::array::from_fn(|a| held.origin[a] + held.dims[a]);
    match streamed.read_box(level, held.origin, hi) {
        Ok(samples) => samples,
        Err(e) => {
            log::warn!("a brick of level {level} could not be read ({e}): its preview shows");
            streamed.preview_box(level, held.origin, hi)
        }
    }
}

/// Computes the bricks' value ranges on a thread of their own (on half the cores).
fn ranges_worker(
    volume: Arc<Volume>,
    encoding: TexelEncoding,
    brick_vox: u32,
) -> std::io::Result<JoinHandle<Option<Vec<BrickRange>>>> {
    std::thread::Builder::new()
        .name("brick ranges".into())
        .spawn(move || {
            let started = Instant::now();
            // Half the cores: the other half keep the frames going meanwhile (with all of them,
            // frames took 120-140 ms for the 3.2 s the ranges took at 2048 x 2048 x 1024 on the
            // H100 machine's 16-core host, 48 ms once they were in).
            let threads = (crate::parallel::cores() / 2).max(1);
            // On a pool of its own: tasks of seconds on rayon's global pool held a frame's
            // residency decision (a parallel iteration there, whose waiting thread took one
            // up) for the whole 5.4 s the ranges took at 2048 x 2048 x 1024 on the H100 machine.
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .thread_name(|i| format!("brick ranges {i}"))
                .build();
            let ranges = match pool {
                Ok(pool) => pool.install(|| brick_ranges(&volume, &encoding, brick_vox, threads)),
                Err(_) => brick_ranges(&volume, &encoding, brick_vox, threads),
            };
            log::debug!(
                "brick value ranges in {:.0} ms",
                started.elapsed().as_secs_f64() * 1e3
            );
            ranges
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_brick_stands_for_the_level_0_entries_inside_its_box_and_a_frame_takes_what_fits() {
        let grid = [10, 8, 3];
        let key = |level, brick| BrickKey { level, brick };
        assert_eq!(covers(grid, &key(0, [9, 7, 2])), 1);
        assert_eq!(covers(grid, &key(2, [0, 0, 0])), 4 * 4 * 3);
        // At the far border only what lies inside: 10 - 8 = 2 across, 8 - 4 = 4, 3 deep.
        assert_eq!(covers(grid, &key(2, [2, 1, 0])), 2 * 4 * 3);
        assert_eq!(covers(grid, &key(4, [0, 0, 0])), 10 * 8 * 3);
        let queue = [key(2, [0, 0, 0]), key(2, [1, 0, 0]), key(0, [0, 0, 0])];
        assert_eq!(fitting(&queue, grid, 48, false), 1);
        assert_eq!(fitting(&queue, grid, 97, false), 3);
        assert_eq!(fitting(&queue, grid, 96, false), 2);
        assert_eq!(fitting(&queue, grid, 10, false), 0);
        assert_eq!(fitting(&queue, grid, 10, true), 1);
        assert_eq!(
            fitting(&[key(0, [0, 0, 0]); 40], grid, usize::MAX, false),
            BATCH
        );
    }

    #[test]
    fn a_frame_that_builds_the_pyramid_whole_sends_the_coarse_bricks_past_its_time() {
        let ms = Duration::from_millis;
        let whole = Pace {
            time: Some(ms(8)),
            entries: usize::MAX,
            later: 1024,
        };
        assert!(goes_on(&whole, ms(7), Some(64)));
        assert!(!goes_on(&whole, ms(8), Some(64)));
        // A brick that a later frame could only send alone: up to four times the time.
        assert!(goes_on(&whole, ms(20), Some(4096)));
        assert!(!goes_on(&whole, ms(32), Some(4096)));
        // A later frame (its entries bounded) stops at its time whatever comes next.
        let later = Pace {
            entries: 1024,
            ..whole
        };
        assert!(!goes_on(&later, ms(9), Some(4096)));
        assert!(goes_on(&Pace::ALL, ms(1000), Some(4096)));
    }

    #[test]
    fn page_writes_cover_every_entry_looked_at_in_few_ascending_runs() {
        // Runs of four in planes of a 64 × 64 grid, as a level-2 brick's entries fall.
        let plane: Vec<usize> = (0..4)
            .flat_map(|y| (0..4).map(move |x| x + 64 * y))
            .collect();
        for planes in [1, 4, 40] {
            let looked_at: Vec<usize> = (0..planes)
                .flat_map(|z| plane.iter().map(move |i| i + 4096 * z + 7))
                .collect();
            let runs = write_runs(&looked_at);
            assert!(runs.len() <= MOST_RUNS && !runs.is_empty());
            assert!(runs.windows(2).all(|w| w[0].1 < w[1].0));
            for i in &looked_at {
                assert_eq!(runs.iter().filter(|r| r.0 <= *i && *i <= r.1).count(), 1);
            }
            // Nothing outside the span of what was looked at is written.
            assert_eq!(runs[0].0, looked_at[0]);
            assert_eq!(runs[runs.len() - 1].1, *looked_at.last().unwrap_or(&0));
        }
        assert!(write_runs(&[]).is_empty());
    }
}
