//! The viewer window: eframe's app ([`app`]) wiring together small parts — the plain state the
//! controls edit ([`ViewerState`]), the scene (the one renderer, the camera, the frame on screen),
//! the view with its gestures, the side panel's sections, the menus, the readout overlay, the
//! background loader, dialogs, and the automation hooks (exit after N frames, screenshot) used by
//! scripts and smoke tests. Gestures, window/level, the level of detail and the redraw rule are
//! pure functions tested without a window.
//!
//! As in egui's `custom3d_wgpu` example, the state holds only plain values; the renderer and
//! every GPU object live in the scene, never in a widget.

pub mod app;
pub mod frames;
pub mod gestures;
#[cfg(test)]
mod glyphs;
pub mod layout;
pub mod loading;
pub mod panels;
pub mod screenshot;
pub mod slices;
pub mod state;
pub mod view;
pub mod window;

use crate::camera::ProjectionKind;
use crate::camera::ViewPreset;
use crate::volume::{ScalarType, ValueRange, Volume};

pub use state::ViewerState;

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
    /// The orientation the header gave, whatever the user said.
    pub header_orientation: Option<crate::volume::Orientation>,
    /// Whether the volume is a file (whose orientation the user may set), not generated.
    pub from_file: bool,
    /// What the values were taken for (CT in HU, CT in scanner units, MR, other).
    pub kind: crate::transfer::fit::DataKind,
    /// [`crate::transfer::fit::DataKind::describe`], for the side panel.
    pub kind_text: String,
    /// What the file said beyond the samples: notes from loading, the header's window, the
    /// DICOM series and the others beside it.
    pub provenance: crate::volume::Provenance,
    /// Where the GPU holds a coarser level than the volume's own: which, and why.
    pub coarser: Option<String>,
    /// How the GPU holds the volume (one texture, or bricks: how many, which level, how much
    /// memory), for the developer readout.
    pub gpu_layout: Option<String>,
    /// How far the bricks of a bricked volume are: levels read, resident of wanted, memory
    /// of the budget (one line, kept current frame by frame).
    pub residency: Option<String>,
}

impl VolumeSummary {
    /// Summarises `volume`.
    pub fn of(volume: &Volume) -> Self {
        let kind = crate::transfer::fit::DataKind::of(volume);
        Self {
            name: volume.name().to_string(),
            dims: volume.dims(),
            spacing_mm: volume.spacing_mm(),
            scalar_type: volume.scalar_type(),
            range: volume.value_range(),
            histogram: volume.histogram().counts.clone(),
            orientation: volume.orientation(),
            reversed_i: volume.reversed_i(),
            header_orientation: volume.header_orientation(),
            from_file: false,
            kind_text: kind.describe(volume.modality()),
            kind,
            provenance: volume.provenance().clone(),
            coarser: None,
            gpu_layout: None,
            residency: None,
        }
    }

    /// The orientation the anatomical views use: the header's, or RAS where it gave none.
    pub(crate) fn orientation_or_assumed(&self) -> crate::volume::Orientation {
        self.orientation
            .unwrap_or(crate::volume::Orientation::ASSUMED)
    }

    /// The orientation in the file's own index frame (before the reversal along i that loading
    /// does for a mirrored one): what the user's flips start from.
    pub(crate) fn file_orientation_or_assumed(&self) -> crate::volume::Orientation {
        let o = self.orientation_or_assumed();
        if self.reversed_i {
            o.with_axis_reversed(0)
        } else {
            o
        }
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
    /// Show the system folder dialog (a DICOM series), or the path prompt where there is none.
    OpenFolderDialog,
    /// Show the path prompt.
    OpenPathPrompt,
    /// Show the file dialog for a segmentation of the volume on screen.
    OpenLabelsDialog,
    /// Open series N (1-based, as listed) of the folder the volume on screen came from.
    OpenSeries(usize),
    /// Open another volume of the 4-D file on screen (counted from 0).
    OpenVolume(u32),
    /// Open another channel of the image on screen (counted from 0).
    OpenChannel(u32),
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
    /// Back to the view a volume opens in (the patient from the front, superior up), framing
    /// the whole volume.
    ResetView,
    /// Turn the view about its line of sight by this many degrees (clockwise on screen).
    Roll(f64),
    /// Take the file's index axes to point this way (in the file's index frame) and open it
    /// again; `None`: back to the header's orientation.
    Reorient(Option<crate::volume::Orientation>),
    /// Switch projection, keeping the size of what is at the orbit centre.
    SetProjection(ProjectionKind),
    /// Show the "Save image" window (path and size).
    SaveImagePrompt,
    /// Open a file from the recent list.
    OpenRecent(std::path::PathBuf),
    /// Divide the central area this way (3D only, 2 × 2, 1 + 3).
    SetLayout(layout::Layout),
    /// Keep the volume within this much GPU memory (`None`: the default) and load it again.
    SetGpuBudget(Option<u64>),
    /// Keep an OME-Zarr store's samples within this much memory (`None`: the default) and load
    /// the volume again.
    SetRamBudget(Option<u64>),
}
