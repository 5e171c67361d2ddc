//! The side panel's orientation controls: which way the file's index axes point in the patient
//! (the header's, the user's, or RAS assumed), and the means to correct it — flip one of the
//! patient's axes, or type a code — for files whose header has no orientation or a wrong one.
//! The correction is kept per file (`ViewerState::orientations`) and the file is opened again
//! with it, so that a mirrored result is unmirrored on loading like any other.

use crate::ui::{Action, VolumeSummary};
use crate::volume::{Direction, Orientation, OrientationSource};

/// The state of the code field between passes (egui keeps it in its memory under this id).
const CODE_FIELD: &str = "orientation code field";

/// The orientation line and, folded under it, the controls that correct it.
pub(crate) fn orientation_ui(ui: &mut egui::Ui, v: &VolumeSummary) -> Option<Action> {
    let mut action = None;
    ui.horizontal(|ui| {
        ui.label("Orientation");
        orientation_label(ui, v);
    });
    if !v.from_file {
        return None;
    }
    // A file without orientation opens with the correction unfolded: the picture may well be
    // upside down, and the fix is one click away.
    let assumed = v.orientation_or_assumed().source == OrientationSource::Assumed;
    egui::CollapsingHeader::new("Correct the orientation")
        .id_salt(("correct orientation", assumed))
        .default_open(assumed)
        .show(ui, |ui| {
            ui.label(
                egui::RichText::new(
                    "When the patient shows upside down or back to front, say which way the \
                     file's axes really point. Kept for this file.",
                )
                .weak(),
            );
            let file = v.file_orientation_or_assumed();
            ui.horizontal(|ui| {
                for (label, d, hint) in [
                    ("Flip S/I", Direction::Superior, "head and feet swapped"),
                    ("Flip A/P", Direction::Anterior, "face and back swapped"),
                    (
                        "Flip R/L",
                        Direction::Right,
                        "the patient's left and right swapped",
                    ),
                ] {
                    if ui.button(label).on_hover_text(hint).clicked() {
                        action = Some(Action::Reorient(Some(file.flipped(d))));
                    }
                }
            });
            if let Some(a) = code_row(ui, &file) {
                action = Some(a);
            }
            if file.source == OrientationSource::User {
                let back = if v.header_orientation.is_some() {
                    "Use the header's"
                } else {
                    "Forget (RAS assumed)"
                };
                if ui.button(back).clicked() {
                    action = Some(Action::Reorient(None));
                }
            }
        });
    action
}

/// A code field (`RAI`, …) with Apply; a code that does not parse says why instead.
fn code_row(ui: &mut egui::Ui, file: &Orientation) -> Option<Action> {
    // Keyed by the code in force: after a flip or a new file the field starts from it again.
    let id = ui.make_persistent_id((CODE_FIELD, file.code()));
    let mut text = ui
        .data(|d| d.get_temp::<String>(id))
        .unwrap_or_else(|| file.code());
    let mut action = None;
    let parsed = Orientation::parse_code(&text);
    ui.horizontal(|ui| {
        let label = ui.label("i, j, k point to");
        let field = ui
            .add(egui::TextEdit::singleline(&mut text).desired_width(48.0))
            .labelled_by(label.id)
            .on_hover_text(
                "Three letters, one each of R/L, A/P and S/I: the patient direction in which \
                 index i, j and k increase (RAI: slices run from the top of the head down)",
            );
        let enter = field.lost_focus() && ui.input(|i| i.key_pressed(egui::Key::Enter));
        let apply = ui.add_enabled(parsed.is_ok(), egui::Button::new("Apply"));
        if (apply.clicked() || enter)
            && let Ok(o) = &parsed
        {
            action = Some(Action::Reorient(Some(*o)));
        }
    });
    if let Err(e) = &parsed {
        ui.colored_label(ui.visuals().warn_fg_color, e.to_string());
    }
    if action.is_some() {
        ui.data_mut(|d| d.remove::<String>(id));
    } else {
        ui.data_mut(|d| d.insert_temp(id, text));
    }
    action
}

/// The volume's orientation code, who gave it, and whether it was read reversed along i.
fn orientation_label(ui: &mut egui::Ui, v: &VolumeSummary) {
    let o = v.orientation_or_assumed();
    let file = v.file_orientation_or_assumed().code();
    let said = match (o.source, v.header_orientation) {
        (OrientationSource::User, Some(h)) => {
            format!("{file} as you set it (the header says {})", h.code())
        }
        (OrientationSource::User, None) => format!("{file} as you set it (the file has none)"),
        (OrientationSource::Header, _) => format!("{file} from the header"),
        (OrientationSource::Assumed, _) => {
            "the file says nothing of where its axes point in the patient; shown as if \
             i, j, k ran to the patient's right, front and head (RAS)"
                .to_string()
        }
        (OrientationSource::AsStored, _) => {
            "no patient orientation in the file: shown as stored (row 0 at the top, column 0 at \
             the left)"
                .to_string()
        }
    };
    // Loading reverses a mirrored file along i (`Volume::unmirrored`), so what is shown is never
    // a mirror image.
    if v.reversed_i {
        ui.colored_label(
            ui.visuals().warn_fg_color,
            format!("{} · i reversed", o.code()),
        )
        .on_hover_text(format!(
            "{said}: a mirror image of the patient, so the samples were reversed along i when \
             loading and the 3D picture is not mirrored (voxel i here is {} − i in the file)",
            v.dims[0].saturating_sub(1)
        ));
        return;
    }
    if o.source == OrientationSource::Assumed {
        ui.colored_label(
            ui.visuals().warn_fg_color,
            format!("none in the file: {} assumed", o.code()),
        )
        .on_hover_text(said);
        return;
    }
    let text = match o.source {
        OrientationSource::User => format!("{} (set by you)", o.code()),
        _ => o.code(),
    };
    ui.label(egui::RichText::new(text).weak())
        .on_hover_text(said);
}
