//! The viewer window: eframe with the wgpu renderer, whose device is created with LeapView's
//! features and limits, and one [`crate::render::VolumeRenderer`] owned by the app (in its
//! [`Scene`]). Each pass takes a finished load, draws the menus and panel, applies gestures to
//! the camera, renders a volume frame only when its inputs changed, and shows the result 1:1 in
//! the central panel.

use std::path::PathBuf;
use std::time::{Duration, Instant};

use egui::{CentralPanel, Color32, Key, KeyboardShortcut, Modifiers, Panel, ViewportCommand};

use crate::camera::ViewPreset;
use crate::render::RenderError;
use crate::settings::Mode;
use crate::transfer::editor::TfEditor;
use crate::transfer::{TransferFunction, ValueSpace};
use crate::ui::controls::{PanelInfo, controls_ui};
use crate::ui::crop::{crop_handles, hint as crop_hint};
use crate::ui::dialogs::Dialogs;
use crate::ui::effects::effects_ui;
use crate::ui::interaction::{window_level_drag, window_level_map};
use crate::ui::loading::{Loader, VolumeSource};
use crate::ui::lod::STILL_AFTER;
use crate::ui::menu::menu_bar;
use crate::ui::orientation_marker;
use crate::ui::overlay::{draw_loading, draw_readout};
use crate::ui::redraw::FrameInputs;
use crate::ui::save_image::{SaveImageEvent, SaveImageForm, save_image_window};
use crate::ui::scene::Scene;
use crate::ui::screenshot::{self, Automation, AutomationError, ShotEvent, TURN_DEG_PER_FRAME};
use crate::ui::tf_editor::tf_editor_ui;
use crate::ui::viewport::view_ui;
use crate::ui::window::native_options;
use crate::ui::{Action, ViewerState, is_ct_like, preset_for_volume};
use crate::volume::{LoadOptions, Volume};

/// Passes without a new frame before the view counts as settled for the screenshot: egui needs
/// a pass or two to settle its layout (panel widths), which can resize the view.
const SETTLED_AFTER_PASSES: u32 = 3;

/// How soon to look again for GPU timings that are on their way.
const RESULTS_POLL: Duration = Duration::from_millis(5);

/// What the window opens with.
#[derive(Clone, Debug, Default)]
pub struct AppOptions {
    /// A volume file; without one, the generated Shepp–Logan phantom.
    pub file: Option<PathBuf>,
    /// Raw-file layout from the command line.
    pub load_options: LoadOptions,
}

/// Why the window could not run.
#[derive(Debug, thiserror::Error)]
pub enum AppError {
    /// A malformed automation variable.
    #[error(transparent)]
    Automation(#[from] AutomationError),
    /// No GPU adapter or device for the window.
    #[error(
        "no usable GPU for the window ({0}). Install a Vulkan driver; without a GPU, Mesa's CPU \
         driver works: `sudo apt-get install mesa-vulkan-drivers`"
    )]
    NoGpu(String),
    /// The window system refused (no display, …).
    #[error("cannot open a window ({0}); is DISPLAY or WAYLAND_DISPLAY set?")]
    Window(String),
    /// The renderer could not start on the window's device.
    #[error("the volume renderer could not start: {0}")]
    Renderer(String),
}

/// Opens the window and runs until it closes.
pub fn run(options: AppOptions) -> Result<(), AppError> {
    let automation = Automation::from_env()?;
    let first = match &options.file {
        Some(path) => VolumeSource::File {
            path: path.clone(),
            options: options.load_options.clone(),
        },
        None => VolumeSource::SheppLogan,
    };
    let title = format!("LeapView — {}", first.label());
    eframe::run_native(
        "leapview",
        native_options(&title),
        Box::new(move |cc| {
            let app = LeapViewApp::new(cc, options.load_options, first, automation)?;
            Ok(Box::new(app))
        }),
    )
    .map_err(|e| match e {
        eframe::Error::Wgpu(e) => AppError::NoGpu(e.to_string()),
        eframe::Error::AppCreation(e) => AppError::Renderer(e.to_string()),
        other => AppError::Window(other.to_string()),
    })
}

/// The app: the plain UI state, the scene (renderer, camera, frame on screen) and what feeds it.
struct LeapViewApp {
    state: ViewerState,
    scene: Scene,
    loader: Loader,
    dialogs: Dialogs,
    automation: Automation,
    load_options: LoadOptions,
    /// The frame on screen when the screenshot was requested.
    shot_inputs: Option<FrameInputs>,
    /// Where the view and the readout were drawn last pass, for the screenshot check.
    view_rect: egui::Rect,
    readout_rect: Option<egui::Rect>,
    /// Where the orientation marker was drawn over the view in the last pass.
    marker_rect: Option<egui::Rect>,
    /// The "Save image" window, while open.
    save_image: Option<SaveImageForm>,
    /// The view's size in pixels last pass.
    view_px: [u32; 2],
    /// When the pointer last moved with a button held, or the wheel turned.
    last_motion: Option<Instant>,
}

impl LeapViewApp {
    fn new(
        cc: &eframe::CreationContext<'_>,
        load_options: LoadOptions,
        first: VolumeSource,
        automation: Automation,
    ) -> Result<Self, AppError> {
        let rs = cc
            .wgpu_render_state
            .as_ref()
            .ok_or_else(|| AppError::Renderer("eframe did not start its wgpu renderer".into()))?;
        let scene = Scene::new(rs).map_err(|e| AppError::Renderer(e.to_string()))?;
        let state = match cc.storage {
            Some(storage) if !automation.is_active() => restored_state(storage),
            _ => ViewerState::default(),
        };
        let mut app = Self {
            state,
            scene,
            loader: Loader::default(),
            dialogs: Dialogs::default(),
            automation,
            load_options,
            shot_inputs: None,
            view_rect: egui::Rect::NOTHING,
            readout_rect: None,
            marker_rect: None,
            save_image: None,
            view_px: [1, 1],
            last_motion: None,
        };
        app.start_loading(first, &cc.egui_ctx);
        Ok(app)
    }

    fn start_loading(&mut self, source: VolumeSource, ctx: &egui::Context) {
        if let Err(e) = self.loader.start(source, ctx) {
            self.dialogs.show_error(e.to_string());
        }
    }

    /// Takes a finished load: uploads it, frames it, picks a fitting preset.
    fn receive_volume(&mut self, ctx: &egui::Context) {
        match self.loader.poll() {
            Some((source, Ok(volume))) => self.show_volume(&volume, &source, ctx),
            Some((_, Err(e))) => {
                self.dialogs
                    .show_error(format!("Cannot open the volume: {e}"));
                self.untitle_if_empty(ctx);
            }
            None => {}
        }
    }

    /// The window was titled after a volume that never came: drop the name.
    fn untitle_if_empty(&self, ctx: &egui::Context) {
        if self.scene.volume().is_none() {
            ctx.send_viewport_cmd(ViewportCommand::Title("LeapView".into()));
        }
    }

    fn show_volume(&mut self, volume: &Volume, source: &VolumeSource, ctx: &egui::Context) {
        match self.scene.show_volume(volume, self.state.projection) {
            Ok(summary) => {
                self.state.effects.forget_data_values();
                self.state.crop = crate::settings::CropBox::FULL;
                if let VolumeSource::File { path, .. } = source {
                    self.state.remember_file(path);
                }
                let name = match source.preferred_preset() {
                    Some(name) => name.to_string(),
                    None => preset_for_volume(&self.state.preset, is_ct_like(summary.range)),
                };
                // The same preset kind keeps the function as edited (and as restored).
                if name != self.state.preset
                    && let Err(e) = self.state.choose_preset(&name)
                {
                    self.dialogs.show_error(e);
                }
                let title = format!("LeapView — {}", summary.name);
                ctx.send_viewport_cmd(ViewportCommand::Title(title));
            }
            Err(e) => {
                let message = match e {
                    RenderError::Volume(e) => e.to_string(),
                    other => other.to_string(),
                };
                self.dialogs
                    .show_error(format!("Cannot show {}: {message}", volume.name()));
                self.untitle_if_empty(ctx);
            }
        }
    }

    fn apply(&mut self, action: Action, ctx: &egui::Context) {
        match action {
            Action::OpenDialog => self.dialogs.open_file_dialog(ctx),
            Action::OpenPathPrompt => self.dialogs.open_prompt(),
            Action::LoadPhantom => self.start_loading(VolumeSource::SheppLogan, ctx),
            Action::LoadVessels => self.start_loading(VolumeSource::VesselTree, ctx),
            Action::Quit => ctx.send_viewport_cmd(ViewportCommand::Close),
            Action::SetView(preset) => self.scene.set_view(preset, self.state.projection),
            Action::ViewFrom(side) => self.scene.view_from(side, self.state.projection),
            Action::ResetView => self
                .scene
                .set_view(ViewPreset::Oblique, self.state.projection),
            Action::SetProjection(kind) => {
                self.state.projection = kind;
                self.scene.set_projection(kind);
            }
            Action::OpenRecent(path) => self.open_file(path, ctx),
            Action::SaveImagePrompt => {
                self.save_image
                    .get_or_insert_with(|| SaveImageForm::new(self.view_px));
            }
        }
        // The change is rendered in the next pass.
        ctx.request_repaint();
    }

    fn open_file(&mut self, path: PathBuf, ctx: &egui::Context) {
        let options = self.load_options.clone();
        self.start_loading(VolumeSource::File { path, options }, ctx);
    }

    /// Keyboard shortcuts and dropped files.
    fn global_input(&mut self, ctx: &egui::Context) {
        let open = KeyboardShortcut::new(Modifiers::COMMAND, Key::O);
        let quit = KeyboardShortcut::new(Modifiers::COMMAND, Key::Q);
        let (open, quit, dropped) = ctx.input_mut(|i| {
            (
                i.consume_shortcut(&open),
                i.consume_shortcut(&quit),
                i.raw.dropped_files.first().map(|f| f.path().to_path_buf()),
            )
        });
        if open {
            self.apply(Action::OpenDialog, ctx);
        }
        if quit {
            self.apply(Action::Quit, ctx);
        }
        if let Some(path) = dropped {
            self.open_file(path, ctx);
        }
    }

    /// The central panel: gestures, the frame, the image and what is drawn over it.
    fn view(&mut self, ui: &mut egui::Ui) {
        let ctx = ui.ctx().clone();
        let area = view_ui(ui, self.scene.camera_mut());
        if area.reset_requested {
            self.apply(Action::ResetView, &ctx);
        }
        if let Some(delta) = area.window_drag {
            self.window_level(delta);
        }
        if area.window_drag_ended {
            self.state.editor.end_gesture();
        }
        if self
            .automation
            .wants_another_frame(self.scene.frames_rendered())
        {
            if let Some(camera) = self.scene.camera_mut() {
                camera.orbit(TURN_DEG_PER_FRAME, 0.0);
            }
            ctx.request_repaint();
        }
        let interacting = self.interacting(&ctx);
        if let Err(message) =
            self.scene
                .render_if_changed(&mut self.state, area.size_px, interacting)
        {
            self.dialogs.show_error(message);
        }
        if self.scene.refining() && !interacting {
            // The next refinement frame comes in the next pass.
            ctx.request_repaint();
        }
        if self.scene.preview_scale().is_some() {
            // Refine once the pointer has been still long enough (or at once, if it is).
            let still_in = self
                .last_motion
                .map_or(Duration::ZERO, |t| STILL_AFTER.saturating_sub(t.elapsed()));
            ctx.request_repaint_after(still_in + Duration::from_millis(1));
        }
        self.view_rect = area.rect;
        self.view_px = area.size_px;
        let [r, g, b] = self.state.background;
        ui.painter()
            .rect_filled(area.rect, 0.0, Color32::from_rgb(r, g, b));
        self.scene.paint(ui, area.rect.min);
        self.marker_rect = None;
        if self.state.show_orientation_marker
            && let Some((camera, _)) = self.scene.camera_and_bounds()
            && let Some(volume) = self.scene.volume()
        {
            self.marker_rect =
                orientation_marker::draw(ui, area.rect, &camera, &volume.orientation_or_assumed());
        }
        if self.state.show_crop_box
            && let Some((camera, bounds)) = self.scene.camera_and_bounds()
        {
            // Moved faces render in the next pass.
            if crop_handles(
                ui,
                area.rect,
                area.size_px,
                &camera,
                &bounds,
                &mut self.state.crop,
            ) {
                ctx.request_repaint();
            }
            crop_hint(ui, area.rect);
        }
        self.readout_rect = None;
        if self.state.show_readout {
            let now = Instant::now();
            let readout = self.scene.readout(&self.state, now);
            self.readout_rect = Some(draw_readout(ui, area.rect, &readout));
            // Refresh when the frame rate changes by itself (down to "idle"); no GPU work.
            if let Some(wait) = self.scene.fps_next_change(now) {
                ctx.request_repaint_after(wait + Duration::from_millis(1));
            }
        }
        if let Some(status) = self.loader.busy()
            && draw_loading(ui, area.rect, &status)
        {
            self.loader.cancel();
            self.untitle_if_empty(&ctx);
        }
        let hovered = ctx.input(|i| i.raw.hovered_files.first().and_then(|f| f.path.clone()));
        if let Some(path) = hovered {
            let name = path
                .file_name()
                .map_or_else(String::new, |n| n.to_string_lossy().into());
            ui.painter()
                .rect_filled(area.rect, 0.0, Color32::from_black_alpha(140));
            ui.painter().text(
                area.rect.center(),
                egui::Align2::CENTER_CENTER,
                format!("Drop to open {name}"),
                egui::FontId::proportional(22.0),
                Color32::WHITE,
            );
        }
    }

    /// Whether the user is dragging or zooming: the pointer moved with a button held, or the
    /// wheel turned, less than [`STILL_AFTER`] ago.
    fn interacting(&mut self, ctx: &egui::Context) -> bool {
        let moving = ctx.input(|i| {
            (i.pointer.any_down() && i.pointer.delta() != egui::Vec2::ZERO)
                || i.smooth_scroll_delta != egui::Vec2::ZERO
                || i.zoom_delta() != 1.0
        });
        if moving {
            self.last_motion = Some(Instant::now());
        }
        self.last_motion.is_some_and(|t| t.elapsed() < STILL_AFTER)
    }

    /// The "Save image" window: renders the view again at the chosen size and writes it.
    fn save_image_ui(&mut self, ctx: &egui::Context) {
        let Some(form) = &mut self.save_image else {
            return;
        };
        match save_image_window(ctx, form, self.view_px) {
            Some(SaveImageEvent::Close) => self.save_image = None,
            Some(SaveImageEvent::Save) => {
                let size = form.size;
                let path = PathBuf::from(&form.path);
                form.status = Some(
                    match self
                        .scene
                        .render_still(&self.state, size)
                        .and_then(|image| image.save(&path).map_err(|e| e.to_string()))
                    {
                        Ok(()) => format!("saved {}×{} to {}", size[0], size[1], path.display()),
                        Err(e) => e,
                    },
                );
                ctx.request_repaint();
            }
            None => {}
        }
    }

    /// A right-drag in the view: the window of MIP, MinIP and X-ray, or the transfer function
    /// shifted and scaled (DVR, isosurface), as 3D Slicer's window/level.
    fn window_level(&mut self, delta: [f32; 2]) {
        let Some(range) = self
            .scene
            .volume()
            .and_then(|v| v.range)
            .filter(|r| r.width() > 0.0)
        else {
            return;
        };
        match self.state.mode {
            Mode::Mip | Mode::MinIp | Mode::Xray | Mode::XrayAttenuation => {
                let window = self.state.effects.window.unwrap_or([range.min, range.max]);
                self.state.effects.window = Some(window_level_drag(window, range, delta));
            }
            Mode::Dvr | Mode::Iso => {
                let tf = self.state.editor.tf();
                let (Some(first), Some(last)) = (tf.opacity.first(), tf.opacity.last()) else {
                    return;
                };
                // One data unit in the function's own coordinates.
                let unit = match tf.space {
                    ValueSpace::Data => 1.0,
                    ValueSpace::Normalized => 1.0 / range.width(),
                };
                let centre = 0.5 * (first[0] + last[0]);
                let width = (last[0] - first[0]).max(unit * range.width() / 1000.0);
                let f = window_level_map(centre, width, range, unit, delta);
                self.state.editor.remap(f);
            }
        }
    }

    /// Screenshot and exit for scripts; see [`crate::ui::screenshot`].
    fn automate(&mut self, ctx: &egui::Context) {
        let quiet_passes = self.scene.note_pass();
        let frames = self.scene.frames_rendered();
        let ready = frames >= 1
            && quiet_passes > SETTLED_AFTER_PASSES
            && !self.scene.results_pending()
            && self.scene.preview_scale().is_none()
            && !self.scene.refining()
            && self.loader.busy().is_none();
        match self.automation.poll_screenshot(ctx, ready) {
            ShotEvent::Requested => self.shot_inputs = self.scene.last_inputs().cloned(),
            ShotEvent::Arrived(path, image) => {
                match screenshot::save(&image, &path) {
                    Ok(()) => log::info!("saved the window to {}", path.display()),
                    Err(e) => log::error!("cannot save the screenshot to {}: {e}", path.display()),
                }
                self.check_screenshot(&image, ctx.pixels_per_point());
            }
            ShotEvent::None => {}
        }
        if frames >= 1 && self.automation.screenshot_waiting() {
            // Keep passes coming until the view has settled.
            ctx.request_repaint();
        }
        if self.automation.should_close(frames) {
            ctx.send_viewport_cmd(ViewportCommand::Close);
        }
    }

    /// Logs how the view in the screenshot differs from the renderer's own image: it must not.
    fn check_screenshot(&self, image: &egui::ColorImage, ppp: f32) {
        if self.shot_inputs.as_ref() != self.scene.last_inputs() {
            log::info!("a new frame was rendered after the screenshot; not compared");
            return;
        }
        let rendered = match self.scene.read_image() {
            Ok(img) => img.to_rgba8(),
            Err(e) => return log::warn!("cannot read the rendered image back: {e}"),
        };
        let px = |v: f32| (v * ppp).round().max(0.0) as usize;
        let origin = [px(self.view_rect.min.x), px(self.view_rect.min.y)];
        let skip: Vec<[usize; 4]> = [self.readout_rect, self.marker_rect]
            .into_iter()
            .flatten()
            .map(|r| [px(r.min.x), px(r.min.y), px(r.max.x), px(r.max.y)])
            .collect();
        let c = screenshot::compare_view(image, origin, &rendered, &skip);
        log::info!(
            "window vs rendered image: {} pixels compared, {} differ, largest difference {} levels",
            c.pixels,
            c.differing,
            c.max_levels
        );
    }
}

impl eframe::App for LeapViewApp {
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        let ctx = ui.ctx().clone();
        // The smoke test counts passes against rendered frames.
        log::trace!("egui pass {}", ctx.cumulative_pass_nr());
        self.receive_volume(&ctx);
        if self.scene.collect_measurements() {
            ctx.request_repaint_after(RESULTS_POLL);
        }
        self.global_input(&ctx);

        let mut actions = Vec::new();
        Panel::top("menu").show(ui, |ui| actions.extend(menu_bar(ui, &mut self.state)));
        let info = PanelInfo {
            path_used: self.scene.path_used(),
            volume: self.scene.volume(),
        };
        let mut show_controls = self.state.show_controls;
        Panel::right("controls")
            .resizable(true)
            .default_size(320.0)
            .show_collapsible(ui, &mut show_controls, |ui| {
                egui::ScrollArea::vertical().show(ui, |ui| {
                    actions.extend(controls_ui(ui, &mut self.state, &info));
                    ui.separator();
                    let volume = self.scene.volume();
                    tf_editor_ui(
                        ui,
                        &mut self.state.editor,
                        volume.and_then(|v| v.range),
                        volume.map_or(&[], |v| v.histogram.as_slice()),
                        &mut self.state.log_histogram,
                    );
                    ui.separator();
                    effects_ui(
                        ui,
                        &mut self.state.mode,
                        &mut self.state.effects,
                        volume.and_then(|v| v.range),
                        volume.map_or(&[], |v| v.histogram.as_slice()),
                    );
                });
            });
        self.state.show_controls = show_controls;
        for action in actions {
            self.apply(action, &ctx);
        }
        CentralPanel::no_frame().show(ui, |ui| self.view(ui));

        if let Some(path) = self.dialogs.ui(&ctx) {
            self.open_file(path, &ctx);
        }
        self.save_image_ui(&ctx);
        self.automate(&ctx);
    }

    fn clear_color(&self, visuals: &egui::Visuals) -> [f32; 4] {
        // Opaque: the window has no see-through parts.
        visuals.panel_fill.to_normalized_gamma_f32()
    }

    fn persist_egui_memory(&self) -> bool {
        false
    }

    /// Keeps the settings and the transfer function being edited for the next run.
    fn save(&mut self, storage: &mut dyn eframe::Storage) {
        if self.automation.is_active() {
            return;
        }
        eframe::set_value(storage, STATE_KEY, &self.state);
        eframe::set_value(storage, TF_KEY, self.state.editor.tf());
    }
}

/// Storage key of the viewer settings.
const STATE_KEY: &str = "viewer-state";
/// Storage key of the transfer function being edited.
const TF_KEY: &str = "transfer-function";

/// The settings and transfer function of the last run; defaults for what is missing or invalid
/// (a stored function that fails validation is dropped with a log line).
fn restored_state(storage: &dyn eframe::Storage) -> ViewerState {
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
