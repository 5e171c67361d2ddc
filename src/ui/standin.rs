//! TEMPORARY stand-ins for `volume::synthetic::{shepp_logan, vessel_tree}`, which are being
//! written on branch `synth`. Same signatures, much simpler content: a skull-like ellipsoid shell
//! and a few tubes, in Hounsfield units. Delete this file once `synth` has landed on `main` and
//! been merged into this branch.

use crate::volume::{Samples, ValueMapping, Volume, VolumeError};

/// Air, soft tissue, bone and contrast-filled vessels, in HU.
const AIR: i16 = -1000;
const BRAIN: i16 = 30;
const FLUID: i16 = 5;
const BONE: i16 = 1000;
const VESSEL: i16 = 350;

/// Normalised coordinates in [-1, 1] of voxel `i` of `n`.
fn coord(i: u32, n: u32) -> f64 {
    2.0 * (f64::from(i) + 0.5) / f64::from(n) - 1.0
}

fn fill(n: u32, value: impl Fn(f64, f64, f64) -> i16) -> Vec<i16> {
    let mut out = Vec::with_capacity((n as usize).pow(3));
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                out.push(value(coord(i, n), coord(j, n), coord(k, n)));
            }
        }
    }
    out
}

/// Stand-in for the Shepp–Logan head phantom: an ellipsoidal skull 8 % thick around brain, with
/// two fluid-filled ventricles.
pub fn shepp_logan(n: u32) -> Result<Volume, VolumeError> {
    let ellipsoid = |x: f64, y: f64, z: f64, c: [f64; 3], r: [f64; 3]| {
        ((x - c[0]) / r[0]).powi(2) + ((y - c[1]) / r[1]).powi(2) + ((z - c[2]) / r[2]).powi(2)
    };
    let samples = fill(n, |x, y, z| {
        let head = ellipsoid(x, y, z, [0.0; 3], [0.69, 0.92, 0.81]);
        if head > 1.0 {
            AIR
        } else if head > 0.92 * 0.92 {
            BONE
        } else if ellipsoid(x, y, z, [0.22, 0.0, 0.0], [0.11, 0.31, 0.25]) < 1.0
            || ellipsoid(x, y, z, [-0.22, 0.0, 0.0], [0.16, 0.41, 0.32]) < 1.0
        {
            FLUID
        } else {
            BRAIN
        }
    });
    Volume::new(
        "Shepp–Logan phantom (stand-in)",
        [n; 3],
        [1.0; 3],
        Samples::I16(samples),
        ValueMapping::IDENTITY,
    )
}

/// Stand-in for the vessel tree: a trunk along z with four branches, radius 3 % of the volume.
pub fn vessel_tree(n: u32, seed: u64) -> Result<Volume, VolumeError> {
    // The seed turns the branches about the trunk, so different seeds give different trees.
    let turn = (seed % 360) as f64 * std::f64::consts::PI / 180.0;
    let mut segments = vec![([0.0, 0.0, -0.9], [0.0, 0.0, 0.3])];
    for b in 0..4 {
        let a = turn + f64::from(b) * std::f64::consts::FRAC_PI_2;
        let z = -0.4 + 0.25 * f64::from(b);
        segments.push(([0.0, 0.0, z], [0.7 * a.cos(), 0.7 * a.sin(), z + 0.5]));
    }
    let samples = fill(n, |x, y, z| {
        let inside = segments.iter().any(|(a, b)| {
            let ab = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
            let ap = [x - a[0], y - a[1], z - a[2]];
            let len2 = ab.iter().map(|c| c * c).sum::<f64>();
            let t = (ap.iter().zip(&ab).map(|(p, q)| p * q).sum::<f64>() / len2).clamp(0.0, 1.0);
            let d2: f64 = (0..3).map(|i| (ap[i] - t * ab[i]).powi(2)).sum();
            d2 < 0.03 * 0.03
        });
        if inside { VESSEL } else { AIR }
    });
    Volume::new(
        format!("Vessel tree (stand-in, seed {seed})"),
        [n; 3],
        [1.0; 3],
        Samples::I16(samples),
        ValueMapping::IDENTITY,
    )
}
