//! The menu bar: File (open, generated volumes, quit), View (standard views, projection, panels)
//! and Help (the mouse and keyboard controls).

use egui::MenuBar;

use crate::camera::{ProjectionKind, ViewPreset};
use crate::volume::Direction;

use crate::mpr::PlaneKind;
use crate::ui::layout::Layout;
use crate::ui::{Action, ViewerState};

/// The standard views with their menu labels, in menu order.
pub const VIEWS: [(ViewPreset, &str); 7] = [
    (ViewPreset::PlusX, "Along +x"),
    (ViewPreset::MinusX, "Along −x"),
    (ViewPreset::PlusY, "Along +y"),
    (ViewPreset::MinusY, "Along −y"),
    (ViewPreset::PlusZ, "Along +z"),
    (ViewPreset::MinusZ, "Along −z"),
    (ViewPreset::Oblique, "Oblique"),
];

/// Menu label of the view from `side`, e.g. "From anterior (A)".
pub(crate) fn view_label(side: Direction) -> String {
    format!("From {} ({})", side.name().to_lowercase(), side.letter())
}

/// The controls, one `(gesture, effect)` pair a line, for the Help menu and the view's tooltip.
pub const CONTROLS: [(&str, &str); 19] = [
    (
        "Left drag",
        "orbit about the centre (horizontal: azimuth, vertical: elevation)",
    ),
    ("Middle drag, Shift + left drag", "pan"),
    ("Mouse wheel, pinch, Ctrl + wheel", "zoom"),
    (
        "Right drag",
        "window/level (horizontal: width, vertical: level); in DVR it shifts and scales the \
         transfer function",
    ),
    (
        "Ctrl + Z, Ctrl + Shift + Z",
        "undo, redo a transfer-function edit",
    ),
    (
        "R, or View menu: Reset view",
        "reset the view (the patient from the front, head up)",
    ),
    (
        "[ and ], or View menu: Roll",
        "turn the view 90° anticlockwise, clockwise",
    ),
    (
        "Side panel: Correct the orientation",
        "a file shown upside down or back to front: flip its axes (kept for the file)",
    ),
    (
        "View menu or panel: A, P, L, R, S, I",
        "look from the patient's front, back, left, right, top, bottom (the file's orientation, \
         RAS where it has none); also along ±x/±y/±z and oblique",
    ),
    ("View menu: Perspective / Orthographic", "projection"),
    (
        "View menu or toolbar: 3D only, 2 × 2, 1 + 3",
        "the 3D view alone, or beside axial, coronal and sagittal slices",
    ),
    (
        "In a slice: left click or drag",
        "move the crosshair (the other slices follow); Shift + drag or middle drag pans",
    ),
    (
        "F12",
        "count samples: the developer readout adds samples taken and leapt (slower)",
    ),
    (
        "In a slice: wheel, Up/Down arrow keys, Page Up/Down; Ctrl + wheel",
        "step one voxel towards head, front or right (back with Down); zoom about the pointer",
    ),
    (
        "In a slice: Ctrl + drag; Alt + drag, Alt + click",
        "tilt the other two planes (oblique; Reset planes in the panel); measure a distance in \
         mm, take the ruler away",
    ),
    ("In a slice: right drag", "window/level of the slices"),
    (
        "With slices: left click on the 3D view",
        "move the crosshair to what the pixel shows (the first surface, or the MIP maximum)",
    ),
    (
        "Ctrl + O",
        "open a file (or drop a file or a DICOM folder onto the window)",
    ),
    ("Ctrl + Q", "quit"),
];

/// The file formats, for the Help menu (the README's Formats section, shorter).
pub const FORMATS: &[&str] = &[
    "NRRD (.nrrd, .nhdr), NIfTI-1 and -2 (.nii, .nii.gz; a 4-D file one volume at a time, \
     chosen in the side panel), MetaImage (.mha, .mhd), raw with its layout.",
    "DICOM: File › Open folder… (or drop a folder) for a series; any file of a series opens \
     that series; a multi-frame file or a Siemens mosaic opens on its own, a single image as a \
     2D image. Every common codec, grey and colour.",
    "A folder with several series: the one with the most slices opens; the others are listed \
     in the side panel's Volume section to choose from.",
    "Slices are ordered by their position along the slice normal, never by file name; gaps, \
     uneven spacing and gantry tilt are resampled and said in the side panel.",
    "TIFF stacks: a multi-page TIFF, OME-TIFF or ImageJ hyperstack, or a folder of 2D slices; \
     8/16-bit and float.",
    "OME-Zarr (NGFF 0.4 and 0.5): a folder, or an address through File › Open path… \
     (https://, s3://, gs://, az://). One larger than Advanced › Store memory, as a TIFF stack \
     larger, is read brick by brick as the view needs it.",
];

/// Draws the menu bar; returns what the user chose.
/// The layouts offered: the three of every volume, and for a 2D image (lying in plane `image`)
/// the image alone first.
fn layouts(image: Option<PlaneKind>) -> Vec<Layout> {
    image
        .map(Layout::Image)
        .into_iter()
        .chain(Layout::ALL)
        .collect()
}

/// The menu bar and the layout toolbar; `image`: the plane of the 2D image shown, if one is.
pub fn menu_bar(
    ui: &mut egui::Ui,
    state: &mut ViewerState,
    image: Option<PlaneKind>,
) -> Option<Action> {
    let mut action = None;
    MenuBar::new().ui(ui, |ui| {
        ui.menu_button("File", |ui| {
            if ui.button("Open…").clicked() {
                action = Some(Action::OpenDialog);
            }
            if ui
                .button("Open folder…")
                .on_hover_text(
                    "A folder of DICOM files: the series in it are listed to choose from",
                )
                .clicked()
            {
                action = Some(Action::OpenFolderDialog);
            }
            if ui.button("Open path…").clicked() {
                action = Some(Action::OpenPathPrompt);
            }
            if ui
                .button("Open segmentation…")
                .on_hover_text(
                    "Labels of the volume on screen (NIfTI, NRRD, Slicer .seg.nrrd, MetaImage, \
                     DICOM SEG), shown over the slices",
                )
                .clicked()
            {
                action = Some(Action::OpenLabelsDialog);
            }
            ui.add_enabled_ui(!state.recent.is_empty(), |ui| {
                ui.menu_button("Recent", |ui| {
                    for path in &state.recent {
                        if ui.button(path.display().to_string()).clicked() {
                            action = Some(Action::OpenRecent(path.clone()));
                        }
                    }
                });
            });
            if ui.button("Save image…").clicked() {
                action = Some(Action::SaveImagePrompt);
            }
            ui.separator();
            if ui.button("Shepp–Logan phantom").clicked() {
                action = Some(Action::LoadPhantom);
            }
            if ui.button("Vessel tree (generated)").clicked() {
                action = Some(Action::LoadVessels);
            }
            ui.separator();
            if ui.button("Quit").clicked() {
                action = Some(Action::Quit);
            }
        });
        ui.menu_button("View", |ui| {
            for side in Direction::VIEWS {
                if ui.button(view_label(side)).clicked() {
                    action = Some(Action::ViewFrom(side));
                }
            }
            ui.menu_button("Along an axis", |ui| {
                for (preset, label) in VIEWS {
                    if ui.button(label).clicked() {
                        action = Some(Action::SetView(preset));
                    }
                }
            });
            if ui.button("Reset view (R)").clicked() {
                action = Some(Action::ResetView);
            }
            if ui.button("Roll 90° anticlockwise ([)").clicked() {
                action = Some(Action::Roll(-90.0));
            }
            if ui.button("Roll 90° clockwise (])").clicked() {
                action = Some(Action::Roll(90.0));
            }
            ui.separator();
            for layout in layouts(image) {
                if ui.radio(state.layout == layout, layout.label()).clicked() {
                    action = Some(Action::SetLayout(layout));
                }
            }
            ui.separator();
            for (kind, label) in [
                (ProjectionKind::Perspective, "Perspective"),
                (ProjectionKind::Orthographic, "Orthographic"),
            ] {
                if ui.radio(state.projection == kind, label).clicked() {
                    action = Some(Action::SetProjection(kind));
                }
            }
            ui.separator();
            ui.checkbox(&mut state.show_controls, "Controls panel");
            ui.checkbox(&mut state.show_readout, "Readout over the 3D view");
            ui.checkbox(&mut state.developer_readout, "Developer readout");
            ui.checkbox(&mut state.statistics, "Count samples (slower; F12)");
            ui.checkbox(
                &mut state.show_orientation_marker,
                "Orientation marker (R, A, S)",
            );
            ui.checkbox(&mut state.show_slice_planes, "Slice planes in the 3D view");
        });
        ui.menu_button("Help", |ui| {
            ui.label(egui::RichText::new("Controls").strong());
            controls_grid(ui);
            ui.separator();
            ui.label(egui::RichText::new("What opens").strong());
            ui.set_max_width(520.0);
            for line in FORMATS {
                ui.label(*line);
            }
        });
        // The layout toolbar: the same choice as View › layouts, one click away.
        ui.separator();
        for layout in layouts(image) {
            if ui
                .selectable_label(state.layout == layout, layout.label())
                .on_hover_text("Layout of the views (also in the View menu)")
                .clicked()
            {
                action = Some(Action::SetLayout(layout));
            }
        }
    });
    action
}

/// The controls as a two-column grid.
fn controls_grid(ui: &mut egui::Ui) {
    egui::Grid::new("controls help")
        .num_columns(2)
        .striped(true)
        .show(ui, |ui| {
            for (gesture, effect) in CONTROLS {
                ui.label(gesture);
                ui.label(effect);
                ui.end_row();
            }
        });
}
