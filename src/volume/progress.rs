//! Progress and cancellation of a load, shared between the thread that reads the samples and
//! the window that shows a progress bar and a Cancel button. The reader reports the sample bytes
//! it has (decompressed and) read, in chunks of at most [`CHUNK_BYTES`], and checks for
//! cancellation after each. Before it reads any sample, it asks the load's admission check
//! (where there is one: the GPU's limits) whether a volume of its header's shape can go where
//! it is going ([`LoadProgress::admit`]): a volume the GPU cannot hold is refused before minutes
//! of reading, not after.

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};

use super::samples::ScalarType;

/// What a header says of a volume before its samples are read.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shape {
    /// Samples along x, y, z.
    pub dims: [u32; 3],
    /// The stored type.
    pub scalar_type: ScalarType,
    /// Whether it is a colour volume.
    pub colour: bool,
}

/// Whether a volume of a shape can be taken; the reason where not.
pub type Admission = dyn Fn(&Shape) -> Result<(), String> + Send + Sync;

/// Largest read between two progress reports (and cancellation checks): 4 MiB, a few
/// milliseconds of gzip decompression.
pub const CHUNK_BYTES: usize = 4 << 20;

/// How far a load has come, whether it should stop, and what may be read.
#[derive(Default)]
pub struct LoadProgress {
    done: AtomicU64,
    total: AtomicU64,
    cancelled: AtomicBool,
    admission: Option<Box<Admission>>,
    slice_stride: u32,
}

impl std::fmt::Debug for LoadProgress {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("LoadProgress")
            .field("done", &self.done)
            .field("total", &self.total)
            .field("cancelled", &self.cancelled)
            .field("admission", &self.admission.is_some())
            .field("slice_stride", &self.slice_stride)
            .finish()
    }
}

impl LoadProgress {
    /// A progress whose load asks `admission` before it reads any sample.
    pub fn with_admission(admission: Box<Admission>) -> Self {
        Self {
            admission: Some(admission),
            ..Self::default()
        }
    }

    /// The same load reading only every `stride`-th slice (along z, from the first): a preview
    /// of a large volume for its statistics (`leapview info`). The volume read has the slices
    /// kept and their spacing ([`strided`]).
    pub fn with_slice_stride(mut self, stride: u32) -> Self {
        self.slice_stride = stride;
        self
    }

    /// Every how many slices one is read (1: all).
    pub(crate) fn slice_stride(&self) -> u32 {
        self.slice_stride.max(1)
    }

    /// Asks the admission check (if any) whether a volume of `shape` can be taken: every reader
    /// calls this once it knows the shape and before it reads a sample.
    pub(crate) fn admit(&self, shape: Shape) -> Result<(), super::error::VolumeError> {
        match &self.admission {
            Some(check) => {
                check(&shape).map_err(|reason| super::error::VolumeError::NotAdmitted { reason })
            }
            None => Ok(()),
        }
    }

    /// Starts counting towards `total` sample bytes.
    pub fn start(&self, total: u64) {
        self.done.store(0, Ordering::Relaxed);
        self.total.store(total, Ordering::Relaxed);
    }

    /// Adds `bytes` read.
    pub fn advance(&self, bytes: u64) {
        self.done.fetch_add(bytes, Ordering::Relaxed);
    }

    /// The share of the samples read, once reading has started.
    pub fn fraction(&self) -> Option<f64> {
        let total = self.total.load(Ordering::Relaxed);
        (total > 0)
            .then(|| (self.done.load(Ordering::Relaxed) as f64 / total as f64).clamp(0.0, 1.0))
    }

    /// Asks the load to stop at its next check.
    pub fn cancel(&self) {
        self.cancelled.store(true, Ordering::Relaxed);
    }

    /// Whether [`LoadProgress::cancel`] was called.
    pub(crate) fn is_cancelled(&self) -> bool {
        self.cancelled.load(Ordering::Relaxed)
    }
}

/// The dimensions and spacing of a volume of `dims` and `spacing_mm` read with `progress`'s
/// slice stride: every stride-th slice along z, the first included.
pub fn strided(
    dims: [u32; 3],
    spacing_mm: [f64; 3],
    progress: Option<&LoadProgress>,
) -> ([u32; 3], [f64; 3]) {
    let stride = progress.map_or(1, LoadProgress::slice_stride);
    if stride <= 1 || dims[2] <= 1 {
        return (dims, spacing_mm);
    }
    (
        [dims[0], dims[1], dims[2].div_ceil(stride)],
        [
            spacing_mm[0],
            spacing_mm[1],
            spacing_mm[2] * f64::from(stride),
        ],
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fraction_counts_towards_the_total_and_cancel_sticks() {
        let p = LoadProgress::default();
        assert_eq!(p.fraction(), None, "not started");
        p.start(200);
        p.advance(50);
        assert_eq!(p.fraction(), Some(0.25));
        p.advance(500);
        assert_eq!(p.fraction(), Some(1.0), "clamped");
        assert!(!p.is_cancelled());
        p.cancel();
        assert!(p.is_cancelled());
    }

    #[test]
    fn the_admission_check_refuses_before_reading() {
        let shape = Shape {
            dims: [4096, 4, 4],
            scalar_type: ScalarType::U8,
            colour: false,
        };
        assert!(
            LoadProgress::default().admit(shape).is_ok(),
            "no check, no refusal"
        );
        let p = LoadProgress::with_admission(Box::new(|s: &Shape| {
            if s.dims[0] > 2048 {
                Err(format!("{} is past 2048", s.dims[0]))
            } else {
                Ok(())
            }
        }));
        let e = p.admit(shape).expect_err("too wide");
        assert!(e.to_string().contains("4096 is past 2048"), "{e}");
        assert!(
            p.admit(Shape {
                dims: [16, 4, 4],
                ..shape
            })
            .is_ok()
        );
    }
}
