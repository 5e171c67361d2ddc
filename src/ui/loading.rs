//! Loading or generating a volume on a background thread, so that the window stays responsive
//! and the old volume stays on screen until the new one is ready. One load at a time: starting
//! another abandons the first (its result is dropped when it arrives). A file load reports how
//! much of its samples it has read, and Cancel stops it at its next chunk.

use std::path::PathBuf;
use std::sync::{Arc, mpsc};
use std::time::Instant;

use crate::volume::error::LoadError;
use crate::volume::synthetic::{shepp_logan, vessel_tree};
use crate::volume::{LoadOptions, LoadProgress, Volume, VolumeError, load_volume};

/// Edge length of the generated volumes, in voxels.
pub const GENERATED_SIZE: u32 = 256;
/// Seed of the generated vessel tree (any fixed value: the tree is the same on every run).
pub const VESSEL_SEED: u64 = 7;

/// Where a volume comes from.
#[derive(Clone, Debug)]
pub enum VolumeSource {
    /// A file (NRRD, NIfTI or raw with `options`).
    File {
        /// The file.
        path: PathBuf,
        /// Raw-file layout from the command line.
        options: LoadOptions,
    },
    /// The generated 3D Shepp–Logan head phantom in HU.
    SheppLogan,
    /// The generated sparse vessel tree.
    VesselTree,
}

impl VolumeSource {
    /// What the loader is busy with, for the spinner.
    pub fn label(&self) -> String {
        match self {
            Self::File { path, .. } => path.file_name().map_or_else(
                || path.display().to_string(),
                |n| n.to_string_lossy().into(),
            ),
            Self::SheppLogan => "Shepp–Logan phantom".into(),
            Self::VesselTree => "vessel tree".into(),
        }
    }

    /// The preset the volume is made for, where that is known: the vessel tree is an
    /// angiogram without units, so the MR angiography preset suits it.
    pub(crate) fn preferred_preset(&self) -> Option<&'static str> {
        match self {
            Self::VesselTree => Some("mr-angio"),
            // Its inside: ventricles, lesions, the skull translucent.
            Self::SheppLogan => Some("ct-brain"),
            Self::File { .. } => None,
        }
    }

    /// Loads or generates the volume (slow: call it off the UI thread), reporting a file's
    /// progress to `progress`.
    pub fn load(&self, progress: &Arc<LoadProgress>) -> Result<Volume, LoadFailure> {
        match self {
            Self::File { path, options } => {
                let options = LoadOptions {
                    progress: Some(Arc::clone(progress)),
                    ..options.clone()
                };
                Ok(load_volume(path, &options)?)
            }
            Self::SheppLogan => Ok(shepp_logan(GENERATED_SIZE)?),
            Self::VesselTree => Ok(vessel_tree(GENERATED_SIZE, VESSEL_SEED)?),
        }
    }
}

/// Why no volume came back.
#[derive(Debug, thiserror::Error)]
pub enum LoadFailure {
    /// The file could not be read.
    #[error(transparent)]
    File(#[from] LoadError),
    /// The generator produced an invalid volume (a bug).
    #[error("the generated volume is invalid: {0}")]
    Generate(#[from] VolumeError),
    /// The loader thread could not start or stopped without an answer.
    #[error("loading {what} stopped unexpectedly: {reason}")]
    Thread {
        /// What was being loaded.
        what: String,
        /// What happened.
        reason: String,
    },
}

struct Pending {
    source: VolumeSource,
    label: String,
    started: Instant,
    progress: Arc<LoadProgress>,
    rx: mpsc::Receiver<Result<Volume, LoadFailure>>,
}

/// A load in progress, as the window shows it.
#[derive(Clone, Debug, PartialEq)]
pub struct LoadStatus {
    /// What is being loaded.
    pub label: String,
    /// When it started.
    pub started: Instant,
    /// Share of the samples read (files only, once the header is read).
    pub fraction: Option<f64>,
    /// Whether the volume is generated rather than read (no progress to show).
    pub generated: bool,
}

/// Wakes the UI when the loader thread ends, whether it answered or panicked.
struct RepaintOnDrop(egui::Context);

impl Drop for RepaintOnDrop {
    fn drop(&mut self) {
        self.0.request_repaint();
    }
}

/// The background loader.
#[derive(Default)]
pub struct Loader {
    pending: Option<Pending>,
    /// The GPU volumes go to: a load checks their shape against it before reading samples.
    gpu: Option<crate::render::GpuContext>,
}

impl Loader {
    /// Checks every volume loaded from now on against `gpu` before its samples are read.
    pub(crate) fn check_against(&mut self, gpu: crate::render::GpuContext) {
        self.gpu = Some(gpu);
    }

    /// Starts loading `source`, abandoning any load in progress, checked against the GPU within
    /// `gpu_budget`. `ctx` is woken when it is done.
    pub fn start(
        &mut self,
        source: VolumeSource,
        ctx: &egui::Context,
        gpu_budget: Option<u64>,
    ) -> Result<(), LoadFailure> {
        let label = source.label();
        let pending_source = source.clone();
        let (tx, rx) = mpsc::channel();
        let waker = RepaintOnDrop(ctx.clone());
        let progress = Arc::new(match &self.gpu {
            Some(gpu) => LoadProgress::with_admission(crate::render::volume_texture::admission(
                gpu, gpu_budget,
            )),
            None => LoadProgress::default(),
        });
        let thread_progress = Arc::clone(&progress);
        std::thread::Builder::new()
            .name("volume loader".into())
            .spawn(move || {
                let _waker = waker;
                let started = Instant::now();
                let result = source.load(&thread_progress);
                log::info!(
                    "loaded {} in {:.2} s",
                    source.label(),
                    started.elapsed().as_secs_f64()
                );
                // The receiver is gone when this load was abandoned: nothing to do then.
                let _ = tx.send(result);
            })
            .map_err(|e| LoadFailure::Thread {
                what: label.clone(),
                reason: e.to_string(),
            })?;
        self.cancel();
        self.pending = Some(Pending {
            source: pending_source,
            label,
            started: Instant::now(),
            progress,
            rx,
        });
        Ok(())
    }

    /// What is being loaded, since when and how far, while a load is in progress.
    pub fn busy(&self) -> Option<LoadStatus> {
        self.pending.as_ref().map(|p| LoadStatus {
            label: p.label.clone(),
            started: p.started,
            fraction: p.progress.fraction(),
            generated: !matches!(p.source, VolumeSource::File { .. }),
        })
    }

    /// Stops the load in progress (a file load ends at its next chunk; a generator runs to its
    /// end, unseen); the volume on screen stays.
    pub fn cancel(&mut self) {
        if let Some(p) = self.pending.take() {
            p.progress.cancel();
            log::info!("cancelled loading {}", p.label);
        }
    }

    /// The result of the load in progress, with its source, once it has arrived.
    pub(crate) fn poll(&mut self) -> Option<(VolumeSource, Result<Volume, LoadFailure>)> {
        let pending = self.pending.as_ref()?;
        let result = match pending.rx.try_recv() {
            Ok(result) => result,
            Err(mpsc::TryRecvError::Empty) => return None,
            Err(mpsc::TryRecvError::Disconnected) => Err(LoadFailure::Thread {
                what: pending.label.clone(),
                reason: "the loader thread ended without a result (see the log)".into(),
            }),
        };
        let source = self.pending.take()?.source;
        Some((source, result))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn wait(loader: &mut Loader) -> Result<Volume, LoadFailure> {
        let deadline = Instant::now() + std::time::Duration::from_secs(60);
        loop {
            if let Some((_, result)) = loader.poll() {
                return result;
            }
            assert!(Instant::now() < deadline, "the loader never answered");
            std::thread::sleep(std::time::Duration::from_millis(5));
        }
    }

    #[test]
    fn a_missing_file_comes_back_as_an_error_naming_it() {
        let ctx = egui::Context::default();
        let mut loader = Loader::default();
        let path = PathBuf::from("/nonexistent/leapview-test.nrrd");
        loader
            .start(
                VolumeSource::File {
                    path: path.clone(),
                    options: LoadOptions::default(),
                },
                &ctx,
                None,
            )
            .expect("thread starts");
        assert_eq!(
            loader.busy().map(|b| b.label),
            Some("leapview-test.nrrd".to_string())
        );
        let err = wait(&mut loader).expect_err("no such file");
        assert!(err.to_string().contains("/nonexistent/leapview-test.nrrd"));
        assert!(loader.busy().is_none());
        assert!(loader.poll().is_none());
    }

    #[test]
    fn cancel_forgets_the_load_and_its_result() {
        let ctx = egui::Context::default();
        let mut loader = Loader::default();
        loader
            .start(VolumeSource::SheppLogan, &ctx, None)
            .expect("thread starts");
        assert!(loader.busy().is_some());
        loader.cancel();
        assert!(loader.busy().is_none());
        // The generator may still finish; its result is never delivered.
        std::thread::sleep(std::time::Duration::from_millis(50));
        assert!(loader.poll().is_none());
    }

    #[test]
    fn a_newer_load_replaces_an_older_one() {
        let ctx = egui::Context::default();
        let mut loader = Loader::default();
        let missing = VolumeSource::File {
            path: PathBuf::from("/nonexistent/a.nrrd"),
            options: LoadOptions::default(),
        };
        loader.start(missing, &ctx, None).expect("thread starts");
        loader
            .start(VolumeSource::SheppLogan, &ctx, None)
            .expect("thread starts");
        let volume = wait(&mut loader).expect("the phantom generates");
        assert_eq!(volume.dims(), [GENERATED_SIZE; 3]);
        // Air in HU: the phantom must be recognised as CT.
        assert!(crate::transfer::fit::DataKind::of(&volume).is_ct());
    }
}
