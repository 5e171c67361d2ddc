//! The camera and the volume it frames: the volume's summary and box, the camera, and the views a
//! volume opens in or the user asks for (a side of the patient, an axis, a projection).

use crate::camera::{Aabb, Camera, ProjectionKind, ViewPreset};
use crate::ui::VolumeSummary;
use crate::ui::gestures::interaction::{framed, with_projection};

/// The camera and the volume it frames.
#[derive(Default)]
pub struct Framing {
    camera: Option<Camera>,
    bounds: Option<Aabb>,
    volume: Option<VolumeSummary>,
    /// Counts the volumes shown (a frame's inputs name the one they are of).
    generation: u64,
}

impl Framing {
    /// A new volume is on screen: frames it in the default view.
    pub fn show(&mut self, summary: VolumeSummary, projection: ProjectionKind) {
        self.bounds = Some(Aabb::of_volume(summary.dims, summary.spacing_mm));
        self.volume = Some(summary);
        self.reset_view(projection);
        self.generation += 1;
    }

    /// Which volume is on screen (counts the volumes shown).
    pub(crate) fn generation(&self) -> u64 {
        self.generation
    }

    /// The camera, once a volume is shown.
    pub fn camera(&self) -> Option<Camera> {
        self.camera
    }

    /// The view a volume opens in: the patient from the front, superior up (by the file's
    /// orientation, RAS where it has none), as a radiologist looks at a 3D rendering; a 2D image
    /// faces the viewer as its slice view shows it (axial from the feet, coronal from the front,
    /// sagittal from the left).
    pub(crate) fn reset_view(&mut self, projection: ProjectionKind) {
        use crate::mpr::PlaneKind;
        use crate::volume::orientation::Direction;
        let plane = self
            .volume
            .as_ref()
            .and_then(|v| crate::mpr::frame::image_plane_of(v.dims, v.orientation_or_assumed()));
        let side = match plane {
            Some(PlaneKind::Axial) => Direction::Inferior,
            Some(PlaneKind::Sagittal) => Direction::Left,
            _ => Direction::Anterior,
        };
        self.view_from(side, projection);
    }

    /// The volume on screen, to keep its GPU lines current.
    pub(crate) fn volume_mut(&mut self) -> Option<&mut VolumeSummary> {
        self.volume.as_mut()
    }

    /// The volume on screen.
    pub fn volume(&self) -> Option<&VolumeSummary> {
        self.volume.as_ref()
    }

    /// The camera and the volume's bounding box, once a volume is shown.
    pub(crate) fn camera_and_bounds(&self) -> Option<(Camera, Aabb)> {
        self.camera.zip(self.bounds)
    }

    /// The camera, once a volume is shown.
    pub(crate) fn camera_mut(&mut self) -> Option<&mut Camera> {
        self.camera.as_mut()
    }

    /// Looks along `preset`, framing the whole volume.
    pub(crate) fn set_view(&mut self, preset: ViewPreset, projection: ProjectionKind) {
        if let Some(bounds) = &self.bounds {
            self.camera = Some(framed(bounds, preset, projection));
        }
    }

    /// Looks at the patient from `side` (the orientation from the header, or RAS), framing the
    /// whole volume.
    pub fn view_from(
        &mut self,
        side: crate::volume::orientation::Direction,
        projection: ProjectionKind,
    ) {
        if let (Some(bounds), Some(volume)) = (&self.bounds, &self.volume) {
            let (dir, up) = volume.orientation_or_assumed().view_from(side);
            self.camera = Some(Camera::framing(bounds, dir, up, projection));
        }
    }

    /// Switches projection without a jump in size.
    pub(crate) fn set_projection(&mut self, kind: ProjectionKind) {
        self.camera = self.camera.map(|c| with_projection(&c, kind));
    }
}
