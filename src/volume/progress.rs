//! Progress and cancellation of a load, shared between the thread that reads the samples and
//! the window that shows a progress bar and a Cancel button. The reader reports the sample bytes
//! it has (decompressed and) read, in chunks of at most [`CHUNK_BYTES`], and checks for
//! cancellation after each.

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};

/// Largest read between two progress reports (and cancellation checks): 4 MiB, a few
/// milliseconds of gzip decompression.
pub const CHUNK_BYTES: usize = 4 << 20;

/// How far a load has come, and whether it should stop.
#[derive(Debug, Default)]
pub struct LoadProgress {
    done: AtomicU64,
    total: AtomicU64,
    cancelled: AtomicBool,
}

impl LoadProgress {
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
    pub fn is_cancelled(&self) -> bool {
        self.cancelled.load(Ordering::Relaxed)
    }
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
}
