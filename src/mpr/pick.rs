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
    let bounds = Aabb::of_volume(volume.dims(), volume.spacing_mm());
    let (origin, dir) = camera.pixel_ray(px.x - 0.5, px.y - 0.5, size, &bounds);
    let (t0, t1) = bounds.intersect(origin, dir)?;
    let t0 = t0.max(0.0);
    let spacing = DVec3::from(volume.spacing_mm());
    let d0 = volume.min_spacing_mm();
    let step = d0 / 2.0;
    let range = volume.value_range()?;
    let dims = volume.dims();
    let value_at = |p: DVec3| -> Option<f64> {
        let v = p / spacing;
        let i: [u32; 3] = std::array::from_fn(|a| {
            (v[a] + 0.5).floor().clamp(0.0, f64::from(dims[a]) - 1.0) as u32
        });
        Some(volume.value(i[0], i[1], i[2])).filter(|x| x.is_finite() && shown(i))
    };
    let samples = ((t1 - t0) / step).ceil().max(0.0) as usize;
    let points = (0..samples).map(|k| origin + dir * (t0 + (k as f64 + 0.5) * step));
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
        Mode::Mip | Mode::Xray | Mode::XrayAttenuation => extreme(points, value_at, |a, b| a > b),
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
    }
}
