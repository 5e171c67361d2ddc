//! The CPU reference ray caster, in f64: what the GPU images are checked against.
//!
//! It shares only the conventions with the GPU code (DESIGN.md, src/sampling.rs), not its
//! mechanisms: rays come from inverting the camera per pixel and an analytic slab test instead of
//! rasterised faces; values come from a hand-written trilinear interpolation with clamp-to-edge
//! instead of the texture unit; the transfer function is evaluated exactly instead of through the
//! baked table. Slow by design; meant for small volumes and images.

mod modes;
mod shade;
pub mod slice;
mod surfaces;
mod trilinear;

use glam::{DMat4, DVec2, DVec3};

use crate::camera::{Aabb, Camera, pixel_to_ndc, unproject};
use crate::counters::FrameCounters;
use crate::imaging::ImageF32;
use crate::settings::RenderSettings;
use crate::transfer::TransferFunction;
use crate::volume::Volume;

pub use modes::{Labelled, RayInput};
pub use shade::{gradient, phong};
pub use surfaces::SurfaceMasks;
pub use trilinear::sample_trilinear;

/// A reference image and its counts.
#[derive(Clone, Debug)]
pub struct ReferenceImage {
    /// The image (alpha = 1: composited over the background).
    pub image: ImageF32,
    /// Sample counts.
    pub counts: FrameCounters,
}

/// Renders `volume` as the GPU would, in f64, on all cores.
pub fn render(
    volume: &Volume,
    tf: &TransferFunction,
    camera: &Camera,
    size: [u32; 2],
    settings: &RenderSettings,
) -> ReferenceImage {
    render_labelled(volume, tf, camera, size, settings, None)
}

/// [`render`] with a segmentation over the volume, shown as `settings.labels` says.
pub fn render_labelled(
    volume: &Volume,
    tf: &TransferFunction,
    camera: &Camera,
    size: [u32; 2],
    settings: &RenderSettings,
    labels: Option<&Labelled<'_>>,
) -> ReferenceImage {
    render_labelled_on(volume, tf, camera, (size, settings), labels, 1)
}

/// [`render_labelled`] with the surfaces' masks on the labels' grid reduced `factor`-fold, as
/// the GPU makes them for labels in bricks past one texture (1: the labels' own grid).
pub fn render_labelled_on(
    volume: &Volume,
    tf: &TransferFunction,
    camera: &Camera,
    (size, settings): ([u32; 2], &RenderSettings),
    labels: Option<&Labelled<'_>>,
    factor: u32,
) -> ReferenceImage {
    let bounds = Aabb::of_volume(volume.dims(), volume.spacing_mm());
    let world_from_clip = camera.clip_from_world(size, &bounds).inverse();
    // Surfaces are found in the shown labels' smoothed mask, as the GPU builds it.
    let smoothing = settings.label_smoothing as f32;
    let mask = labels
        .filter(|_| settings.labels.surfaces())
        .map(|l| surfaces::SurfaceMasks::new(l, smoothing, factor.max(1)));
    let caster = Caster {
        volume,
        tf,
        labels,
        surface_mask: mask.as_ref(),
        // Rays run through the cropping box (the whole bounding box when nothing is cropped).
        bounds: settings.crop.world(&bounds),
        world_from_clip,
        size,
        settings,
    };
    let rows: Vec<u32> = (0..size[1]).collect();
    let threads = std::thread::available_parallelism()
        .map_or(1, |n| n.get())
        .min(size[1].max(1) as usize);
    let chunk = rows.len().div_ceil(threads.max(1)).max(1);
    let parts: Vec<(Vec<[f32; 4]>, FrameCounters)> = std::thread::scope(|scope| {
        let handles: Vec<_> = rows
            .chunks(chunk)
            .map(|ys| {
                let caster = &caster;
                scope.spawn(move || {
                    let mut counts = FrameCounters::default();
                    let mut pixels = Vec::with_capacity(ys.len() * size[0] as usize);
                    for &y in ys {
                        for x in 0..size[0] {
                            pixels.push(caster.pixel(x, y, &mut counts));
                        }
                    }
                    (pixels, counts)
                })
            })
            .collect();
        handles
            .into_iter()
            .map(|h| h.join().unwrap_or_else(|e| std::panic::resume_unwind(e)))
            .collect()
    });
    let mut counts = FrameCounters::default();
    let mut pixels = Vec::with_capacity(size[0] as usize * size[1] as usize);
    for (p, c) in parts {
        pixels.extend(p);
        counts.add(&c);
    }
    ReferenceImage {
        image: ImageF32 {
            width: size[0],
            height: size[1],
            pixels,
        },
        counts,
    }
}

struct Caster<'a> {
    volume: &'a Volume,
    tf: &'a TransferFunction,
    labels: Option<&'a Labelled<'a>>,
    surface_mask: Option<&'a surfaces::SurfaceMasks>,
    bounds: Aabb,
    world_from_clip: DMat4,
    size: [u32; 2],
    settings: &'a RenderSettings,
}

impl Caster<'_> {
    fn pixel(&self, x: u32, y: u32, counts: &mut FrameCounters) -> [f32; 4] {
        let bg = DVec3::from_array(self.settings.background);
        let ndc = pixel_to_ndc(DVec2::new(x as f64 + 0.5, y as f64 + 0.5), self.size);
        // The ray starts on the near plane (t = 0), like the GPU's near-plane cap.
        let origin = unproject(self.world_from_clip, ndc, 0.0);
        let dir = (unproject(self.world_from_clip, ndc, 1.0) - origin).normalize();
        let rgb = match self.bounds.intersect(origin, dir) {
            Some((t0, t1)) if t1 > t0.max(0.0) => {
                counts.rays += 1;
                let entry = t0.max(0.0);
                let ray = RayInput {
                    volume: self.volume,
                    tf: self.tf,
                    labels: self.labels,
                    surface_mask: self.surface_mask,
                    settings: self.settings,
                    bounds: self.bounds,
                    pixel: [x, y],
                    entry: origin + dir * entry,
                    dir,
                    length_mm: t1 - entry,
                    offset: if self.settings.jitter {
                        crate::sampling::jittered_offset(x, y, self.settings.sample_offset)
                    } else {
                        self.settings.sample_offset
                    },
                };
                modes::cast(&ray, counts).unwrap_or(bg)
            }
            _ => bg,
        };
        [rgb.x as f32, rgb.y as f32, rgb.z as f32, 1.0]
    }
}
