//! Dialogs: the error message (an egui modal with the one-line message), the system file dialog
//! (rfd through the XDG desktop portal, on a thread so the window keeps drawing), and a typed-path
//! prompt for systems without a portal.

use std::path::PathBuf;
use std::sync::mpsc;
use std::time::{Duration, Instant};

use egui::{Id, Modal};

/// A file dialog that answers "nothing chosen" faster than this did not show at all (no portal
/// and no zenity): no person closes a file dialog within half a second.
const DIALOG_FAILED_WITHIN: Duration = Duration::from_millis(500);

/// File extensions offered in the file dialog.
const VOLUME_EXTENSIONS: [&str; 9] = [
    "nrrd", "nhdr", "nii", "gz", "raw", "mha", "mhd", "dcm", "DICOMDIR",
];

/// What a chosen file is for.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Purpose {
    /// A volume to open.
    #[default]
    Volume,
    /// A segmentation of the volume on screen.
    Labels,
}

/// The window's dialogs.
#[derive(Default)]
pub struct Dialogs {
    /// What the open dialog or prompt chooses a file for.
    purpose: Purpose,
    /// Error messages waiting to be seen, oldest first.
    errors: Vec<String>,
    /// The typed path while the prompt is open, and whether it has had the focus yet.
    prompt: Option<(String, bool)>,
    /// The system file dialog while it is open: (started, answer).
    picker: Option<(Instant, mpsc::Receiver<Option<PathBuf>>)>,
    /// A dropped file that may be labels or an image, and why it may be labels.
    dropped: Option<(PathBuf, String)>,
}

impl Dialogs {
    /// Shows `message` in a modal dialog, on one line (wgpu's errors come with a "Caused by"
    /// chain over several), once even when the same error repeats.
    pub fn show_error(&mut self, message: impl Into<String>) {
        let message = one_line(&message.into());
        log::warn!("{message}");
        if !self.errors.contains(&message) {
            self.errors.push(message);
        }
    }

    /// Asks whether the dropped file at `path` is the segmentation of the image on screen
    /// (`why` it may be) or an image to open.
    pub fn ask_dropped(&mut self, path: PathBuf, why: String) {
        self.dropped = Some((path, why));
    }

    /// Whether an error is on screen.
    pub fn has_error(&self) -> bool {
        !self.errors.is_empty()
    }

    /// Opens the path prompt for a volume.
    pub(crate) fn open_prompt(&mut self) {
        if self.prompt.is_none() && self.picker.is_none() {
            self.purpose = Purpose::Volume;
        }
        self.prompt.get_or_insert_with(|| (String::new(), false));
    }

    /// Opens the system file dialog, or the path prompt where there can be none.
    pub(crate) fn open_file_dialog(&mut self, ctx: &egui::Context) {
        self.open_dialog(ctx, false, Purpose::Volume);
    }

    /// Opens the system folder dialog (for a DICOM series), or the path prompt.
    pub(crate) fn open_folder_dialog(&mut self, ctx: &egui::Context) {
        self.open_dialog(ctx, true, Purpose::Volume);
    }

    /// Opens the system file dialog for a segmentation, or the path prompt.
    pub(crate) fn open_labels_dialog(&mut self, ctx: &egui::Context) {
        self.open_dialog(ctx, false, Purpose::Labels);
    }

    fn open_dialog(&mut self, ctx: &egui::Context, folder: bool, purpose: Purpose) {
        if self.picker.is_some() || self.prompt.is_some() {
            return;
        }
        self.purpose = purpose;
        if !portal_possible() {
            log::info!("no D-Bus session and no zenity: asking for a path instead");
            self.prompt = Some((String::new(), false));
            return;
        }
        let title = match purpose {
            Purpose::Volume => "Open a volume",
            Purpose::Labels => "Open a segmentation of the volume on screen",
        };
        let (tx, rx) = mpsc::channel();
        let ctx = ctx.clone();
        let spawned = std::thread::Builder::new()
            .name("file dialog".into())
            .spawn(move || {
                let picked = if folder {
                    rfd::FileDialog::new()
                        .set_title("Open a folder of DICOM files")
                        .pick_folder()
                } else {
                    rfd::FileDialog::new()
                        .set_title(title)
                        .add_filter(
                            "Volumes (NRRD, NIfTI, MetaImage, DICOM, raw)",
                            &VOLUME_EXTENSIONS,
                        )
                        .add_filter("All files", &["*"])
                        .pick_file()
                };
                let _ = tx.send(picked);
                ctx.request_repaint();
            });
        match spawned {
            Ok(_) => self.picker = Some((Instant::now(), rx)),
            Err(e) => {
                log::warn!("cannot start the file dialog: {e}");
                self.prompt = Some((String::new(), false));
            }
        }
    }

    /// Draws the open dialogs and returns a file the user chose, and what for.
    pub fn ui(&mut self, ctx: &egui::Context) -> Option<(PathBuf, Purpose)> {
        let mut chosen = self.poll_picker();
        if let Some(message) = self.errors.first() {
            let response = Modal::new(Id::unique("leapview error")).show(ctx, |ui| {
                ui.set_max_width(480.0);
                ui.heading("Something went wrong");
                ui.add_space(4.0);
                ui.label(message.as_str());
                ui.add_space(8.0);
                ui.button("OK").clicked()
            });
            if response.inner || response.should_close() {
                self.errors.remove(0);
            }
        } else if self.dropped.is_some() {
            return self.dropped_ui(ctx);
        } else if self.prompt.is_some() {
            chosen = chosen.or_else(|| self.prompt_ui(ctx));
        }
        chosen.map(|path| (path, self.purpose))
    }

    /// The question about a dropped file: its segmentation, or a new image? The file and what
    /// for once answered.
    fn dropped_ui(&mut self, ctx: &egui::Context) -> Option<(PathBuf, Purpose)> {
        let (path, why) = self.dropped.as_ref()?;
        let name = path.file_name().map_or_else(
            || path.display().to_string(),
            |n| n.to_string_lossy().into(),
        );
        // `Some(None)`: cancelled.
        let mut answer: Option<Option<Purpose>> = None;
        let response = Modal::new(Id::unique("leapview dropped")).show(ctx, |ui| {
            ui.set_max_width(480.0);
            ui.heading(format!("Open {name}"));
            ui.add_space(4.0);
            ui.label(format!(
                "It may be the segmentation of the image on screen: {why}."
            ));
            ui.add_space(8.0);
            ui.horizontal(|ui| {
                if ui.button("As its segmentation").clicked() {
                    answer = Some(Some(Purpose::Labels));
                }
                if ui.button("As a new image").clicked() {
                    answer = Some(Some(Purpose::Volume));
                }
                if ui.button("Cancel").clicked() {
                    answer = Some(None);
                }
            });
        });
        if response.should_close() {
            answer = answer.or(Some(None));
        }
        let purpose = answer?;
        let (path, _) = self.dropped.take()?;
        purpose.map(|p| (path, p))
    }

    /// The answer of the system file dialog; opens the prompt when the dialog could not show.
    fn poll_picker(&mut self) -> Option<PathBuf> {
        let (started, rx) = self.picker.as_ref()?;
        let answer = match rx.try_recv() {
            Ok(answer) => answer,
            Err(mpsc::TryRecvError::Empty) => return None,
            Err(mpsc::TryRecvError::Disconnected) => None,
        };
        let elapsed = started.elapsed();
        self.picker = None;
        if answer.is_none() && elapsed < DIALOG_FAILED_WITHIN {
            log::info!("the file dialog did not show (no desktop portal?): asking for a path");
            self.prompt = Some((String::new(), false));
        }
        answer
    }

    fn prompt_ui(&mut self, ctx: &egui::Context) -> Option<PathBuf> {
        let purpose = self.purpose;
        let (text, focused_once) = self.prompt.as_mut()?;
        let mut open = false;
        let mut cancel = false;
        let response = Modal::new(Id::unique("leapview open path")).show(ctx, |ui| {
            ui.set_width(520.0);
            if purpose == Purpose::Labels {
                ui.heading("Open a segmentation");
                ui.label(
                    "Path of the labels of the volume on screen: NIfTI, NRRD or Slicer \
                     .seg.nrrd, MetaImage, or a DICOM SEG file:",
                );
            } else {
                ui.heading("Open a volume");
                ui.label(
                    "Path of a NRRD (.nrrd, .nhdr), NIfTI (.nii, .nii.gz), MetaImage (.mha, .mhd), \
                 TIFF or raw file, a DICOM file, a folder of DICOM files or TIFF slices, or an \
                 OME-Zarr store: a folder, or an address (https://, s3://, gs://, az://; \
                 credentials from the AWS_, GOOGLE_ or AZURE_ environment variables):",
                );
            }
            let edit = ui.add(
                egui::TextEdit::singleline(text)
                    .desired_width(f32::INFINITY)
                    .hint_text("/path/to/volume.nii.gz or s3://bucket/image.ome.zarr"),
            );
            if !*focused_once {
                edit.request_focus();
                *focused_once = true;
            }
            let entered = edit.lost_focus() && ui.input(|i| i.key_pressed(egui::Key::Enter));
            ui.horizontal(|ui| {
                open = ui.button("Open").clicked() || entered;
                cancel = ui.button("Cancel").clicked();
            });
        });
        if response.should_close() {
            cancel = true;
        }
        let path = expand_home(text.trim());
        if open && !path.as_os_str().is_empty() {
            self.prompt = None;
            return Some(path);
        }
        if cancel {
            self.prompt = None;
        }
        None
    }
}

/// Whether rfd can show a dialog at all: it needs the desktop portal on the D-Bus session bus,
/// or zenity as its fallback.
fn portal_possible() -> bool {
    let has_session_bus = std::env::var_os("DBUS_SESSION_BUS_ADDRESS").is_some()
        || std::env::var_os("XDG_RUNTIME_DIR")
            .is_some_and(|dir| PathBuf::from(dir).join("bus").exists());
    let has_zenity = std::env::var_os("PATH")
        .is_some_and(|paths| std::env::split_paths(&paths).any(|p| p.join("zenity").is_file()));
    has_session_bus || has_zenity
}

/// The lines of `text`, trimmed and joined by spaces.
fn one_line(text: &str) -> String {
    text.lines()
        .map(str::trim)
        .filter(|l| !l.is_empty())
        .collect::<Vec<_>>()
        .join(" ")
}

/// `~/x` → `$HOME/x`; anything else as it is.
fn expand_home(text: &str) -> PathBuf {
    match (text.strip_prefix("~/"), std::env::var_os("HOME")) {
        (Some(rest), Some(home)) => PathBuf::from(home).join(rest),
        _ => PathBuf::from(text),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn home_is_expanded_only_at_the_start() {
        let home = std::env::var_os("HOME").map(PathBuf::from);
        if let Some(home) = home {
            assert_eq!(expand_home("~/a.nrrd"), home.join("a.nrrd"));
        }
        assert_eq!(expand_home("/x/~/a.nrrd"), PathBuf::from("/x/~/a.nrrd"));
    }

    #[test]
    fn repeated_errors_show_once() {
        let mut dialogs = Dialogs::default();
        dialogs.show_error("the GPU refused");
        dialogs.show_error("the GPU refused");
        assert_eq!(dialogs.errors.len(), 1);
        assert!(dialogs.has_error());
        dialogs.show_error("Validation Error\n\nCaused by:\n    In a pass\n");
        assert_eq!(dialogs.errors[1], "Validation Error Caused by: In a pass");
    }
}
