//! The "Effect" section of the side panel: the mode and its parameters (lighting, isosurface
//! value over the histogram, window, MIP colouring, X-ray attenuation).

use egui::{ComboBox, DragValue, Sense, Slider, SliderClamping, Stroke, vec2};

use crate::settings::{GradientScheme, Light, MAX_ISO_REFINEMENT, MipColor, Mode, Shading};
use crate::volume::ValueRange;

use crate::ui::ViewerState;

/// Height of the histogram under the iso slider, in points.
const HISTOGRAM_HEIGHT: f32 = 56.0;

/// Mode names as the panel shows them.
fn mode_label(mode: Mode) -> &'static str {
    match mode {
        Mode::Dvr => "DVR (compositing)",
        Mode::Iso => "Isosurface",
        Mode::Mip => "MIP",
        Mode::MinIp => "MinIP",
        Mode::Xray => "X-ray (mean)",
        Mode::XrayAttenuation => "X-ray (radiograph)",
    }
}

/// Draws the section; `range` and `histogram` describe the volume on screen, if any.
pub(crate) fn effects_ui(
    ui: &mut egui::Ui,
    state: &mut ViewerState,
    range: Option<ValueRange>,
    histogram: &[u64],
) {
    ui.heading("Effect");
    let fx = &mut state.render;
    ComboBox::from_id_salt("mode")
        .selected_text(mode_label(fx.mode))
        .show_ui(ui, |ui| {
            for m in Mode::ALL {
                ui.selectable_value(&mut fx.mode, m, mode_label(m));
            }
        });
    let mode = fx.mode;
    if mode == Mode::Iso {
        iso_ui(ui, &mut fx.iso, range, histogram);
    }
    if matches!(
        mode,
        Mode::Mip | Mode::MinIp | Mode::Xray | Mode::XrayAttenuation
    ) {
        window_ui(ui, &mut fx.window, range);
    }
    if matches!(mode, Mode::Mip | Mode::MinIp) {
        ui.horizontal(|ui| {
            ui.label("Colour");
            ui.selectable_value(&mut fx.mip_color, MipColor::Window, "grey (window)");
            ui.selectable_value(&mut fx.mip_color, MipColor::Tf, "transfer function");
        });
    }
    if mode == Mode::XrayAttenuation {
        ui.horizontal(|ui| {
            ui.label("μ at window top (1/mm)");
            ui.add(
                Slider::new(&mut fx.xray_density_per_mm, 0.0..=0.2)
                    .max_decimals(4)
                    .clamping(SliderClamping::Edits),
            );
        });
    }
    if mode.can_shade() {
        lighting_ui(ui, state);
    }
}

fn iso_ui(
    ui: &mut egui::Ui,
    iso: &mut crate::settings::IsoSettings,
    range: Option<ValueRange>,
    histogram: &[u64],
) {
    let Some(range) = range.filter(|r| r.width() > 0.0) else {
        ui.label("Iso value: the volume is constant");
        return;
    };
    let mut value = iso.value.unwrap_or(range.denormalize(0.5));
    ui.label("Iso value (click or drag on the histogram)");
    histogram_picker(ui, histogram, range, &mut value);
    ui.add(
        Slider::new(&mut value, range.min..=range.max)
            .clamping(SliderClamping::Edits)
            .max_decimals(2),
    );
    if iso.value.is_some() || value != range.denormalize(0.5) {
        iso.value = Some(value);
    }
    ui.horizontal(|ui| {
        ui.label("Refinement steps");
        ui.add(Slider::new(
            &mut iso.refine_iterations,
            0..=MAX_ISO_REFINEMENT,
        ))
        .on_hover_text("False-position steps between the two samples around a hit");
    });
}

/// A log-scale histogram over the value range with a marker at `value`; clicking or dragging on
/// it moves `value`.
fn histogram_picker(ui: &mut egui::Ui, counts: &[u64], range: ValueRange, value: &mut f64) {
    let width = ui.available_width().max(64.0);
    let (rect, response) =
        ui.allocate_exact_size(vec2(width, HISTOGRAM_HEIGHT), Sense::click_and_drag());
    let painter = ui.painter_at(rect);
    let visuals = ui.visuals();
    painter.rect_filled(rect, 2.0, visuals.extreme_bg_color);
    let peak = counts
        .iter()
        .map(|&c| (c as f64).ln_1p())
        .fold(0.0, f64::max);
    if peak > 0.0 {
        let bar = rect.width() / counts.len() as f32;
        let stroke = Stroke::new(bar.max(1.0), visuals.weak_text_color());
        for (i, &c) in counts.iter().enumerate() {
            let h = ((c as f64).ln_1p() / peak) as f32 * rect.height();
            let x = rect.left() + (i as f32 + 0.5) * bar;
            painter.line_segment(
                [
                    egui::pos2(x, rect.bottom()),
                    egui::pos2(x, rect.bottom() - h),
                ],
                stroke,
            );
        }
    }
    if let Some(pos) = response.interact_pointer_pos() {
        let t = f64::from((pos.x - rect.left()) / rect.width()).clamp(0.0, 1.0);
        *value = range.denormalize(t);
    }
    let x = rect.left() + range.normalize(*value).clamp(0.0, 1.0) as f32 * rect.width();
    painter.line_segment(
        [egui::pos2(x, rect.top()), egui::pos2(x, rect.bottom())],
        Stroke::new(2.0, visuals.selection.bg_fill),
    );
}

fn window_ui(ui: &mut egui::Ui, window: &mut Option<[f64; 2]>, range: Option<ValueRange>) {
    let Some(range) = range.filter(|r| r.width() > 0.0) else {
        return;
    };
    let [mut lo, mut hi] = window.unwrap_or([range.min, range.max]);
    let speed = range.width() / 500.0;
    let before = [lo, hi];
    ui.horizontal(|ui| {
        ui.label("Window");
        ui.add(DragValue::new(&mut lo).speed(speed).prefix("lo "));
        ui.add(DragValue::new(&mut hi).speed(speed).prefix("hi "));
        if ui
            .small_button("full")
            .on_hover_text("The volume's whole value range")
            .clicked()
        {
            *window = None;
        }
    });
    if [lo, hi] != before {
        // Keep lo < hi whichever end moved.
        let gap = range.width() / 1000.0;
        if hi <= lo {
            if lo != before[0] {
                lo = hi - gap;
            } else {
                hi = lo + gap;
            }
        }
        *window = Some([lo, hi]);
    }
}

fn lighting_ui(ui: &mut egui::Ui, state: &mut ViewerState) {
    let fx = &mut state.render;
    let mut lit = fx.shading == Shading::Phong;
    ui.checkbox(&mut lit, "Phong lighting")
        .on_hover_text("Per-sample lighting from on-the-fly gradients");
    fx.shading = if lit { Shading::Phong } else { Shading::Off };
    ui.add_enabled_ui(lit, |ui| {
        egui::Grid::new("phong").num_columns(2).show(ui, |ui| {
            let p = &mut state.render.phong;
            for (label, v, max) in [
                ("Ambient Ka", &mut p.ambient, 1.0),
                ("Diffuse Kd", &mut p.diffuse, 1.0),
                ("Specular Ks", &mut p.specular, 1.0),
                ("Exponent n", &mut p.shininess, 128.0),
            ] {
                ui.label(label);
                ui.add(Slider::new(v, 0.0..=max).clamping(SliderClamping::Edits));
                ui.end_row();
            }
            light_rows(ui, state);
            shadow_rows(ui, state);
            occlusion_rows(ui, state);
            ui.label("Light only above");
            ui.add(
                Slider::new(&mut state.render.light_min_weight, 0.0..=0.05)
                    .logarithmic(true)
                    .smallest_positive(1e-4)
                    .max_decimals(4)
                    .clamping(SliderClamping::Edits),
            )
            .on_hover_text(
                "DVR samples weighing less than this in their pixel (opacity × what shows \
                 through) are left unlit, without their gradient reads: faster where much is \
                 faint or hidden (Quality presets set it; 0 lights every sample)",
            );
            ui.end_row();
            ui.label("Gradients");
            let gradient = &mut state.render.gradient;
            ui.horizontal(|ui| {
                ui.selectable_value(gradient, GradientScheme::Central, "central");
                ui.selectable_value(gradient, GradientScheme::FourthOrder, "4th order");
            });
            ui.end_row();
        });
    });
}

/// The shadows' rows of the lighting grid: on or off, the shadow rays' step and reach.
fn shadow_rows(ui: &mut egui::Ui, state: &mut ViewerState) {
    let shadows = &mut state.render.shadows;
    ui.label("Shadows");
    ui.checkbox(&mut shadows.on, "cast").on_hover_text(
        "DVR: each lit sample dimmed by the opacity between it and the light (a directional \
         light by a shadow ray that leaps empty space; the headlight by what lies in front of \
         the sample). Samples below 'Light only above' are not shadowed.",
    );
    ui.end_row();
    if shadows.on {
        let (lo, hi) = crate::settings::effects::SHADOW_STEP_RANGE;
        ui.label("shadow step");
        ui.add(
            Slider::new(&mut shadows.step_vox, lo..=hi)
                .logarithmic(true)
                .suffix(" vox")
                .clamping(SliderClamping::Always),
        )
        .on_hover_text("Distance between a shadow ray's samples: smaller is finer and slower");
        ui.end_row();
        ui.label("shadow reach");
        ui.add(Slider::new(&mut shadows.reach, 0.02..=1.0).clamping(SliderClamping::Always))
            .on_hover_text(
                "How far a shadow ray reaches, as a share of the volume's diagonal: 1 all the \
                 way, less keeps shadows local (and costs less)",
            );
        ui.end_row();
        ui.label("softness");
        let most = crate::settings::effects::MOST_SHADOW_SOFTNESS;
        ui.add(
            Slider::new(&mut shadows.softness_deg, 0.0..=most)
                .suffix("°")
                .clamping(SliderClamping::Always),
        )
        .on_hover_text(
            "The light's angular radius: 0 casts hard shadows; above, soft shadows, noisy while \
             the view moves and smooth once 'refine when still' has averaged its frames",
        );
        ui.end_row();
    }
}

/// The ambient occlusion's rows of the lighting grid: on or off, and the rays' reach.
fn occlusion_rows(ui: &mut egui::Ui, state: &mut ViewerState) {
    let occlusion = &mut state.render.occlusion;
    ui.label("Occlusion");
    ui.checkbox(&mut occlusion.on, "ambient").on_hover_text(
        "Each lit sample's ambient light scaled by how open its surroundings are: six short \
         rays over the side its gradient points away from (folds and crevices darken)",
    );
    ui.end_row();
    if occlusion.on {
        let (lo, hi) = crate::settings::effects::OCCLUSION_RADIUS_RANGE;
        ui.label("occlusion reach");
        ui.add(
            Slider::new(&mut occlusion.radius_vox, lo..=hi)
                .suffix(" vox")
                .clamping(SliderClamping::Always),
        )
        .on_hover_text("How far the occlusion rays look: farther darkens larger hollows, slower");
        ui.end_row();
    }
}

/// The light's rows of the lighting grid: headlight, or where a directional light comes from.
fn light_rows(ui: &mut egui::Ui, state: &mut ViewerState) {
    ui.label("Light");
    let mut headlight = state.render.light == Light::Headlight;
    if ui.checkbox(&mut headlight, "headlight").changed() {
        state.set_headlight(headlight);
    }
    ui.end_row();
    if !headlight {
        let mut angles = state.light_angles;
        ui.label("from azimuth");
        ui.add(Slider::new(&mut angles[0], -180.0..=180.0).suffix("°"));
        ui.end_row();
        ui.label("elevation");
        ui.add(Slider::new(&mut angles[1], -90.0..=90.0).suffix("°"));
        ui.end_row();
        if angles != state.light_angles {
            state.set_light_angles(angles);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_mode_shows_without_touching_the_state() {
        let range = ValueRange {
            min: -1000.0,
            max: 3000.0,
        };
        let counts: Vec<u64> = (0..256).map(|i| (i * 37 % 101) as u64).collect();
        for m in Mode::ALL {
            let ctx = egui::Context::default();
            let mut state = ViewerState::default();
            state.render.mode = m;
            let before = state.clone();
            let mut out = ctx.run_ui(egui::RawInput::default(), |ui| {
                effects_ui(ui, &mut state, Some(range), &counts);
            });
            out.textures_delta.clear();
            assert_eq!(state, before, "{m:?}");
        }
    }
}
