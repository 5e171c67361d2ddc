//! Window/level by right-drag, as 3D Slicer does it: a pure function of the drag, the mode and
//! the data. MIP, MinIP and X-ray move their grey window; DVR and isosurfaces shift and scale the
//! transfer function's points instead (one undo step per drag, the editor's business).

use crate::settings::Mode;
use crate::transfer::{TransferFunction, ValueSpace};
use crate::volume::ValueRange;

/// Window/level speed: points of drag per full value range.
pub const WINDOW_POINTS_PER_RANGE: f64 = 500.0;

/// The narrowest window or function a drag leaves, as a share of the value range.
pub const NARROWEST_SHARE: f64 = 1.0 / 1000.0;

/// What a right-drag changes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum WindowLevelEdit {
    /// The grey window of MIP, MinIP and X-ray becomes this (data units).
    Window([f64; 2]),
    /// The transfer function's point coordinates are mapped through this.
    Transfer(AffineMap),
}

/// `x ↦ centre + shift + (x − centre) · scale`: the transfer function's points scaled about
/// `centre` and shifted.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AffineMap {
    /// Fixed point of the scaling.
    pub centre: f64,
    /// Shift after scaling.
    pub shift: f64,
    /// Scale factor.
    pub scale: f64,
}

impl AffineMap {
    /// The image of `x`.
    pub fn apply(&self, x: f64) -> f64 {
        self.centre + self.shift + (x - self.centre) * self.scale
    }
}

/// What a right-drag of `delta` points does in `mode`: to `window` (data units; `None` = the
/// whole range) or to `tf`. `None` when the volume is constant or the function has no points.
pub fn drag(
    mode: Mode,
    window: Option<[f64; 2]>,
    tf: &TransferFunction,
    range: ValueRange,
    delta: [f32; 2],
) -> Option<WindowLevelEdit> {
    if range.width().is_nan() || range.width() <= 0.0 {
        return None;
    }
    match mode {
        Mode::Mip | Mode::MinIp | Mode::Xray | Mode::XrayAttenuation => {
            let window = window.unwrap_or([range.min, range.max]);
            Some(WindowLevelEdit::Window(window_drag(window, range, delta)))
        }
        Mode::Dvr | Mode::Iso => {
            let (first, last) = (tf.opacity.first()?, tf.opacity.last()?);
            // One data unit in the function's own coordinates.
            let unit = match tf.space {
                ValueSpace::Data => 1.0,
                ValueSpace::Normalized => 1.0 / range.width(),
            };
            let centre = 0.5 * (first[0] + last[0]);
            let width = (last[0] - first[0]).max(unit * range.width() * NARROWEST_SHARE);
            Some(WindowLevelEdit::Transfer(transfer_drag(
                centre, width, range, unit, delta,
            )))
        }
    }
}

/// The window after a drag of `delta` points: horizontal motion widens (right) or narrows the
/// window, vertical motion moves its centre (down = higher level, so the image darkens). The
/// width stays at least [`NARROWEST_SHARE`] of the range.
pub(crate) fn window_drag(window: [f64; 2], range: ValueRange, delta: [f32; 2]) -> [f64; 2] {
    let k = range.width() / WINDOW_POINTS_PER_RANGE;
    let width =
        (window[1] - window[0] + f64::from(delta[0]) * k).max(range.width() * NARROWEST_SHARE);
    let level = 0.5 * (window[0] + window[1]) + f64::from(delta[1]) * k;
    [level - 0.5 * width, level + 0.5 * width]
}

/// The same drag applied to a transfer function whose opacity points span `width` around
/// `centre` (in the function's coordinates, `unit` of them per data unit): the scale follows the
/// width's change, the shift the level's.
fn transfer_drag(
    centre: f64,
    width: f64,
    range: ValueRange,
    unit: f64,
    delta: [f32; 2],
) -> AffineMap {
    let [lo, hi] = window_drag([-0.5 * width / unit, 0.5 * width / unit], range, delta);
    AffineMap {
        centre,
        shift: 0.5 * (lo + hi) * unit,
        scale: (hi - lo) * unit / width,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ct() -> ValueRange {
        ValueRange {
            min: -1000.0,
            max: 3000.0,
        }
    }

    #[test]
    fn right_drag_widens_with_x_and_moves_the_level_with_y() {
        let range = ct();
        let w = window_drag([0.0, 400.0], range, [50.0, 0.0]);
        // 50 points = 50/500 of 4000 = 400 wider, same centre.
        assert_eq!(w, [-200.0, 600.0]);
        let w = window_drag([0.0, 400.0], range, [0.0, 25.0]);
        assert_eq!(w, [200.0, 600.0]);
        let w = window_drag([0.0, 400.0], range, [-5000.0, 0.0]);
        assert!(
            (w[1] - w[0] - 4.0).abs() < 1e-9,
            "the width stops at a thousandth"
        );
        // The TF map: a rightward drag scales points about the centre, a downward one shifts.
        let f = transfer_drag(100.0, 400.0, range, 1.0, [50.0, 25.0]);
        assert!((f.apply(100.0) - 300.0).abs() < 1e-9);
        assert!((f.apply(300.0) - (300.0 + 200.0 * 2.0)).abs() < 1e-9);
    }

    #[test]
    fn the_mode_decides_what_a_drag_moves() {
        let tf = TransferFunction {
            opacity: vec![[0.0, 0.0], [400.0, 1.0]],
            space: ValueSpace::Data,
            ..TransferFunction::grey_ramp()
        };
        let range = ct();
        for mode in [Mode::Mip, Mode::MinIp, Mode::Xray, Mode::XrayAttenuation] {
            // From the whole range: wider by 50/500 of it.
            assert_eq!(
                drag(mode, None, &tf, range, [50.0, 0.0]),
                Some(WindowLevelEdit::Window([-1200.0, 3200.0])),
                "{mode:?}"
            );
        }
        for mode in [Mode::Dvr, Mode::Iso] {
            let Some(WindowLevelEdit::Transfer(f)) = drag(mode, None, &tf, range, [0.0, 25.0])
            else {
                panic!("{mode:?} edits the function");
            };
            // 25 points down = 200 data units up, about the points' centre (200).
            assert!((f.apply(200.0) - 400.0).abs() < 1e-9, "{mode:?}");
            assert!((f.scale - 1.0).abs() < 1e-12, "{mode:?}");
        }
        let constant = ValueRange { min: 5.0, max: 5.0 };
        assert_eq!(drag(Mode::Mip, None, &tf, constant, [1.0, 1.0]), None);
    }

    #[test]
    fn a_normalised_function_moves_by_the_same_data_units() {
        let range = ct();
        let tf = TransferFunction {
            opacity: vec![[0.25, 0.0], [0.75, 1.0]],
            space: ValueSpace::Normalized,
            ..TransferFunction::grey_ramp()
        };
        let Some(WindowLevelEdit::Transfer(f)) = drag(Mode::Dvr, None, &tf, range, [0.0, 25.0])
        else {
            panic!("DVR edits the function");
        };
        // 200 data units of a 4000-unit range are 0.05 in normalised coordinates.
        assert!((f.apply(0.5) - 0.55).abs() < 1e-12);
    }
}
