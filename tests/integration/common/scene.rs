//! The small scene the mode and pre-integration tests render against the f64 reference.

use glam::DVec3;
use leapview::transfer::{TransferFunction, ValueSpace};
use leapview::volume::{Samples, ValueMapping, Volume};

/// A 28×24×20 volume on anisotropic spacing: a smooth ball, an off-centre dense cube and a dark
/// hole, so that MIP, MinIP, isosurfaces and X-ray all have structure.
pub fn scene() -> Volume {
    let dims = [28u32, 24, 20];
    let spacing = [1.0, 1.2, 1.5];
    let mut v = Vec::new();
    for z in 0..dims[2] {
        for y in 0..dims[1] {
            for x in 0..dims[0] {
                let p = DVec3::new(x as f64, y as f64 * 1.2, z as f64 * 1.5);
                let r = (p - DVec3::new(14.0, 14.0, 14.0)).length();
                let ball = 700.0 * (1.0 - r / 11.0).clamp(0.0, 1.0);
                let cube = if (3..9).contains(&x) && (4..10).contains(&y) && (2..7).contains(&z) {
                    950.0
                } else {
                    0.0
                };
                let hole = if (p - DVec3::new(20.0, 8.0, 20.0)).length() < 4.0 {
                    -200.0
                } else {
                    0.0
                };
                v.push((100.0 + ball + cube + hole) as f32);
            }
        }
    }
    Volume::new(
        "scene",
        dims,
        spacing,
        Samples::F32(v),
        ValueMapping::IDENTITY,
    )
    .expect("valid")
}

/// Opacity rising from 300 to 1000, colours from blue to warm white.
pub fn tf() -> TransferFunction {
    TransferFunction {
        opacity: vec![[0.0, 0.0], [300.0, 0.0], [500.0, 0.2], [1000.0, 0.7]],
        color: vec![
            [0.0, 0.3, 0.5, 1.0],
            [500.0, 1.0, 0.6, 0.3],
            [1000.0, 1.0, 1.0, 0.9],
        ],
        space: ValueSpace::Data,
    }
}
