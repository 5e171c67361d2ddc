//! What a click on the 3D view points at, for moving the crosshair there: along the pixel's ray
//! through the volume, the first visible surface (DVR: where the accumulated opacity passes ½;
//! isosurface: the first sample at or above the iso value) or the brightest (MIP, X-ray) or
//! darkest (MinIP) sample. Marched on the CPU at half the finest spacing, nearest-voxel values:
//! a pick, not a picture. Where the view shows only a segmentation's shown labels, only their
//! voxels ([`pick_shown`]).

use glam::{DVec2, DVec3};

use crate::camera::{Aabb, Camera};
use crate::settings::{Mode, RenderSettings};
use crate::transfer::TransferFunction;
use crate::volume::Volume;

/// Accumulated opacity at which a DVR ray has met its surface.
pub const SURFACE_OPACITY: f64 = 0.5;

/// The world point (the renderer's frame: voxel coordinates times the spacing) the pixel at
/// `px` (pixels from the view's top-left corner, view `size` pixels) points at, by `settings`'
/// mode and `tf`; `None` when the ray misses the volume or meets nothing.
pub fn pick(
    volume: &Volume,
    settings: &RenderSettings,
    tf: &TransferFunction,
    camera: &Camera,
    size: [u32; 2],
    px: DVec2,
) -> Option<DVec3> {
    pick_shown(volume, settings, tf, camera, size, px, |_| true)
}

/// [`pick`] where only the voxels `shown` admits take part (a view cut to a segmentation's
/// shown labels: the rest is not on screen).
pub fn pick_shown(
    volume: &Volume,
    settings: &RenderSettings,
    tf: &TransferFunction,
    camera: &Camera,
    size: [u32; 2],
    px: DVec2,
    shown: impl Fn([u32; 3]) -> bool,
) -> Option<DVec3> {
    let ray = RayPick::new(volume, camera, size, px)?;
    ray.image(settings, tf, shown)
}

/// [`pick`] in a view that draws a segmentation's labels as surfaces over the image: the first
/// point where the surfaces entered so far (`surface` gives a voxel's shown label and its
/// opacity; a surface where the label changes) hide half of what lies behind, else what [`pick`]
/// finds (the isosurface's crossing where it lies in front).
pub fn pick_surfaces(
    volume: &Volume,
    settings: &RenderSettings,
    tf: &TransferFunction,
    camera: &Camera,
    size: [u32; 2],
    px: DVec2,
    surface: impl Fn([u32; 3]) -> Option<(u16, f64)>,
) -> Option<DVec3> {
    let ray = RayPick::new(volume, camera, size, px)?;
    let mut accumulated = 0.0;
    let mut before = None;
    let mut hit = None;
    for (t, p) in ray.points() {
        let here = surface(ray.voxel(p));
        let entered = here.filter(|&(l, _)| before != Some(l));
        before = here.map(|(l, _)| l);
        if let Some((_, alpha)) = entered {
            accumulated += (1.0 - accumulated) * alpha.clamp(0.0, 1.0);
            if accumulated >= SURFACE_OPACITY {
                hit = Some((t, p));
                break;
            }
        }
    }
    let image = ray.image(settings, tf, |_| true);
    match (hit, image) {
        (Some((t, p)), Some(q)) if settings.mode == Mode::Iso || settings.mode == Mode::Dvr => {
            // The nearer of the two.
            Some(if (q - ray.origin).dot(ray.dir) < t {
                q
            } else {
                p
            })
        }
        (Some((_, p)), _) => Some(p),
        (None, q) => q,
    }
}

/// A pixel's ray through the volume, sampled at half the finest spacing.
struct RayPick<'a> {
    volume: &'a Volume,
    origin: DVec3,
    dir: DVec3,
    t0: f64,
    t1: f64,
    step: f64,
}

impl<'a> RayPick<'a> {
    fn new(volume: &'a Volume, camera: &Camera, size: [u32; 2], px: DVec2) -> Option<Self> {
        let bounds = Aabb::of_volume(volume.dims(), volume.spacing_mm());
        let (origin, dir) = camera.pixel_ray(px.x - 0.5, px.y - 0.5, size, &bounds);
        let (t0, t1) = bounds.intersect(origin, dir)?;
        Some(Self {
            volume,
            origin,
            dir,
            t0: t0.max(0.0),
            t1,
            step: volume.min_spacing_mm() / 2.0,
        })
    }

    /// The samples: their distance along the ray and their point.
    fn points(&self) -> impl Iterator<Item = (f64, DVec3)> + '_ {
        let samples = ((self.t1 - self.t0) / self.step).ceil().max(0.0) as usize;
        (0..samples).map(|k| {
            let t = self.t0 + (k as f64 + 0.5) * self.step;
            (t, self.origin + self.dir * t)
        })
    }

    /// The voxel nearest world point `p`.
    fn voxel(&self, p: DVec3) -> [u32; 3] {
        let v = p / DVec3::from(self.volume.spacing_mm());
        let dims = self.volume.dims();
        std::array::from_fn(|a| (v[a] + 0.5).floor().clamp(0.0, f64::from(dims[a]) - 1.0) as u32)
    }

    /// What the image shows along the ray by `settings`' mode, only the voxels `shown` admits.
    fn image(
        &self,
        settings: &RenderSettings,
        tf: &TransferFunction,
        shown: impl Fn([u32; 3]) -> bool,
    ) -> Option<DVec3> {
        let volume = self.volume;
        let range = volume.value_range()?;
        let (step, d0) = (self.step, volume.min_spacing_mm());
        let value_at = |p: DVec3| -> Option<f64> {
            let i = self.voxel(p);
            Some(volume.value(i[0], i[1], i[2])).filter(|x| x.is_finite() && shown(i))
        };
        let points = self.points().map(|(_, p)| p);
        match settings.mode {
            Mode::Dvr => {
                let mut accumulated = 0.0;
                for p in points {
                    let Some(v) = value_at(p) else { continue };
                    let alpha = tf.opacity_at(v, range).clamp(0.0, 1.0);
                    let alpha = 1.0 - (1.0 - alpha).powf(step / d0);
                    accumulated += (1.0 - accumulated) * alpha;
                    if accumulated >= SURFACE_OPACITY {
                        return Some(p);
                    }
                }
                None
            }
            Mode::Iso => {
                let threshold = range.denormalize(settings.iso.threshold(range));
                points
                    .into_iter()
                    .find(|p| value_at(*p).is_some_and(|v| v >= threshold))
            }
            Mode::MinIp => extreme(points, value_at, |a, b| a < b),
            Mode::Mip | Mode::Xray | Mode::XrayAttenuation => {
                extreme(points, value_at, |a, b| a > b)
            }
        }
    }
}

/// The first point whose value beats every other by `better`.
fn extreme(
    points: impl Iterator<Item = DVec3>,
    value_at: impl Fn(DVec3) -> Option<f64>,
    better: impl Fn(f64, f64) -> bool,
) -> Option<DVec3> {
    let mut best: Option<(f64, DVec3)> = None;
    for p in points {
        if let Some(v) = value_at(p)
            && best.is_none_or(|(b, _)| better(v, b))
        {
            best = Some((v, p));
        }
    }
    best.map(|(_, p)| p)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::ProjectionKind;
    use crate::volume::synthetic::analytic::sphere;

    #[test]
    fn a_click_on_a_sphere_lands_on_its_near_surface() {
        // A ball of radius 10 voxels (value 1000) in a 32³ box of zeros, 1 mm voxels.
        let volume = sphere(32, 10.0, 1000.0, 0.0).expect("sphere");
        let bounds = Aabb::of_volume(volume.dims(), volume.spacing_mm());
        let camera = Camera::framing(
            &bounds,
            DVec3::NEG_Y,
            DVec3::Z,
            ProjectionKind::Orthographic,
        );
        let size = [64, 64];
        let centre = bounds.center();
        let mut settings = RenderSettings::default();
        // Opaque above 500.
        let tf = TransferFunction {
            opacity: vec![[0.0, 0.0], [499.0, 0.0], [501.0, 1.0], [1000.0, 1.0]],
            color: vec![[0.0, 1.0, 1.0, 1.0], [1000.0, 1.0, 1.0, 1.0]],
            space: crate::transfer::ValueSpace::Data,
        };
        for mode in [Mode::Dvr, Mode::Iso, Mode::Mip] {
            settings.mode = mode;
            settings.iso.value = Some(500.0);
            let hit = pick(
                &volume,
                &settings,
                &tf,
                &camera,
                size,
                DVec2::new(32.0, 32.0),
            )
            .unwrap_or_else(|| panic!("{mode:?}: the centre ray hits the ball"));
            // The near surface lies 10 mm from the centre, towards the camera.
            let depth = (hit - centre).length();
            if mode == Mode::Mip {
                assert!(
                    depth <= 10.5,
                    "{mode:?}: a brightest point lies inside: {hit}"
                );
            } else {
                assert!(
                    (depth - 10.0).abs() <= 1.0,
                    "{mode:?}: {hit} is {depth} mm from the centre"
                );
                assert!(
                    (hit - centre).dot(camera.eye - centre) > 0.0,
                    "{mode:?}: {hit} is on the far side"
                );
            }
        }
        // A corner ray misses the ball: nothing visible.
        settings.mode = Mode::Dvr;
        assert_eq!(
            pick(&volume, &settings, &tf, &camera, size, DVec2::new(1.0, 1.0)),
            None
        );
        // Cut to the voxels behind the centre (a segmentation's shown labels): the ray passes
        // the near half and meets the cut face at the centre.
        let behind = |v: [u32; 3]| f64::from(v[1]) <= centre.y;
        let px = DVec2::new(32.0, 32.0);
        let hit =
            pick_shown(&volume, &settings, &tf, &camera, size, px, behind).expect("the cut face");
        assert!((hit.y - centre.y).abs() <= 1.0, "{hit} is not at the cut");
        assert_eq!(
            pick_shown(&volume, &settings, &tf, &camera, size, px, |_| false),
            None
        );
        // Labels drawn as surfaces over an image that shows nothing: the first surface that
        // hides half (the near one at 0.3 does not, the one behind the centre makes it 0.79).
        let clear = TransferFunction {
            opacity: vec![[0.0, 0.0], [1000.0, 0.0]],
            ..tf.clone()
        };
        // The camera looks along -y: high y is near.
        let near = |v: [u32; 3]| f64::from(v[1]) >= centre.y + 8.0;
        let surfaces = |v: [u32; 3]| {
            if near(v) {
                Some((1, 0.3))
            } else {
                (f64::from(v[1]) <= centre.y).then_some((2, 0.7))
            }
        };
        let hit = pick_surfaces(&volume, &settings, &clear, &camera, size, px, surfaces)
            .expect("the surface behind the centre");
        assert!((hit.y - centre.y).abs() <= 1.0, "{hit} is not at label 2");
        // In front of them, the ball's opaque surface is picked (10 mm from the centre).
        let far = |v: [u32; 3]| (f64::from(v[1]) <= centre.y - 12.0).then_some((3, 1.0));
        let hit = pick_surfaces(&volume, &settings, &tf, &camera, size, px, far).expect("the ball");
        assert!(((hit - centre).length() - 10.0).abs() <= 1.0, "{hit}");
    }
}
