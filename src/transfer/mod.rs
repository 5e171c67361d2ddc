//! Transfer functions: piecewise-linear opacity and colour over data values, as in the
//! DESIGN.md JSON format, plus their baking into the GPU lookup table.
//!
//! Opacity is that of a slab one `d0` thick (`d0` = the smallest voxel spacing); colours are
//! linear RGB in 0..1. Both curves are clamped beyond their end points.

pub mod blank;
pub mod editor;
pub mod fit;
pub mod io;
pub mod lut;
pub mod preintegration;
pub mod presets;

use serde::{Deserialize, Serialize};

use crate::volume::ValueRange;

pub use io::TransferError;

/// Whether point values are data units or fractions of the volume's value range.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ValueSpace {
    /// Values are in data units (Hounsfield units for CT): the DESIGN.md format.
    #[default]
    Data,
    /// Values are fractions of the volume's value range: 0 = minimum, 1 = maximum. Used by presets
    /// for modalities without absolute units (MRI) and by the grey ramp.
    Normalized,
}

/// A piecewise-linear transfer function.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TransferFunction {
    /// `(value, alpha)` points sorted by value; alpha per `d0`, in 0..1.
    pub opacity: Vec<[f64; 2]>,
    /// `(value, r, g, b)` points sorted by value; components in 0..1.
    pub color: Vec<[f64; 4]>,
    /// The space point values are given in.
    #[serde(default, skip_serializing_if = "is_data_space")]
    pub space: ValueSpace,
}

fn is_data_space(space: &ValueSpace) -> bool {
    *space == ValueSpace::Data
}

impl TransferFunction {
    /// A ramp from transparent black at the volume's minimum to opaque white at its maximum.
    pub fn grey_ramp() -> Self {
        Self {
            opacity: vec![[0.0, 0.0], [1.0, 1.0]],
            color: vec![[0.0, 0.0, 0.0, 0.0], [1.0, 1.0, 1.0, 1.0]],
            space: ValueSpace::Normalized,
        }
    }

    /// Converts a point value to data units for a volume whose value range is `range`.
    pub(crate) fn to_data(&self, value: f64, range: ValueRange) -> f64 {
        match self.space {
            ValueSpace::Data => value,
            ValueSpace::Normalized => range.denormalize(value),
        }
    }

    /// Opacity per `d0` at `value` (data units).
    pub fn opacity_at(&self, value: f64, range: ValueRange) -> f64 {
        let x = self.point_coordinate(value, range);
        evaluate(&self.opacity, x, |p| p[0], |p| [p[1]])[0]
    }

    /// Linear RGB colour at `value` (data units).
    pub fn color_at(&self, value: f64, range: ValueRange) -> [f64; 3] {
        let x = self.point_coordinate(value, range);
        evaluate(&self.color, x, |p| p[0], |p| [p[1], p[2], p[3]])
    }

    /// The coordinate a data value has on the point axis (itself, or normalised).
    fn point_coordinate(&self, value: f64, range: ValueRange) -> f64 {
        match self.space {
            ValueSpace::Data => value,
            ValueSpace::Normalized => range.normalize(value),
        }
    }
}

/// Evaluates a piecewise-linear curve given by sorted points at `x`, clamped at both ends. Where
/// several points share a value (a step), the last of them holds from that value on.
fn evaluate<P, const N: usize>(
    points: &[P],
    x: f64,
    key: impl Fn(&P) -> f64,
    val: impl Fn(&P) -> [f64; N],
) -> [f64; N] {
    let Some(first) = points.first() else {
        return [0.0; N];
    };
    // Index of the first point whose value is greater than x.
    let upper = points.partition_point(|p| key(p) <= x);
    if upper == 0 {
        return val(first);
    }
    if upper == points.len() {
        return val(&points[points.len() - 1]);
    }
    let (a, b) = (&points[upper - 1], &points[upper]);
    let (xa, xb) = (key(a), key(b));
    let t = if xb > xa { (x - xa) / (xb - xa) } else { 1.0 };
    let (va, vb) = (val(a), val(b));
    std::array::from_fn(|i| va[i] + t * (vb[i] - va[i]))
}

#[cfg(test)]
mod tests {
    use super::*;

    const RANGE: ValueRange = ValueRange {
        min: -1000.0,
        max: 3000.0,
    };

    #[test]
    fn piecewise_linear_with_clamping_and_steps() {
        let tf = TransferFunction {
            opacity: vec![[0.0, 0.0], [100.0, 0.5], [100.0, 0.8], [200.0, 1.0]],
            color: vec![[0.0, 1.0, 0.0, 0.0]],
            space: ValueSpace::Data,
        };
        assert_eq!(tf.opacity_at(-50.0, RANGE), 0.0);
        assert_eq!(tf.opacity_at(50.0, RANGE), 0.25);
        assert_eq!(tf.opacity_at(100.0, RANGE), 0.8);
        assert_eq!(tf.opacity_at(150.0, RANGE), 0.9);
        assert_eq!(tf.opacity_at(1e9, RANGE), 1.0);
        assert_eq!(tf.color_at(7.0, RANGE), [1.0, 0.0, 0.0]);
    }

    #[test]
    fn normalized_space_follows_the_volume_range() {
        let tf = TransferFunction::grey_ramp();
        assert_eq!(tf.opacity_at(1000.0, RANGE), 0.5);
        assert_eq!(tf.color_at(3000.0, RANGE), [1.0, 1.0, 1.0]);
        assert_eq!(tf.to_data(0.25, RANGE), 0.0);
    }
}
