//! The scene LeapView is compared with its peers on (VTK, vispy, pygfx; docs/benchmarks/README.md,
//! "The peers"): an 8-bit cube, mostly zero, holding three Gaussian blobs, a hollow spherical
//! shell and a thin rod — smooth fog, a hard thin surface and a sub-block feature, the three things
//! a ray caster meets in practice.

use super::{coverage, cube_len};
use crate::parallel::fill_slabs;
use crate::volume::{error::VolumeError, model::Volume, samples::Samples, samples::ValueMapping};

/// Blobs: centre (fractions of the edge), standard deviation (fraction of the edge), peak value.
const BLOBS: [([f64; 3], f64, f64); 3] = [
    ([0.32, 0.36, 0.40], 0.085, 200.0),
    ([0.66, 0.60, 0.52], 0.085, 170.0),
    ([0.50, 0.30, 0.70], 0.070, 230.0),
];
/// Blob values below this are cut to zero (the blobs end at about 2.5 standard deviations).
const BLOB_CUT: f64 = 8.0;
/// The shell: centre, outer radius and thickness (fractions of the edge), value.
const SHELL: ([f64; 3], f64, f64, f64) = ([0.5, 0.5, 0.5], 0.40, 0.02, 150.0);
/// The rod along z: its axis at (x, y) (fractions), radius in voxels, value.
const ROD: ([f64; 2], f64, f64) = ([0.72, 0.26], 1.5, 250.0);

/// The scene at `n³` voxels of 1 mm (uint8; about 84 % of the voxels are zero).
pub fn peer_scene(n: u32) -> Result<Volume, VolumeError> {
    let len = cube_len(n, crate::volume::samples::ScalarType::U8)?;
    let nu = n as usize;
    let edge = f64::from(n);
    let mut samples = vec![0u8; len];
    fill_slabs(&mut samples, nu * nu, |z_first, slab| {
        for (i, out) in slab.iter_mut().enumerate() {
            let voxel = [i % nu, (i / nu) % nu, z_first + i / (nu * nu)];
            let p = voxel.map(|c| (c as f64 + 0.5) / edge);
            *out = value_at(p, edge).round().clamp(0.0, 255.0) as u8;
        }
    });
    Volume::new(
        format!("peer-scene-{n}"),
        [n; 3],
        [1.0; 3],
        Samples::U8(samples),
        ValueMapping::IDENTITY,
    )
}

/// The scene's value at `p` (fractions of the edge) in a cube of `edge` voxels: the largest of
/// its parts there.
fn value_at(p: [f64; 3], edge: f64) -> f64 {
    let dist = |c: [f64; 3]| {
        ((p[0] - c[0]).powi(2) + (p[1] - c[1]).powi(2) + (p[2] - c[2]).powi(2)).sqrt()
    };
    let mut v: f64 = 0.0;
    for (centre, sigma, peak) in BLOBS {
        let b = peak * (-0.5 * (dist(centre) / sigma).powi(2)).exp();
        if b >= BLOB_CUT {
            v = v.max(b);
        }
    }
    let voxel = 1.0 / edge;
    let (centre, radius, thickness, value) = SHELL;
    // Signed distance to the shell's wall: negative inside the wall.
    let wall = (dist(centre) - (radius - 0.5 * thickness)).abs() - 0.5 * thickness;
    v = v.max(value * coverage(wall, voxel));
    let ([x, y], rod_radius, rod_value) = ROD;
    let to_axis = ((p[0] - x).powi(2) + (p[1] - y).powi(2)).sqrt();
    v.max(rod_value * coverage(to_axis - rod_radius * voxel, voxel))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mostly_zero_with_every_part_present() {
        let v = peer_scene(64).expect("scene");
        let Samples::U8(s) = v.samples().expect("in memory") else {
            panic!("uint8")
        };
        let zero = s.iter().filter(|&&x| x == 0).count() as f64 / s.len() as f64;
        // The parts' volumes: blobs to 2.5 σ ≈ 0.12 of the cube, the shell ≈ 0.04, the rod less.
        assert!((0.78..0.90).contains(&zero), "zero fraction {zero}");
        let at = |x: usize, y: usize, z: usize| s[x + 64 * (y + 64 * z)];
        // A blob centre, the shell's wall on the x axis, the rod's axis.
        assert!(at(20, 23, 25) > 150);
        assert!(at(56, 32, 32) > 60, "{}", at(56, 32, 32));
        assert_eq!(at(46, 16, 5), 250);
    }
}
