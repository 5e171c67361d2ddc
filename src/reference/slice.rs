//! The f64 reference of a slice view: each pixel's value sampled from the volume's samples at
//! the patient point the pixel shows (trilinear with clamp-to-edge inside the volume's box, or
//! the nearest voxel), what `render::slice` is checked against.

use glam::{DVec2, DVec3};

use crate::mpr::{PatientFrame, Slab, SliceView};
use crate::volume::Volume;

use super::trilinear::sample_trilinear;

/// The value (data units) at voxel coordinates `v`: `None` outside the volume's box, or where a
/// NaN or infinite sample takes part.
fn sample_at_voxel(volume: &Volume, frame: &PatientFrame, v: DVec3, nearest: bool) -> Option<f64> {
    if nearest {
        let [i, j, k] = frame.voxel_index(v)?;
        let value = volume.value(i, j, k);
        return value.is_finite().then_some(value);
    }
    if !frame.contains(v) {
        return None;
    }
    // sample_trilinear takes index-frame millimetres (voxel centre i at i × spacing).
    sample_trilinear(volume, v * DVec3::from(volume.spacing_mm()))
}

/// Every pixel's value of `view` (row-major, row 0 at the top), computed in f64 from the pixel
/// centre's patient point; with a slab, its samples along the normal combined (NaN: no value).
pub fn slice_values(
    volume: &Volume,
    view: &SliceView,
    nearest: bool,
    slab: Option<Slab>,
) -> Vec<f64> {
    let frame = PatientFrame::of(volume);
    let normal = view.plane.normal();
    let (count, step) = slab.map_or((1, 0.0), |s| s.samples(&frame, normal));
    let [w, h] = view.size;
    let mut out = Vec::with_capacity(w as usize * h as usize);
    for y in 0..h {
        for x in 0..w {
            let p = view.to_patient(DVec2::new(f64::from(x) + 0.5, f64::from(y) + 0.5));
            let at = |offset: f64| {
                let v = frame.to_voxel(p + normal * offset);
                sample_at_voxel(volume, &frame, v, nearest).unwrap_or(f64::NAN)
            };
            out.push(match slab {
                Some(slab) if count > 1 => {
                    let middle = f64::from(count - 1) / 2.0;
                    slab.mode
                        .combine((0..count).map(|s| at((f64::from(s) - middle) * step)))
                }
                _ => at(0.0),
            });
        }
    }
    out
}
