//! The viewer window: eframe with the wgpu renderer, whose device is created with LeapView's
//! features and limits, and one [`crate::render::VolumeRenderer`] owned by the app (in its
//! [`Scene`]). Each pass takes a finished load, draws the menus and panel, applies gestures to
//! the camera, renders a volume frame only when its inputs changed, and shows the result 1:1 in
//! the central panel.

mod automation;
mod labels;
mod persistence;
mod view;

use std::path::PathBuf;
use std::time::{Duration, Instant};

use egui::{CentralPanel, Key, KeyboardShortcut, Modifiers, Panel, ViewportCommand};

use crate::labels::DropGuess;
use crate::render::RenderError;
use crate::transfer::fit::preset_for_kind;
use crate::ui::frames::redraw::FrameInputs;
use crate::ui::frames::scene::Scene;
use crate::ui::layout::Layout;
use crate::ui::loading::{Loader, VolumeSource};
use crate::ui::panels::controls::{PanelInfo, controls_ui};
use crate::ui::panels::dialogs::{Dialogs, Purpose};
use crate::ui::panels::effects::effects_ui;
use crate::ui::panels::menu::menu_bar;
use crate::ui::panels::save_image::{SaveImageEvent, SaveImageForm, save_image_window};
use crate::ui::panels::tf_editor::tf_editor_ui;
use crate::ui::screenshot::{Automation, AutomationError};
use crate::ui::window::native_options;
use crate::ui::{Action, ViewerState};
use crate::volume::{LoadOptions, Volume};
use persistence::{STATE_KEY, TF_KEY, restored_state};

/// How soon to look again for GPU timings that are on their way.
const RESULTS_POLL: Duration = Duration::from_millis(5);

/// What the window opens with.
#[derive(Clone, Debug, Default)]
pub struct AppOptions {
    /// A volume file; without one, the generated Shepp–Logan phantom.
    pub file: Option<PathBuf>,
    /// Raw-file layout from the command line.
    pub load_options: LoadOptions,
    /// `--gpu-budget`, over the one the window kept.
    pub gpu_budget: Option<u64>,
    /// A segmentation of the file, shown over the slices once it is open.
    pub labels: Option<PathBuf>,
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
         driver works (scripts/setup-debian.sh installs it: mesa-vulkan-drivers)"
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
            let mut app = LeapViewApp::new(
                cc,
                options.load_options,
                first,
                automation,
                options.gpu_budget,
            )?;
            app.pending_labels = options.labels;
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
    /// What lies under the pointer in the 3D view this pass (where a segmentation is shown).
    hover_3d: Option<crate::ui::slices::Probe>,
    readout_rect: Option<egui::Rect>,
    /// Where the orientation marker was drawn over the view in the last pass.
    marker_rect: Option<egui::Rect>,
    /// The slice planes' outlines drawn over the 3D view in the last pass (segments, points).
    plane_lines: Vec<[egui::Pos2; 2]>,
    /// The "Save image" window, while open.
    save_image: Option<SaveImageForm>,
    /// The view's size in pixels last pass.
    view_px: [u32; 2],
    /// When the pointer last moved with a button held, or the wheel turned.
    last_motion: Option<Instant>,
    /// Where the volume on screen came from.
    shown_source: Option<VolumeSource>,
    /// The outcome of an image being saved, while it is.
    saving: Option<std::sync::mpsc::Receiver<Result<String, String>>>,
    /// The layout the user had when a 2D image opened in its own (restored for a volume).
    layout_before_image: Option<Layout>,
    /// The slice views (drawn when the layout has them).
    slices: crate::ui::slices::SliceViews,
    /// A segmentation being read.
    labels_load: Option<labels::LabelsLoad>,
    /// A segmentation to read once a volume is shown.
    pending_labels: Option<PathBuf>,
    /// The file of the segmentation shown (the key its style is kept under).
    labels_file: Option<String>,
}

impl LeapViewApp {
    fn new(
        cc: &eframe::CreationContext<'_>,
        load_options: LoadOptions,
        first: VolumeSource,
        automation: Automation,
        gpu_budget: Option<u64>,
    ) -> Result<Self, AppError> {
        let rs = cc
            .wgpu_render_state
            .as_ref()
            .ok_or_else(|| AppError::Renderer("eframe did not start its wgpu renderer".into()))?;
        let scene = Scene::new(rs, &cc.egui_ctx).map_err(|e| AppError::Renderer(e.to_string()))?;
        let slices = crate::ui::slices::SliceViews::new(rs);
        let mut state = match cc.storage {
            Some(storage) if !automation.is_active() => restored_state(storage),
            _ => ViewerState::default(),
        };
        if gpu_budget.is_some() {
            state.gpu_budget = gpu_budget;
        }
        if load_options.ram_budget.is_some() {
            state.ram_budget = load_options.ram_budget;
        }
        let mut loader = Loader::default();
        loader.check_against(crate::render::GpuContext::new(
            &rs.adapter,
            rs.device.clone(),
            rs.queue.clone(),
        ));
        let mut app = Self {
            state,
            scene,
            loader,
            dialogs: Dialogs::default(),
            automation,
            load_options,
            shot_inputs: None,
            view_rect: egui::Rect::NOTHING,
            hover_3d: None,
            readout_rect: None,
            marker_rect: None,
            plane_lines: Vec::new(),
            save_image: None,
            view_px: [1, 1],
            last_motion: None,
            shown_source: None,
            saving: None,
            layout_before_image: None,
            slices,
            labels_load: None,
            pending_labels: None,
            labels_file: None,
        };
        // A file's orientation as corrected before, unless the command line gives one.
        let first = match first {
            VolumeSource::File { path, mut options } => {
                if options.orientation.is_none() {
                    options.orientation = app.state.orientation_for(&path);
                }
                VolumeSource::File { path, options }
            }
            other => other,
        };
        app.start_loading(first, &cc.egui_ctx);
        Ok(app)
    }

    fn start_loading(&mut self, source: VolumeSource, ctx: &egui::Context) {
        // The memory budget as the window sets it now, whatever it was when the file was first
        // opened.
        let source = match source {
            VolumeSource::File { path, mut options } => {
                options.ram_budget = self.state.ram_budget;
                VolumeSource::File { path, options }
            }
            other => other,
        };
        if let Err(e) = self.loader.start(source, ctx, self.state.gpu_budget) {
            self.dialogs.show_error(e.to_string());
        }
    }

    /// Takes a finished load: uploads it, frames it, picks a fitting preset.
    fn receive_volume(&mut self, ctx: &egui::Context) {
        match self.loader.poll() {
            Some((source, Ok(volume))) => self.show_volume(volume, &source, ctx),
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

    fn show_volume(&mut self, volume: Volume, source: &VolumeSource, ctx: &egui::Context) {
        // Shared by the renderer (its bricks come from it), the slices and the readouts.
        let volume = std::sync::Arc::new(volume);
        let from_file = matches!(source, VolumeSource::File { .. });
        match self.scene.show_volume(
            &volume,
            (self.state.projection, self.state.gpu_budget),
            from_file,
        ) {
            Ok(summary) => {
                self.shown_source = Some(source.clone());
                self.state.forget_volume_values();
                // MIP, MinIP and X-ray start from the header's window, else the data's, as
                // `leapview render` does.
                self.state.render.window = summary.provenance.window.or_else(|| {
                    summary.range.and_then(|range| {
                        crate::transfer::fit::default_window(&crate::volume::Histogram {
                            range,
                            counts: summary.histogram.clone(),
                        })
                    })
                });
                for note in &summary.provenance.notes {
                    log::warn!("{}: {note}", summary.name);
                }
                if let VolumeSource::File { path, .. } = source {
                    self.state.remember_file(path);
                }
                let name = source
                    .preferred_preset()
                    .unwrap_or_else(|| preset_for_kind(&self.state.preset, &summary.kind));
                // The same preset on the same kind of data keeps the function as edited (and as
                // restored); a CT in other scanner units gets the preset fitted anew.
                let refit = self.state.fitted_to.as_ref() != Some(&summary.kind);
                if (name != self.state.preset || refit)
                    && let Err(e) = self.state.choose_preset_for(name, summary.kind.clone())
                {
                    self.dialogs.show_error(e);
                }
                // A 2D image opens alone in its plane; a volume after one, in the layout the
                // user had before.
                match crate::mpr::frame::image_plane_of(
                    summary.dims,
                    summary.orientation_or_assumed(),
                ) {
                    Some(kind) => {
                        if self.state.layout.has_3d() {
                            self.layout_before_image = Some(self.state.layout);
                        }
                        self.state.layout = Layout::Image(kind);
                        log::info!("a 2D image: shown alone in its {} plane", kind.name());
                    }
                    None if !self.state.layout.has_3d() => {
                        self.state.layout = self.layout_before_image.take().unwrap_or_default();
                    }
                    None => {}
                }
                let title = format!("LeapView — {}", summary.name);
                ctx.send_viewport_cmd(ViewportCommand::Title(title));
                // The slices start from the same window as MIP: the header's, else the data's.
                let window = self.state.render.window.unwrap_or([0.0, 1.0]);
                if let Some((texture, format)) = self.scene.volume_texture() {
                    self.slices
                        .set_volume(std::sync::Arc::clone(&volume), texture, format, window);
                }
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
            Action::OpenFolderDialog => self.dialogs.open_folder_dialog(ctx),
            Action::OpenSeries(number) => self.open_series(number, ctx),
            Action::OpenVolume(index) => self.open_volume(index, ctx),
            Action::OpenChannel(index) => self.open_channel(index, ctx),
            Action::OpenPathPrompt => self.dialogs.open_prompt(),
            Action::OpenLabelsDialog => self.dialogs.open_labels_dialog(ctx),
            Action::LoadPhantom => self.start_loading(VolumeSource::SheppLogan, ctx),
            Action::LoadVessels => self.start_loading(VolumeSource::VesselTree, ctx),
            Action::Quit => ctx.send_viewport_cmd(ViewportCommand::Close),
            Action::SetView(preset) => self
                .scene
                .framing_mut()
                .set_view(preset, self.state.projection),
            Action::ViewFrom(side) => self
                .scene
                .framing_mut()
                .view_from(side, self.state.projection),
            Action::ResetView => self.scene.framing_mut().reset_view(self.state.projection),
            Action::Roll(deg) => {
                if let Some(camera) = self.scene.framing_mut().camera_mut() {
                    camera.roll(deg);
                }
            }
            Action::Reorient(orientation) => self.reorient(orientation, ctx),
            Action::SetGpuBudget(budget) => {
                self.state.gpu_budget = budget;
                if let Some(source) = self.shown_source.clone() {
                    self.start_loading(source, ctx);
                }
            }
            Action::SetRamBudget(budget) => {
                self.state.ram_budget = budget;
                if let Some(source) = self.shown_source.clone() {
                    self.start_loading(source, ctx);
                }
            }
            Action::SetProjection(kind) => {
                self.state.projection = kind;
                self.scene.framing_mut().set_projection(kind);
            }
            Action::SetLayout(layout) => self.state.layout = layout,
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
        let mut options = self.load_options.clone();
        // The orientation given on the command line is for the file named there.
        options.orientation = self.state.orientation_for(&path);
        self.start_loading(VolumeSource::File { path, options }, ctx);
    }

    /// Opens another series of the folder (or file) the volume on screen came from.
    fn open_series(&mut self, number: usize, ctx: &egui::Context) {
        let Some(VolumeSource::File { path, mut options }) = self.shown_source.clone() else {
            return;
        };
        options.series = Some(crate::volume::dicom::SeriesChoice::Number(number));
        self.start_loading(VolumeSource::File { path, options }, ctx);
    }

    /// Opens another volume of the 4-D file on screen.
    fn open_volume(&mut self, index: u32, ctx: &egui::Context) {
        let Some(VolumeSource::File { path, mut options }) = self.shown_source.clone() else {
            return;
        };
        options.volume = Some(index);
        self.start_loading(VolumeSource::File { path, options }, ctx);
    }

    /// Opens channel `index` (counted from 0) of the image on screen, at the same volume.
    fn open_channel(&mut self, index: u32, ctx: &egui::Context) {
        let Some(VolumeSource::File { path, mut options }) = self.shown_source.clone() else {
            return;
        };
        options.channel = Some(index);
        self.start_loading(VolumeSource::File { path, options }, ctx);
    }

    /// Takes the file on screen to be oriented as `orientation` (`None`: as its header says),
    /// remembers that for the file, and opens it again so that the views, the marker and a
    /// reversal along i follow.
    fn reorient(&mut self, orientation: Option<crate::volume::Orientation>, ctx: &egui::Context) {
        let Some(VolumeSource::File { path, .. }) = self.shown_source.clone() else {
            return;
        };
        self.state.set_orientation_for(&path, orientation);
        self.open_file(path, ctx);
    }

    /// Keyboard shortcuts and dropped files.
    fn global_input(&mut self, ctx: &egui::Context) {
        let open = KeyboardShortcut::new(Modifiers::COMMAND, Key::O);
        let quit = KeyboardShortcut::new(Modifiers::COMMAND, Key::Q);
        let statistics = KeyboardShortcut::new(Modifiers::NONE, Key::F12);
        let (open, quit, count, dropped) = ctx.input_mut(|i| {
            (
                i.consume_shortcut(&open),
                i.consume_shortcut(&quit),
                i.consume_shortcut(&statistics),
                i.raw.dropped_files.first().map(|f| f.path().to_path_buf()),
            )
        });
        if count {
            self.state.statistics = !self.state.statistics;
        }
        if open {
            self.apply(Action::OpenDialog, ctx);
        }
        if quit {
            self.apply(Action::Quit, ctx);
        }
        if let Some(path) = dropped {
            // Over a volume, a file that is its labels opens as them; one that may be is asked
            // about; anything else opens as an image.
            let dims = self.slices.volume().map(|v| v.dims());
            match dims.map(|d| crate::labels::guess_dropped(&path, d)) {
                Some(DropGuess::Labels(why)) => {
                    log::info!("{} opens as the segmentation: {why}", path.display());
                    self.open_labels(path, ctx);
                }
                Some(DropGuess::Ask(why)) => self.dialogs.ask_dropped(path, why),
                Some(DropGuess::Image) | None => self.open_file(path, ctx),
            }
        }
    }

    /// The "Save image" window: renders the view again at the chosen size and writes it, on a
    /// thread of its own (the window stays responsive; the status says when it is written).
    fn save_image_ui(&mut self, ctx: &egui::Context) {
        if let Some(rx) = &self.saving
            && let Ok(outcome) = rx.try_recv()
        {
            self.saving = None;
            if let Some(form) = &mut self.save_image {
                form.status = Some(outcome.unwrap_or_else(|e| e));
            }
        }
        let Some(form) = &mut self.save_image else {
            return;
        };
        match save_image_window(ctx, form, self.view_px) {
            Some(SaveImageEvent::Close) => self.save_image = None,
            Some(SaveImageEvent::Save) if self.saving.is_none() => {
                let size = form.size;
                let path = PathBuf::from(&form.path);
                match self.scene.save_still(&self.state, size, path, ctx) {
                    Ok(rx) => {
                        form.status = Some(format!("rendering {}×{}…", size[0], size[1]));
                        self.saving = Some(rx);
                    }
                    Err(e) => form.status = Some(e),
                }
                ctx.request_repaint();
            }
            Some(SaveImageEvent::Save) | None => {}
        }
    }
}

impl eframe::App for LeapViewApp {
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        let ctx = ui.ctx().clone();
        // The smoke test counts passes against rendered frames.
        log::trace!("egui pass {}", ctx.cumulative_pass_nr());
        self.receive_volume(&ctx);
        self.receive_labels(&ctx);
        self.keep_label_style();
        if self.scene.collect_measurements() {
            ctx.request_repaint_after(RESULTS_POLL);
        }
        self.global_input(&ctx);

        let mut actions = Vec::new();
        let image = self
            .scene
            .volume()
            .and_then(|v| crate::mpr::frame::image_plane_of(v.dims, v.orientation_or_assumed()));
        Panel::top("menu").show(ui, |ui| {
            actions.extend(menu_bar(ui, &mut self.state, image));
        });
        let info = PanelInfo {
            path_used: self.scene.path_used(),
            strategy_used: self.scene.strategy_used(),
            volume: self.scene.volume(),
        };
        let mut show_controls = self.state.show_controls;
        Panel::right("controls")
            .resizable(true)
            // As wide as its widest row (the cropping sliders) from the first pass: a panel that
            // grew once a volume's rows appeared would resize the view under its first frame.
            .default_size(370.0)
            .show_collapsible(ui, &mut show_controls, |ui| {
                egui::ScrollArea::vertical().show(ui, |ui| {
                    let slices = &mut self.slices;
                    let volume = self.scene.volume();
                    let middle = |ui: &mut egui::Ui, state: &mut ViewerState| {
                        let range = volume.and_then(|v| v.range);
                        let histogram = volume.map_or(&[][..], |v| v.histogram.as_slice());
                        // A 2D image shows no 3D view: no mode, lighting or ray casting.
                        if state.layout.has_3d() {
                            effects_ui(ui, state, range, histogram);
                            ui.separator();
                        }
                        tf_editor_ui(
                            ui,
                            &mut state.editor,
                            range,
                            histogram,
                            &mut state.log_histogram,
                            slices.hover().and_then(|p| p.value),
                        );
                        ui.separator();
                        if state.layout.has_slices() && volume.is_some() {
                            slices.labels_ui(
                                ui,
                                &mut state.render.labels,
                                &mut state.render.label_smoothing,
                            );
                            slices.controls_ui(ui);
                            ui.separator();
                        }
                    };
                    actions.extend(controls_ui(ui, &mut self.state, &info, middle));
                });
            });
        self.state.show_controls = show_controls;
        for action in actions {
            self.apply(action, &ctx);
        }
        CentralPanel::no_frame().show(ui, |ui| self.view(ui));

        match self.dialogs.ui(&ctx) {
            Some((path, Purpose::Volume)) => self.open_file(path, &ctx),
            Some((path, Purpose::Labels)) => self.open_labels(path, &ctx),
            None => {}
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

    /// Logs what the window was left at (scripts and the window tests read it).
    fn on_exit(&mut self) {
        log::info!(
            "closing with preset {}, strategy {}, mode {:?}",
            self.state.preset,
            self.state.render.strategy.label(),
            self.state.render.mode
        );
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
