//! Thick slabs: a slice that shows the largest, smallest or mean value over a thickness of the
//! volume centred on its plane, as radiologists page through vessels (MIP) or airways (MinIP).

use glam::DVec3;

use super::frame::PatientFrame;

/// Most samples across one slab: a bound on a pixel's work.
pub const MAX_SLAB_SAMPLES: u32 = 2048;

/// How a slab's samples become one value (`leapview slice --mode`).
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize, clap::ValueEnum,
)]
pub enum SlabMode {
    /// The largest value (maximum intensity projection).
    Mip,
    /// The smallest value (minimum intensity projection).
    #[value(name = "minip")]
    MinIp,
    /// The mean.
    Mean,
}

impl SlabMode {
    /// Its name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Self::Mip => "mip",
            Self::MinIp => "minip",
            Self::Mean => "mean",
        }
    }

    /// Combines `values` (those with no value, NaN, left out); NaN when none has one.
    pub fn combine(self, values: impl IntoIterator<Item = f64>) -> f64 {
        let (mut n, mut sum, mut lo, mut hi) = (0u32, 0.0, f64::INFINITY, f64::NEG_INFINITY);
        for v in values.into_iter().filter(|v| !v.is_nan()) {
            n += 1;
            sum += v;
            lo = lo.min(v);
            hi = hi.max(v);
        }
        if n == 0 {
            return f64::NAN;
        }
        match self {
            Self::Mip => hi,
            Self::MinIp => lo,
            Self::Mean => sum / f64::from(n),
        }
    }
}

/// A thick slab: its full thickness (mm) and how its samples combine.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Slab {
    /// Thickness in millimetres, centred on the plane.
    pub thickness_mm: f64,
    /// How samples combine.
    pub mode: SlabMode,
}

impl Slab {
    /// Where its samples lie: `count` of them, `step` mm apart along `normal`, at offsets
    /// `(s − (count − 1) / 2) × step` from the plane. The step is half the spacing of the
    /// volume's axis closest to the normal (no voxel is stepped over); the span is at most the
    /// thickness.
    pub fn samples(&self, frame: &PatientFrame, normal: DVec3) -> (u32, f64) {
        let step = frame.step_along(normal) / 2.0;
        if !(self.thickness_mm.is_finite() && self.thickness_mm > 0.0 && step > 0.0) {
            return (1, step);
        }
        let count = (self.thickness_mm / step).floor() + 1.0;
        (count.min(f64::from(MAX_SLAB_SAMPLES)) as u32, step)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::volume::Orientation;

    #[test]
    fn slab_samples_span_the_thickness_at_half_the_spacing_along_the_normal() {
        let f = PatientFrame::new(
            Orientation::parse_code("LPS").expect("code"),
            [0.5, 0.5, 2.0],
            [8, 8, 8],
            DVec3::ZERO,
            false,
        );
        let slab = Slab {
            thickness_mm: 10.0,
            mode: SlabMode::Mip,
        };
        assert_eq!(slab.samples(&f, DVec3::Z), (11, 1.0));
        assert_eq!(slab.samples(&f, DVec3::X), (41, 0.25));
        let thin = Slab {
            thickness_mm: 0.0,
            ..slab
        };
        assert_eq!(thin.samples(&f, DVec3::Z).0, 1);
    }

    #[test]
    fn modes_combine_what_has_a_value() {
        let v = [3.0, f64::NAN, -1.0, 7.0];
        assert_eq!(SlabMode::Mip.combine(v), 7.0);
        assert_eq!(SlabMode::MinIp.combine(v), -1.0);
        assert_eq!(SlabMode::Mean.combine(v), 3.0);
        assert!(SlabMode::Mean.combine([f64::NAN]).is_nan());
    }
}
