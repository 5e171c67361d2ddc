//! Builds the output slices a [`super::geometry::SlicePlan::Resample`] describes from the decoded
//! frames: linear interpolation along the normal, each frame sampled bilinearly at its in-plane
//! shift (integer shifts read pixels as they are). Outside a shifted frame, `fill`.

use super::geometry::Source;
use super::pixels::Stored;

/// One frame's value at output pixel (x, y), shifted by `shift`.
fn sample<T: Stored>(
    frame: &[T],
    size: [usize; 2],
    x: usize,
    y: usize,
    shift: [f64; 2],
    fill: f64,
) -> f64 {
    let (u, v) = (x as f64 + shift[0], y as f64 + shift[1]);
    // A shift far outside the frame (a corrupt header's gantry tilt) reads only fill; bounding it
    // first keeps the indices below from overflowing.
    let outside = |w: f64, n: usize| !(w > -1.0 && w < n as f64);
    if outside(u, size[0]) || outside(v, size[1]) {
        return fill;
    }
    let at = |i: i64, j: i64| -> f64 {
        if i < 0 || j < 0 || i >= size[0] as i64 || j >= size[1] as i64 {
            fill
        } else {
            frame[i as usize + size[0] * j as usize].to_f64()
        }
    };
    let (u0, v0) = (u.floor(), v.floor());
    let (fu, fv) = (u - u0, v - v0);
    let (i, j) = (u0 as i64, v0 as i64);
    if fu.abs() < 1e-6 && fv.abs() < 1e-6 {
        return at(i, j);
    }
    let top = at(i, j) * (1.0 - fu) + at(i + 1, j) * fu;
    let bottom = at(i, j + 1) * (1.0 - fu) + at(i + 1, j + 1) * fu;
    top * (1.0 - fv) + bottom * fv
}

/// Writes output slice `sources` into `out` (`size[0] * size[1]` samples) from `frames`, where
/// frame f is `frames[f * plane..(f + 1) * plane]`.
pub fn resample_slice<T: Stored>(
    frames: &[T],
    size: [usize; 2],
    sources: &[Source],
    fill: T,
    out: &mut [T],
) {
    let plane = size[0] * size[1];
    let fill = fill.to_f64();
    for (index, o) in out.iter_mut().enumerate().take(plane) {
        let (x, y) = (index % size[0], index / size[0]);
        let value: f64 = sources
            .iter()
            .map(|s| {
                let frame = &frames[s.frame * plane..(s.frame + 1) * plane];
                s.weight * sample(frame, size, x, y, s.shift, fill)
            })
            .sum();
        *o = T::from_f64_rounded(value);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slices_interpolate_between_frames_and_shift_within_them() {
        // Two 2 x 2 frames.
        let frames: Vec<i16> = vec![0, 10, 20, 30, 100, 110, 120, 130];
        let mut out = vec![0i16; 4];
        let half = [
            Source {
                frame: 0,
                weight: 0.5,
                shift: [0.0, 0.0],
            },
            Source {
                frame: 1,
                weight: 0.5,
                shift: [0.0, 0.0],
            },
        ];
        resample_slice(&frames, [2, 2], &half, -1, &mut out);
        assert_eq!(out, vec![50, 60, 70, 80]);
        // Frame 1 shifted one row: row 0 reads its row 1, row 1 falls outside (fill).
        let shifted = [Source {
            frame: 1,
            weight: 1.0,
            shift: [0.0, 1.0],
        }];
        resample_slice(&frames, [2, 2], &shifted, -1, &mut out);
        assert_eq!(out, vec![120, 130, -1, -1]);
        // Half a column: bilinear.
        let half_column = [Source {
            frame: 0,
            weight: 1.0,
            shift: [0.5, 0.0],
        }];
        resample_slice(&frames, [2, 2], &half_column, 0, &mut out);
        assert_eq!(out, vec![5, 5, 25, 15]);
        // Shifts no frame reaches (a huge in-plane shift, not finite): fill, not an overflow.
        for shift in [
            [1e300, 0.0],
            [-1e19, 2.0],
            [f64::NAN, 0.0],
            [0.0, f64::INFINITY],
        ] {
            let far = [Source {
                frame: 0,
                weight: 1.0,
                shift,
            }];
            resample_slice(&frames, [2, 2], &far, -7, &mut out);
            assert_eq!(out, vec![-7; 4], "{shift:?}");
        }
    }
}
