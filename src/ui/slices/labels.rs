//! A segmentation over the slice views: the label map, its textures on the GPU, which segments
//! are shown and how (fill opacity, outlines, each segment's colour and opacity).

use std::collections::{BTreeMap, BTreeSet};
use std::sync::Arc;

use crate::labels::{LabelMap, Segment};
use crate::render::labels::GpuLabels;
use crate::render::slice::LabelLook;
use crate::settings::LabelView;
use crate::ui::state::LabelStyle;

/// The labels shown over the slices of one volume.
pub struct ShownLabels {
    /// The labels on the volume's grid.
    pub map: Arc<LabelMap>,
    /// Its textures, shared with the 3D view.
    gpu: Arc<GpuLabels>,
    /// Hidden segments, by (layer, value).
    hidden: BTreeSet<(u16, u16)>,
    /// Segments given another colour or opacity in the panel, by (layer, value): sRGB and
    /// opacity (the file's colour, opaque, for the rest).
    styled: BTreeMap<(u16, u16), [u8; 4]>,
    /// How they are drawn.
    pub look: LabelLook,
    /// Counts changes of what is shown: a new one redraws every pane.
    generation: u64,
    /// Counts changes of which segments are shown (the 3D view redraws for those alone).
    shown_generation: u64,
    /// The volume they lie on (`Source::generation`).
    pub(super) volume: u64,
    /// The panel's search text.
    search: String,
}

/// What the segmentation's panel asked for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum LabelsAction {
    /// Take the segmentation away.
    Close,
}

impl ShownLabels {
    /// `map`'s labels, all shown, on `device`.
    pub(super) fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        map: Arc<LabelMap>,
        volume: u64,
    ) -> Result<Self, String> {
        let gpu =
            Arc::new(GpuLabels::new(device, queue, Arc::clone(&map)).map_err(|e| e.to_string())?);
        Ok(Self {
            map,
            gpu,
            hidden: BTreeSet::new(),
            styled: BTreeMap::new(),
            look: LabelLook::default(),
            generation: 0,
            shown_generation: 0,
            volume,
            search: String::new(),
        })
    }

    /// Whether `segment` is shown.
    fn is_shown(&self, segment: &Segment) -> bool {
        !self.hidden.contains(&(segment.layer, segment.value))
    }

    /// Shows the segments `shown` says (by layer and value), hides the others, and redraws.
    fn show_only(&mut self, queue: &wgpu::Queue, shown: impl Fn(&Segment) -> bool) {
        self.hidden = self
            .map
            .segments()
            .iter()
            .filter(|s| !shown(s))
            .map(|s| (s.layer, s.value))
            .collect();
        self.restyle(queue);
    }

    /// How the segmentation is shown, to keep for its file.
    pub(super) fn style(&self) -> LabelStyle {
        LabelStyle {
            hidden: self.hidden.iter().copied().collect(),
            styled: self.styled.iter().map(|(k, v)| (*k, *v)).collect(),
            fill: self.look.opacity,
            outlines: self.look.outline,
        }
    }

    /// Shows the segmentation as `style` says (kept for its file), and redraws.
    pub(super) fn apply_style(&mut self, queue: &wgpu::Queue, style: &LabelStyle) {
        self.hidden = style.hidden.iter().copied().collect();
        self.styled = style.styled.iter().copied().collect();
        self.look = LabelLook {
            opacity: style.fill.clamp(0.0, 1.0),
            outline: style.outlines,
        };
        self.restyle(queue);
    }

    /// A segment's colour and opacity as drawn (alpha 0 where hidden).
    fn style_of(&self, s: &Segment) -> [u8; 4] {
        let key = (s.layer, s.value);
        let [r, g, b] = s.colour;
        let [r, g, b, a] = self.styled.get(&key).copied().unwrap_or([r, g, b, 255]);
        [r, g, b, if self.hidden.contains(&key) { 0 } else { a }]
    }

    /// Writes every segment's colour, opacity and visibility to the GPU, and redraws.
    fn restyle(&mut self, queue: &wgpu::Queue) {
        self.gpu.show_styled(queue, &self.map, |s| self.style_of(s));
        self.generation += 1;
        self.shown_generation += 1;
    }

    /// What the 3D view shows: the textures and the count of visibility changes.
    pub(super) fn for_3d(&self) -> (Arc<GpuLabels>, u64) {
        (Arc::clone(&self.gpu), self.shown_generation)
    }

    /// What a pane draws them with: the textures, the generation and the look.
    pub(super) fn for_pane(&self) -> (&GpuLabels, u64, LabelLook) {
        // A label atlas taken by the volume after the pane drew (labels in bricks) draws again.
        let generation = self.generation + self.gpu.atlas_changes();
        (&self.gpu, generation, self.look)
    }

    /// Whether the labels travel in the volume's bricks (no surfaces for those).
    pub fn in_bricks(&self) -> bool {
        self.gpu.in_bricks()
    }

    /// The side panel's section: fill opacity, outlines, and each segment (shown or not, its
    /// colour, name, value and voxels), searchable by name, all at once or one alone.
    pub(super) fn ui(
        &mut self,
        ui: &mut egui::Ui,
        queue: &wgpu::Queue,
        (view, smoothing): (&mut LabelView, &mut f64),
    ) -> Option<LabelsAction> {
        let mut action = None;
        let map = Arc::clone(&self.map);
        let segments = map.segments();
        ui.horizontal(|ui| {
            ui.strong("Segmentation");
            ui.label(format!("{} · {} segments", map.name(), segments.len()))
                .on_hover_text(map.notes().join("\n"));
            if ui.small_button("Close").clicked() {
                action = Some(LabelsAction::Close);
            }
        });
        ui.horizontal(|ui| {
            ui.label("3D");
            for (value, text, hover) in [
                (
                    LabelView::Colour,
                    "colour",
                    "each sample in its shown label's colour",
                ),
                (
                    LabelView::Inside,
                    "inside",
                    "the image only inside the shown labels, the rest cut away",
                ),
                (
                    LabelView::ColourInside,
                    "both",
                    "only inside the shown labels, each in its colour",
                ),
                (
                    LabelView::Surfaces,
                    "surfaces",
                    "each shown label's boundary as a smooth lit surface over the image",
                ),
                (LabelView::Off, "off", "the image alone"),
            ] {
                let coarse = value.surfaces() && self.gpu.in_bricks();
                ui.selectable_value(view, value, text)
                    .on_hover_text(if coarse {
                        "each shown label's boundary as a smooth lit surface over the image (these \
                     labels travel in the volume's bricks: past one of this GPU's 3D textures, \
                     their surfaces are found on a grid reduced to fit one)"
                    } else {
                        hover
                    });
            }
        });
        if view.surfaces() {
            ui.horizontal(|ui| {
                ui.label("Smoothing");
                let most = crate::labels::surface::MOST_SMOOTHING;
                ui.add(egui::Slider::new(smoothing, 0.0..=most).fixed_decimals(1))
                    .on_hover_text(
                        "a Gaussian's width in voxels: 0 shows the voxels' outline, more rounds \
                         steps away and thins structures one or two voxels across",
                    );
            });
            let classes = self.gpu.classes();
            if !classes.clashes.is_empty() {
                ui.label(format!(
                    "{} touching pairs share a class: no wall between them",
                    classes.clashes.len()
                ))
                .on_hover_text(format!(
                    "walls between touching labels are drawn where their classes differ; the \
                     shown labels take {} classes (the most there are), so some neighbours \
                     share one and show as one body: hide some labels to part them",
                    classes.used
                ));
            }
        }
        let before = self.look;
        ui.horizontal(|ui| {
            ui.label("Fill");
            ui.add(egui::Slider::new(&mut self.look.opacity, 0.0..=1.0).fixed_decimals(2));
            ui.checkbox(&mut self.look.outline, "outlines");
        });
        if self.look != before {
            self.generation += 1;
        }
        let mut shown: Vec<bool> = segments.iter().map(|s| self.is_shown(s)).collect();
        let mut changed = false;
        let mut restyled = false;
        ui.horizontal(|ui| {
            ui.add(
                egui::TextEdit::singleline(&mut self.search)
                    .hint_text("search by name")
                    .desired_width(150.0),
            );
            if ui.button("All").clicked() {
                shown.iter_mut().for_each(|v| *v = true);
                changed = true;
            }
            if ui.button("None").clicked() {
                shown.iter_mut().for_each(|v| *v = false);
                changed = true;
            }
        });
        let needle = self.search.to_lowercase();
        egui::ScrollArea::vertical()
            .id_salt("segments")
            .max_height(260.0)
            .show(ui, |ui| {
                for (i, s) in segments.iter().enumerate() {
                    if !needle.is_empty() && !s.name.to_lowercase().contains(&needle) {
                        continue;
                    }
                    ui.horizontal(|ui| {
                        changed |= ui.checkbox(&mut shown[i], "").changed();
                        let [r, g, b] = s.colour;
                        let key = (s.layer, s.value);
                        let [mut cr, mut cg, mut cb, mut a] =
                            self.styled.get(&key).copied().unwrap_or([r, g, b, 255]);
                        let mut rgb = [cr, cg, cb];
                        let picked = egui::color_picker::color_edit_button_srgb(ui, &mut rgb)
                            .on_hover_text("its colour");
                        let mut opacity = f32::from(a) / 255.0;
                        let faded = ui
                            .add(
                                egui::DragValue::new(&mut opacity)
                                    .range(0.05..=1.0)
                                    .speed(0.01)
                                    .fixed_decimals(2),
                            )
                            .on_hover_text(
                                "its opacity: the fill over the slices, its colour's weight in 3D",
                            );
                        if picked.changed() || faded.changed() {
                            [cr, cg, cb] = rgb;
                            a = (opacity * 255.0).round() as u8;
                            self.styled.insert(key, [cr, cg, cb, a]);
                            restyled = true;
                        }
                        ui.label(&s.name).on_hover_text(format!(
                            "label {} (layer {}), {} voxels",
                            s.value, s.layer, s.voxels
                        ));
                        if ui.small_button("only").clicked() {
                            shown.iter_mut().for_each(|v| *v = false);
                            shown[i] = true;
                            changed = true;
                        }
                    });
                }
            });
        if restyled && !changed {
            self.restyle(queue);
        }
        if changed {
            let keep: BTreeSet<(u16, u16)> = segments
                .iter()
                .zip(&shown)
                .filter(|(_, on)| **on)
                .map(|(s, _)| (s.layer, s.value))
                .collect();
            self.show_only(queue, |s| keep.contains(&(s.layer, s.value)));
        }
        action
    }

    /// The shown segment at stored voxel `[i, j, k]`, as its surface in 3D is drawn: its value
    /// and opacity (0 … 1).
    pub fn surface_at(&self, voxel: [u32; 3]) -> Option<(u16, f64)> {
        let s = self.segment_at(voxel)?;
        Some((s.value, f64::from(self.style_of(s)[3]) / 255.0))
    }

    /// The shown segment at stored voxel `[i, j, k]` of the volume, if any.
    pub fn segment_at(&self, [i, j, k]: [u32; 3]) -> Option<&Segment> {
        let [nx, ny, _] = self.map.dims().map(|d| d as usize);
        let index = i as usize + nx * (j as usize + ny * k as usize);
        (0..self.map.layers().len())
            .filter_map(|layer| self.map.segment_at(layer, index))
            .find(|s| self.is_shown(s))
    }
}
