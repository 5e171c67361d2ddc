//! A streamed volume's bricks read from their store and encoded on threads of their own, so
//! that no frame waits for the store: a frame asks for the bricks it misses, nearest first, and
//! sends those that have come; until then the coarser ones it holds stand in.

use std::collections::{HashMap, HashSet};
use std::sync::Arc;
use std::sync::mpsc::{Receiver, Sender, channel};

use crate::accel::residency::BrickKey;

/// Bricks asked for and not yet come, at most: enough to keep every reader busy, few enough
/// that what a frame asks for next (the view moved) is read soon.
pub(super) const IN_FLIGHT: usize = 64;

/// Bricks come and not yet sent that are kept, at most (those no frame wanted lately go).
const READY_MOST: usize = 256;

/// How long [`Fetcher::wait_for`] waits for any brick to come before it gives up.
const PATIENCE: std::time::Duration = std::time::Duration::from_secs(60);

/// Encodes one brick's slot, reading it from the store.
pub(super) type Encode = Arc<dyn Fn(BrickKey) -> Vec<u8> + Send + Sync>;

/// The readers and what they have read.
pub(super) struct Fetcher {
    pool: rayon::ThreadPool,
    encode: Encode,
    sent: Sender<(BrickKey, Vec<u8>)>,
    came: Receiver<(BrickKey, Vec<u8>)>,
    asked: HashSet<BrickKey>,
    ready: HashMap<BrickKey, Vec<u8>>,
}

impl Fetcher {
    /// Readers on `threads` threads of their own, each brick through `encode`.
    pub(super) fn new(threads: usize, encode: Encode) -> Result<Self, rayon::ThreadPoolBuildError> {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads.max(1))
            .thread_name(|i| format!("brick reader {i}"))
            .build()?;
        let (sent, came) = channel();
        Ok(Self {
            pool,
            encode,
            sent,
            came,
            asked: HashSet::new(),
            ready: HashMap::new(),
        })
    }

    /// Takes in what the readers have read, then asks for the first of `wanted` (in the order
    /// given) that are neither read nor asked for, while fewer than [`IN_FLIGHT`] are.
    pub(super) fn ask(&mut self, wanted: &[BrickKey]) {
        while let Ok((key, bytes)) = self.came.try_recv() {
            self.asked.remove(&key);
            self.ready.insert(key, bytes);
        }
        if self.ready.len() > READY_MOST {
            // What the frame no longer wants goes first; it is read again if asked.
            let keep: HashSet<&BrickKey> = wanted.iter().collect();
            self.ready.retain(|k, _| keep.contains(k));
        }
        for key in wanted {
            if self.asked.len() >= IN_FLIGHT {
                break;
            }
            if self.ready.contains_key(key) || !self.asked.insert(*key) {
                continue;
            }
            let (encode, sent, key) = (Arc::clone(&self.encode), self.sent.clone(), *key);
            self.pool.spawn(move || {
                // The frame may have gone (the volume was closed): nothing to send to.
                let _ = sent.send((key, encode(key)));
            });
        }
    }

    /// Waits until every one of `keys` has been read (asking for them, and for those of
    /// `ahead` after them, as readers come free), or until no brick has come for
    /// [`PATIENCE`]: what has not come by then is read by the caller.
    pub(super) fn wait_for(&mut self, keys: &[BrickKey], ahead: &[BrickKey]) {
        let wanted: Vec<BrickKey> = keys.iter().chain(ahead).copied().collect();
        self.ask(&wanted);
        while !keys.iter().all(|k| self.ready.contains_key(k)) {
            match self.came.recv_timeout(PATIENCE) {
                Ok((key, bytes)) => {
                    self.asked.remove(&key);
                    self.ready.insert(key, bytes);
                    self.ask(&wanted);
                }
                Err(_) => return,
            }
        }
    }

    /// Whether `key`'s slot has been read.
    pub(super) fn is_ready(&self, key: &BrickKey) -> bool {
        self.ready.contains_key(key)
    }

    /// `key`'s slot, read (it is no longer kept).
    pub(super) fn take(&mut self, key: &BrickKey) -> Option<Vec<u8>> {
        self.ready.remove(key)
    }

    /// Bricks asked for and not yet read.
    pub(super) fn in_flight(&self) -> usize {
        self.asked.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bricks_asked_for_come_in_and_are_taken_once() {
        let encode: Encode = Arc::new(|k: BrickKey| vec![k.brick[0] as u8; 4]);
        let mut fetcher = Fetcher::new(2, encode).expect("pool");
        let keys: Vec<BrickKey> = (0..100)
            .map(|x| BrickKey {
                level: 0,
                brick: [x, 0, 0],
            })
            .collect();
        fetcher.ask(&keys);
        assert_eq!(fetcher.in_flight(), IN_FLIGHT);
        let started = std::time::Instant::now();
        while !keys.iter().all(|k| fetcher.is_ready(k)) {
            assert!(
                started.elapsed().as_secs() < 30,
                "the readers never finished"
            );
            std::thread::sleep(std::time::Duration::from_millis(5));
            fetcher.ask(&keys);
        }
        assert_eq!(fetcher.in_flight(), 0);
        assert_eq!(fetcher.take(&keys[7]), Some(vec![7; 4]));
        assert_eq!(fetcher.take(&keys[7]), None);
    }
}
