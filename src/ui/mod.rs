//! The viewer window's user interface, in small parts that `app.rs` wires together: the plain
//! state the controls edit ([`ViewerState`]), the view with its mouse and keyboard handling, the
//! side panel, the menus, the readout overlay, the background loader, dialogs, and the
//! automation hooks (exit after N frames, screenshot) used by scripts and smoke tests.
//!
//! As in egui's `custom3d_wgpu` example, the state here holds only plain values; the renderer
//! and every GPU object live in the app struct, never in a widget.

pub mod controls;
pub mod crop;
pub mod dialogs;
pub mod effects;
pub mod interaction;
pub mod loading;
pub mod lod;
pub mod menu;
pub mod orientation_marker;
pub mod overlay;
pub mod redraw;
pub mod save_image;
pub mod scene;
pub mod screenshot;
pub mod tf_editor;
pub mod viewport;
pub mod window;

use serde::{Deserialize, Serialize};

use crate::camera::{ProjectionKind, ViewPreset};
use crate::settings::DEFAULT_TERMINATION_ALPHA;
use crate::settings::{Mode, QualityPreset, RenderPath, RenderSettings, Strategy};
use crate::transfer::editor::TfEditor;
use crate::transfer::{TransferFunction, presets};
use crate::volume::{ScalarType, ValueRange, Volume};

/// Preset chosen for volumes that look like CT (values in Hounsfield units).
pub const DEFAULT_CT_PRESET: &str = "ct-bone";
/// Preset chosen for every other volume (MRI and unitless data).
pub const DEFAULT_OTHER_PRESET: &str = "mr-default";

/// Below this minimum (data units) a volume is taken for CT: air is −1000 HU, and no MRI or
/// unitless volume has values this negative.
pub const CT_MINIMUM_BELOW: f64 = -500.0;

/// Everything the controls edit, as plain serialisable values (persisted in a later issue).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ViewerState {
    /// Transfer-function preset name (one of [`crate::transfer::presets::NAMES`]) last loaded
    /// into the editor.
    pub preset: String,
    /// The transfer function being edited, with its undo history (the function itself is saved
    /// between runs under its own key, see `src/app.rs`; the history is not).
    #[serde(skip)]
    pub editor: TfEditor,
    /// Whether the editor's histogram has a log scale.
    #[serde(default = "yes")]
    pub log_histogram: bool,
    /// DVR, isosurface, MIP, MinIP or X-ray.
    #[serde(default = "default_mode")]
    pub mode: Mode,
    /// The mode's parameters.
    #[serde(default)]
    pub effects: effects::EffectState,
    /// RC, RC-t, RC-s or RC-s with the distance field.
    pub strategy: Strategy,
    /// Edge of the leaping blocks in voxels (RC-s).
    #[serde(default = "default_block")]
    pub block_vox: u32,
    /// Whether frames that would miss the frame budget while the user drags are rendered at a
    /// lower resolution (refined once still).
    #[serde(default = "yes")]
    pub interaction_lod: bool,
    /// Whether frames count samples (slower statistics variant) for the readout.
    #[serde(default)]
    pub statistics: bool,
    /// Fragment, compute, or let the renderer pick.
    pub path: RenderPath,
    /// Sample step in units of the smallest voxel spacing.
    pub step_vox: f64,
    /// RC-t stops once accumulated opacity exceeds this.
    pub termination_alpha: f64,
    /// Jittered ray starts.
    #[serde(default)]
    pub jitter: bool,
    /// Pre-integrated classification (DVR).
    #[serde(default)]
    pub preintegrated: bool,
    /// Background colour as 8-bit RGB; stored into the image as it is, like the PNG output.
    pub background: [u8; 3],
    /// Perspective or orthographic projection.
    pub projection: ProjectionKind,
    /// Whether the side panel is open.
    pub show_controls: bool,
    /// Whether the readout (FPS, GPU time, adapter, volume) is drawn over the view.
    pub show_readout: bool,
    /// Frames averaged, at shifted sample grids, once the view is still (1: no refinement).
    #[serde(default = "default_refine_frames")]
    pub refine_frames: u32,
    /// Whether the orientation marker (R/A/S axes) is drawn in the view's corner.
    #[serde(default = "yes")]
    pub show_orientation_marker: bool,
    /// The part of the volume shown (reset to the whole volume for each volume opened).
    #[serde(skip)]
    pub crop: crate::settings::CropBox,
    /// Whether the cropping box and its handles are drawn over the view.
    #[serde(default)]
    pub show_crop_box: bool,
    /// Files opened successfully, newest first (at most [`RECENT_FILES`]).
    #[serde(default)]
    pub recent: Vec<std::path::PathBuf>,
}

/// Length of the File › Recent list.
pub const RECENT_FILES: usize = 8;

impl Default for ViewerState {
    fn default() -> Self {
        let render = RenderSettings::default();
        let mut state = Self {
            preset: DEFAULT_CT_PRESET.to_string(),
            editor: TfEditor::new(
                presets::preset(DEFAULT_CT_PRESET)
                    .unwrap_or_else(|_| TransferFunction::grey_ramp()),
            ),
            log_histogram: true,
            mode: render.mode,
            effects: effects::EffectState::default(),
            strategy: render.strategy,
            path: render.path,
            step_vox: render.step_vox,
            block_vox: render.block_vox,
            statistics: false,
            interaction_lod: true,
            termination_alpha: DEFAULT_TERMINATION_ALPHA,
            jitter: false,
            background: [0, 0, 0],
            projection: ProjectionKind::Perspective,
            show_controls: true,
            show_readout: true,
            show_orientation_marker: true,
            refine_frames: DEFAULT_REFINE_FRAMES,
            recent: Vec::new(),
            preintegrated: false,
            crop: crate::settings::CropBox::FULL,
            show_crop_box: false,
        };
        state.apply_quality(QualityPreset::Balanced);
        state
    }
}

/// Frames a still view is refined to by default: 8 shifted grids sample each ray as densely as
/// a step 8 times finer.
pub const DEFAULT_REFINE_FRAMES: u32 = 8;

/// Most frames the refinement control offers.
pub const MAX_REFINE_FRAMES: u32 = 64;

fn default_refine_frames() -> u32 {
    DEFAULT_REFINE_FRAMES
}

fn yes() -> bool {
    true
}

fn default_mode() -> Mode {
    RenderSettings::default().mode
}

fn default_block() -> u32 {
    crate::settings::DEFAULT_BLOCK_VOX
}

impl ViewerState {
    /// The renderer's settings for this state. The distance-field strategy leaps by the
    /// transfer function or the window, so isosurface, MIP and MinIP fall back to RC-s with it
    /// ([`ViewerState::strategy_in_use`]).
    pub fn render_settings(&self) -> RenderSettings {
        let mut settings = RenderSettings {
            mode: self.mode,
            strategy: self.strategy,
            path: self.path,
            step_vox: self.step_vox,
            termination_alpha: self.termination_alpha,
            jitter: self.jitter,
            preintegrated: self.preintegrated,
            background: self.background.map(|c| f64::from(c) / 255.0),
            block_vox: self.block_vox,
            crop: self.crop,
            ..RenderSettings::default()
        };
        self.effects.apply(&mut settings);
        settings
    }

    /// Loads preset `name` into the editor (one undo step); an unknown name changes nothing.
    pub fn choose_preset(&mut self, name: &str) -> Result<(), String> {
        self.editor.load_preset(name).map_err(|e| e.to_string())?;
        self.preset = name.to_string();
        Ok(())
    }

    /// Puts `path` first in the recent files (once), dropping the oldest beyond
    /// [`RECENT_FILES`].
    pub fn remember_file(&mut self, path: &std::path::Path) {
        self.recent.retain(|p| p != path);
        self.recent.insert(0, path.to_path_buf());
        self.recent.truncate(RECENT_FILES);
    }

    /// Sets the knobs `preset` decides (step, termination, jitter, pre-integration, gradients,
    /// iso refinement).
    pub fn apply_quality(&mut self, preset: QualityPreset) {
        let mut s = self.render_settings();
        preset.apply(&mut s);
        self.step_vox = s.step_vox;
        self.termination_alpha = s.termination_alpha;
        self.jitter = s.jitter;
        self.preintegrated = s.preintegrated;
        self.effects.gradient = s.gradient;
        self.effects.iso.refine_iterations = s.iso.refine_iterations;
    }

    /// The preset the current knobs match, `None` for custom settings.
    pub fn quality(&self) -> Option<QualityPreset> {
        QualityPreset::of(&self.render_settings())
    }

    /// The strategy frames use: the chosen one, or RC-s where the mode cannot use the
    /// distance field.
    pub fn strategy_in_use(&self) -> Strategy {
        self.strategy.for_mode(self.mode)
    }
}

/// Whether a volume with this value range looks like CT (see [`CT_MINIMUM_BELOW`]).
pub fn is_ct_like(range: Option<ValueRange>) -> bool {
    range.is_some_and(|r| r.min < CT_MINIMUM_BELOW)
}

/// The preset to use after opening a volume: the current one when it suits the volume's kind
/// (a `ct-*` preset for CT, an `mr-*` preset otherwise, the grey ramp for either), else the
/// default for that kind.
pub fn preset_for_volume(current: &str, ct_like: bool) -> String {
    let fits = current == "grey-ramp"
        || (ct_like && current.starts_with("ct-"))
        || (!ct_like && current.starts_with("mr-"));
    if fits {
        current.to_string()
    } else if ct_like {
        DEFAULT_CT_PRESET.to_string()
    } else {
        DEFAULT_OTHER_PRESET.to_string()
    }
}

/// What the window shows about the loaded volume.
#[derive(Clone, Debug, PartialEq)]
pub struct VolumeSummary {
    /// Name (file name or generator).
    pub name: String,
    /// Samples along x, y, z.
    pub dims: [u32; 3],
    /// Voxel spacing in millimetres.
    pub spacing_mm: [f64; 3],
    /// Stored sample type.
    pub scalar_type: ScalarType,
    /// Finite value range in data units.
    pub range: Option<ValueRange>,
    /// Sample counts in equal bins over `range`.
    pub histogram: Vec<u64>,
    /// Anatomical orientation of the index axes, if the file's header gave one (after any
    /// reversal along i, see [`Volume::unmirrored`]).
    pub orientation: Option<crate::volume::Orientation>,
    /// Whether the samples were reversed along i because the file's orientation is mirrored.
    pub reversed_i: bool,
}

impl VolumeSummary {
    /// Summarises `volume`.
    pub fn of(volume: &Volume) -> Self {
        Self {
            name: volume.name().to_string(),
            dims: volume.dims(),
            spacing_mm: volume.spacing_mm(),
            scalar_type: volume.scalar_type(),
            range: volume.value_range(),
            histogram: volume.histogram().counts.clone(),
            orientation: volume.orientation(),
            reversed_i: volume.reversed_i(),
        }
    }

    /// The orientation the anatomical views use: the header's, or RAS where it gave none.
    pub fn orientation_or_assumed(&self) -> crate::volume::Orientation {
        self.orientation
            .unwrap_or(crate::volume::Orientation::ASSUMED)
    }

    /// One line: dims, type and spacing, e.g. `256×256×256 int16, 0.8×0.8×1 mm`.
    pub fn line(&self) -> String {
        let [x, y, z] = self.dims;
        let [sx, sy, sz] = self.spacing_mm;
        format!(
            "{x}×{y}×{z} {}, {sx:.3}×{sy:.3}×{sz:.3} mm",
            self.scalar_type
        )
    }
}

/// Something the user asked for through a menu, the side panel or a key.
#[derive(Clone, Debug, PartialEq)]
pub enum Action {
    /// Show the system file dialog (or the path prompt where there is none).
    OpenDialog,
    /// Show the path prompt.
    OpenPathPrompt,
    /// Generate the Shepp–Logan head phantom.
    LoadPhantom,
    /// Generate the vessel tree.
    LoadVessels,
    /// Close the window.
    Quit,
    /// Look along a standard direction, framing the whole volume.
    SetView(ViewPreset),
    /// Look at the patient from one side (the A, P, L, R, S, I views), framing the whole volume.
    ViewFrom(crate::volume::Direction),
    /// Back to the default (oblique) view, framing the whole volume.
    ResetView,
    /// Switch projection, keeping the size of what is at the orbit centre.
    SetProjection(ProjectionKind),
    /// Show the "Save image" window (path and size).
    SaveImagePrompt,
    /// Open a file from the recent list.
    OpenRecent(std::path::PathBuf),
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recent_files_are_newest_first_unique_and_bounded() {
        let mut state = ViewerState::default();
        for i in 0..12 {
            state.remember_file(std::path::Path::new(&format!("/data/{i}.nrrd")));
        }
        state.remember_file(std::path::Path::new("/data/9.nrrd"));
        assert_eq!(state.recent.len(), RECENT_FILES);
        assert_eq!(state.recent[0], std::path::PathBuf::from("/data/9.nrrd"));
        assert_eq!(state.recent[1], std::path::PathBuf::from("/data/11.nrrd"));
        assert_eq!(
            state
                .recent
                .iter()
                .filter(|p| p.ends_with("9.nrrd"))
                .count(),
            1
        );
    }
    use crate::transfer::presets::NAMES;

    #[test]
    fn ct_is_recognised_by_air() {
        let ct = ValueRange {
            min: -1024.0,
            max: 3071.0,
        };
        let mr = ValueRange {
            min: 0.0,
            max: 4095.0,
        };
        assert!(is_ct_like(Some(ct)));
        assert!(!is_ct_like(Some(mr)));
        assert!(!is_ct_like(None));
    }

    #[test]
    fn preset_follows_the_kind_of_volume() {
        assert_eq!(preset_for_volume("ct-skin", true), "ct-skin");
        assert_eq!(preset_for_volume("ct-skin", false), DEFAULT_OTHER_PRESET);
        assert_eq!(preset_for_volume("mr-angio", true), DEFAULT_CT_PRESET);
        assert_eq!(preset_for_volume("grey-ramp", false), "grey-ramp");
        // Whatever is chosen is a preset that exists.
        for name in NAMES {
            for ct in [false, true] {
                assert!(NAMES.contains(&preset_for_volume(name, ct).as_str()));
            }
        }
    }

    #[test]
    fn state_gives_valid_settings() {
        let state = ViewerState {
            background: [255, 128, 0],
            ..ViewerState::default()
        };
        let settings = state.render_settings();
        assert_eq!(settings.validate(), Ok(()));
        for mode in Mode::ALL {
            let df = ViewerState {
                mode,
                strategy: Strategy::RcSDistance,
                ..ViewerState::default()
            };
            assert_eq!(df.render_settings().validate(), Ok(()), "{mode:?}");
        }
        assert_eq!(settings.background[0], 1.0);
        assert_eq!(settings.background[2], 0.0);
        assert!(NAMES.contains(&state.preset.as_str()));
    }
}
