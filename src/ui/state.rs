//! What the window's controls edit, as plain serialisable values: one [`RenderSettings`] (the
//! renderer's own description of a frame, not copies of its fields) and what only the window
//! has — the transfer-function editor, the view's toggles, the recent files.

use serde::{Deserialize, Serialize};

use crate::camera::ProjectionKind;
use crate::settings::{Light, QualityPreset, RenderSettings, Strategy};
use crate::transfer::editor::TfEditor;
use crate::transfer::fit::{DataKind, fitted_preset};
use crate::transfer::{TransferFunction, presets};
use crate::volume::Orientation;

/// The key a file's orientation (or a segmentation's style) is kept under: its absolute path,
/// so that the same file opened from another folder finds it.
pub(crate) fn file_key(path: &std::path::Path) -> String {
    std::fs::canonicalize(path)
        .unwrap_or_else(|_| path.to_path_buf())
        .display()
        .to_string()
}

/// Frames a still view is refined to by default: 8 shifted grids sample each ray as densely as
/// a step 8 times finer.
pub const DEFAULT_REFINE_FRAMES: u32 = 8;

/// Most frames the refinement control offers.
pub const MAX_REFINE_FRAMES: u32 = 64;

/// Length of the File › Recent list.
pub const RECENT_FILES: usize = 8;

/// Where a directional light comes from by default: azimuth and elevation in degrees.
pub const DEFAULT_LIGHT_ANGLES: [f64; 2] = [45.0, 30.0];

/// Everything the controls edit. Persisted between runs (`src/ui/app/persistence.rs`); what a stored state
/// lacks takes its default.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct ViewerState {
    /// What frames render: mode and its parameters, strategy, path, quality knobs, background,
    /// cropping. The window edits these directly.
    pub render: RenderSettings,
    /// Transfer-function preset name (one of [`crate::transfer::presets::NAMES`]) last loaded
    /// into the editor.
    pub preset: String,
    /// The transfer function being edited, with its undo history (the function itself is saved
    /// between runs under its own key, see `src/ui/app/persistence.rs`; the history is not).
    #[serde(skip)]
    pub editor: TfEditor,
    /// The kind of data the transfer function was fitted to (CT presets are mapped onto CT in
    /// scanner units): a volume of another kind gets its own fit.
    pub fitted_to: Option<DataKind>,
    /// Whether the editor's histogram has a log scale.
    pub log_histogram: bool,
    /// Azimuth and elevation in degrees of where a directional light comes from: the sliders'
    /// own values, kept while the headlight is on so that unticking it brings them back.
    pub light_angles: [f64; 2],
    /// Whether frames that would miss the frame budget while the user drags are rendered at a
    /// lower resolution (refined once still).
    pub interaction_lod: bool,
    /// Whether frames count samples (slower statistics variant) for the readout.
    pub statistics: bool,
    /// Perspective or orthographic projection.
    pub projection: ProjectionKind,
    /// Whether the side panel is open.
    pub show_controls: bool,
    /// Whether the readout (the volume, what the picture shows, a slow frame rate) is drawn
    /// over the 3D view.
    pub show_readout: bool,
    /// Whether the readout adds the engineering lines (frame rate, GPU time, strategy, path,
    /// adapter, latencies); "count samples" adds them too.
    pub developer_readout: bool,
    /// The most GPU memory a volume may take, in bytes (`None`: only the GPU's limits bound it);
    /// past it the volume is shown from bricks of a coarser level. `--gpu-budget` sets it for a
    /// run.
    pub gpu_budget: Option<u64>,
    /// The most memory an OME-Zarr store's or a TIFF stack's samples may take, in bytes
    /// (`None`: half the memory available); one larger is read brick by brick. `--ram-budget`
    /// sets it for a run.
    pub ram_budget: Option<u64>,
    /// Frames averaged, at shifted sample grids, once the view is still (1: no refinement).
    pub refine_frames: u32,
    /// Whether the orientation marker (R/A/S axes) is drawn in the view's corner.
    pub show_orientation_marker: bool,
    /// Whether the cropping box and its handles are drawn over the view.
    pub show_crop_box: bool,
    /// How the central area is divided between the 3D view and the slice views.
    pub layout: crate::ui::layout::Layout,
    /// Whether the 3D view outlines the slice planes (when slices are shown).
    pub show_slice_planes: bool,
    /// Files opened successfully, newest first (at most [`RECENT_FILES`]).
    pub recent: Vec<std::path::PathBuf>,
    /// The orientation the user gave for a file (its absolute path → a code such as `RAI`, in
    /// the file's index frame), used in place of the header's whenever that file opens.
    pub orientations: std::collections::BTreeMap<String, String>,
    /// How a segmentation was shown (its absolute path → hidden segments, colours, opacities,
    /// fill and outlines), restored whenever that file opens again.
    pub label_styles: std::collections::BTreeMap<String, LabelStyle>,
}

/// How one segmentation file is shown: which segments are hidden, those given another colour
/// or opacity (by layer and value: sRGB and opacity), the fill's opacity and the outlines.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct LabelStyle {
    /// Hidden segments, by (layer, value).
    pub hidden: Vec<(u16, u16)>,
    /// Segments of another colour or opacity: (layer, value) and sRGB + opacity.
    pub styled: Vec<((u16, u16), [u8; 4])>,
    /// The fill's opacity over the slices.
    pub fill: f32,
    /// Whether outlines are drawn.
    pub outlines: bool,
}

impl Default for ViewerState {
    fn default() -> Self {
        let mut render = RenderSettings::default();
        QualityPreset::Balanced.apply(&mut render);
        Self {
            render,
            preset: presets::DEFAULT_CT_PRESET.to_string(),
            editor: TfEditor::new(
                presets::preset(presets::DEFAULT_CT_PRESET)
                    .unwrap_or_else(|_| TransferFunction::grey_ramp()),
            ),
            fitted_to: None,
            log_histogram: true,
            light_angles: DEFAULT_LIGHT_ANGLES,
            statistics: false,
            interaction_lod: true,
            projection: ProjectionKind::Perspective,
            show_controls: true,
            show_readout: true,
            developer_readout: false,
            gpu_budget: None,
            ram_budget: None,
            show_orientation_marker: true,
            refine_frames: DEFAULT_REFINE_FRAMES,
            recent: Vec::new(),
            show_crop_box: false,
            layout: crate::ui::layout::Layout::default(),
            show_slice_planes: true,
            orientations: std::collections::BTreeMap::new(),
            label_styles: std::collections::BTreeMap::new(),
        }
    }
}

impl ViewerState {
    /// What the picture shows, in a reader's words: the transfer function's preset, the iso value,
    /// or the window of a projection.
    pub fn look(&self) -> String {
        let render = &self.render;
        let window = || match render.window {
            Some([lo, hi]) => format!(
                "window {} … {} (W {} L {})",
                crate::text::number(lo),
                crate::text::number(hi),
                crate::text::number(hi - lo),
                crate::text::number(0.5 * (lo + hi))
            ),
            None => "window: the data's".to_string(),
        };
        // The preset the transfer function started from (fitted to the data, perhaps edited since).
        let preset = || format!("preset {}", self.preset);
        match render.mode {
            crate::settings::Mode::Dvr => preset(),
            crate::settings::Mode::Iso => match render.iso.value {
                Some(v) => format!("isosurface at {}", crate::text::number(v)),
                None => "isosurface".to_string(),
            },
            crate::settings::Mode::Mip => format!("MIP · {}", window()),
            crate::settings::Mode::MinIp => format!("MinIP · {}", window()),
            crate::settings::Mode::Xray => format!("X-ray mean · {}", window()),
            crate::settings::Mode::XrayAttenuation => format!("radiograph · {}", window()),
        }
    }

    /// Loads preset `name` into the editor (one undo step); an unknown name changes nothing.
    pub(crate) fn choose_preset(&mut self, name: &str) -> Result<(), String> {
        let kind = self.fitted_to.clone().unwrap_or(DataKind::Other);
        self.choose_preset_for(name, kind)
    }

    /// Loads preset `name` fitted to data of `kind` (one undo step), and remembers the kind.
    pub(crate) fn choose_preset_for(&mut self, name: &str, kind: DataKind) -> Result<(), String> {
        let tf = fitted_preset(name, &kind).map_err(|e| e.to_string())?;
        self.editor.set(tf);
        self.preset = name.to_string();
        log::info!("transfer function preset {name}");
        self.fitted_to = Some(kind);
        Ok(())
    }

    /// Puts `path` first in the recent files (once), dropping the oldest beyond
    /// [`RECENT_FILES`].
    pub(crate) fn remember_file(&mut self, path: &std::path::Path) {
        self.recent.retain(|p| p != path);
        self.recent.insert(0, path.to_path_buf());
        self.recent.truncate(RECENT_FILES);
    }

    /// The orientation the user gave for the file at `path`, if any (a stored code that no
    /// longer parses is ignored).
    pub(crate) fn orientation_for(&self, path: &std::path::Path) -> Option<Orientation> {
        let code = self.orientations.get(&file_key(path))?;
        Orientation::parse_code(code).ok()
    }

    /// Remembers `orientation` for the file at `path` (`None`: back to the header's).
    pub(crate) fn set_orientation_for(
        &mut self,
        path: &std::path::Path,
        orientation: Option<Orientation>,
    ) {
        let key = file_key(path);
        match orientation {
            Some(o) => {
                self.orientations.insert(key, o.code());
            }
            None => {
                self.orientations.remove(&key);
            }
        }
    }

    /// The preset the current knobs match, `None` for custom settings.
    pub fn quality(&self) -> Option<QualityPreset> {
        QualityPreset::of(&self.render)
    }

    /// The strategy frames use: the chosen one, or RC-s where the mode cannot use the
    /// distance field.
    pub(crate) fn strategy_in_use(&self) -> Strategy {
        self.render.strategy.for_mode(self.render.mode)
    }

    /// Forgets the values in data units (iso value, window) and the cropping box when another
    /// volume opens: they belong to the old volume.
    pub(crate) fn forget_volume_values(&mut self) {
        self.render.iso.value = None;
        self.render.window = None;
        self.render.crop = crate::settings::CropBox::FULL;
    }

    /// Switches between the headlight and a directional light from [`Self::light_angles`].
    pub(crate) fn set_headlight(&mut self, headlight: bool) {
        self.render.light = if headlight {
            Light::Headlight
        } else {
            light_from(self.light_angles)
        };
    }

    /// Sets the directional light's angles (and the light, unless the headlight is on).
    pub(crate) fn set_light_angles(&mut self, angles: [f64; 2]) {
        self.light_angles = angles;
        if self.render.light != Light::Headlight {
            self.render.light = light_from(angles);
        }
    }

    /// The background as 8-bit RGB (what the colour button edits; stored into the image as it
    /// is, like the PNG output).
    pub(crate) fn background_rgb8(&self) -> [u8; 3] {
        self.render
            .background
            .map(|c| (c.clamp(0.0, 1.0) * 255.0).round() as u8)
    }

    /// Sets the background from 8-bit RGB.
    pub(crate) fn set_background_rgb8(&mut self, rgb: [u8; 3]) {
        self.render.background = rgb.map(|c| f64::from(c) / 255.0);
    }
}

/// A light shining from the direction azimuth/elevation `angles` (degrees) name, towards the
/// volume.
fn light_from(angles: [f64; 2]) -> Light {
    let [az, el] = angles.map(f64::to_radians);
    let from = [el.cos() * az.sin(), el.cos() * az.cos(), el.sin()];
    Light::Direction(from.map(|c| -c))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::settings::Mode;

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

    #[test]
    fn a_segmentations_style_survives_the_stored_state() {
        let mut state = ViewerState::default();
        let style = LabelStyle {
            hidden: vec![(0, 3)],
            styled: vec![((0, 2), [40, 200, 90, 128])],
            fill: 0.25,
            outlines: false,
        };
        state
            .label_styles
            .insert("/data/seg.nrrd".into(), style.clone());
        let stored = serde_json::to_string(&state).expect("serialises");
        let back: ViewerState = serde_json::from_str(&stored).expect("parses");
        assert_eq!(back.label_styles.get("/data/seg.nrrd"), Some(&style));
        // A state stored before styles were kept still reads.
        let old: ViewerState = serde_json::from_str("{}").expect("parses");
        assert!(old.label_styles.is_empty());
    }

    #[test]
    fn a_files_orientation_is_kept_by_its_absolute_path_until_reset() {
        let dir = std::env::temp_dir().join(format!("leapview-orient-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("temp dir");
        let file = dir.join("head.nrrd");
        std::fs::write(&file, b"x").expect("file");
        let mut state = ViewerState::default();
        assert_eq!(state.orientation_for(&file), None);
        let rai = Orientation::parse_code("RAI").expect("valid");
        state.set_orientation_for(&file, Some(rai));
        // The same file by another spelling of its path.
        let other = dir.join(".").join("head.nrrd");
        assert_eq!(
            state.orientation_for(&other).map(|o| o.code()),
            Some("RAI".into())
        );
        // It survives a round trip through the stored state.
        let stored = serde_json::to_string(&state).expect("serialises");
        let back: ViewerState = serde_json::from_str(&stored).expect("parses");
        assert_eq!(back.orientation_for(&file), Some(rai));
        state.set_orientation_for(&file, None);
        assert_eq!(state.orientation_for(&file), None);
        // Another file is not affected, and a stored code that is no longer valid is ignored.
        state
            .orientations
            .insert("/elsewhere.nii".into(), "XYZ".into());
        assert_eq!(
            state.orientation_for(std::path::Path::new("/elsewhere.nii")),
            None
        );
        std::fs::remove_dir_all(&dir).expect("clean up");
    }

    #[test]
    fn state_gives_valid_settings() {
        let mut state = ViewerState::default();
        state.set_background_rgb8([255, 128, 0]);
        assert_eq!(state.render.validate(), Ok(()));
        for mode in Mode::ALL {
            let mut df = ViewerState::default();
            df.render.mode = mode;
            df.render.strategy = Strategy::RcSDistance;
            assert_eq!(df.render.validate(), Ok(()), "{mode:?}");
        }
        assert_eq!(state.render.background[0], 1.0);
        assert_eq!(state.render.background[2], 0.0);
        assert_eq!(state.background_rgb8(), [255, 128, 0]);
        assert!(presets::NAMES.contains(&state.preset.as_str()));
        assert_eq!(state.quality(), Some(QualityPreset::Balanced));
    }

    #[test]
    fn a_directional_light_shines_towards_the_volume_and_comes_back_after_the_headlight() {
        let mut state = ViewerState::default();
        assert_eq!(state.render.light, Light::Headlight);
        state.set_light_angles([0.0, 90.0]);
        assert_eq!(
            state.render.light,
            Light::Headlight,
            "the headlight stays on"
        );
        state.set_headlight(false);
        // From straight above (elevation 90°): shining down −z.
        let Light::Direction(d) = state.render.light else {
            panic!("a direction")
        };
        assert!(d[0].abs() < 1e-12 && d[1].abs() < 1e-12 && (d[2] + 1.0).abs() < 1e-12);
        state.set_headlight(true);
        state.set_headlight(false);
        assert_eq!(state.render.light, Light::Direction(d));
    }

    #[test]
    fn new_volumes_drop_values_in_the_old_units_and_the_crop() {
        let mut state = ViewerState::default();
        state.render.window = Some([0.0, 1.0]);
        state.render.iso.value = Some(300.0);
        state.render.crop.min = [0.25; 3];
        state.forget_volume_values();
        assert_eq!((state.render.window, state.render.iso.value), (None, None));
        assert!(state.render.crop.is_full());
    }

    #[test]
    fn a_stored_state_missing_fields_takes_their_defaults() {
        let stored = r#"{"preset": "mr-angio", "show_readout": false}"#;
        let state: ViewerState = serde_json::from_str(stored).expect("parses");
        assert_eq!(state.preset, "mr-angio");
        assert!(!state.show_readout);
        assert_eq!(state.render, ViewerState::default().render);
    }
}
