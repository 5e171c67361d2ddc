//! What is kept between runs: the viewer state and the transfer function as edited (eframe's
//! storage); scripted runs neither read nor write it.

use crate::transfer::TransferFunction;
use crate::transfer::editor::TfEditor;
use crate::ui::ViewerState;

/// Storage key of the viewer settings.
pub(super) const STATE_KEY: &str = "viewer-state";
/// Storage key of the transfer function being edited.
pub(super) const TF_KEY: &str = "transfer-function";

/// The settings and transfer function of the last run; defaults for what is missing or invalid
/// (a stored function that fails validation is dropped with a log line).
pub(super) fn restored_state(storage: &dyn eframe::Storage) -> ViewerState {
    let mut state: ViewerState = eframe::get_value(storage, STATE_KEY).unwrap_or_default();
    if let Some(tf) = eframe::get_value::<TransferFunction>(storage, TF_KEY) {
        match tf.validate() {
            Ok(()) => state.editor = TfEditor::new(tf),
            Err(e) => log::warn!("the saved transfer function is not used: {e}"),
        }
    } else if let Err(e) = state.editor.load_preset(&state.preset) {
        log::warn!("saved preset: {e}");
    }
    state
}
