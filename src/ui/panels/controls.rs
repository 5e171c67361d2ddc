//! The side panel: the series, transfer-function preset and quality, cropping, views and
//! orientation, background and projection, what is loaded, and, collapsed under "Advanced", the
//! renderer's knobs (strategy, block, ray loop, step, termination, statistics).

use egui::{ComboBox, Slider, SliderClamping};

use crate::camera::ProjectionKind;
use crate::settings::{
    ConcretePath, DEFAULT_TERMINATION_ALPHA, Mode, QualityPreset, RenderPath, RenderSettings,
    Strategy,
};
use crate::text::number;
use crate::transfer::presets::NAMES;

use crate::ui::panels::menu::VIEWS;
use crate::ui::{Action, ViewerState, VolumeSummary};

/// Step slider range in voxels: 1/8 voxel is finer than any visible difference; 4 voxels is
/// coarse enough to show the undersampling artefacts the step trades against speed.
pub const STEP_RANGE_VOX: std::ops::RangeInclusive<f64> = 0.125..=4.0;

/// Termination slider range: below 0.5 the image visibly loses everything behind the first
/// half-opaque surface; 1 means "never stop early".
pub const TERMINATION_RANGE: std::ops::RangeInclusive<f64> = 0.5..=1.0;

/// What the panel shows besides the state it edits.
pub struct PanelInfo<'a> {
    /// The path `auto` resolved to (from the last frame), if known.
    pub path_used: Option<ConcretePath>,
    /// The strategy the last frame ran with (what `auto` stood for), if known.
    pub strategy_used: Option<Strategy>,
    /// The volume on screen.
    pub volume: Option<&'a VolumeSummary>,
}

/// Draws the panel contents; returns an action for the buttons that need the app.
///
/// The order is a reader's: what is open (a DICOM folder's series and the notes from loading
/// it), the preset and quality, then `middle` (the app's mode and lighting, transfer-function
/// editor and slice settings), cropping, the views and orientation, what is loaded; the
/// renderer's own knobs (strategy, block, ray loop, step, termination, statistics) last, in a
/// collapsed "Advanced" section.
///
/// The sliders round only what the user edits (`SliderClamping::Edits`): with egui's default
/// they would round the value on every pass, and the default termination 1 − 1/255 would
/// silently become 0.9961, giving other images than `leapview render`.
pub fn controls_ui(
    ui: &mut egui::Ui,
    state: &mut ViewerState,
    info: &PanelInfo,
    middle: impl FnOnce(&mut egui::Ui, &mut ViewerState),
) -> Option<Action> {
    let mut action = None;
    // Where the volume came from, first: the series chooser of a DICOM folder and what loading
    // had to say (a resampled gap, an assumption) must not hide below the fold.
    // A file's time points and channels are chosen here too.
    if let Some(v) = info.volume
        && (v.provenance.series.is_some()
            || !v.provenance.notes.is_empty()
            || v.provenance.volumes.is_some()
            || v.provenance.channels.is_some())
    {
        ui.heading(if v.provenance.series.is_some() {
            "Series"
        } else {
            "Source"
        });
        series_rows(ui, v, &mut action);
        ui.separator();
    }
    ui.heading("Display");
    egui::Grid::new("display controls")
        .num_columns(2)
        .spacing([8.0, 6.0])
        .show(ui, |ui| {
            preset_row(ui, state);
            // Quality, refinement, cropping and the renderer's knobs are the 3D view's: a 2D
            // image alone in its plane has none.
            if state.layout.has_3d() {
                quality_rows(ui, state);
            }
        });
    ui.separator();
    middle(ui, state);
    let three_d = state.layout.has_3d();
    if let Some(volume) = info.volume.filter(|_| three_d) {
        ui.heading("Cropping");
        let crop = &mut state.render.crop;
        crate::ui::view::crop::crop_ui(ui, crop, &mut state.show_crop_box, volume.dims);
        ui.separator();
    }
    ui.heading("View");
    if let Some(a) = view_section(ui, info.volume, three_d) {
        action = Some(a);
    }
    if three_d {
        egui::Grid::new("look controls")
            .num_columns(2)
            .spacing([8.0, 6.0])
            .show(ui, |ui| {
                if let Some(a) = look_rows(ui, state) {
                    action = Some(a);
                }
            });
    }
    ui.separator();
    ui.heading("Volume");
    volume_section(ui, info.volume);
    if !three_d {
        return action;
    }
    ui.separator();
    egui::CollapsingHeader::new("Advanced")
        .id_salt("advanced")
        .default_open(false)
        .show(ui, |ui| {
            ui.label(
                egui::RichText::new(
                    "How the renderer works: every strategy and ray loop gives the same picture",
                )
                .weak(),
            );
            egui::Grid::new("render controls")
                .num_columns(2)
                .spacing([8.0, 6.0])
                .show(ui, |ui| {
                    strategy_rows(ui, state, info.strategy_used);
                    path_row(ui, state, info.path_used);
                    sampling_rows(ui, state);
                    readout_rows(ui, state);
                    if let Some(budget) = gpu_budget_row(ui, state.gpu_budget) {
                        action = Some(Action::SetGpuBudget(budget));
                    }
                    if let Some(budget) = ram_budget_row(ui, state.ram_budget) {
                        action = Some(Action::SetRamBudget(budget));
                    }
                });
        });
    action
}

/// Budgets the GPU-memory list offers, in bytes: round decimal sizes, as the list names them.
const GPU_BUDGETS: [u64; 8] = [
    250_000_000,
    500_000_000,
    1_000_000_000,
    2_000_000_000,
    4_000_000_000,
    8_000_000_000,
    16_000_000_000,
    32_000_000_000,
];

/// The GPU memory a volume may take (the default: a share of what the driver reports free);
/// a new choice, where one was made.
fn gpu_budget_row(ui: &mut egui::Ui, budget: Option<u64>) -> Option<Option<u64>> {
    budget_row(
        ui,
        ("GPU memory", "gpu budget"),
        "The most GPU memory the volume may take; past it the volume is shown from bricks of a \
         coarser level (the overlay says so). Changing it loads the volume again.",
        &GPU_BUDGETS,
        budget,
    )
}

/// Budgets the store-memory list offers, in bytes.
const RAM_BUDGETS: [u64; 7] = [
    1_000_000_000,
    2_000_000_000,
    4_000_000_000,
    8_000_000_000,
    16_000_000_000,
    32_000_000_000,
    64_000_000_000,
];

/// The memory an OME-Zarr store's or a TIFF stack's samples may take (the default: half the
/// memory available); a new choice, where one was made.
fn ram_budget_row(ui: &mut egui::Ui, budget: Option<u64>) -> Option<Option<u64>> {
    budget_row(
        ui,
        ("Store memory", "ram budget"),
        "The most memory an OME-Zarr store's or a TIFF stack's samples may take; a larger one is \
         read brick by brick as the view needs them, its decoded chunks cached within this. \
         Changing it loads the volume again.",
        &RAM_BUDGETS,
        budget,
    )
}

/// A row choosing a budget among `options` (or the default) under `label`; a new choice,
/// where one was made.
fn budget_row(
    ui: &mut egui::Ui,
    (label, id): (&str, &str),
    hover: &str,
    options: &[u64],
    budget: Option<u64>,
) -> Option<Option<u64>> {
    let name = |b: Option<u64>| b.map_or_else(|| "default".to_string(), crate::text::bytes);
    let label = ui.label(label).on_hover_text(hover);
    let mut chosen = None;
    ComboBox::from_id_salt(id)
        .selected_text(name(budget))
        .show_ui(ui, |ui| {
            for option in std::iter::once(None).chain(options.iter().copied().map(Some)) {
                if ui
                    .selectable_label(budget == option, name(option))
                    .clicked()
                    && budget != option
                {
                    chosen = Some(option);
                }
            }
        })
        .response
        .labelled_by(label.id);
    ui.end_row();
    chosen
}

/// The transfer-function preset.
fn preset_row(ui: &mut egui::Ui, state: &mut ViewerState) {
    // Combo boxes are named by their row's label (screen readers, the UI tests).
    let label = ui.label("Transfer function");
    ComboBox::from_id_salt("preset")
        .selected_text(state.preset.as_str())
        .show_ui(ui, |ui| {
            for name in NAMES {
                if ui.selectable_label(state.preset == name, name).clicked() {
                    // Presets are built in: loading one cannot fail.
                    let _ = state.choose_preset(name);
                }
            }
        })
        .response
        .labelled_by(label.id);
    ui.end_row();
}

/// Strategy and block size.
fn strategy_rows(ui: &mut egui::Ui, state: &mut ViewerState, used: Option<Strategy>) {
    ui.label("Strategy");
    let in_use = state.strategy_in_use();
    let strategy = &mut state.render.strategy;
    ui.horizontal(|ui| {
        for (value, label, hint) in [
            (
                Strategy::Auto,
                "auto",
                "RC-t or leaping, whichever renders these settings faster on this GPU \
                 (timed when they change; the same image either way)",
            ),
            (Strategy::Rc, "RC", "Every sample from entry to exit"),
            (
                Strategy::RcT,
                "RC-t",
                "Stop once the ray is (nearly) opaque",
            ),
            (
                Strategy::RcS,
                "RC-s",
                "RC-t plus leaping over empty octree nodes (the paper)",
            ),
            (
                Strategy::RcSDistance,
                "RC-s-df",
                "RC-t plus leaping by a distance field over blocks",
            ),
        ] {
            ui.selectable_value(strategy, value, label)
                .on_hover_text(hint);
        }
    });
    ui.end_row();

    // What the selection stands for, on a row of its own (always there, so that neither the
    // panel's width nor the rows under it move when the first frame tells or a click changes it).
    let (text, hint) = match *strategy {
        Strategy::Auto => (
            match used.filter(|u| *u != Strategy::Auto) {
                Some(used) => format!("uses {}", used.label()),
                None => "decided when the view is still".to_owned(),
            },
            "Timed on this volume, transfer function, mode and image size once the view was \
             still; a CPU driver takes leaping untimed",
        ),
        s if in_use != s => (
            "RC-s in this mode".to_owned(),
            "The distance field is built beforehand from the transfer function, the window or \
             the iso value; what MIP and MinIP can skip depends on the extreme each ray has \
             found so far, so they leap by the octree",
        ),
        Strategy::Rc => ("no acceleration".to_owned(), "The reference for timings"),
        Strategy::RcT => (
            "early termination".to_owned(),
            "The same image as every other strategy",
        ),
        Strategy::RcS => ("leaps by the octree".to_owned(), "The same image as RC-t"),
        Strategy::RcSDistance => (
            "leaps by a distance field".to_owned(),
            "The same image as RC-t",
        ),
    };
    ui.label("");
    ui.label(egui::RichText::new(text).weak())
        .on_hover_text(hint);
    ui.end_row();

    ui.label("Block (voxels)");
    let auto = crate::settings::default_block_vox(state.render.mode, state.render.strategy);
    let auto_label = format!("auto ({auto})");
    let block = &mut state.render.block_vox;
    ui.add_enabled_ui(state.render.strategy.leaps(), |ui| {
        ComboBox::from_id_salt("block")
            .selected_text(block.map_or(auto_label.clone(), |b| b.to_string()))
            .show_ui(ui, |ui| {
                ui.selectable_value(block, None, auto_label)
                    .on_hover_text("The edge measured fastest for this mode and strategy");
                for b in crate::accel::pyramid::BLOCK_SIZES {
                    ui.selectable_value(block, Some(b), b.to_string());
                }
            })
            .response
            .on_hover_text("Edge of the blocks whose emptiness the rays test");
    });
    ui.end_row();
}

/// What the readout adds and how dragging renders: sample counts, the developer readout, the
/// interaction preview.
fn readout_rows(ui: &mut egui::Ui, state: &mut ViewerState) {
    ui.label("Statistics");
    ui.checkbox(&mut state.statistics, "count samples")
        .on_hover_text(
            "Samples taken, samples with non-zero opacity, regions leapt, lookups in the leaping \
             structure per ray (slower)",
        );
    ui.end_row();

    ui.label("Readout");
    ui.checkbox(&mut state.developer_readout, "developer readout")
        .on_hover_text(
            "Frame rate, GPU time, strategy and ray loop, adapter and latencies over the 3D view",
        );
    ui.end_row();

    ui.label("Interaction");
    ui.checkbox(&mut state.interaction_lod, "preview while dragging")
        .on_hover_text(format!(
            "While you drag, a frame that would take more than {} ms renders at a lower \
             resolution; the full-quality frame follows once the pointer is still",
            crate::ui::frames::lod::BUDGET_MS
        ));
    ui.end_row();
}

/// The ray-loop path, and what `auto` chose.
fn path_row(ui: &mut egui::Ui, state: &mut ViewerState, path_used: Option<ConcretePath>) {
    let label = ui.label("Ray loop");
    let path = &mut state.render.path;
    ui.horizontal(|ui| {
        ComboBox::from_id_salt("path")
            .selected_text(path_label(*path))
            .show_ui(ui, |ui| {
                for p in [RenderPath::Auto, RenderPath::Fragment, RenderPath::Compute] {
                    ui.selectable_value(path, p, path_label(p));
                }
            })
            .response
            .labelled_by(label.id);
        if *path == RenderPath::Auto {
            let chosen = match path_used {
                Some(ConcretePath::Fragment) => "uses fragment",
                Some(ConcretePath::Compute) => "uses compute",
                None => "(decided at the first frame)",
            };
            ui.label(chosen).on_hover_text(
                "Auto timed both paths once on this GPU and kept the faster \
                     (a CPU driver takes the compute path)",
            );
        }
    });
    ui.end_row();
}

/// The quality preset (it sets the sampling knobs of the Advanced section) and refinement.
fn quality_rows(ui: &mut egui::Ui, state: &mut ViewerState) {
    ui.label("Quality");
    let current = state.quality();
    let render = &mut state.render;
    ComboBox::from_id_salt("quality")
        .selected_text(current.map_or("Custom", QualityPreset::label))
        .show_ui(ui, |ui| {
            for preset in QualityPreset::ALL {
                if ui
                    .selectable_label(current == Some(preset), preset.label())
                    .on_hover_text(quality_hint(preset))
                    .clicked()
                {
                    preset.apply(render);
                }
            }
        })
        .response
        .on_hover_text(
            "Step, termination, jitter, pre-integration, gradients and iso refinement chosen \
             from the accuracy benchmark's Pareto front (docs/accuracy)",
        );
    ui.end_row();

    ui.label("Refine when still");
    ui.add(
        Slider::new(
            &mut state.refine_frames,
            1..=crate::ui::state::MAX_REFINE_FRAMES,
        )
        .logarithmic(true)
        .suffix(" frames"),
    )
    .on_hover_text(
        "Once the view is still, render it again with the samples shifted along the rays and \
         show the mean: 8 frames sample each ray as densely as an 8× finer step, for 8 frames' \
         time spent only while nothing changes (1: off). Saved images are refined the same way.",
    );
    ui.end_row();
}

/// The sampling knobs the quality preset sets: step, jitter, pre-integration, termination.
fn sampling_rows(ui: &mut egui::Ui, state: &mut ViewerState) {
    let render = &mut state.render;
    ui.label("Step (voxels)");
    ui.add(
        Slider::new(&mut render.step_vox, STEP_RANGE_VOX)
            .logarithmic(true)
            .max_decimals(3)
            .clamping(SliderClamping::Edits),
    )
    .on_hover_text("Distance between samples along a ray, in units of the smallest voxel spacing");
    ui.end_row();

    ui.label("Jitter");
    ui.checkbox(&mut render.jitter, "jittered ray starts")
        .on_hover_text(
            "A per-pixel offset of the first sample: fine noise instead of wood-grain rings. \
             While \"Refine when still\" is above 1 frame, still views are always jittered: \
             their mean converges as without it",
        );
    ui.end_row();

    ui.label("Pre-integration");
    ui.add_enabled(
        render.mode == Mode::Dvr,
        egui::Checkbox::new(&mut render.preintegrated, "pre-integrated classification"),
    )
    .on_hover_text(
        "Classify each segment between samples by the transfer function integrated over its \
         values: thin TF features survive large steps (slower; on smooth ramps plain sampling \
         is as accurate)",
    );
    ui.end_row();
    termination_row(ui, render);
}

/// The termination threshold of RC-t and the leaping strategies.
fn termination_row(ui: &mut egui::Ui, render: &mut RenderSettings) {
    ui.label("Termination");
    let alpha = &mut render.termination_alpha;
    ui.add_enabled_ui(render.strategy.terminates_early(), |ui| {
        ui.horizontal(|ui| {
            ui.add(
                Slider::new(alpha, TERMINATION_RANGE)
                    .max_decimals(4)
                    .clamping(SliderClamping::Edits),
            )
            .on_hover_text("RC-t stops once accumulated opacity exceeds this");
            if ui
                .small_button("1−1/255")
                .on_hover_text("The default: what is left is below one 8-bit level")
                .clicked()
            {
                *alpha = DEFAULT_TERMINATION_ALPHA;
            }
        });
    });
    ui.end_row();
}

/// Background and projection; the projection is the app's to switch (it keeps the size).
fn look_rows(ui: &mut egui::Ui, state: &mut ViewerState) -> Option<Action> {
    ui.label("Background");
    let mut rgb = state.background_rgb8();
    if ui.color_edit_button_srgb(&mut rgb).changed() {
        state.set_background_rgb8(rgb);
    }
    ui.end_row();

    let mut action = None;
    ui.label("Projection");
    ui.horizontal(|ui| {
        for (kind, label) in [
            (ProjectionKind::Perspective, "Perspective"),
            (ProjectionKind::Orthographic, "Orthographic"),
        ] {
            if ui
                .selectable_label(state.projection == kind, label)
                .clicked()
            {
                action = Some(Action::SetProjection(kind));
            }
        }
    });
    ui.end_row();
    action
}

/// The anatomical and axis views and Reset (where a 3D view is shown: `three_d`), and the file's
/// orientation.
fn view_section(
    ui: &mut egui::Ui,
    volume: Option<&VolumeSummary>,
    three_d: bool,
) -> Option<Action> {
    let mut action = None;
    if three_d {
        action = camera_buttons(ui);
    }
    if let Some(v) = volume
        && let Some(a) = crate::ui::panels::orientation_controls::orientation_ui(ui, v)
    {
        action = Some(a);
    }
    action
}

/// The 3D view's camera: the anatomical and axis views, Reset and Roll.
fn camera_buttons(ui: &mut egui::Ui) -> Option<Action> {
    let mut action = None;
    ui.horizontal(|ui| {
        for side in crate::volume::Direction::VIEWS {
            if ui
                .button(side.letter().to_string())
                .on_hover_text(crate::ui::panels::menu::view_label(side))
                .clicked()
            {
                action = Some(Action::ViewFrom(side));
            }
        }
    });
    ui.horizontal_wrapped(|ui| {
        for (preset, label) in VIEWS {
            let short = label.trim_start_matches("Along ");
            if ui.button(short).on_hover_text(label).clicked() {
                action = Some(Action::SetView(preset));
            }
        }
    });
    ui.horizontal(|ui| {
        if ui.button("Reset view (R)").clicked() {
            action = Some(Action::ResetView);
        }
        if ui
            .button("Roll −90°")
            .on_hover_text("Turn the view 90° anticlockwise ([)")
            .clicked()
        {
            action = Some(Action::Roll(-90.0));
        }
        if ui
            .button("Roll +90°")
            .on_hover_text("Turn the view 90° clockwise (])")
            .clicked()
        {
            action = Some(Action::Roll(90.0));
        }
    });
    action
}

/// A DICOM series' facts, the notes from loading it, and the other series of its folder to
/// choose from.
fn series_rows(ui: &mut egui::Ui, v: &VolumeSummary, action: &mut Option<Action>) {
    let p = &v.provenance;
    if let Some(s) = &p.series {
        let mut line = s.modality_or_unknown().to_string();
        if !s.description.is_empty() {
            line.push_str(&format!(" · {}", s.description));
        }
        if s.date.len() == 8 {
            line.push_str(&format!(
                " · {}-{}-{}",
                &s.date[..4],
                &s.date[4..6],
                &s.date[6..]
            ));
        }
        ui.label(line)
            .on_hover_text(format!("SeriesInstanceUID {}", s.uid));
    }
    for note in &p.notes {
        ui.label(egui::RichText::new(format!("Note: {note}")).small())
            .on_hover_text("How the file was read");
    }
    if p.listing.len() > 1 {
        let chosen = p.chosen.unwrap_or(0);
        let shown = |i: usize| p.listing.get(i).cloned().unwrap_or_default();
        egui::ComboBox::from_id_salt("series")
            .width(ui.available_width() - 8.0)
            .selected_text(shown(chosen))
            .show_ui(ui, |ui| {
                for i in 0..p.listing.len() {
                    if ui.selectable_label(i == chosen, shown(i)).clicked() && i != chosen {
                        *action = Some(Action::OpenSeries(i + 1));
                    }
                }
            })
            .response
            .on_hover_text(format!(
                "{} series in this folder; choose one to open it",
                p.listing.len()
            ));
    }
    if let Some(volumes) = p.volumes {
        index_chooser(ui, volumes, Pick::Volume, action);
    }
    if let Some(channels) = p.channels {
        index_chooser(ui, channels, Pick::Channel, action);
    }
    if let Some(skipped) = &p.skipped {
        ui.label(
            egui::RichText::new(format!("skipped: {skipped}"))
                .weak()
                .small(),
        );
    }
}

/// What an index chooser picks: a volume of a 4-D file (a time point) or a channel.
#[derive(Clone, Copy)]
enum Pick {
    Volume,
    Channel,
}

impl Pick {
    fn label(self) -> &'static str {
        match self {
            Self::Volume => "Volume",
            Self::Channel => "Channel",
        }
    }

    fn hover(self) -> &'static str {
        match self {
            Self::Volume => {
                "Which volume of this 4-D file (a time point, a diffusion direction) is shown"
            }
            Self::Channel => "Which channel of this image is shown",
        }
    }

    fn action(self, index: u32) -> Action {
        match self {
            Self::Volume => Action::OpenVolume(index),
            Self::Channel => Action::OpenChannel(index),
        }
    }
}

/// The volume of a 4-D file (or the channel of an image) to show: a slider (the file is read
/// again once it is let go) and a step either way.
fn index_chooser(
    ui: &mut egui::Ui,
    index: crate::volume::VolumeIndex,
    pick: Pick,
    action: &mut Option<Action>,
) {
    let id = ui.make_persistent_id((pick.label(), "chooser"));
    let mut shown = ui
        .data(|d| d.get_temp::<u32>(id))
        .unwrap_or(index.chosen + 1);
    let name = pick.label().to_lowercase();
    ui.horizontal(|ui| {
        ui.label(pick.label());
        if ui
            .add_enabled(index.chosen > 0, egui::Button::new("<"))
            .on_hover_text(format!("The {name} before"))
            .clicked()
        {
            *action = Some(pick.action(index.chosen - 1));
        }
        let slider = ui
            .add(
                egui::Slider::new(&mut shown, 1..=index.count)
                    .suffix(format!(" of {}", index.count)),
            )
            .on_hover_text(pick.hover());
        if ui
            .add_enabled(index.chosen + 1 < index.count, egui::Button::new(">"))
            .on_hover_text(format!("The {name} after"))
            .clicked()
        {
            *action = Some(pick.action(index.chosen + 1));
        }
        let settled = slider.drag_stopped() || (slider.changed() && !slider.dragged());
        if settled && shown != index.chosen + 1 {
            *action = Some(pick.action(shown - 1));
        }
    });
    if action.is_some() {
        ui.data_mut(|d| d.remove::<u32>(id));
    } else {
        ui.data_mut(|d| d.insert_temp(id, shown));
    }
}

/// What is loaded.
fn volume_section(ui: &mut egui::Ui, volume: Option<&VolumeSummary>) {
    match volume {
        Some(v) => {
            ui.label(v.name.as_str());
            ui.label(v.line());
            if let Some(r) = v.range {
                ui.label(format!("values {} … {}", number(r.min), number(r.max)));
            }
            ui.label(egui::RichText::new(v.kind.short_label()).weak())
                .on_hover_text(&v.kind_text);
        }
        None => {
            ui.label("none yet");
        }
    }
}

fn path_label(path: RenderPath) -> &'static str {
    match path {
        RenderPath::Auto => "auto",
        RenderPath::Fragment => "fragment",
        RenderPath::Compute => "compute",
    }
}

/// What a quality preset is for, from the figures in docs/accuracy/README.md.
fn quality_hint(preset: QualityPreset) -> &'static str {
    match preset {
        QualityPreset::Fast => {
            "1-voxel steps, central gradients, stop at 99 %, jitter: 1.7–2.6× faster than \
             Balanced, 2.5–4× its error"
        }
        QualityPreset::Balanced => {
            "½-voxel steps, fourth-order gradients: on the accuracy front of every dataset"
        }
        QualityPreset::Reference => {
            "⅛-voxel pre-integrated steps, fourth-order gradients: 4–6× the time of Balanced, \
             1.7–4× less error (8–26× on thin TF features)"
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Shows the panel once, without any input, and returns the state afterwards.
    fn shown(mut state: ViewerState) -> ViewerState {
        let ctx = egui::Context::default();
        let info = PanelInfo {
            path_used: None,
            strategy_used: None,
            volume: None,
        };
        let mut output = ctx.run_ui(egui::RawInput::default(), |ui| {
            let action = controls_ui(ui, &mut state, &info, |_, _| {});
            assert_eq!(action, None);
        });
        // No painter here: the font atlas upload is dropped on purpose.
        output.textures_delta.clear();
        state
    }

    #[test]
    fn showing_the_panel_changes_nothing() {
        let state = ViewerState::default();
        assert_eq!(shown(state.clone()), state);
        // Values with more digits than the sliders show survive too.
        let mut odd = ViewerState::default();
        odd.render.step_vox = 0.333_333_333;
        odd.render.termination_alpha = 0.987_654_321;
        assert_eq!(shown(odd.clone()), odd);
    }
}
