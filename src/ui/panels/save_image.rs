//! The "Save image" window: a path (PNG, or EXR for linear f32) and a size in pixels, the
//! window's size by default. The image is rendered again at that size at full quality, not
//! scaled from the screen.

/// What the window holds between passes.
#[derive(Clone, Debug, PartialEq)]
pub struct SaveImageForm {
    /// Output file.
    pub path: String,
    /// Image size in pixels.
    pub size: [u32; 2],
    /// The outcome of the last save, shown under the buttons.
    pub status: Option<String>,
}

impl SaveImageForm {
    /// A form for an image the size of the view (`view_px`).
    pub fn new(view_px: [u32; 2]) -> Self {
        Self {
            path: "leapview.png".to_string(),
            size: view_px.map(|n| n.max(1)),
            status: None,
        }
    }
}

/// What the user asked for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SaveImageEvent {
    /// Render and write the image.
    Save,
    /// Close the window.
    Close,
}

/// Draws the window; `view_px` is the view's current size for the "window size" button.
pub(crate) fn save_image_window(
    ctx: &egui::Context,
    form: &mut SaveImageForm,
    view_px: [u32; 2],
) -> Option<SaveImageEvent> {
    let mut event = None;
    let mut open = true;
    egui::Window::new("Save image")
        .open(&mut open)
        .collapsible(false)
        .resizable(false)
        .show(ctx, |ui| {
            ui.horizontal(|ui| {
                ui.label("File");
                ui.text_edit_singleline(&mut form.path)
                    .on_hover_text(".png: 8-bit RGBA; .exr: linear RGBA f32");
            });
            ui.horizontal(|ui| {
                ui.label("Size");
                ui.add(egui::DragValue::new(&mut form.size[0]).range(1..=65536));
                ui.label("×");
                ui.add(egui::DragValue::new(&mut form.size[1]).range(1..=65536));
                if ui.button("window size").clicked() {
                    form.size = view_px.map(|n| n.max(1));
                }
            });
            ui.horizontal(|ui| {
                if ui.button("Save").clicked() {
                    event = Some(SaveImageEvent::Save);
                }
                if ui.button("Close").clicked() {
                    event = Some(SaveImageEvent::Close);
                }
            });
            if let Some(status) = &form.status {
                ui.label(status);
            }
        });
    if !open {
        event = Some(SaveImageEvent::Close);
    }
    event
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_form_starts_at_the_view_size_and_never_at_zero() {
        assert_eq!(SaveImageForm::new([800, 600]).size, [800, 600]);
        assert_eq!(SaveImageForm::new([0, 600]).size, [1, 600]);
        assert!(SaveImageForm::new([1, 1]).path.ends_with(".png"));
    }
}
