//! Segmentations in the window: File › Open segmentation… (or `--labels` on the command line)
//! reads one on a thread of its own for the volume on screen, then the slices show it.

use std::path::PathBuf;
use std::sync::{Arc, mpsc};

use super::LeapViewApp;
use crate::labels::{LabelMap, LabelOptions, load_labels};
use crate::ui::layout::Layout;

/// A segmentation being read: its file and the answer to come.
pub(super) struct LabelsLoad {
    path: PathBuf,
    answer: mpsc::Receiver<Result<LabelMap, String>>,
}

impl LeapViewApp {
    /// Reads the segmentation at `path` for the volume on screen (or the next one shown, while
    /// none is).
    pub(super) fn open_labels(&mut self, path: PathBuf, ctx: &egui::Context) {
        let Some(volume) = self.slices.volume() else {
            self.pending_labels = Some(path);
            return;
        };
        let (tx, rx) = mpsc::channel();
        let ctx = ctx.clone();
        let file = path.clone();
        let spawned = std::thread::Builder::new()
            .name("labels".into())
            .spawn(move || {
                let read = load_labels(&file, &volume, &LabelOptions::default())
                    .map_err(|e| e.to_string());
                let _ = tx.send(read);
                ctx.request_repaint();
            });
        match spawned {
            Ok(_) => {
                self.labels_load = Some(LabelsLoad { path, answer: rx });
            }
            Err(e) => self
                .dialogs
                .show_error(format!("Cannot read the segmentation: {e}")),
        }
    }

    /// Takes a finished segmentation: shown over the slices (in a layout that has them).
    pub(super) fn receive_labels(&mut self, ctx: &egui::Context) {
        // Kept pending again while no volume is shown.
        if let Some(path) = self.pending_labels.take() {
            self.open_labels(path, ctx);
        }
        let Some(load) = &self.labels_load else {
            return;
        };
        let answer = match load.answer.try_recv() {
            Ok(answer) => answer,
            Err(mpsc::TryRecvError::Empty) => return,
            Err(mpsc::TryRecvError::Disconnected) => Err("the reader stopped".into()),
        };
        let path = load.path.display().to_string();
        let key = crate::ui::state::file_key(&load.path);
        self.labels_load = None;
        let shown = answer.and_then(|map| {
            for note in map.notes() {
                log::warn!("{}: {note}", map.name());
            }
            log::info!(
                "segmentation {}: {} segments",
                map.name(),
                map.segments().len()
            );
            self.slices
                .set_labels(Arc::new(map))
                .map_err(|e| format!("{path}: {e}"))
        });
        if shown.is_ok() {
            // As the user left this file's segmentation last time.
            if let Some(style) = self.state.label_styles.get(&key) {
                self.slices.apply_label_style(&style.clone());
            }
            self.labels_file = Some(key);
        }
        match shown {
            Ok(()) if !self.state.layout.has_slices() => self.state.layout = Layout::OnePlusThree,
            Ok(()) => {}
            Err(e) => self
                .dialogs
                .show_error(format!("Cannot show the segmentation: {e}")),
        }
    }

    /// Keeps how the segmentation on screen is shown for its file (each pass; a no-op while it
    /// is unchanged).
    pub(super) fn keep_label_style(&mut self) {
        let (Some(key), Some(style)) = (&self.labels_file, self.slices.label_style()) else {
            return;
        };
        if self.state.label_styles.get(key) != Some(&style) {
            self.state.label_styles.insert(key.clone(), style);
        }
    }
}
