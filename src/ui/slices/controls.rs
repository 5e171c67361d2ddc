//! The side panel's "Slices" section: sampling, thick slab, window, and the crosshair's place.

use crate::mpr::{Slab, SlabMode};

use super::SliceViews;

/// Slab thickness a new slab starts with (mm).
const DEFAULT_SLAB_MM: f64 = 10.0;

impl SliceViews {
    /// The "Slices" section of the side panel.
    pub fn controls_ui(&mut self, ui: &mut egui::Ui) {
        ui.heading("Slices");
        egui::Grid::new("slice controls")
            .num_columns(2)
            .show(ui, |ui| {
                ui.label("Sampling");
                ui.horizontal(|ui| {
                    ui.radio_value(&mut self.nearest, false, "trilinear");
                    ui.radio_value(&mut self.nearest, true, "nearest voxel");
                });
                ui.end_row();
                ui.label("Thick slab");
                ui.horizontal(|ui| {
                    let mut mode = self.slab.map(|s| s.mode);
                    ui.radio_value(&mut mode, None, "off");
                    for m in [SlabMode::Mip, SlabMode::MinIp, SlabMode::Mean] {
                        ui.radio_value(&mut mode, Some(m), m.name());
                    }
                    let thickness = self.slab.map_or(DEFAULT_SLAB_MM, |s| s.thickness_mm);
                    self.slab = mode.map(|mode| Slab {
                        thickness_mm: thickness,
                        mode,
                    });
                });
                ui.end_row();
                if let Some(slab) = &mut self.slab {
                    ui.label("Slab (mm)");
                    ui.add(
                        egui::DragValue::new(&mut slab.thickness_mm)
                            .range(0.1..=500.0)
                            .speed(0.2),
                    );
                    ui.end_row();
                }
                ui.label("Colour");
                ui.checkbox(&mut self.colour_by_tf, "by the transfer function")
                    .on_hover_text(
                        "Its colour blended over the grey by its opacity: what it hides stays grey",
                    );
                ui.end_row();
                ui.label("Grey");
                ui.checkbox(&mut self.invert, "inverted (low values white)")
                    .on_hover_text(
                        "As radiographs stored MONOCHROME1 are shown (on for them by default); \
                         the values are unchanged",
                    );
                ui.end_row();
                ui.label("Window");
                ui.horizontal(|ui| {
                    let [mut lo, mut hi] = self.window;
                    let speed = ((hi - lo).abs() / 200.0).max(1e-6);
                    ui.add(egui::DragValue::new(&mut lo).speed(speed));
                    ui.label("to");
                    ui.add(egui::DragValue::new(&mut hi).speed(speed));
                    if hi > lo {
                        self.window = [lo, hi];
                    }
                });
                ui.end_row();
                let p = self.crosshair;
                ui.label("Crosshair");
                ui.label(format!("{:.1}, {:.1}, {:.1} mm (LPS)", p.x, p.y, p.z));
                ui.end_row();
            });
        ui.horizontal(|ui| {
            if ui.button("Crosshair to the centre").clicked()
                && let Some(source) = &self.source
            {
                self.crosshair = source.frame.centre();
            }
            if ui
                .button("Reset planes")
                .on_hover_text(
                    "Back to axial, coronal and sagittal (Ctrl + drag in a slice tilts the others)",
                )
                .clicked()
            {
                self.reset_planes();
            }
        });
    }
}
