//! The geometry of a series by the standard (PS3.3 C.7.6.2, image plane module): slices ordered by
//! `ImagePositionPatient` projected on the normal of `ImageOrientationPatient`, never by file
//! name, `InstanceNumber` or `SliceLocation`; the slice spacing from those positions, not from
//! `SliceThickness`; `PixelSpacing` read as row spacing, then column spacing.
//!
//! A regular series is stacked as it is. A series with a gap (missing slices), spacing uneven by
//! more than [`SPACING_TOLERANCE`] of its median, or a gantry tilt (slices shifted across the
//! normal by more than [`TILT_TOLERANCE`] of a pixel) is resampled to a regular grid along the
//! normal by linear interpolation (tilted slices shifted back in their plane, bilinearly), and a
//! note says where and why. Several slices at one position (echoes, phases, repeats in one series)
//! are refused: LeapView does not guess which volume a user wants. Pure: no file is touched.

use super::header::FrameHeader;
use crate::volume::error::dicom::DicomError;

/// Slice spacing may differ from the median by this share (or [`MIN_TOLERANCE_MM`], whichever is
/// larger) before the series counts as irregular: positions are written rounded.
pub const SPACING_TOLERANCE: f64 = 0.01;
/// The smallest spacing tolerance, in mm.
pub const MIN_TOLERANCE_MM: f64 = 1e-3;
/// Slices shifted across the normal by more than this share of the smallest pixel spacing make a
/// gantry tilt.
pub const TILT_TOLERANCE: f64 = 0.01;

/// Where a series' axes come from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AxesFrom {
    /// ImageOrientationPatient: the patient frame, with positions in it.
    Plane,
    /// PatientOrientation's letters (radiographs, NM): directions, no positions.
    Letters,
    /// Nothing: the image as stored (`Orientation::AS_STORED`'s axes, which the axial view shows
    /// row 0 at the top and column 0 at the left).
    Stored,
}

/// One input frame's share of an output slice.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Source {
    /// The frame, as an index into the series' frames.
    pub frame: usize,
    /// Its weight (the weights of a slice add up to 1).
    pub weight: f64,
    /// Added to an output voxel's (column, row) to find it in the frame, in pixels.
    pub shift: [f64; 2],
}

/// How the output slices come from the frames.
#[derive(Clone, Debug, PartialEq)]
pub enum SlicePlan {
    /// Output slice k is frame `order[k]`, as stored.
    Stack(Vec<usize>),
    /// Output slice k interpolates its sources.
    Resample(Vec<Vec<Source>>),
}

/// A series' frames as a regular volume.
#[derive(Clone, Debug, PartialEq)]
pub struct Geometry {
    /// Columns, rows, slices.
    pub dims: [u32; 3],
    /// Column spacing, row spacing, slice spacing, in mm.
    pub spacing_mm: [f64; 3],
    /// The direction of increasing column, row and slice index, as unit vectors in LPS.
    pub axes_lps: [[f64; 3]; 3],
    /// Who said where the axes point.
    pub axes_from: AxesFrom,
    /// The centre of the first voxel, in mm (LPS).
    pub origin_lps: [f64; 3],
    /// Where each slice comes from.
    pub plan: SlicePlan,
    /// What a user should know: assumptions, gaps, resampling, one slice.
    pub notes: Vec<String>,
}

impl Geometry {
    /// Every `stride`-th slice of this geometry (the first included), the spacing between them
    /// `stride` times as large: a preview of a large series for its statistics.
    pub fn strided(mut self, stride: u32) -> Self {
        if stride <= 1 || self.dims[2] <= 1 {
            return self;
        }
        let step = stride as usize;
        self.plan = match self.plan {
            SlicePlan::Stack(order) => SlicePlan::Stack(order.into_iter().step_by(step).collect()),
            SlicePlan::Resample(plan) => {
                SlicePlan::Resample(plan.into_iter().step_by(step).collect())
            }
        };
        self.dims[2] = self.dims[2].div_ceil(stride);
        self.spacing_mm[2] *= f64::from(stride);
        self
    }
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

fn fail(reason: String) -> DicomError {
    DicomError::Geometry { reason }
}

fn mm(v: f64) -> String {
    crate::text::number(v)
}

/// The LPS unit vector of a PatientOrientation direction (its first letter: L, R, A, P, H
/// for head, F for foot; the letters after it tilt it, which the nearest axis ignores).
fn letter_direction(code: &str) -> Option<[f64; 3]> {
    Some(match code.trim().chars().next()? {
        'L' => [1.0, 0.0, 0.0],
        'R' => [-1.0, 0.0, 0.0],
        'P' => [0.0, 1.0, 0.0],
        'A' => [0.0, -1.0, 0.0],
        'H' => [0.0, 0.0, 1.0],
        'F' => [0.0, 0.0, -1.0],
        _ => return None,
    })
}

/// Row and column directions from PatientOrientation (`L\F`: rows run to the patient's left,
/// columns to the feet), where the two are perpendicular.
fn letters(code: &str) -> Option<([f64; 3], [f64; 3])> {
    let mut parts = code.split('\\');
    let (r, c) = (
        letter_direction(parts.next()?)?,
        letter_direction(parts.next()?)?,
    );
    (dot(r, c) == 0.0).then_some((r, c))
}

/// Row and column directions from `ImageOrientationPatient`, checked to be orthogonal unit
/// vectors; for one image or the frames of one object without it, from PatientOrientation or
/// else as stored.
fn directions(
    first: &FrameHeader,
    single: bool,
) -> Result<([f64; 3], [f64; 3], AxesFrom), DicomError> {
    let Some(o) = first.orientation else {
        return if single {
            Ok(stored_directions(first))
        } else {
            Err(fail(format!(
                "'{}' and the other slices have no ImageOrientationPatient, so their order cannot \
                 be known (LeapView orders slices by position along the normal, never by file \
                 name or InstanceNumber)",
                first.label
            )))
        };
    };
    let r = [o[0], o[1], o[2]];
    let c = [o[3], o[4], o[5]];
    let (nr, nc) = (norm(r), norm(c));
    let usable = o.iter().all(|v| v.is_finite())
        && (nr - 1.0).abs() < 0.01
        && (nc - 1.0).abs() < 0.01
        && (dot(r, c) / (nr * nc)).abs() < 0.01;
    if !usable {
        return Err(DicomError::BadField {
            file: first.label.clone(),
            field: "ImageOrientationPatient",
            value: o.map(mm).join("\\"),
            expected: "it must be two orthogonal unit vectors (row, then column direction)",
        });
    }
    Ok((r.map(|v| v / nr), c.map(|v| v / nc), AxesFrom::Plane))
}

/// The directions of an image without ImageOrientationPatient: PatientOrientation's, else as
/// stored.
fn stored_directions(first: &FrameHeader) -> ([f64; 3], [f64; 3], AxesFrom) {
    match first.patient_orientation.as_deref().and_then(letters) {
        Some((r, c)) => (r, c, AxesFrom::Letters),
        None => ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], AxesFrom::Stored),
    }
}

/// The pixel spacing (row, column), or 1 mm with a note.
fn pixel_spacing(first: &FrameHeader, notes: &mut Vec<String>) -> [f64; 2] {
    match first.pixel_spacing {
        Some(s) if s.iter().all(|v| v.is_finite() && *v > 0.0) => s,
        Some(s) => {
            notes.push(format!(
                "PixelSpacing {}\\{} is not usable: 1 mm pixels assumed",
                mm(s[0]),
                mm(s[1])
            ));
            [1.0, 1.0]
        }
        None => {
            notes.push("no PixelSpacing: 1 mm pixels assumed".into());
            [1.0, 1.0]
        }
    }
}

/// The frames of one multi-frame object that says nothing of where they lie (no plane position
/// or orientation, neither per frame nor shared): stacked in their stored order, which the object
/// defines, `SpacingBetweenSlices` (else `SliceThickness`, else 1 mm) apart, with a note that the
/// patient orientation is unknown.
fn unplaced_frames(
    frames: &[FrameHeader],
    [row_sp, col_sp]: [f64; 2],
    mut notes: Vec<String>,
) -> Geometry {
    let first = &frames[0];
    let mut order: Vec<usize> = (0..frames.len()).collect();
    order.sort_by_key(|&i| frames[i].frame);
    let (step, from) = match [first.spacing_between_slices, first.slice_thickness]
        .map(|v| v.filter(|v| v.is_finite() && *v > 0.0))
    {
        [Some(s), _] => (s, "SpacingBetweenSlices"),
        [None, Some(t)] => (t, "SliceThickness"),
        _ => (1.0, "an assumed 1 mm: no spacing in the file"),
    };
    let (r, c, axes_from) = stored_directions(first);
    notes.push(format!(
        "the file gives no plane position or orientation for its {} frames: they are stacked in \
         their stored order, {} mm apart (from {from}); {}",
        frames.len(),
        mm(step),
        match axes_from {
            AxesFrom::Letters => "the directions from PatientOrientation",
            _ => "the patient orientation is unknown: shown as stored",
        }
    ));
    Geometry {
        dims: [first.columns, first.rows, frames.len() as u32],
        spacing_mm: [col_sp, row_sp, step],
        axes_lps: [r, c, cross(r, c)],
        axes_from,
        origin_lps: [0.0; 3],
        plan: SlicePlan::Stack(order),
        notes,
    }
}

/// Assembles the frames of one series (as [`super::series::group`] made it: same size,
/// orientation and spacing) into a regular volume.
pub fn assemble(frames: &[FrameHeader]) -> Result<Geometry, DicomError> {
    let first = frames
        .first()
        .ok_or_else(|| fail("the series has no frame".into()))?;
    if first.rows == 0 || first.columns == 0 {
        return Err(DicomError::BadField {
            file: first.label.clone(),
            field: "Rows x Columns",
            value: format!("{} x {}", first.rows, first.columns),
            expected: "an image has at least one row and one column",
        });
    }
    let single = frames.len() == 1;
    let mut notes = Vec::new();
    let [row_sp, col_sp] = pixel_spacing(first, &mut notes);
    if !single
        && frames
            .iter()
            .all(|f| f.file == first.file && f.position.is_none() && f.orientation.is_none())
    {
        return Ok(unplaced_frames(frames, [row_sp, col_sp], notes));
    }
    let (r, c, axes_from) = directions(first, single)?;
    match axes_from {
        AxesFrom::Letters => notes.push(format!(
            "no ImageOrientationPatient: directions from PatientOrientation {}",
            first.patient_orientation.as_deref().unwrap_or_default()
        )),
        AxesFrom::Stored => notes.push(
            "no patient orientation: shown as stored, row 0 at the top and column 0 at the left"
                .into(),
        ),
        AxesFrom::Plane => {}
    }
    let n = cross(r, c);
    let mut positions = Vec::with_capacity(frames.len());
    for f in frames {
        match f.position {
            Some(p) if p.iter().all(|v| v.is_finite()) => positions.push(p),
            _ if single => {
                notes.push("no ImagePositionPatient: the slice placed at the origin".into());
                positions.push([0.0; 3]);
            }
            _ => {
                return Err(fail(format!(
                    "'{}' has no usable ImagePositionPatient, so its place in the series cannot be \
                     known (LeapView orders slices by position, never by file name or \
                     InstanceNumber)",
                    f.label
                )));
            }
        }
    }
    let dims_xy = [first.columns, first.rows];
    if single {
        let thickness = [first.spacing_between_slices, first.slice_thickness]
            .into_iter()
            .flatten()
            .find(|v| v.is_finite() && *v > 0.0);
        let (thickness, from) = match thickness {
            Some(t) if first.spacing_between_slices == Some(t) => (t, "SpacingBetweenSlices"),
            Some(t) => (t, "SliceThickness"),
            None => (
                row_sp.min(col_sp),
                "the pixel spacing: no thickness in the header",
            ),
        };
        notes.push(format!(
            "a single image: shown as a 2D image, facing the viewer (in 3D, a slab one voxel, \
             {} mm from {from}, thick)",
            mm(thickness)
        ));
        return Ok(Geometry {
            dims: [dims_xy[0], dims_xy[1], 1],
            spacing_mm: [col_sp, row_sp, thickness],
            axes_lps: [r, c, n],
            axes_from,
            origin_lps: positions[0],
            plan: SlicePlan::Stack(vec![0]),
            notes,
        });
    }
    let d: Vec<f64> = positions.iter().map(|p| dot(*p, n)).collect();
    if let Some(k) = d.iter().position(|v| !v.is_finite()) {
        return Err(fail(format!(
            "the position of '{}' is too far out to place ({} mm)",
            frames[k].label,
            positions[k].map(mm).join("\\")
        )));
    }
    let mut order: Vec<usize> = (0..frames.len()).collect();
    order.sort_by(|&a, &b| d[a].total_cmp(&d[b]).then(a.cmp(&b)));
    let gaps: Vec<f64> = order.windows(2).map(|w| d[w[1]] - d[w[0]]).collect();
    let mut sorted_gaps = gaps.clone();
    sorted_gaps.sort_by(f64::total_cmp);
    let median = sorted_gaps[sorted_gaps.len() / 2];
    let duplicate_tolerance = MIN_TOLERANCE_MM.max(1e-3 * median);
    if let Some(k) = gaps.iter().position(|g| *g <= duplicate_tolerance) {
        let shared = gaps.iter().filter(|g| **g <= duplicate_tolerance).count();
        return Err(fail(format!(
            "{} slices lie where another does ('{}' and '{}' at {} mm along the normal): the series \
             holds several volumes (echoes, phases or repeats), which LeapView does not separate; \
             export one of them as its own series",
            shared + 1,
            frames[order[k]].label,
            frames[order[k + 1]].label,
            mm(d[order[k]])
        )));
    }
    let tolerance = (SPACING_TOLERANCE * median).max(MIN_TOLERANCE_MM);
    let p0 = positions[order[0]];
    let (d0, d_last) = (d[order[0]], d[order[order.len() - 1]]);
    let label = |k: usize| frames[order[k]].label.as_str();
    let mut irregular = false;
    let mut uneven: Option<(usize, f64, usize)> = None; // (where, largest deviation, count)
    for (k, g) in gaps.iter().enumerate() {
        if (g - median).abs() <= tolerance {
            continue;
        }
        irregular = true;
        if *g > 1.5 * median {
            let missing = ((g / median).round() as i64 - 1).max(1);
            notes.push(format!(
                "about {missing} slice{} missing between '{}' and '{}' ({} to {} mm along the \
                 normal: a gap of {} mm where the spacing is {} mm)",
                if missing == 1 { "" } else { "s" },
                label(k),
                label(k + 1),
                mm(d[order[k]]),
                mm(d[order[k + 1]]),
                mm(*g),
                mm(median)
            ));
        } else {
            let deviation = (g - median).abs();
            uneven = Some(match uneven {
                Some((at, worst, count)) if worst >= deviation => (at, worst, count + 1),
                Some((_, _, count)) => (k, deviation, count + 1),
                None => (k, deviation, 1),
            });
        }
    }
    if let Some((k, worst, count)) = uneven {
        notes.push(format!(
            "uneven slice spacing: {count} of {} gaps differ from the median {} mm by more than \
             {} % (up to {} mm, between '{}' and '{}')",
            gaps.len(),
            mm(median),
            mm(100.0 * SPACING_TOLERANCE),
            mm(worst),
            label(k),
            label(k + 1)
        ));
    }
    let lateral = |p: [f64; 3]| {
        let delta = sub(p, p0);
        let along = dot(delta, n);
        norm(sub(delta, n.map(|v| v * along)))
    };
    let tilt_mm = order
        .iter()
        .map(|&f| lateral(positions[f]))
        .fold(0.0, f64::max);
    // A gantry tilt shifts slices across the normal by less than the series is long (tilts stay
    // below 45°); a slice shifted past the image's and the series' size together lies elsewhere.
    let reach = f64::from(dims_xy[0]) * col_sp + f64::from(dims_xy[1]) * row_sp + (d_last - d0);
    if tilt_mm.is_nan() || tilt_mm > 2.0 * reach {
        let (k, far) =
            order
                .iter()
                .map(|&f| (f, lateral(positions[f])))
                .fold((order[0], 0.0), |a, b| {
                    if b.1 > a.1 || b.1.is_nan() { b } else { a }
                });
        return Err(fail(format!(
            "'{}' lies {} mm across the slices' normal from the first slice, beyond any gantry \
             tilt (ImagePositionPatient {})",
            frames[k].label,
            mm(far),
            positions[k].map(mm).join("\\")
        )));
    }
    let tilted = tilt_mm > TILT_TOLERANCE * row_sp.min(col_sp);
    if tilted {
        let last = lateral(positions[order[order.len() - 1]]);
        let degrees = last.atan2(d_last - d0).to_degrees();
        notes.push(format!(
            "gantry tilt: the slices are shifted across their normal (by {} mm over the series, \
             about {} degrees); each slice is shifted back so the volume is true to the patient",
            mm(last),
            mm((degrees * 100.0).round() / 100.0)
        ));
    }
    let spacing_mm = |s: f64| [col_sp, row_sp, s];
    if !irregular && !tilted {
        let mean = (d_last - d0) / (frames.len() - 1) as f64;
        if !(mean.is_finite() && mean > 0.0) {
            return Err(fail(format!(
                "its slices span {} mm: no spacing can be taken from their positions",
                mm(d_last - d0)
            )));
        }
        return Ok(Geometry {
            dims: [dims_xy[0], dims_xy[1], frames.len() as u32],
            spacing_mm: spacing_mm(mean),
            axes_lps: [r, c, n],
            axes_from,
            origin_lps: p0,
            plan: SlicePlan::Stack(order),
            notes,
        });
    }
    let step = if irregular {
        median
    } else {
        (d_last - d0) / (frames.len() - 1) as f64
    };
    if !(step.is_finite() && step > 0.0 && ((d_last - d0) / step).is_finite()) {
        return Err(fail(format!(
            "its slices span {} mm at a spacing of {} mm: no regular grid fits",
            mm(d_last - d0),
            mm(step)
        )));
    }
    // Counted in f64 and bounded before any conversion: a far-out slice must not overflow it.
    let steps = ((d_last - d0) / step).round();
    let most = (4 * frames.len() + 16).min(crate::volume::limits::MAX_DIMENSION as usize);
    if steps + 1.0 > most as f64 {
        return Err(fail(format!(
            "its {} slices span {} mm at a median spacing of {} mm: {} slices on a regular grid, \
             too many to resample",
            frames.len(),
            mm(d_last - d0),
            mm(median),
            mm(steps + 1.0)
        )));
    }
    let count = steps as u64 + 1;
    let shift = |f: usize| {
        let delta = sub(p0, positions[f]);
        [dot(delta, r) / col_sp, dot(delta, c) / row_sp]
    };
    let sorted_d: Vec<f64> = order.iter().map(|&f| d[f]).collect();
    let plan = (0..count)
        .map(|k| {
            let t = (d0 + k as f64 * step).min(d_last);
            // The last sorted frame at or below t.
            let a = sorted_d.partition_point(|v| *v <= t).saturating_sub(1);
            let source = |i: usize, weight: f64| Source {
                frame: order[i],
                weight,
                shift: shift(order[i]),
            };
            if a + 1 >= order.len() {
                return vec![source(a, 1.0)];
            }
            let w = (t - sorted_d[a]) / (sorted_d[a + 1] - sorted_d[a]);
            if w <= 1e-9 {
                vec![source(a, 1.0)]
            } else if w >= 1.0 - 1e-9 {
                vec![source(a + 1, 1.0)]
            } else {
                vec![source(a, 1.0 - w), source(a + 1, w)]
            }
        })
        .collect();
    notes.push(format!(
        "resampled to a regular grid of {count} slices {} mm apart (linear interpolation between \
         the {} slices)",
        mm(step),
        frames.len()
    ));
    Ok(Geometry {
        dims: [dims_xy[0], dims_xy[1], count as u32],
        spacing_mm: spacing_mm(step),
        axes_lps: [r, c, n],
        axes_from,
        origin_lps: p0,
        plan: SlicePlan::Resample(plan),
        notes,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::volume::dicom::series::tests::frame;

    fn at(heights: &[f64]) -> Vec<FrameHeader> {
        heights
            .iter()
            .enumerate()
            .map(|(i, z)| frame("s", i, *z))
            .collect()
    }

    #[test]
    fn slices_are_ordered_by_position_along_the_normal_not_by_file() {
        let g = assemble(&at(&[4.0, 0.0, 2.0, 6.0])).expect("regular");
        assert_eq!(g.plan, SlicePlan::Stack(vec![1, 2, 0, 3]));
        assert_eq!(g.dims, [4, 3, 4]);
        // PixelSpacing is row spacing (0.5) then column spacing (0.25): x is columns.
        assert_eq!(g.spacing_mm, [0.25, 0.5, 2.0]);
        assert_eq!(g.origin_lps, [-10.0, -20.0, 0.0]);
        assert!(g.notes.is_empty());
        // Instance numbers and SliceLocation play no part: a sagittal series whose normal is
        // -x orders by -x.
        let mut frames = at(&[0.0, 0.0, 0.0]);
        for (f, x) in frames.iter_mut().zip([3.0, 1.0, 2.0]) {
            f.orientation = Some([0.0, 1.0, 0.0, 0.0, 0.0, -1.0]);
            f.position = Some([x, 0.0, 0.0]);
            f.instance_number = Some(x as i64);
        }
        // normal = (0,1,0) x (0,0,-1) = (-1, 0, 0): ascending along it is descending x.
        let g = assemble(&frames).expect("regular");
        assert_eq!(g.plan, SlicePlan::Stack(vec![0, 2, 1]));
        assert_eq!(g.axes_lps[2], [-1.0, 0.0, 0.0]);
    }

    #[test]
    fn spacing_comes_from_positions_not_thickness() {
        let mut frames = at(&[0.0, 1.25, 2.5]);
        frames
            .iter_mut()
            .for_each(|f| f.slice_thickness = Some(5.0));
        assert_eq!(assemble(&frames).expect("ok").spacing_mm[2], 1.25);
        // Rounded positions within the tolerance stay a plain stack.
        let g = assemble(&at(&[0.0, 1.2501, 2.4999, 3.75])).expect("ok");
        assert!(matches!(g.plan, SlicePlan::Stack(_)));
    }

    #[test]
    fn a_gap_is_named_and_resampled() {
        let g = assemble(&at(&[0.0, 2.0, 4.0, 8.0, 10.0])).expect("ok");
        assert_eq!(g.dims[2], 6);
        assert_eq!(g.spacing_mm[2], 2.0);
        assert!(
            g.notes[0].contains("about 1 slice missing between 'IM0002' and 'IM0003'"),
            "{:?}",
            g.notes
        );
        let SlicePlan::Resample(plan) = g.plan else {
            panic!("not resampled")
        };
        // Slice 3 (6 mm) is half IM0002 (4 mm), half IM0003 (8 mm).
        assert_eq!(plan[3].len(), 2);
        assert_eq!((plan[3][0].frame, plan[3][0].weight), (2, 0.5));
        assert_eq!((plan[3][1].frame, plan[3][1].weight), (3, 0.5));
        assert_eq!(
            plan[4],
            vec![Source {
                frame: 3,
                weight: 1.0,
                shift: [0.0, 0.0]
            }]
        );
    }

    #[test]
    fn uneven_spacing_is_named() {
        let g = assemble(&at(&[0.0, 1.0, 2.2, 3.0, 4.0])).expect("ok");
        assert!(
            g.notes[0].starts_with("uneven slice spacing: 2 of 4 gaps"),
            "{:?}",
            g.notes
        );
        assert!(matches!(g.plan, SlicePlan::Resample(_)));
    }

    #[test]
    fn a_gantry_tilt_shifts_slices_back() {
        // Each slice 1 mm higher and 0.5 mm further posterior (+y): a 26.6 degree tilt.
        let mut frames = at(&[0.0, 1.0, 2.0]);
        for (k, f) in frames.iter_mut().enumerate() {
            f.position = Some([-10.0, -20.0 + 0.5 * k as f64, k as f64]);
        }
        let g = assemble(&frames).expect("ok");
        assert!(g.notes[0].starts_with("gantry tilt"), "{:?}", g.notes);
        assert!(g.notes[0].contains("26.57 degrees"), "{:?}", g.notes);
        let SlicePlan::Resample(plan) = g.plan else {
            panic!("not resampled")
        };
        // Output voxel (x, y) of slice 2 is at y - 20 mm; frame 2's first row is at -19 mm: one
        // row spacing (0.5 mm) is 2 rows back.
        assert_eq!(plan[2][0].shift, [0.0, -2.0]);
    }

    #[test]
    fn a_far_out_slice_is_refused_not_overflowed() {
        // Found by the dicom_series fuzz target: 9e27 steps overflowed the slice count to 0.
        let e = assemble(&at(&[2.0, 1.5, -1.3476555094338099e28, 1e-300])).expect_err("too far");
        assert!(e.to_string().contains("too many to resample"), "{e}");
    }

    #[test]
    fn several_volumes_in_one_series_are_refused() {
        let e = assemble(&at(&[0.0, 1.0, 0.0, 1.0])).expect_err("two volumes");
        assert!(e.to_string().contains("several volumes"), "{e}");
    }

    #[test]
    fn a_single_slice_is_one_voxel_thick_and_says_so() {
        let mut frames = at(&[3.0]);
        frames[0].slice_thickness = Some(2.5);
        let g = assemble(&frames).expect("ok");
        assert_eq!((g.dims, g.spacing_mm), ([4, 3, 1], [0.25, 0.5, 2.5]));
        assert!(g.notes[0].contains("single image"), "{:?}", g.notes);
    }

    /// A radiograph: no ImageOrientationPatient, no position. PatientOrientation `L\F` puts
    /// rows towards the patient's left and columns towards the feet (a coronal image, head up);
    /// without it the image is as stored (DICOM's default plane, which the axial view shows
    /// row 0 at the top, column 0 at the left), not RAS (which showed it rotated 180°).
    #[test]
    fn an_image_without_orientation_takes_patient_orientation_or_is_as_stored() {
        let mut frames = at(&[0.0]);
        frames[0].orientation = None;
        frames[0].position = None;
        frames[0].patient_orientation = Some("L\\F".into());
        let g = assemble(&frames).expect("a radiograph");
        assert_eq!(g.axes_from, AxesFrom::Letters);
        assert_eq!(
            g.axes_lps,
            [[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]]
        );
        frames[0].patient_orientation = Some("A\\FR".into());
        assert_eq!(
            assemble(&frames).expect("oblique letters").axes_lps[0],
            [0.0, -1.0, 0.0]
        );
        frames[0].patient_orientation = None;
        let g = assemble(&frames).expect("as stored");
        assert_eq!(g.axes_from, AxesFrom::Stored);
        assert_eq!(g.axes_lps[..2], [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
        assert!(
            g.notes.iter().any(|n| n.contains("shown as stored")),
            "{:?}",
            g.notes
        );
        // Letters that are not two perpendicular directions are as stored.
        frames[0].patient_orientation = Some("L\\R".into());
        assert_eq!(
            assemble(&frames).expect("bad letters").axes_from,
            AxesFrom::Stored
        );
    }

    #[test]
    fn missing_positions_or_bad_orientation_are_refused() {
        let mut frames = at(&[0.0, 1.0]);
        frames[1].position = None;
        assert!(assemble(&frames).is_err());
        let mut frames = at(&[0.0, 1.0]);
        frames
            .iter_mut()
            .for_each(|f| f.orientation = Some([1.0, 0.0, 0.0, 1.0, 0.0, 0.0]));
        assert!(matches!(
            assemble(&frames),
            Err(DicomError::BadField { .. })
        ));
        frames.iter_mut().for_each(|f| f.orientation = None);
        assert!(assemble(&frames).is_err());
    }
}
