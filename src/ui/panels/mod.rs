//! The panels: the side panel's sections (display, effect, transfer-function editor, cropping,
//! orientation), the menu bar, the Save image window and the dialogs.

pub mod controls;
pub mod dialogs;
pub mod effects;
pub mod menu;
pub mod orientation_controls;
pub mod save_image;
pub mod tf_editor;
