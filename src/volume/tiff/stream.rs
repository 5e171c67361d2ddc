//! A TIFF stack larger than the memory budget, read where it lies ([`BrickSource`]). One pass
//! over its slices at opening halves them, pair by pair, into the coarse levels (those that fit
//! half the budget together are held whole) and counts the statistics of every voxel; a box of a
//! finer level is read from the strips or tiles of the slices it covers, decoded ones kept in a
//! [`Cache`], and halved as often as its level asks. Memory: the held levels, the cache, and a
//! slice per core during the pass.

use std::path::PathBuf;
use std::sync::{Arc, Mutex};

use rayon::prelude::*;

use super::{TiffDecoder, append, bad, open, reserved, same_shape, tiff_error};
use crate::volume::downsample::{Level, halve, halved_dims, level_dims};
use crate::volume::error::VolumeError;
use crate::volume::progress::LoadProgress;
use crate::volume::samples::{Samples, ScalarType, ValueMapping};
use crate::volume::stats::{Counts, Histogram, ValueRange};
use crate::volume::streamed::{BrickSource, Streamed, preview_level, voxels};
use crate::volume::tiles::{Cache, Tile, copy_overlap, empty};

/// Where a stack's slices are.
pub(super) enum Pages {
    /// Pages of one file (a multi-page stack, OME-TIFF, an ImageJ hyperstack), one per slice.
    File { path: PathBuf, pages: Vec<u64> },
    /// One file per slice.
    Folder(Vec<PathBuf>),
}

impl Pages {
    fn count(&self) -> usize {
        match self {
            Self::File { pages, .. } => pages.len(),
            Self::Folder(files) => files.len(),
        }
    }

    /// Slice `z` in words, for errors.
    fn name(&self, z: u32) -> String {
        match self {
            Self::File { pages, .. } => format!("page {}", pages[z as usize] + 1),
            Self::Folder(files) => files[z as usize]
                .file_name()
                .unwrap_or_default()
                .to_string_lossy()
                .into_owned(),
        }
    }
}

/// Statistics of every voxel: range, histogram, non-finite count.
pub(super) type Statistics = (Option<ValueRange>, Histogram, u64);

/// A stack streamed: its source, with the preview, and (8- and 16-bit) every voxel's statistics.
pub(super) struct Opened {
    pub(super) streamed: Streamed,
    pub(super) statistics: Option<Statistics>,
    /// The first level held whole, and its voxels.
    pub(super) first_held: (u32, [u32; 3]),
}

/// The source of a stack's boxes.
struct TiffSource {
    pages: Pages,
    dims: [u32; 3],
    scalar: ScalarType,
    /// Each slice's strip or tile size (x, y), as the pass found it.
    chunks: Vec<[u32; 2]>,
    /// Levels `first_held..` whole, finest first, down to one voxel.
    held: Vec<Tile>,
    first_held: u32,
    held_bytes: u64,
    /// The most bytes of decoded strips and tiles kept.
    budget: u64,
    cache: Mutex<Cache<[u32; 3]>>,
    /// Decoders of a multi-page file, each keeping its walk of the file's directories.
    decoders: Mutex<Vec<TiffDecoder>>,
}

/// Opens the stack `pages`, whose pages are `w` × `h` of `scalar`, streamed under `budget`
/// bytes: one pass over every slice (progress, cancel) builds the held levels.
pub(super) fn open_streamed(
    pages: Pages,
    (w, h, scalar): (u32, u32, ScalarType),
    budget: u64,
    progress: Option<&LoadProgress>,
) -> Result<Opened, VolumeError> {
    let depth = u32::try_from(pages.count()).map_err(|_| bad("too many slices"))?;
    let dims = [w, h, depth];
    let size = scalar.size_bytes() as u64;
    // Never level 0 whole: that is what streaming avoids.
    let preview = preview_level(dims, budget, scalar).max(1);
    let first_held = first_held(dims, size, budget / 2, preview);
    let mut source = TiffSource {
        pages,
        dims,
        scalar,
        chunks: Vec::new(),
        held: Vec::new(),
        first_held,
        held_bytes: 0,
        budget: 0,
        cache: Mutex::new(Cache::default()),
        decoders: Mutex::new(Vec::new()),
    };
    let (level, counts) = source.pass(progress)?;
    let mut d = level_dims(dims, first_held);
    let mut held = vec![Tile {
        samples: level,
        dims: d,
    }];
    while d != [1; 3] {
        let last = &held[held.len() - 1];
        let samples = halve(&last.samples, d);
        d = halved_dims(d, [true; 3]);
        held.push(Tile { samples, dims: d });
    }
    let held_bytes: u64 = held.iter().map(|t| t.samples.len() as u64 * size).sum();
    let preview_tile = &held[(preview - first_held) as usize];
    let preview_samples = Level {
        dims: preview_tile.dims,
        samples: preview_tile.samples.clone(),
        colour: None,
    };
    let preview_bytes = voxels(preview_tile.dims) * size;
    source.held = held;
    source.held_bytes = held_bytes;
    source.budget = budget.saturating_sub(held_bytes + preview_bytes);
    let statistics = counts.map(|c| c.statistics(ValueMapping::IDENTITY));
    let first = (first_held, level_dims(dims, first_held));
    let streamed = Streamed::new(Arc::new(source), dims, preview_samples, preview)?;
    Ok(Opened {
        streamed,
        statistics,
        first_held: first,
    })
}

/// The finest level (from 1, at most `most`) from which on every level of a volume of `dims`
/// fits `room` bytes together.
fn first_held(dims: [u32; 3], size: u64, room: u64, most: u32) -> u32 {
    let bytes_from = |k: u32| {
        let mut total = 0u64;
        let mut j = k;
        loop {
            let d = level_dims(dims, j);
            total += voxels(d) * size;
            if d == [1; 3] {
                return total;
            }
            j += 1;
        }
    };
    (1..most).find(|&k| bytes_from(k) <= room).unwrap_or(most)
}

/// Slices halved level by level as they come, down to one level: a slice of a finer level
/// waits for its pair (the last of an odd count is halved alone, as halving repeats it).
struct Cascade {
    /// Voxels of each level, from 0 to the last.
    dims: Vec<[u32; 3]>,
    waiting: Vec<Option<Samples>>,
    seen: Vec<u32>,
    /// The last level's slices.
    out: Vec<Samples>,
}

impl Cascade {
    fn new(dims: [u32; 3], to: u32) -> Self {
        let n = to as usize;
        Self {
            dims: (0..=to).map(|k| level_dims(dims, k)).collect(),
            waiting: (0..n).map(|_| None).collect(),
            seen: vec![0; n],
            out: Vec::new(),
        }
    }

    fn push(&mut self, level: usize, slice: Samples) {
        if level + 1 == self.dims.len() {
            self.out.push(slice);
            return;
        }
        let i = self.seen[level];
        self.seen[level] += 1;
        let [w, h, d] = self.dims[level];
        let pair = match self.waiting[level].take() {
            Some(first) => Samples::concat(vec![first, slice]),
            None if i + 1 == d => slice,
            None => {
                self.waiting[level] = Some(slice);
                return;
            }
        };
        let n = (pair.len() / (w as usize * h as usize)) as u32;
        let halved = halve(&pair, [w, h, n]);
        self.push(level + 1, halved);
    }

    fn finish(self) -> Samples {
        Samples::concat(self.out)
    }
}

impl TiffSource {
    /// Reads every slice once, a slice per core at a time, halving them into the first held
    /// level and counting their statistics (8- and 16-bit).
    fn pass(
        &mut self,
        progress: Option<&LoadProgress>,
    ) -> Result<(Samples, Option<Counts>), VolumeError> {
        let [w, h, d] = self.dims;
        let slice_bytes = u64::from(w) * u64::from(h) * self.scalar.size_bytes() as u64;
        if let Some(p) = progress {
            p.start(slice_bytes * u64::from(d));
        }
        let mut counts = Counts::for_type(self.scalar);
        let mut cascade = Cascade::new(self.dims, self.first_held);
        let group = crate::parallel::cores().max(1) as u32;
        for z0 in (0..d).step_by(group as usize) {
            if progress.is_some_and(LoadProgress::is_cancelled) {
                return Err(VolumeError::Cancelled);
            }
            let z1 = (z0 + group).min(d);
            let this = &*self;
            let slices: Vec<(Samples, [u32; 2])> = (z0..z1)
                .into_par_iter()
                .map(|z| this.read_slice(z))
                .collect::<Result<_, _>>()?;
            for (slice, chunk) in slices {
                self.chunks.push(chunk);
                if let Some(c) = counts.as_mut() {
                    c.add(&slice);
                }
                cascade.push(0, slice);
                if let Some(p) = progress {
                    p.advance(slice_bytes);
                }
            }
        }
        let level = cascade.finish();
        let want = voxels(level_dims(self.dims, self.first_held));
        if level.len() as u64 != want {
            return Err(bad(format!(
                "halving the stack gave {} voxels for {want}",
                level.len()
            )));
        }
        Ok((level, counts))
    }

    /// Runs `f` on a decoder at slice `z`'s page.
    fn with_page<T>(
        &self,
        z: u32,
        f: impl FnOnce(&mut TiffDecoder) -> Result<T, VolumeError>,
    ) -> Result<T, VolumeError> {
        match &self.pages {
            Pages::Folder(files) => f(&mut open(&files[z as usize])?),
            Pages::File { path, pages } => {
                let pooled = self.decoders.lock().ok().and_then(|mut d| d.pop());
                let mut decoder = match pooled {
                    Some(d) => d,
                    None => open(path)?,
                };
                let page = usize::try_from(pages[z as usize]).map_err(|_| bad("too many pages"))?;
                decoder.seek_to_image(page).map_err(tiff_error)?;
                let out = f(&mut decoder)?;
                if let Ok(mut pool) = self.decoders.lock() {
                    pool.push(decoder);
                }
                Ok(out)
            }
        }
    }

    /// Slice `z` whole, and its strip or tile size; a page of another shape than the first
    /// is refused.
    fn read_slice(&self, z: u32) -> Result<(Samples, [u32; 2]), VolumeError> {
        let [w, h, _] = self.dims;
        self.with_page(z, |decoder| {
            same_shape(decoder, (w, h, self.scalar), || self.pages.name(z))?;
            let (cw, ch) = decoder.chunk_dimensions();
            let mut samples = reserved(self.scalar, u64::from(w) * u64::from(h))?;
            append(&mut samples, decoder.read_image().map_err(tiff_error)?)?;
            if samples.len() as u64 != u64::from(w) * u64::from(h) {
                return Err(bad(format!(
                    "{} decodes to {} samples for {w} x {h}",
                    self.pages.name(z),
                    samples.len()
                )));
            }
            Ok((samples, [cw.clamp(1, w), ch.clamp(1, h)]))
        })
    }

    /// Strip or tile (`cx`, `cy`) of slice `z`, from the cache or decoded.
    fn tile(&self, z: u32, cx: u32, cy: u32) -> Result<Arc<Tile>, VolumeError> {
        let key = [cx, cy, z];
        if let Some(tile) = self.lock().get(&key) {
            return Ok(tile);
        }
        let [w, h, _] = self.dims;
        let [cw, ch] = self.chunks[z as usize];
        let index = cy * w.div_ceil(cw) + cx;
        let data = [cw.min(w - cx * cw), ch.min(h - cy * ch), 1];
        let decoded = self.with_page(z, |decoder| {
            if decoder.chunk_dimensions().0.clamp(1, w) != cw {
                return Err(bad(format!(
                    "{} changed its tiles since it was opened",
                    self.pages.name(z)
                )));
            }
            let mut s = reserved(self.scalar, u64::from(cw) * u64::from(ch))?;
            append(&mut s, decoder.read_chunk(index).map_err(tiff_error)?)?;
            Ok(s)
        })?;
        let n = decoded.len() as u64;
        let samples = if n == voxels(data) {
            decoded
        } else if n == u64::from(cw) * u64::from(ch) {
            // A padded edge tile: its data part.
            let padded = Tile {
                samples: decoded,
                dims: [cw, ch, 1],
            };
            let mut out = empty(self.scalar, voxels(data) as usize);
            copy_overlap(&padded, [0; 3], &mut out, ([0; 3], data));
            out
        } else {
            return Err(bad(format!(
                "a strip or tile of {} decodes to {n} samples for {} x {}",
                self.pages.name(z),
                data[0],
                data[1]
            )));
        };
        let tile = Arc::new(Tile {
            samples,
            dims: data,
        });
        self.lock().put(key, Arc::clone(&tile), self.budget);
        Ok(tile)
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, Cache<[u32; 3]>> {
        self.cache.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// The box `lo..hi` of level 0, from the strips or tiles it covers.
    fn read_level0(&self, lo: [u32; 3], hi: [u32; 3]) -> Result<Samples, VolumeError> {
        let dims: [u32; 3] = std::array::from_fn(|a| hi[a] - lo[a]);
        let mut out = empty(self.scalar, voxels(dims) as usize);
        for z in lo[2]..hi[2] {
            let [cw, ch] = self.chunks[z as usize];
            for cy in lo[1] / ch..=(hi[1] - 1) / ch {
                for cx in lo[0] / cw..=(hi[0] - 1) / cw {
                    let tile = self.tile(z, cx, cy)?;
                    copy_overlap(&tile, [cx * cw, cy * ch, z], &mut out, (lo, dims));
                }
            }
        }
        Ok(out)
    }
}

impl BrickSource for TiffSource {
    fn read_box(&self, level: u32, lo: [u32; 3], hi: [u32; 3]) -> Result<Samples, VolumeError> {
        let want: [u32; 3] = std::array::from_fn(|a| hi[a].saturating_sub(lo[a]));
        let d = level_dims(self.dims, level);
        if (0..3).any(|a| lo[a] >= hi[a] || hi[a] > d[a]) {
            return Err(bad(format!(
                "a box {lo:?}..{hi:?} of level {level} outside its {d:?} voxels"
            )));
        }
        if level >= self.first_held {
            let k = ((level - self.first_held) as usize).min(self.held.len() - 1);
            let mut out = empty(self.scalar, voxels(want) as usize);
            copy_overlap(&self.held[k], [0; 3], &mut out, (lo, want));
            return Ok(out);
        }
        let from: [u32; 3] = std::array::from_fn(|a| lo[a] << level);
        let to: [u32; 3] = std::array::from_fn(|a| {
            (u64::from(hi[a]) << level).min(u64::from(self.dims[a])) as u32
        });
        let mut samples = self.read_level0(from, to)?;
        let mut dims: [u32; 3] = std::array::from_fn(|a| to[a] - from[a]);
        for _ in 0..level {
            samples = halve(&samples, dims);
            dims = halved_dims(dims, [true; 3]);
        }
        if dims != want {
            return Err(bad(format!(
                "a box of level {level} came out {dims:?} voxels for {want:?}"
            )));
        }
        Ok(samples)
    }

    fn held_bytes(&self) -> u64 {
        self.held_bytes + self.lock().bytes()
    }

    fn budget_bytes(&self) -> u64 {
        self.held_bytes + self.budget
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_held_levels_are_the_finest_that_fit_together() {
        // 64³ of 2 bytes: level 1 is 64 KiB, level 2 8 KiB, the rest about 1.2 KiB.
        let dims = [64, 64, 64];
        assert_eq!(first_held(dims, 2, 80_000, 6), 1);
        assert_eq!(first_held(dims, 2, 60_000, 6), 2);
        assert_eq!(first_held(dims, 2, 5_000, 6), 3);
        // Never past the preview.
        assert_eq!(first_held(dims, 2, 0, 4), 4);
    }

    #[test]
    fn slices_halved_pair_by_pair_equal_the_volume_halved() {
        let dims = [5u32, 3, 7];
        let n = voxels(dims) as usize;
        let samples = Samples::U16((0..n).map(|i| ((i * 7919) % 1000) as u16).collect());
        let plane = 15;
        for to in 1..=3u32 {
            let mut cascade = Cascade::new(dims, to);
            for z in 0..7 {
                cascade.push(0, samples.slice(z * plane..(z + 1) * plane));
            }
            let mut want = samples.clone();
            let mut d = dims;
            for _ in 0..to {
                want = halve(&want, d);
                d = halved_dims(d, [true; 3]);
            }
            assert_eq!(cascade.finish(), want, "to level {to}");
        }
    }
}
