//! The "Effect" section of the side panel: the mode and its parameters (lighting, isosurface
//! value over the histogram, window, MIP colouring, X-ray attenuation).

use egui::{ComboBox, DragValue, Sense, Slider, SliderClamping, Stroke, vec2};
use serde::{Deserialize, Serialize};

use crate::settings::effects::{
    DEFAULT_XRAY_DENSITY_PER_MM, GradientScheme, IsoSettings, Light, MAX_ISO_REFINEMENT, MipColor,
    Phong, Shading,
};
use crate::settings::{Mode, RenderSettings};
use crate::volume::ValueRange;

/// Height of the histogram under the iso slider, in points.
const HISTOGRAM_HEIGHT: f32 = 56.0;

/// The effect parameters the panel edits (a subset of [`RenderSettings`], with the light as two
/// angles a slider can hold).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct EffectState {
    /// Lighting on or off (DVR and isosurface).
    pub shading: Shading,
    /// Phong coefficients.
    pub phong: Phong,
    /// Light at the eye (else from `light_angles`).
    pub headlight: bool,
    /// Azimuth and elevation in degrees of where a directional light comes from.
    pub light_angles: [f64; 2],
    /// Gradient estimator.
    pub gradient: GradientScheme,
    /// Isosurface value (data units) and refinement.
    pub iso: IsoSettings,
    /// MIP/MinIP/X-ray window in data units; `None` = the value range.
    pub window: Option<[f64; 2]>,
    /// MIP/MinIP colouring.
    pub mip_color: MipColor,
    /// X-ray attenuation per mm at the window's top.
    pub xray_density_per_mm: f64,
}

impl Default for EffectState {
    fn default() -> Self {
        let s = RenderSettings::default();
        Self {
            shading: s.shading,
            phong: s.phong,
            headlight: true,
            light_angles: [45.0, 30.0],
            gradient: s.gradient,
            iso: s.iso,
            window: s.window,
            mip_color: s.mip_color,
            xray_density_per_mm: DEFAULT_XRAY_DENSITY_PER_MM,
        }
    }
}

impl EffectState {
    /// Writes these parameters into `settings`.
    pub fn apply(&self, settings: &mut RenderSettings) {
        settings.shading = self.shading;
        settings.phong = self.phong;
        settings.light = self.light();
        settings.gradient = self.gradient;
        settings.iso = self.iso;
        settings.window = self.window;
        settings.mip_color = self.mip_color;
        settings.xray_density_per_mm = self.xray_density_per_mm;
    }

    /// The light: a headlight, or shining from the direction the angles name towards the volume.
    pub fn light(&self) -> Light {
        if self.headlight {
            return Light::Headlight;
        }
        let [az, el] = self.light_angles.map(f64::to_radians);
        let from = [el.cos() * az.sin(), el.cos() * az.cos(), el.sin()];
        Light::Direction(from.map(|c| -c))
    }

    /// Forgets the values in data units (iso value, window) when another volume opens: they
    /// belong to the old volume's units.
    pub fn forget_data_values(&mut self) {
        self.iso.value = None;
        self.window = None;
    }
}

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
pub fn effects_ui(
    ui: &mut egui::Ui,
    mode: &mut Mode,
    fx: &mut EffectState,
    range: Option<ValueRange>,
    histogram: &[u64],
) {
    ui.heading("Effect");
    ComboBox::from_id_salt("mode")
        .selected_text(mode_label(*mode))
        .show_ui(ui, |ui| {
            for m in Mode::ALL {
                ui.selectable_value(mode, m, mode_label(m));
            }
        });
    if *mode == Mode::Iso {
        iso_ui(ui, fx, range, histogram);
    }
    if matches!(
        *mode,
        Mode::Mip | Mode::MinIp | Mode::Xray | Mode::XrayAttenuation
    ) {
        window_ui(ui, fx, range);
    }
    if matches!(*mode, Mode::Mip | Mode::MinIp) {
        ui.horizontal(|ui| {
            ui.label("Colour");
            ui.selectable_value(&mut fx.mip_color, MipColor::Window, "grey (window)");
            ui.selectable_value(&mut fx.mip_color, MipColor::Tf, "transfer function");
        });
    }
    if *mode == Mode::XrayAttenuation {
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
        lighting_ui(ui, fx);
    }
}

fn iso_ui(ui: &mut egui::Ui, fx: &mut EffectState, range: Option<ValueRange>, histogram: &[u64]) {
    let Some(range) = range.filter(|r| r.width() > 0.0) else {
        ui.label("Iso value: the volume is constant");
        return;
    };
    let mut value = fx.iso.value.unwrap_or(range.denormalize(0.5));
    ui.label("Iso value (click or drag on the histogram)");
    histogram_picker(ui, histogram, range, &mut value);
    ui.add(
        Slider::new(&mut value, range.min..=range.max)
            .clamping(SliderClamping::Edits)
            .max_decimals(2),
    );
    if fx.iso.value.is_some() || value != range.denormalize(0.5) {
        fx.iso.value = Some(value);
    }
    ui.horizontal(|ui| {
        ui.label("Refinement steps");
        ui.add(Slider::new(
            &mut fx.iso.refine_iterations,
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

fn window_ui(ui: &mut egui::Ui, fx: &mut EffectState, range: Option<ValueRange>) {
    let Some(range) = range.filter(|r| r.width() > 0.0) else {
        return;
    };
    let [mut lo, mut hi] = fx.window.unwrap_or([range.min, range.max]);
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
            fx.window = None;
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
        fx.window = Some([lo, hi]);
    }
}

fn lighting_ui(ui: &mut egui::Ui, fx: &mut EffectState) {
    let mut lit = fx.shading == Shading::Phong;
    ui.checkbox(&mut lit, "Phong lighting")
        .on_hover_text("Per-sample lighting from on-the-fly gradients");
    fx.shading = if lit { Shading::Phong } else { Shading::Off };
    ui.add_enabled_ui(lit, |ui| {
        egui::Grid::new("phong").num_columns(2).show(ui, |ui| {
            let p = &mut fx.phong;
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
            ui.label("Light");
            ui.checkbox(&mut fx.headlight, "headlight");
            ui.end_row();
            if !fx.headlight {
                ui.label("from azimuth");
                ui.add(Slider::new(&mut fx.light_angles[0], -180.0..=180.0).suffix("°"));
                ui.end_row();
                ui.label("elevation");
                ui.add(Slider::new(&mut fx.light_angles[1], -90.0..=90.0).suffix("°"));
                ui.end_row();
            }
            ui.label("Gradients");
            ui.horizontal(|ui| {
                ui.selectable_value(&mut fx.gradient, GradientScheme::Central, "central");
                ui.selectable_value(&mut fx.gradient, GradientScheme::FourthOrder, "4th order");
            });
            ui.end_row();
        });
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_state_gives_the_default_settings() {
        let mut settings = RenderSettings::default();
        EffectState::default().apply(&mut settings);
        assert_eq!(settings, RenderSettings::default());
    }

    #[test]
    fn a_directional_light_shines_towards_the_volume() {
        let fx = EffectState {
            headlight: false,
            light_angles: [0.0, 90.0],
            ..EffectState::default()
        };
        // From straight above (elevation 90°): shining down −z.
        let Light::Direction(d) = fx.light() else {
            panic!("a direction")
        };
        assert!(d[0].abs() < 1e-12 && d[1].abs() < 1e-12 && (d[2] + 1.0).abs() < 1e-12);
    }

    #[test]
    fn every_mode_shows_without_touching_the_state() {
        let range = ValueRange {
            min: -1000.0,
            max: 3000.0,
        };
        let counts: Vec<u64> = (0..256).map(|i| (i * 37 % 101) as u64).collect();
        for m in Mode::ALL {
            let ctx = egui::Context::default();
            let (mut mode, mut fx) = (m, EffectState::default());
            let mut out = ctx.run_ui(egui::RawInput::default(), |ui| {
                effects_ui(ui, &mut mode, &mut fx, Some(range), &counts);
            });
            out.textures_delta.clear();
            assert_eq!((mode, &fx), (m, &EffectState::default()), "{m:?}");
        }
    }

    #[test]
    fn new_volumes_drop_values_in_the_old_units() {
        let mut fx = EffectState {
            window: Some([0.0, 1.0]),
            ..EffectState::default()
        };
        fx.iso.value = Some(300.0);
        fx.forget_data_values();
        assert_eq!((fx.window, fx.iso.value), (None, None));
    }
}
