//! Multiplanar reformatting (slice views), the pure part: where the voxels lie in the patient's
//! frame ([`frame`]), the axial, coronal, sagittal and oblique planes with the patient directions
//! at their edges ([`plane`]), and a view of a plane in pixels with its zoom and pan ([`view`]).
//! The GPU sampling is `render::slice`; the f64 reference `reference::slice`.

pub mod frame;
pub mod pick;
pub mod plane;
pub mod slab;
pub mod view;

pub use frame::PatientFrame;
pub use plane::{Plane, PlaneKind};
pub use slab::{Slab, SlabMode};
pub use view::SliceView;

/// A value through a window `[lo, hi]` (data units) as an 8-bit grey level: 0 at or below `lo`,
/// 255 at or above `hi`, linear between, rounded to nearest; 0 for a missing value (NaN). The
/// slice shader's `grey` is its twin.
pub fn grey(value: f64, [lo, hi]: [f64; 2]) -> u8 {
    if value.is_nan() {
        return 0;
    }
    let t = if hi > lo {
        ((value - lo) / (hi - lo)).clamp(0.0, 1.0)
    } else if value >= hi {
        1.0
    } else {
        0.0
    };
    (t * 255.0).round() as u8
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grey_maps_the_window_linearly_and_clamps() {
        assert_eq!(grey(-1000.0, [0.0, 100.0]), 0);
        assert_eq!(grey(0.0, [0.0, 100.0]), 0);
        assert_eq!(grey(50.0, [0.0, 100.0]), 128);
        assert_eq!(grey(100.0, [0.0, 100.0]), 255);
        assert_eq!(grey(1e9, [0.0, 100.0]), 255);
        assert_eq!(grey(f64::NAN, [0.0, 100.0]), 0);
        // A window of zero width is a threshold.
        assert_eq!(grey(5.0, [5.0, 5.0]), 255);
        assert_eq!(grey(4.9, [5.0, 5.0]), 0);
    }
}
