//! Work spread over every core: items by index on rayon's pool of threads, results in order
//! ([`parallel`]), or a buffer of z slices filled a slab per thread ([`fill_slabs`]). Used by the
//! loaders, the generators, the GPU upload and the downsampling.

use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

/// Runs `work(i)` for `i` in `0..count` on every core; results in order. Stops early (remaining
/// items `None`) once `stop` says so.
pub fn parallel<R: Send>(
    count: usize,
    stop: &(dyn Fn() -> bool + Sync),
    work: &(dyn Fn(usize) -> R + Sync),
) -> Vec<Option<R>> {
    parallel_on(cores(), count, stop, work)
}

/// The cores this process may use.
pub fn cores() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}

/// [`parallel`] on at most `threads` threads (work in the background that leaves cores to the
/// frames).
pub fn parallel_on<R: Send>(
    threads: usize,
    count: usize,
    stop: &(dyn Fn() -> bool + Sync),
    work: &(dyn Fn(usize) -> R + Sync),
) -> Vec<Option<R>> {
    let threads = threads.clamp(1, count.max(1));
    let next = AtomicUsize::new(0);
    let results: Mutex<Vec<Option<R>>> = Mutex::new((0..count).map(|_| None).collect());
    // On rayon's pool, not threads spawned per call: streamed bricks come in batches of 16,
    // several a frame, and each batch would spawn a thread per core.
    rayon::scope(|scope| {
        for _ in 0..threads {
            scope.spawn(|_| {
                loop {
                    let i = next.fetch_add(1, Ordering::Relaxed);
                    if i >= count || stop() {
                        break;
                    }
                    let r = work(i);
                    if let Ok(mut all) = results.lock() {
                        all[i] = Some(r);
                    }
                }
            });
        }
    });
    results.into_inner().unwrap_or_default()
}

/// Fills `buf` (`slice_len` samples per z slice) in parallel, one contiguous slab of z slices
/// per thread: `fill(z_first, slab)` receives the index of the slab's first slice and its
/// samples. The result does not depend on the number of threads as long as `fill` writes every
/// voxel from its coordinates alone.
pub fn fill_slabs<T: Send>(buf: &mut [T], slice_len: usize, fill: impl Fn(usize, &mut [T]) + Sync) {
    if slice_len == 0 || buf.is_empty() {
        return;
    }
    let slices = buf.len().div_ceil(slice_len);
    let threads = std::thread::available_parallelism()
        .map(|t| t.get())
        .unwrap_or(1)
        .clamp(1, slices);
    let slices_per_slab = slices.div_ceil(threads);
    std::thread::scope(|scope| {
        for (i, slab) in buf.chunks_mut(slices_per_slab * slice_len).enumerate() {
            let fill = &fill;
            scope.spawn(move || fill(i * slices_per_slab, slab));
        }
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slabs_cover_every_slice_once() {
        let mut buf = vec![0u32; 7 * 5];
        fill_slabs(&mut buf, 5, |z0, slab| {
            for (i, v) in slab.iter_mut().enumerate() {
                *v += (z0 * 5 + i) as u32;
            }
        });
        let expected: Vec<u32> = (0..35).collect();
        assert_eq!(buf, expected);
    }

    #[test]
    fn every_item_runs_once_and_results_keep_their_order() {
        let results = parallel(100, &|| false, &|i| i * 3);
        assert_eq!(results, (0..100).map(|i| Some(i * 3)).collect::<Vec<_>>());
    }
}
