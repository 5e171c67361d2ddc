//! Volumes read where they live: the samples of a volume too large to hold whole stay in their
//! store (an OME-Zarr store, a TIFF stack) and are read a box of one level at a time, as the
//! GPU's bricks ask for them. A coarse level, the preview, is held whole for what needs every
//! voxel at once: the statistics, `info`, a hovered voxel's value.

use std::sync::Arc;

use super::downsample::{Level, level_dims};
use super::error::VolumeError;
use super::samples::{Samples, ScalarType};

/// Where a streamed volume's samples are read from.
pub trait BrickSource: Send + Sync {
    /// The box `lo..hi` (x, y, z voxels of level `level`, inside `level_dims(dims, level)`) of
    /// level `level` as LeapView halves the volume ([`super::downsample`]), x fastest, in the
    /// volume's stored type.
    fn read_box(&self, level: u32, lo: [u32; 3], hi: [u32; 3]) -> Result<Samples, VolumeError>;

    /// Bytes the source holds in memory now (its cache of decoded chunks).
    fn held_bytes(&self) -> u64;

    /// The most bytes its cache may hold.
    fn budget_bytes(&self) -> u64;

    /// How many boxes are best read at once (the cores; more where reads wait on a network).
    fn readers(&self) -> usize {
        crate::parallel::cores()
    }
}

/// A volume's samples read from a [`BrickSource`], with the preview held whole.
#[derive(Clone)]
pub struct Streamed {
    source: Arc<dyn BrickSource>,
    dims: [u32; 3],
    preview: Level,
    preview_level: u32,
    /// Whether x is read reversed (the volume was unmirrored, `Volume::unmirrored`).
    reversed_x: bool,
}

impl std::fmt::Debug for Streamed {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Streamed")
            .field("dims", &self.dims)
            .field("preview_level", &self.preview_level)
            .field("reversed_x", &self.reversed_x)
            .finish_non_exhaustive()
    }
}

impl Streamed {
    /// The samples of a volume of `dims` read from `source`, with level `preview_level` held
    /// whole as `preview`.
    pub fn new(
        source: Arc<dyn BrickSource>,
        dims: [u32; 3],
        preview: Level,
        preview_level: u32,
    ) -> Result<Self, VolumeError> {
        let expected = level_dims(dims, preview_level);
        if preview.dims != expected || preview.samples.len() as u64 != voxels(expected) {
            return Err(VolumeError::SampleCountMismatch {
                dims: expected,
                expected: voxels(expected),
                actual: preview.samples.len() as u64,
            });
        }
        Ok(Self {
            source,
            dims,
            preview,
            preview_level,
            reversed_x: false,
        })
    }

    /// Reads the box `lo..hi` of level `level` (see [`BrickSource::read_box`]).
    pub fn read_box(&self, level: u32, lo: [u32; 3], hi: [u32; 3]) -> Result<Samples, VolumeError> {
        if !self.reversed_x {
            return self.source.read_box(level, lo, hi);
        }
        let width = level_dims(self.dims, level)[0];
        let from = [width - hi[0], lo[1], lo[2]];
        let to = [width - lo[0], hi[1], hi[2]];
        let mut samples = self.source.read_box(level, from, to)?;
        samples.reverse_rows((hi[0] - lo[0]) as usize);
        Ok(samples)
    }

    /// The box `lo..hi` of level `level` from the preview alone: each voxel that of the
    /// preview voxel holding it (the preview's own where `level` is as coarse or coarser).
    pub fn preview_box(&self, level: u32, lo: [u32; 3], hi: [u32; 3]) -> Samples {
        let d = self.preview.dims;
        let at = |c: u32, a: usize| -> usize {
            let finer = self.preview_level.saturating_sub(level);
            let coarser = level.saturating_sub(self.preview_level);
            let v = (u64::from(c) << coarser) >> finer;
            v.min(u64::from(d[a] - 1)) as usize
        };
        let mut indices = Vec::new();
        for z in lo[2]..hi[2] {
            for y in lo[1]..hi[1] {
                let row = d[0] as usize * (at(y, 1) + d[1] as usize * at(z, 2));
                indices.extend((lo[0]..hi[0]).map(|x| row + at(x, 0)));
            }
        }
        self.preview.samples.gather(&indices)
    }

    /// Voxels of level 0 along x, y, z.
    pub fn dims(&self) -> [u32; 3] {
        self.dims
    }

    /// The level held whole.
    pub fn preview(&self) -> &Level {
        &self.preview
    }

    /// Which level the preview is.
    pub fn preview_level(&self) -> u32 {
        self.preview_level
    }

    /// How many boxes are best read at once.
    pub fn readers(&self) -> usize {
        self.source.readers()
    }

    /// Bytes the source's cache holds now, and the most it may.
    pub fn cache_bytes(&self) -> (u64, u64) {
        (self.source.held_bytes(), self.source.budget_bytes())
    }

    /// The samples reversed along x (see `Volume::unmirrored`).
    pub(crate) fn reversed(mut self) -> Self {
        self.preview
            .samples
            .reverse_rows(self.preview.dims[0] as usize);
        self.reversed_x = !self.reversed_x;
        self
    }
}

/// Voxels of a box of `dims`.
pub(crate) fn voxels(dims: [u32; 3]) -> u64 {
    dims.iter().map(|&d| u64::from(d)).product()
}

/// The most voxels a preview level holds (32 MiB of 16-bit samples).
const PREVIEW_VOXELS: u64 = 1 << 24;

/// The preview level of a volume of `dims` streamed under `budget`: the finest of at most
/// [`PREVIEW_VOXELS`] and a quarter of the budget (at most one voxel).
pub(crate) fn preview_level(dims: [u32; 3], budget: u64, scalar: ScalarType) -> u32 {
    let most = PREVIEW_VOXELS.min(budget / 4 / scalar.size_bytes() as u64);
    (0..32)
        .find(|&k| voxels(level_dims(dims, k)) <= most || level_dims(dims, k) == [1; 3])
        .unwrap_or(0)
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::volume::downsample::halve;

    /// A source over samples held in memory, its levels halved as LeapView halves them: what
    /// a store written by `leapview convert` holds.
    pub(crate) struct MemorySource {
        levels: Vec<Level>,
    }

    impl MemorySource {
        pub(crate) fn new(samples: Samples, dims: [u32; 3], count: u32) -> Self {
            let mut levels = vec![Level {
                dims,
                samples,
                colour: None,
            }];
            for _ in 1..count {
                let last = &levels[levels.len() - 1];
                let next = Level {
                    dims: level_dims(last.dims, 1),
                    samples: halve(&last.samples, last.dims),
                    colour: None,
                };
                levels.push(next);
            }
            Self { levels }
        }

        pub(crate) fn level(&self, level: u32) -> &Level {
            &self.levels[level as usize]
        }
    }

    impl BrickSource for MemorySource {
        fn read_box(&self, level: u32, lo: [u32; 3], hi: [u32; 3]) -> Result<Samples, VolumeError> {
            let l = &self.levels[level as usize];
            let mut out = Vec::new();
            for z in lo[2]..hi[2] {
                for y in lo[1]..hi[1] {
                    for x in lo[0]..hi[0] {
                        let i = x + l.dims[0] * (y + l.dims[1] * z);
                        out.push(l.samples.get_f64(i as usize) as u16);
                    }
                }
            }
            Ok(Samples::U16(out))
        }

        fn held_bytes(&self) -> u64 {
            0
        }

        fn budget_bytes(&self) -> u64 {
            0
        }
    }

    #[test]
    fn a_reversed_volume_reads_its_boxes_mirrored_in_x() {
        let dims = [5, 3, 2];
        let samples = Samples::U16((0..30).collect());
        let source = Arc::new(MemorySource::new(samples, dims, 2));
        let preview = source.level(1).clone();
        let streamed = Streamed::new(source, dims, preview, 1).expect("streamed");
        let plain = streamed.read_box(0, [1, 0, 0], [3, 1, 1]).expect("box");
        assert_eq!(plain, Samples::U16(vec![1, 2]));
        let reversed = streamed.reversed();
        // Voxels x = 1, 2 of the reversed volume are x = 3, 2 of the stored one.
        let mirrored = reversed.read_box(0, [1, 1, 1], [3, 2, 2]).expect("box");
        assert_eq!(mirrored, Samples::U16(vec![23, 22]));
        assert_eq!(reversed.preview().samples.get_f64(0), {
            let l = MemorySource::new(Samples::U16((0..30).collect()), dims, 2);
            l.level(1).samples.get_f64(2)
        });
    }

    #[test]
    fn a_box_from_the_preview_takes_the_preview_voxel_holding_each() {
        let dims = [8, 4, 4];
        let source = Arc::new(MemorySource::new(Samples::U16((0..128).collect()), dims, 3));
        let preview = source.level(1).clone();
        let streamed = Streamed::new(source.clone(), dims, preview.clone(), 1).expect("streamed");
        // Level 0: each voxel that of the level-1 voxel holding it.
        let fine = streamed.preview_box(0, [2, 1, 0], [6, 2, 1]);
        let at = |x: u32| preview.samples.get_f64(x as usize) as u16;
        assert_eq!(fine, Samples::U16(vec![at(1), at(1), at(2), at(2)]));
        // Level 1: the preview itself; level 2: every other preview voxel.
        assert_eq!(streamed.preview_box(1, [0; 3], [4, 2, 2]), preview.samples);
        let coarse = streamed.preview_box(2, [0, 0, 0], [2, 1, 1]);
        assert_eq!(coarse, Samples::U16(vec![at(0), at(2)]));
    }

    #[test]
    fn a_preview_of_the_wrong_shape_is_refused() {
        let dims = [5, 3, 2];
        let source = Arc::new(MemorySource::new(Samples::U16(vec![0; 30]), dims, 2));
        let wrong = source.level(0).clone();
        assert!(Streamed::new(source, dims, wrong, 1).is_err());
    }
}
