//! The slice views beside the 3D view: axial, coronal and sagittal planes through one crosshair
//! point in the patient's frame, sampled on the GPU by `render::slice` from the ray caster's own
//! volume texture, each redrawn only when what it shows changed. Gestures per pane
//! (`pane`): click or drag to move the crosshair, the wheel (or arrow keys, Page Up/Down) to
//! step one voxel along the plane's normal, Ctrl+wheel to zoom, a middle- or Shift-drag to pan,
//! a right-drag for window/level.

mod controls;
mod crop_edit;
mod labels;
mod pane;
mod planes_3d;

use std::sync::Arc;

use glam::DVec3;

use crate::mpr::{PatientFrame, Plane, PlaneKind, Slab};
use crate::render::slice::{SliceBricks, SliceRenderer};
use crate::render::table_texture::TableTexture;
use crate::render::volume_texture::{VolumeView, texel_units};
use crate::transfer::TransferFunction;
use crate::volume::Volume;

use labels::LabelsAction;
pub use labels::ShownLabels;
pub use pane::Probe;
use pane::{PaneLook, SlicePane};

/// The window's GPU handles the slice views draw with.
struct SliceGpu {
    device: wgpu::Device,
    queue: wgpu::Queue,
    egui_renderer: Arc<egui::mutex::RwLock<egui_wgpu::Renderer>>,
    renderer: SliceRenderer,
}

/// The volume the slices show: its samples (for the value under the cursor), its patient frame
/// and its texture on the GPU (shared with the ray caster).
struct Source {
    volume: Arc<Volume>,
    frame: PatientFrame,
    texture: VolumeView,
    format: wgpu::TextureFormat,
    /// Counts volumes shown: a new one redraws every pane.
    generation: u64,
    /// The renderer's page-table generation last seen: new bricks redraw every pane.
    contents: u64,
    /// The bricks a slab leaps over, built when a slab is first drawn (`None` inside: the
    /// device cannot hold them, and slabs take every sample).
    bricks: std::cell::OnceCell<Option<SliceBricks>>,
}

impl Source {
    /// The bricks of this volume, built on first use.
    fn bricks(&self, gpu: &SliceGpu) -> Option<&SliceBricks> {
        self.bricks
            .get_or_init(|| {
                let (texel_max, _, _) = texel_units(&self.volume, self.format);
                gpu.renderer.build_bricks(
                    &gpu.device,
                    &gpu.queue,
                    &self.texture,
                    self.volume.dims(),
                    texel_max,
                )
            })
            .as_ref()
    }
}

/// The slice views' state: the crosshair, the look shared by all panes, and each pane.
pub struct SliceViews {
    gpu: Result<SliceGpu, String>,
    source: Option<Source>,
    generation: u64,
    /// The crosshair point (mm, LPS), which every plane passes through.
    crosshair: DVec3,
    panes: Vec<SlicePane>,
    /// Each pane's plane orientation (its point is the crosshair's), by pane: standard until
    /// tilted with Ctrl + drag in another pane.
    planes: Vec<Plane>,
    /// The grey window of the slices (data units).
    pub window: [f64; 2],
    /// The nearest voxel instead of trilinear interpolation.
    pub nearest: bool,
    /// A thick slab instead of a thin slice.
    pub slab: Option<Slab>,
    /// Blend the transfer function's colour over the grey by its opacity.
    pub colour_by_tf: bool,
    /// Grey from white at the window's low end to black at its high end: on for a volume whose
    /// file asks for it (DICOM MONOCHROME1), and the user's to change.
    pub invert: bool,
    /// Whether a 2D image is shown alone (its own layout): no crosshair lines over it.
    pub alone: bool,
    /// The colour table of the transfer function last given, for the volume shown.
    colours: Option<Colours>,
    /// The point under the pointer in a slice this pass, if any.
    hover: Option<Probe>,
    /// A segmentation over the slices.
    labels: Option<ShownLabels>,
}

/// A transfer function's colour table on the GPU, for one volume (its value range).
struct Colours {
    tf: TransferFunction,
    volume: u64,
    table: TableTexture,
    /// Counts tables built: a new one redraws every pane.
    generation: u64,
}

impl SliceViews {
    /// Slice views drawing with eframe's device.
    pub fn new(rs: &egui_wgpu::RenderState) -> Self {
        let gpu = SliceRenderer::new(&rs.device)
            .map(|renderer| SliceGpu {
                device: rs.device.clone(),
                queue: rs.queue.clone(),
                egui_renderer: rs.renderer.clone(),
                renderer,
            })
            .map_err(|e| e.to_string());
        Self {
            gpu,
            source: None,
            generation: 0,
            crosshair: DVec3::ZERO,
            panes: PlaneKind::STANDARD
                .into_iter()
                .map(SlicePane::new)
                .collect(),
            planes: standard_planes(),
            window: [0.0, 1.0],
            nearest: false,
            slab: None,
            colour_by_tf: false,
            invert: false,
            alone: false,
            colours: None,
            hover: None,
            labels: None,
        }
    }

    /// Shows `map` (on the volume's grid) over the slices, every segment shown; the reason
    /// where it cannot be.
    pub fn set_labels(&mut self, map: Arc<crate::labels::LabelMap>) -> Result<(), String> {
        let (Ok(gpu), Some(source)) = (&self.gpu, &self.source) else {
            return Err("no volume to show labels over".into());
        };
        if map.dims() != source.volume.dims() {
            return Err("the labels are of another volume".into());
        }
        self.labels = Some(ShownLabels::new(
            &gpu.device,
            &gpu.queue,
            map,
            source.generation,
        )?);
        Ok(())
    }

    /// The segmentation over the slices, if any.
    pub fn labels(&self) -> Option<&ShownLabels> {
        self.labels.as_ref()
    }

    /// The segmentation, to change what it shows, and the queue its colours go through.
    fn labels_mut(&mut self) -> Option<(&mut ShownLabels, &wgpu::Queue)> {
        let queue = &self.gpu.as_ref().ok()?.queue;
        Some((self.labels.as_mut()?, queue))
    }

    /// How the segmentation is shown, if there is one (kept for its file).
    pub fn label_style(&self) -> Option<crate::ui::state::LabelStyle> {
        self.labels.as_ref().map(ShownLabels::style)
    }

    /// Shows the segmentation as `style` (kept for its file) says.
    pub fn apply_label_style(&mut self, style: &crate::ui::state::LabelStyle) {
        if let Some((labels, queue)) = self.labels_mut() {
            labels.apply_style(queue, style);
        }
    }

    /// The segmentation for the 3D view, if any: its textures and the count of visibility
    /// changes.
    pub fn labels_3d(&self) -> Option<(Arc<crate::render::labels::GpuLabels>, u64)> {
        self.labels.as_ref().map(ShownLabels::for_3d)
    }

    /// The segmentation's section of the side panel, where there is one; `view`: how it shows
    /// in 3D.
    pub fn labels_ui(
        &mut self,
        ui: &mut egui::Ui,
        view: &mut crate::settings::LabelView,
        smoothing: &mut f64,
    ) {
        let Some((labels, queue)) = self.labels_mut() else {
            return;
        };
        if labels.ui(ui, queue, (view, smoothing)) == Some(LabelsAction::Close) {
            self.labels = None;
        }
        ui.separator();
    }

    /// The volume the slices show.
    pub fn volume(&self) -> Option<Arc<Volume>> {
        self.source.as_ref().map(|s| Arc::clone(&s.volume))
    }

    /// The transfer function the slices are coloured by (when `colour_by_tf`): its table is
    /// rebuilt when it or the volume changed.
    pub fn set_transfer_function(&mut self, tf: &TransferFunction) {
        let (Ok(gpu), Some(source)) = (&self.gpu, &self.source) else {
            return;
        };
        if !self.colour_by_tf
            || self
                .colours
                .as_ref()
                .is_some_and(|c| c.volume == source.generation && c.tf == *tf)
        {
            return;
        }
        let generation = self.colours.as_ref().map_or(0, |c| c.generation + 1);
        self.colours = Some(Colours {
            tf: tf.clone(),
            volume: source.generation,
            table: gpu
                .renderer
                .colour_table(&gpu.device, &gpu.queue, tf, &source.volume),
            generation,
        });
    }

    /// Shows `volume`, already on the GPU as `texture` in `format`: the crosshair at its centre,
    /// every pane fitted anew, the window `window`.
    pub fn set_volume(
        &mut self,
        volume: Arc<Volume>,
        texture: VolumeView,
        format: wgpu::TextureFormat,
        window: [f64; 2],
    ) {
        let frame = PatientFrame::of(&volume);
        self.generation += 1;
        self.crosshair = frame.centre();
        self.window = window;
        self.invert = volume.provenance().invert_grey;
        for pane in &mut self.panes {
            pane.forget_view();
        }
        self.planes = standard_planes();
        // Labels lie on one volume's grid.
        self.labels = None;
        self.source = Some(Source {
            volume,
            frame,
            texture,
            format,
            generation: self.generation,
            contents: 0,
            bricks: std::cell::OnceCell::new(),
        });
    }

    /// Notes that the volume's bricks changed on the GPU (`generation`: the renderer's
    /// [`crate::render::VolumeRenderer::pages_generation`]): the panes draw again, and the bricks a
    /// slab leaps over are built again from what is there now.
    pub(crate) fn set_contents(&mut self, generation: u64) {
        if let Some(source) = &mut self.source
            && source.contents != generation
        {
            source.contents = generation;
            source.bricks = std::cell::OnceCell::new();
        }
    }

    /// The planes of the panes (a slab's thickness with them) in the volume's continuous voxel
    /// coordinates, for the bricks' residency.
    pub(crate) fn planes_in_voxels(&self) -> Vec<crate::render::volume_texture::SlicePlane> {
        let Some(source) = &self.source else {
            return Vec::new();
        };
        let half_mm = self.slab.map_or(0.0, |s| 0.5 * s.thickness_mm);
        self.planes
            .iter()
            .map(|plane| {
                let plane = plane.through(self.crosshair);
                let at = |p: DVec3| source.frame.to_voxel(p) + DVec3::splat(0.5);
                let origin = at(plane.point);
                let right = at(plane.point + plane.right) - origin;
                let up = at(plane.point + plane.up) - origin;
                let normal = right.cross(up).normalize_or_zero();
                let reach = (at(plane.point + plane.normal() * half_mm) - origin).dot(normal);
                crate::render::volume_texture::SlicePlane {
                    point: origin.to_array(),
                    normal: normal.to_array(),
                    half_thickness: reach.abs(),
                }
            })
            .collect()
    }

    /// The crosshair point (mm, LPS).
    pub fn crosshair(&self) -> DVec3 {
        self.crosshair
    }

    /// Moves the crosshair (the planes follow), clamped into the volume's box.
    fn set_crosshair(&mut self, p: DVec3) {
        self.crosshair = match &self.source {
            Some(s) => {
                let dims = s.frame.dims();
                let v = s.frame.to_voxel(p);
                let v = DVec3::from(std::array::from_fn::<f64, 3, _>(|a| {
                    v[a].clamp(-0.5, f64::from(dims[a]) - 0.5)
                }));
                s.frame.to_patient(v)
            }
            None => p,
        };
    }

    /// What lies under the pointer in a slice view this pass.
    pub fn hover(&self) -> Option<&Probe> {
        self.hover.as_ref()
    }

    /// Starts a pass: forgets last pass's pointer position.
    pub fn begin_pass(&mut self) {
        self.hover = None;
    }

    /// Moves the crosshair to what the 3D view's pixel `px` (of a `size` view seen by
    /// `camera`) shows by `settings` and `tf` (`mpr::pick`); nothing when it shows nothing.
    pub fn pick(
        &mut self,
        settings: &crate::settings::RenderSettings,
        tf: &crate::transfer::TransferFunction,
        camera: &crate::camera::Camera,
        size: [u32; 2],
        px: glam::DVec2,
    ) {
        let Some(source) = &self.source else { return };
        if let Some(world) = self.pick_world(settings, tf, camera, size, px) {
            let spacing = DVec3::from(source.volume.spacing_mm());
            let p = source.frame.to_patient(world / spacing);
            self.set_crosshair(p);
            log::debug!(
                "crosshair picked in 3D at {:.2}, {:.2}, {:.2} mm",
                p.x,
                p.y,
                p.z
            );
        }
    }

    /// The world point the 3D view's pixel `px` shows (`mpr::pick`), only the shown labels'
    /// voxels where the view cuts the image to them, their surfaces first where it draws them.
    fn pick_world(
        &self,
        settings: &crate::settings::RenderSettings,
        tf: &crate::transfer::TransferFunction,
        camera: &crate::camera::Camera,
        size: [u32; 2],
        px: glam::DVec2,
    ) -> Option<DVec3> {
        let source = self.source.as_ref()?;
        let volume = &source.volume;
        let labels = self.labels.as_ref();
        match labels {
            Some(labels) if settings.labels.cuts() => {
                crate::mpr::pick::pick_shown(volume, settings, tf, camera, size, px, |v| {
                    labels.segment_at(v).is_some()
                })
            }
            Some(labels) if settings.labels.surfaces() => {
                crate::mpr::pick::pick_surfaces(volume, settings, tf, camera, size, px, |v| {
                    labels.surface_at(v)
                })
            }
            _ => crate::mpr::pick::pick(volume, settings, tf, camera, size, px),
        }
    }

    /// What the 3D view's pixel `px` shows, as a probe: its point, voxel and value (`None`
    /// where the ray meets nothing).
    pub fn probe_3d(
        &self,
        settings: &crate::settings::RenderSettings,
        tf: &crate::transfer::TransferFunction,
        camera: &crate::camera::Camera,
        size: [u32; 2],
        px: glam::DVec2,
    ) -> Option<Probe> {
        let source = self.source.as_ref()?;
        let world = self.pick_world(settings, tf, camera, size, px)?;
        let volume = &source.volume;
        let v = world / DVec3::from(volume.spacing_mm());
        let dims = volume.dims();
        let voxel: [u32; 3] =
            std::array::from_fn(|a| (v[a] + 0.5).floor().clamp(0.0, f64::from(dims[a] - 1)) as u32);
        let [i, j, k] = voxel;
        Some(Probe {
            kind: None,
            patient: source.frame.to_patient(v),
            voxel: Some(voxel),
            value: Some(volume.value(i, j, k)).filter(|x| x.is_finite()),
            preview_level: volume.streaming().map(|s| s.preview_level()),
        })
    }

    /// Back to the standard axial, coronal and sagittal planes.
    pub(crate) fn reset_planes(&mut self) {
        self.planes = standard_planes();
    }

    /// Outlines the three slice planes over the 3D view in `rect` (its image `size_px` pixels,
    /// seen by `camera`, the volume in `bounds`), in each pane's colour; returns the segments
    /// drawn.
    pub(crate) fn draw_planes_3d(
        &self,
        ui: &egui::Ui,
        rect: egui::Rect,
        size_px: [u32; 2],
        camera: &crate::camera::Camera,
        bounds: &crate::camera::Aabb,
    ) -> Vec<[egui::Pos2; 2]> {
        if let Some(source) = &self.source {
            let planes: Vec<(PlaneKind, Plane)> = self
                .panes
                .iter()
                .zip(&self.planes)
                .map(|(pane, plane)| (pane.kind(), plane.through(self.crosshair)))
                .collect();
            planes_3d::draw(ui, rect, size_px, camera, bounds, &source.frame, &planes)
        } else {
            Vec::new()
        }
    }

    /// Draws the pane of `kind` in `rect` and applies its gestures.
    pub fn pane_ui(
        &mut self,
        ui: &mut egui::Ui,
        kind: PlaneKind,
        rect: egui::Rect,
        crop: Option<&mut crate::settings::CropBox>,
    ) {
        let Some(index) = self.panes.iter().position(|p| p.kind() == kind) else {
            return;
        };
        let (Ok(gpu), Some(source)) = (&self.gpu, &self.source) else {
            let text = match &self.gpu {
                Err(e) => format!("Slices cannot be drawn: {e}"),
                Ok(_) => "No volume".to_string(),
            };
            pane::draw_message(ui, rect, &text);
            return;
        };
        let plane = |i: usize| self.planes[i].through(self.crosshair);
        let (a, b) = ((index + 1) % 3, (index + 2) % 3);
        let look = PaneLook {
            crosshair: self.crosshair,
            plane: plane(index),
            others: [
                (self.panes[a].kind(), plane(a)),
                (self.panes[b].kind(), plane(b)),
            ],
            window: self.window,
            invert: self.invert,
            nearest: self.nearest,
            slab: self.slab,
            crop: crop.as_deref().copied(),
            colours: self
                .colours
                .as_ref()
                .filter(|c| self.colour_by_tf && c.volume == source.generation)
                .map(|c| (&c.table, c.generation)),
            labels: self
                .labels
                .as_ref()
                .filter(|l| l.volume == source.generation)
                .map(ShownLabels::for_pane),
            alone: self.alone,
            directions: source
                .volume
                .orientation()
                .is_none_or(|o| o.source != crate::volume::OrientationSource::AsStored),
        };
        let outcome = self.panes[index].ui(ui, rect, gpu, source, look);
        if let Some(p) = outcome.crosshair {
            self.set_crosshair(p);
            let c = self.crosshair;
            log::debug!("crosshair moved to {:.2}, {:.2}, {:.2} mm", c.x, c.y, c.z);
        }
        if let Some(window) = outcome.window {
            self.window = window;
        }
        if let Some(turn) = outcome.tilt {
            // The other planes turn about this one's normal through the crosshair.
            let axis = self.planes[index].normal();
            for j in [a, b] {
                self.planes[j] = self.planes[j].tilted(axis, turn);
            }
        }
        if outcome.hover.is_some() {
            self.hover = outcome.hover;
        }
        if let (Some(new), Some(crop)) = (outcome.crop, crop) {
            *crop = new;
        }
    }
}

/// The standard planes, one per pane, in pane order.
fn standard_planes() -> Vec<Plane> {
    PlaneKind::STANDARD
        .into_iter()
        .map(|k| Plane::standard(k, DVec3::ZERO))
        .collect()
}
