//! The transfer-function editor panel: the opacity curve drawn over the volume's histogram (log
//! or linear), a colour bar with its stops, undo and redo. Every edit goes through
//! [`TfEditor`]; the scene hands the result to the renderer in the same pass, which re-bakes
//! the table and rebuilds the leaping structures before the next frame.
//!
//! Mouse: drag a handle to move it; click or drag on empty canvas to add a point; right-click a
//! handle to delete it. On the colour bar: click to add a stop (in the colour there), drag a stop
//! to move it, right-click to delete, click a stop to pick its colour below. Save and Load read
//! and write the DESIGN.md JSON format at the path in the field.

use egui::{Color32, Id, Pos2, Rect, Sense, Stroke, pos2, vec2};

use crate::transfer::editor::{Curve, TfEditor};
use crate::transfer::{TransferFunction, ValueSpace};
use crate::volume::ValueRange;

/// Height of the opacity canvas, points.
const CANVAS_HEIGHT: f32 = 120.0;
/// Height of the colour bar, points.
const BAR_HEIGHT: f32 = 18.0;
/// How close the pointer must be to grab a handle, points.
const GRAB_RADIUS: f32 = 8.0;
/// Handle radius, points.
const HANDLE_RADIUS: f32 = 4.0;

/// Maps point coordinates (the TF's own space) to the canvas and back.
#[derive(Clone, Copy)]
struct Axis {
    rect: Rect,
    range: ValueRange,
    space: ValueSpace,
}

impl Axis {
    /// Share of the width (0..1) of a point coordinate.
    fn t(&self, coordinate: f64) -> f32 {
        let s = match self.space {
            ValueSpace::Data => self.range.normalize(coordinate),
            ValueSpace::Normalized => coordinate,
        };
        s as f32
    }

    fn x(&self, coordinate: f64) -> f32 {
        self.rect.left() + self.t(coordinate).clamp(0.0, 1.0) * self.rect.width()
    }

    fn coordinate(&self, x: f32) -> f64 {
        let s = f64::from((x - self.rect.left()) / self.rect.width()).clamp(0.0, 1.0);
        match self.space {
            ValueSpace::Data => self.range.denormalize(s),
            ValueSpace::Normalized => s,
        }
    }

    fn y(&self, alpha: f64) -> f32 {
        self.rect.bottom() - alpha.clamp(0.0, 1.0) as f32 * self.rect.height()
    }

    fn alpha(&self, y: f32) -> f64 {
        f64::from((self.rect.bottom() - y) / self.rect.height()).clamp(0.0, 1.0)
    }
}

/// The stop or point a drag holds, kept in egui's memory between passes.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Held(Curve, usize);

/// Draws the editor for the volume's value `range` and `histogram`; returns whether the
/// transfer function changed.
pub fn tf_editor_ui(
    ui: &mut egui::Ui,
    editor: &mut TfEditor,
    range: Option<ValueRange>,
    histogram: &[u64],
    log_scale: &mut bool,
    marker: Option<f64>,
) -> bool {
    let before = editor.tf().clone();
    ui.heading("Transfer function editor");
    let Some(range) = range.filter(|r| r.width() > 0.0) else {
        ui.label("(no volume with a value range)");
        return false;
    };
    ui.horizontal(|ui| {
        if ui
            .add_enabled(editor.can_undo(), egui::Button::new("Undo"))
            .on_hover_text("Ctrl+Z")
            .clicked()
        {
            editor.undo();
        }
        if ui
            .add_enabled(editor.can_redo(), egui::Button::new("Redo"))
            .on_hover_text("Ctrl+Shift+Z")
            .clicked()
        {
            editor.redo();
        }
        ui.checkbox(log_scale, "log histogram");
    });
    let nothing_focused = ui.ctx().memory(|m| m.focused().is_none());
    if nothing_focused {
        let (undo, redo) = ui.input(|i| {
            let z = i.key_pressed(egui::Key::Z) && i.modifiers.command;
            (
                z && !i.modifiers.shift,
                (z && i.modifiers.shift) || (i.key_pressed(egui::Key::Y) && i.modifiers.command),
            )
        });
        if undo {
            editor.undo();
        } else if redo {
            editor.redo();
        }
    }
    opacity_canvas(ui, editor, range, histogram, *log_scale, marker);
    color_bar(ui, editor, range);
    file_row(ui, editor);
    ui.label(format!(
        "{} opacity points, {} colour stops · values in {}",
        editor.tf().opacity.len(),
        editor.tf().color.len(),
        match editor.tf().space {
            ValueSpace::Data => "data units",
            ValueSpace::Normalized => "fractions of the range",
        }
    ));
    *editor.tf() != before
}

fn opacity_canvas(
    ui: &mut egui::Ui,
    editor: &mut TfEditor,
    range: ValueRange,
    histogram: &[u64],
    log_scale: bool,
    marker: Option<f64>,
) {
    let width = ui.available_width().max(64.0);
    let (rect, response) =
        ui.allocate_exact_size(vec2(width, CANVAS_HEIGHT), Sense::click_and_drag());
    // Named for screen readers and for the UI tests, which find the canvas by this name.
    let response = response.accessible_name("Opacity curve");
    let axis = Axis {
        rect,
        range,
        space: editor.tf().space,
    };
    let id = response.id.with("held");
    handle_opacity_input(ui, editor, &response, axis, id);
    let painter = ui.painter_at(rect);
    let visuals = ui.visuals();
    painter.rect_filled(rect, 2.0, visuals.extreme_bg_color);
    draw_histogram(
        &painter,
        rect,
        histogram,
        log_scale,
        visuals.weak_text_color(),
    );
    // The value under the pointer in a slice view, on the histogram.
    if let Some(value) = marker {
        let x = axis.x(match editor.tf().space {
            ValueSpace::Data => value,
            ValueSpace::Normalized => range.normalize(value),
        });
        if rect.x_range().contains(x) {
            painter.line_segment(
                [pos2(x, rect.top()), pos2(x, rect.bottom())],
                Stroke::new(1.0, egui::Color32::from_rgb(255, 200, 0)),
            );
        }
    }
    let tf = editor.tf();
    let points: Vec<Pos2> = tf
        .opacity
        .iter()
        .map(|p| pos2(axis.x(p[0]), axis.y(p[1])))
        .collect();
    if let (Some(first), Some(last)) = (points.first(), points.last()) {
        let mut line = vec![pos2(rect.left(), first.y)];
        line.extend(&points);
        line.push(pos2(rect.right(), last.y));
        painter.add(egui::Shape::line(
            line,
            Stroke::new(1.5, visuals.strong_text_color()),
        ));
    }
    let held = ui.data(|d| d.get_temp::<Held>(id));
    for (i, (p, point)) in points.iter().zip(&tf.opacity).enumerate() {
        let fill = rgb(tf.color_at(tf.to_data(point[0], range), range));
        let stroke = if held == Some(Held(Curve::Opacity, i)) {
            Stroke::new(2.0, visuals.selection.stroke.color)
        } else {
            Stroke::new(1.0, visuals.strong_text_color())
        };
        painter.circle(*p, HANDLE_RADIUS, fill, stroke);
    }
}

fn handle_opacity_input(
    ui: &egui::Ui,
    editor: &mut TfEditor,
    response: &egui::Response,
    axis: Axis,
    id: Id,
) {
    let nearest = |editor: &TfEditor, pos: Pos2| -> Option<usize> {
        editor
            .tf()
            .opacity
            .iter()
            .enumerate()
            .map(|(i, p)| (i, pos2(axis.x(p[0]), axis.y(p[1])).distance(pos)))
            .filter(|(_, d)| *d <= GRAB_RADIUS)
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .map(|(i, _)| i)
    };
    if response.secondary_clicked()
        && let Some(pos) = response.interact_pointer_pos()
        && let Some(i) = nearest(editor, pos)
    {
        // The last point stays; the editor refuses to delete it.
        let _ = editor.remove(Curve::Opacity, i);
        return;
    }
    // A drag starts where the button went down, not where the pointer is once it has moved
    // past egui's drag threshold.
    let press = ui.input(|i| i.pointer.press_origin());
    if response.drag_started()
        && let Some(pos) = press.or(response.interact_pointer_pos())
    {
        let index = match nearest(editor, pos) {
            Some(i) => Some(i),
            None => editor
                .add_opacity(axis.coordinate(pos.x), axis.alpha(pos.y))
                .ok(),
        };
        if let Some(i) = index {
            ui.data_mut(|d| d.insert_temp(id, Held(Curve::Opacity, i)));
        }
    }
    if response.dragged()
        && let Some(pos) = response.interact_pointer_pos()
        && let Some(Held(Curve::Opacity, i)) = ui.data(|d| d.get_temp::<Held>(id))
        && let Ok(new) = editor.move_opacity(i, axis.coordinate(pos.x), axis.alpha(pos.y))
    {
        ui.data_mut(|d| d.insert_temp(id, Held(Curve::Opacity, new)));
    }
    if response.drag_stopped() {
        editor.end_gesture();
        ui.data_mut(|d| d.remove::<Held>(id));
    }
    if response.clicked()
        && let Some(pos) = response.interact_pointer_pos()
        && nearest(editor, pos).is_none()
    {
        let _ = editor.add_opacity(axis.coordinate(pos.x), axis.alpha(pos.y));
    }
}

fn color_bar(ui: &mut egui::Ui, editor: &mut TfEditor, range: ValueRange) {
    let width = ui.available_width().max(64.0);
    let (rect, response) = ui.allocate_exact_size(vec2(width, BAR_HEIGHT), Sense::click_and_drag());
    let response = response.accessible_name("Colour bar");
    let axis = Axis {
        rect,
        range,
        space: editor.tf().space,
    };
    let selected_id = response.id.with("selected");
    handle_color_input(ui, editor, &response, &axis, selected_id);
    paint_color_bar(ui, editor.tf(), &axis, ui.data(|d| d.get_temp(selected_id)));
    let selected = ui.data(|d| d.get_temp::<usize>(selected_id));
    if let Some(i) = selected.filter(|&i| i < editor.tf().color.len()) {
        let p = editor.tf().color[i];
        let mut rgb_f32 = [p[1] as f32, p[2] as f32, p[3] as f32];
        ui.horizontal(|ui| {
            ui.label(format!("stop at {:.4}", p[0]));
            if egui::color_picker::color_edit_button_rgb(ui, &mut rgb_f32).changed() {
                let _ = editor.set_color(i, rgb_f32.map(f64::from));
            }
        });
    }
}

/// The colour bar's gestures: right-click deletes a stop, a click selects one or adds one at the
/// colour already there, a drag moves one (one undo step). The selected stop is kept under
/// `selected_id`.
fn handle_color_input(
    ui: &egui::Ui,
    editor: &mut TfEditor,
    response: &egui::Response,
    axis: &Axis,
    selected_id: egui::Id,
) {
    let id = response.id.with("held");
    let nearest = |tf: &TransferFunction, x: f32| -> Option<usize> {
        tf.color
            .iter()
            .enumerate()
            .map(|(i, p)| (i, (axis.x(p[0]) - x).abs()))
            .filter(|(_, d)| *d <= GRAB_RADIUS)
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .map(|(i, _)| i)
    };
    let pointer = response.interact_pointer_pos();
    if response.secondary_clicked()
        && let Some(pos) = pointer
        && let Some(i) = nearest(editor.tf(), pos.x)
    {
        let _ = editor.remove(Curve::Color, i);
        ui.data_mut(|d| d.remove::<usize>(selected_id));
    } else if response.clicked()
        && let Some(pos) = pointer
    {
        let index = nearest(editor.tf(), pos.x).or_else(|| {
            let value = axis.coordinate(pos.x);
            let tf = editor.tf();
            let c = tf.color_at(tf.to_data(value, axis.range), axis.range);
            editor.add_color(value, c).ok()
        });
        if let Some(i) = index {
            ui.data_mut(|d| d.insert_temp(selected_id, i));
        }
    }
    let press = ui.input(|i| i.pointer.press_origin());
    if response.drag_started()
        && let Some(pos) = press.or(pointer)
        && let Some(i) = nearest(editor.tf(), pos.x)
    {
        ui.data_mut(|d| d.insert_temp(id, Held(Curve::Color, i)));
    }
    if response.dragged()
        && let Some(pos) = pointer
        && let Some(Held(Curve::Color, i)) = ui.data(|d| d.get_temp::<Held>(id))
        && let Ok(new) = editor.move_color(i, axis.coordinate(pos.x))
    {
        ui.data_mut(|d| {
            d.insert_temp(id, Held(Curve::Color, new));
            d.insert_temp(selected_id, new);
        });
    }
    if response.drag_stopped() {
        editor.end_gesture();
        ui.data_mut(|d| d.remove::<Held>(id));
    }
}

/// The bar: the colour at each column, then the stops as ticks (the selected one thicker).
fn paint_color_bar(ui: &egui::Ui, tf: &TransferFunction, axis: &Axis, selected: Option<usize>) {
    let rect = axis.rect;
    let painter = ui.painter_at(rect);
    let columns = rect.width().max(1.0) as usize;
    for c in 0..columns {
        let x = rect.left() + c as f32;
        let value = tf.to_data(axis.coordinate(x + 0.5), axis.range);
        painter.line_segment(
            [pos2(x + 0.5, rect.top()), pos2(x + 0.5, rect.bottom())],
            Stroke::new(1.0, rgb(tf.color_at(value, axis.range))),
        );
    }
    for (i, p) in tf.color.iter().enumerate() {
        let x = axis.x(p[0]);
        let width = if selected == Some(i) { 3.0 } else { 1.5 };
        painter.line_segment(
            [pos2(x, rect.top()), pos2(x, rect.bottom())],
            Stroke::new(width, Color32::WHITE),
        );
    }
}

/// A path field with Save and Load (the DESIGN.md JSON format); the outcome is shown under it.
fn file_row(ui: &mut egui::Ui, editor: &mut TfEditor) {
    let path_id = ui.scope_id().with("tf file path");
    let status_id = ui.scope_id().with("tf file status");
    let mut path: String = ui
        .data(|d| d.get_temp(path_id))
        .unwrap_or_else(|| "transfer-function.json".to_string());
    ui.horizontal(|ui| {
        ui.add(egui::TextEdit::singleline(&mut path).desired_width(170.0))
            .on_hover_text("JSON file (DESIGN.md format)");
        let status = if ui.button("Save").clicked() {
            Some(match editor.tf().save(std::path::Path::new(&path)) {
                Ok(()) => format!("saved {path}"),
                Err(e) => e.to_string(),
            })
        } else if ui.button("Load").clicked() {
            Some(match TransferFunction::load(std::path::Path::new(&path)) {
                Ok(tf) => {
                    editor.set(tf);
                    format!("loaded {path}")
                }
                Err(e) => e.to_string(),
            })
        } else {
            None
        };
        if let Some(status) = status {
            ui.data_mut(|d| d.insert_temp(status_id, status));
        }
    });
    ui.data_mut(|d| d.insert_temp(path_id, path));
    if let Some(status) = ui.data(|d| d.get_temp::<String>(status_id)) {
        ui.small(status);
    }
}

fn rgb(c: [f64; 3]) -> Color32 {
    let [r, g, b] = c.map(|x| (x.clamp(0.0, 1.0) * 255.0).round() as u8);
    Color32::from_rgb(r, g, b)
}

fn draw_histogram(
    painter: &egui::Painter,
    rect: Rect,
    counts: &[u64],
    log_scale: bool,
    color: Color32,
) {
    let scale = |c: u64| {
        if log_scale {
            (c as f64).ln_1p()
        } else {
            c as f64
        }
    };
    let peak = counts.iter().map(|&c| scale(c)).fold(0.0, f64::max);
    if peak <= 0.0 || counts.is_empty() {
        return;
    }
    let bar = rect.width() / counts.len() as f32;
    let stroke = Stroke::new(bar.max(1.0), color.gamma_multiply(0.6));
    for (i, &c) in counts.iter().enumerate() {
        let h = (scale(c) / peak) as f32 * rect.height();
        let x = rect.left() + (i as f32 + 0.5) * bar;
        painter.line_segment([pos2(x, rect.bottom()), pos2(x, rect.bottom() - h)], stroke);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_axis_maps_both_spaces_and_round_trips() {
        let rect = Rect::from_min_size(pos2(10.0, 20.0), vec2(200.0, 100.0));
        let range = ValueRange {
            min: -1000.0,
            max: 3000.0,
        };
        for space in [ValueSpace::Data, ValueSpace::Normalized] {
            let axis = Axis { rect, range, space };
            let c = match space {
                ValueSpace::Data => 1000.0,
                ValueSpace::Normalized => 0.5,
            };
            assert_eq!(axis.x(c), 110.0);
            assert!((axis.coordinate(axis.x(c)) - c).abs() < 1e-9 * c.abs().max(1.0));
            assert_eq!(axis.y(1.0), 20.0);
            assert_eq!(axis.alpha(axis.y(0.25)), 0.25);
        }
    }
}
