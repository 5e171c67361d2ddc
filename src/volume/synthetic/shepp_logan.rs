//! The 3D Shepp–Logan head phantom in Hounsfield units: LeapView's default volume.
//!
//! Geometry: the ten ellipsoids of the "modified" 3D Shepp–Logan phantom as tabulated in
//! M. Schabel's `phantom3d.m` (MATLAB Central File Exchange 9416), whose intensities come from
//! P. Toft, *The Radon Transform* (1996), pp. 199–200, extending Shepp & Logan (1974) to 3D
//! after Kak & Slaney, *Principles of Computerized Tomographic Imaging* (1988). Centres and
//! semi-axes are fractions of the half field of view; angles are `phantom3d`'s Euler angles
//! (φ about z, θ about x, ψ about z). Unlike `phantom3d`, which subtracts the centre after
//! rotating, each ellipsoid is rotated about its own centre (as MATLAB's 2D `phantom` does), so the
//! two tilted ventricles sit exactly at x = ±0.22.
//!
//! Intensities: instead of the table's unitless 1, −0.8, −0.2, 0.1 the ellipsoids add the
//! Hounsfield-unit contributions of [`CONTRIBUTIONS_HU`] to air (−1000 HU), so the regions read:
//!
//! | region                                     | ellipsoids       | HU                 |
//! |--------------------------------------------|------------------|--------------------|
//! | air outside the head                       | –                | −1000              |
//! | skull (the shell between 1 and 2)          | 1                | +1000              |
//! | brain                                      | 1, 2             | +35                |
//! | ventricles (CSF, hypodense)                | 1, 2, 3 or 4     | +5                 |
//! | large central mass                         | 1, 2, 5          | +45                |
//! | two hyperdense lesions (like fresh blood)  | 1, 2, 6 or 7     | +60                |
//! | small posterior features                   | 1, 2, 8 / 9 / 10 | +80 / +50 / +15    |
//!
//! Where ellipsoids overlap, contributions add, as in the original phantom.
//!
//! Axes: the table's x is the patient's left–right axis, its y the "up" of the classic 2D
//! image (anterior), its z superior. LeapView's volumes follow DICOM (y posterior, see
//! `camera.rs`), so world y is the table's −y: looking along +z with anterior up shows the
//! classic Shepp–Logan picture. The grid covers [−1, 1]³ of table coordinates with voxel centres
//! at `(i + ½)·2/n − 1` over a [`FIELD_OF_VIEW_MM`] field of view, so the head measures
//! 159 × 212 × 186 mm (left–right × front–back × height) at every `n`.
//!
//! Realism touches, as a scanner sees a head: every edge is the voxel's partial volume of the
//! ellipsoid seen through a Gaussian point-spread function of [`PSF_SIGMA_MM`] (2.4 mm full width
//! at half maximum, a soft-tissue head kernel at 1 mm slices), so that surfaces span two to three
//! voxels instead of one and gradient lighting does not terrace them into rings; and mild CT noise of
//! [`NOISE_SIGMA_HU`] on tissue, none in air, so the background stays exactly −1000 HU.

use glam::DVec3;

use super::rng::{UNIT_NOISE_BOUND, unit_noise};
use super::{coverage, cube_len};
use crate::parallel::fill_slabs;
use crate::volume::{error::VolumeError, model::Volume, samples::Samples, samples::ValueMapping};

/// Width of the field of view along every axis, millimetres (256 voxels: 0.898 mm each).
pub const FIELD_OF_VIEW_MM: f64 = 230.0;
/// Air, outside the head.
pub const AIR_HU: f64 = -1000.0;
/// Cortical bone of the skull.
pub const BONE_HU: f64 = 1000.0;
/// Brain parenchyma.
pub const BRAIN_HU: f64 = 35.0;
/// Cerebrospinal fluid in the ventricles.
pub const CSF_HU: f64 = 5.0;
/// Standard deviation of the scanner's point-spread function, millimetres.
pub const PSF_SIGMA_MM: f64 = 1.0;
/// How many standard deviations of the point-spread function an edge reaches; beyond it the
/// coverage is exactly 0 or 1 (the Gaussian tail there is below 10⁻⁸).
const PSF_REACH: f64 = 6.0;
/// The display window a scanner would store with it (DICOM `WindowCenter` 45, `WindowWidth` 90):
/// every soft-tissue region apart, from the ventricles' 5 HU to the brightest lesion's 80 HU, as
/// the classic Shepp–Logan picture shows them.
pub const DISPLAY_WINDOW_HU: [f64; 2] = [0.0, 90.0];
/// Standard deviation of the noise on tissue; 3 HU is a low-noise head CT.
pub const NOISE_SIGMA_HU: f64 = 3.0;
/// The largest deviation the noise can cause (it is bounded, see [`super::rng::unit_noise`]).
pub const NOISE_BOUND_HU: f64 = NOISE_SIGMA_HU * UNIT_NOISE_BOUND;

/// Additive contribution of each ellipsoid, HU, in table order (see the module documentation).
pub const CONTRIBUTIONS_HU: [f64; 10] = [
    BONE_HU - AIR_HU,   // 1: head, air → bone
    BRAIN_HU - BONE_HU, // 2: brain, bone → brain
    CSF_HU - BRAIN_HU,  // 3: right ventricle
    CSF_HU - BRAIN_HU,  // 4: left ventricle
    10.0,               // 5: central mass, 45 HU
    25.0,               // 6: hyperdense lesion, 60 HU
    25.0,               // 7: hyperdense lesion, 60 HU
    45.0,               // 8: 80 HU
    15.0,               // 9: 50 HU
    -20.0,              // 10: hypodense, 15 HU
];

/// Seed of the noise stream (the phantom takes no seed: it is always the same picture).
const NOISE_SEED: u64 = 0x5EE9_1065;

/// One row of the table: semi-axes (a, b, c), centre (x0, y0, z0), Euler angles (φ, θ, ψ) in
/// degrees, all in table coordinates.
const TABLE: [([f64; 3], [f64; 3], [f64; 3]); 10] = [
    ([0.6900, 0.920, 0.810], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]),
    ([0.6624, 0.874, 0.780], [0.0, -0.0184, 0.0], [0.0, 0.0, 0.0]),
    ([0.1100, 0.310, 0.220], [0.22, 0.0, 0.0], [-18.0, 0.0, 10.0]),
    ([0.1600, 0.410, 0.280], [-0.22, 0.0, 0.0], [18.0, 0.0, 10.0]),
    ([0.2100, 0.250, 0.410], [0.0, 0.35, -0.15], [0.0, 0.0, 0.0]),
    ([0.0460, 0.046, 0.050], [0.0, 0.1, 0.25], [0.0, 0.0, 0.0]),
    ([0.0460, 0.046, 0.050], [0.0, -0.1, 0.25], [0.0, 0.0, 0.0]),
    (
        [0.0460, 0.023, 0.050],
        [-0.08, -0.605, 0.0],
        [0.0, 0.0, 0.0],
    ),
    ([0.0230, 0.023, 0.020], [0.0, -0.606, 0.0], [0.0, 0.0, 0.0]),
    ([0.0230, 0.046, 0.020], [0.06, -0.605, 0.0], [0.0, 0.0, 0.0]),
];

/// An ellipsoid ready for rasterising at one voxel size (normalised units, world frame).
struct Prepared {
    /// Rows map an offset from the centre to unit-sphere coordinates (rotation, then 1/semi-axis).
    rows: [DVec3; 3],
    /// Centre in world normalised coordinates.
    centre: DVec3,
    /// Half-extent of the axis-aligned box outside which the coverage is zero.
    half_extent: DVec3,
    /// Below this `q = |rows·(p − c)|²` the coverage is 1, above `q_empty` it is 0.
    q_full: f64,
    /// See `q_full`.
    q_empty: f64,
    /// Additive contribution, HU.
    hu: f64,
    /// Width of the edge profile: the voxel's box and the point-spread function together, as one
    /// Gaussian's standard deviation (normalised units); 0 for the bare partial-volume ramp.
    edge_sigma: f64,
}

impl Prepared {
    /// The ellipsoid `index` at voxel size `voxel` seen through a point-spread function of
    /// standard deviation `psf_sigma` (both normalised units).
    fn new(index: usize, voxel: f64, psf_sigma: f64) -> Self {
        let (semi, centre, euler) = TABLE[index];
        let [phi, theta, psi] = euler.map(f64::to_radians);
        let (sp, cp, st, ct, ss, cs) = (
            phi.sin(),
            phi.cos(),
            theta.sin(),
            theta.cos(),
            psi.sin(),
            psi.cos(),
        );
        // phantom3d's rotation, table frame; local = alpha · (t − c).
        let alpha = [
            DVec3::new(cs * cp - ct * sp * ss, cs * sp + ct * cp * ss, ss * st),
            DVec3::new(-ss * cp - ct * sp * cs, -ss * sp + ct * cp * cs, cs * st),
            DVec3::new(st * sp, -st * cp, ct),
        ];
        // World y is table −y: flipping the y component of every row maps world offsets.
        let flip = DVec3::new(1.0, -1.0, 1.0);
        let rows = std::array::from_fn(|i| alpha[i] * flip / semi[i]);
        // The approximate distance is at least (√q − 1)·min semi-axis (see `coverage_at`), so
        // coverage is exactly 1 or 0 once √q is that far below or above 1.
        // A box of one voxel has the variance voxel²/12 of a Gaussian; with the PSF's, one
        // Gaussian of the summed variance describes the edge to within a few HU.
        let edge_sigma = if psf_sigma > 0.0 {
            (psf_sigma * psf_sigma + voxel * voxel / 12.0).sqrt()
        } else {
            0.0
        };
        let reach = (0.5 * voxel).max(PSF_REACH * edge_sigma);
        let margin = reach / semi.iter().copied().fold(f64::INFINITY, f64::min);
        let grow = 1.0 + margin;
        let half_extent = DVec3::from_array(std::array::from_fn(|axis| {
            (0..3)
                .map(|j| (alpha[j][axis] * semi[j]).powi(2))
                .sum::<f64>()
                .sqrt()
                * grow
        }));
        Self {
            rows,
            centre: DVec3::new(centre[0], -centre[1], centre[2]),
            half_extent,
            q_full: (1.0 - margin).max(0.0).powi(2),
            q_empty: grow * grow,
            hu: 0.0,
            edge_sigma,
        }
    }

    /// Fraction of the voxel centred at `p` inside the ellipsoid.
    fn coverage_at(&self, p: DVec3, voxel: f64) -> f64 {
        let offset = p - self.centre;
        let l = DVec3::new(
            self.rows[0].dot(offset),
            self.rows[1].dot(offset),
            self.rows[2].dot(offset),
        );
        let q = l.length_squared();
        if q >= self.q_empty {
            return 0.0;
        }
        if q <= self.q_full {
            return 1.0;
        }
        // Signed distance ≈ (√q − 1) / |∇√q|, exact for spheres; ∇√q = rowsᵀ·l / √q.
        let s = q.sqrt();
        let grad = (self.rows[0] * l.x + self.rows[1] * l.y + self.rows[2] * l.z).length() / s;
        let d = (s - 1.0) / grad;
        if self.edge_sigma > 0.0 {
            blurred_coverage(d, self.edge_sigma)
        } else {
            coverage(d, voxel)
        }
    }
}

/// Share of a voxel at signed distance `d` from a surface (negative inside) that a Gaussian edge
/// profile of standard deviation `sigma` gives: `½ erfc(d / (σ √2))`.
fn blurred_coverage(d: f64, sigma: f64) -> f64 {
    let x = d / (sigma * std::f64::consts::SQRT_2);
    if x.abs() * std::f64::consts::SQRT_2 >= PSF_REACH {
        return if x > 0.0 { 0.0 } else { 1.0 };
    }
    0.5 * erfc(x)
}

/// The complementary error function, to 1.2·10⁻⁷ everywhere (Numerical Recipes' `erfcc`,
/// a Chebyshev fit).
fn erfc(x: f64) -> f64 {
    let z = x.abs();
    let t = 1.0 / (1.0 + 0.5 * z);
    let poly = -z * z - 1.265_512_23
        + t * (1.000_023_68
            + t * (0.374_091_96
                + t * (0.096_784_18
                    + t * (-0.186_288_06
                        + t * (0.278_868_07
                            + t * (-1.135_203_98
                                + t * (1.488_515_87 + t * (-0.822_152_23 + t * 0.170_872_77))))))));
    let r = t * poly.exp();
    if x >= 0.0 { r } else { 2.0 - r }
}

/// The 3D Shepp–Logan head phantom on an `n³` grid, in Hounsfield units (`i16`, identity
/// mapping), with spacing [`FIELD_OF_VIEW_MM`]` / n` on every axis (0.898 mm at `n = 256`).
///
/// Fails with [`VolumeError::ZeroDimension`] when `n` is zero.
pub fn shepp_logan(n: u32) -> Result<Volume, VolumeError> {
    generate(n, NOISE_SIGMA_HU)
}

/// The phantom with noise of standard deviation `noise_sigma_hu` on tissue (0 for none).
pub(crate) fn generate(n: u32, noise_sigma_hu: f64) -> Result<Volume, VolumeError> {
    let len = cube_len(n, crate::volume::samples::ScalarType::I16)?;
    let nu = n as usize;
    let voxel = 2.0 / n as f64;
    let psf_sigma = PSF_SIGMA_MM * 2.0 / FIELD_OF_VIEW_MM;
    let ellipsoids: Vec<Prepared> = (0..TABLE.len())
        .map(|i| Prepared {
            hu: CONTRIBUTIONS_HU[i],
            ..Prepared::new(i, voxel, psf_sigma)
        })
        .collect();
    let centre_of = |i: usize| (i as f64 + 0.5) * voxel - 1.0;
    let mut samples = vec![0i16; len];
    fill_slabs(&mut samples, nu * nu, |z_first, slab| {
        let mut hu = vec![0.0f64; nu];
        let mut head = vec![0.0f64; nu];
        for (r, row) in slab.chunks_mut(nu).enumerate() {
            let (y, z) = (r % nu, z_first + r / nu);
            let (py, pz) = (centre_of(y), centre_of(z));
            hu.fill(AIR_HU);
            head.fill(0.0);
            for (k, e) in ellipsoids.iter().enumerate() {
                if (py - e.centre.y).abs() > e.half_extent.y
                    || (pz - e.centre.z).abs() > e.half_extent.z
                {
                    continue;
                }
                // Voxels whose centre lies within the box's x range.
                let lo = ((e.centre.x - e.half_extent.x + 1.0) / voxel - 0.5).ceil();
                let hi = ((e.centre.x + e.half_extent.x + 1.0) / voxel - 0.5).floor();
                let (lo, hi) = (lo.max(0.0) as usize, hi.min(nu as f64 - 1.0));
                if hi < 0.0 {
                    continue;
                }
                for x in lo..=hi as usize {
                    let c = e.coverage_at(DVec3::new(centre_of(x), py, pz), voxel);
                    hu[x] += e.hu * c;
                    if k == 0 {
                        head[x] = c;
                    }
                }
            }
            let row_index = (y + nu * (z_first + r / nu)) as u64 * nu as u64;
            for (x, out) in row.iter_mut().enumerate() {
                let noise = if head[x] > 0.0 && noise_sigma_hu > 0.0 {
                    noise_sigma_hu * head[x] * unit_noise(NOISE_SEED, row_index + x as u64)
                } else {
                    0.0
                };
                // Values stay within −1000 − 9 … 1000 + 9 HU, far inside i16.
                *out = (hu[x] + noise).round() as i16;
            }
        }
    });
    Volume::new(
        format!("shepp-logan-{n}"),
        [n; 3],
        [FIELD_OF_VIEW_MM / n as f64; 3],
        Samples::I16(samples),
        ValueMapping::IDENTITY,
    )
    .map(|v| {
        v.with_modality(Some(crate::volume::modality::Modality::Ct { angio: false }))
            .with_orientation(Some(ORIENTATION))
            .with_provenance(crate::volume::model::Provenance {
                window: Some(DISPLAY_WINDOW_HU),
                ..Default::default()
            })
    })
}

/// The phantom's anatomical orientation: DICOM's LPS (i to the patient's left, j to the back,
/// k to the head), as the axes above say.
pub const ORIENTATION: crate::volume::orientation::Orientation =
    crate::volume::orientation::Orientation {
        axes: [
            crate::volume::orientation::Direction::Left,
            crate::volume::orientation::Direction::Posterior,
            crate::volume::orientation::Direction::Superior,
        ],
        source: crate::volume::orientation::OrientationSource::Header,
    };

#[cfg(test)]
mod tests;
