//! A dense MR-like head for benchmarks: tissue fills about 78 % of the box, so a brain transfer
//! function leaves almost no block empty and space leaping has little to skip. It is the
//! counterpart of the sparse [`super::vessel_tree`]: together they bracket the datasets of the
//! papers, from a 99 % empty angiogram to a tightly cropped head.
//!
//! What it models: a T1-weighted head scan cropped close to the scalp (the field of view cuts
//! the front, back, top and bottom of the head a little), with bright scalp fat, dark skull, a
//! thin layer of dark cerebrospinal fluid around the brain, a folded grey-matter cortex (sulci
//! are the zero sheets of a band-limited random field, lined with cortex), bright white matter
//! beneath, two ventricles, a smooth intensity bias across the field (receive-coil
//! inhomogeneity), mild noise on tissue and a faint Rayleigh-like noise floor (0–6) in the air,
//! as in magnitude MR images. The outline is a superellipsoid of exponent 3: fuller than an
//! ellipsoid, as a cropped head fills the box. Values are `u8`, 0–255; the geometry is the same
//! at every `n` for a given seed.

use glam::{DMat3, DVec3};

use super::rng::{SplitMix64, unit_noise};
use super::{coverage, cube_len};
use crate::parallel::fill_slabs;
use crate::volume::zarr::write::Slabs;
use crate::volume::{error::VolumeError, model::Volume, samples::Samples, samples::ValueMapping};

/// Edge of the cubic field of view, millimetres (0.78 mm voxels at `n = 256`).
pub const FIELD_OF_VIEW_MM: f64 = 200.0;
/// Semi-axes of the outline in half fields of view (left–right, front–back, height); beyond 1
/// the box crops the head.
const SEMI_AXES: [f64; 3] = [1.0, 1.08, 1.03];
/// Layers from the outside in: (outer boundary as an outline radius, T1 intensity): scalp fat,
/// skull, cerebrospinal fluid, cortex. One unit of radius is about 100 mm.
const LAYERS: [(f64, f64); 4] = [(1.0, 185.0), (0.95, 30.0), (0.90, 50.0), (0.88, 105.0)];
/// Outline radius of the brain's surface (the last layer's boundary).
const BRAIN_SURFACE: f64 = 0.88;
/// Cortical thickness, normalised units (3 mm).
const CORTEX: f64 = 0.03;
/// White matter intensity.
const WHITE_MATTER: f64 = 150.0;
/// Cerebrospinal fluid (around the brain, in sulci and ventricles).
const CSF: f64 = 50.0;
/// Lattice cells of the sulcal field across the box: about one fold every 15 mm.
const SULCUS_CELLS: usize = 14;
/// Depth below the brain's surface at which sulci end, normalised units (16 mm).
const SULCUS_DEPTH: f64 = 0.16;
/// Half-width of a sulcus in field units (the field spans −1…1).
const SULCUS_HALF_WIDTH: f64 = 0.1;
/// Standard deviation of the noise on tissue, in stored units.
const TISSUE_NOISE: f64 = 3.0;

/// Smooth random field in [−1, 1], periodic over the unit cube: values on a coarse lattice,
/// blended with smoothstep weights (C¹-continuous "value noise"). Sampled through a random
/// rotation so that its lattice does not line up with the voxel grid.
struct ValueNoise {
    cells: usize,
    values: Vec<f64>,
    rotation: DMat3,
}

impl ValueNoise {
    fn new(rng: &mut SplitMix64, cells: usize) -> Self {
        let values = (0..cells.pow(3)).map(|_| rng.range(-1.0, 1.0)).collect();
        let axis = DVec3::new(rng.range(-1.0, 1.0), rng.range(-1.0, 1.0), 1.0).normalize();
        let rotation = DMat3::from_axis_angle(axis, rng.range(0.3, 1.2));
        Self {
            cells,
            values,
            rotation,
        }
    }

    /// The field at `p` (any point; one period is the unit cube).
    fn at(&self, p: [f64; 3]) -> f64 {
        let g = self.cells;
        let p = self.rotation * DVec3::from_array(p) * g as f64;
        let mut lo = [0usize; 3];
        let mut hi = [0usize; 3];
        let mut w = [0.0f64; 3];
        for a in 0..3 {
            // Rotated points of the unit cube lie within ±√3·g of the origin: shifting by a
            // multiple of the period makes them positive, so a plain remainder wraps them.
            let t = p[a] + (2 * g) as f64;
            // t is positive, so truncation is the floor (and much cheaper than `floor`).
            let cell = t as u32;
            let f = t - cell as f64;
            lo[a] = (cell % g as u32) as usize;
            hi[a] = if lo[a] + 1 == g { 0 } else { lo[a] + 1 };
            w[a] = f * f * (3.0 - 2.0 * f);
        }
        let v = |x: usize, y: usize, z: usize| self.values[x + g * (y + g * z)];
        let lerp = |a: f64, b: f64, t: f64| a + (b - a) * t;
        let edge = |y: usize, z: usize| lerp(v(lo[0], y, z), v(hi[0], y, z), w[0]);
        let face = |z: usize| lerp(edge(lo[1], z), edge(hi[1], z), w[1]);
        lerp(face(lo[2]), face(hi[2]), w[2])
    }
}

/// The outline's radius at `u` (normalised coordinates in [−1, 1]³): below 1 is inside.
fn outline_radius(u: [f64; 3]) -> f64 {
    // A superellipsoid of exponent 3.
    let s: f64 = (0..3).map(|a| (u[a] / SEMI_AXES[a]).abs().powi(3)).sum();
    cube_root(s)
}

/// `s^(1/3)` for `s ≥ 0`: an exponent-dividing first guess (within 5 %) and four Newton steps
/// (each squares the relative error), exact to rounding and several times faster than the
/// software `cbrt` the standard library uses here.
fn cube_root(s: f64) -> f64 {
    if s <= 0.0 {
        return 0.0;
    }
    let mut y = f64::from_bits(s.to_bits() / 3 + 0x2A9F_7893_782D_A1CE);
    for _ in 0..4 {
        y -= (y * y * y - s) / (3.0 * y * y);
    }
    y
}

/// Whether `u` lies in one of the two ventricles, as a coverage in [0, 1] for voxel size `h`.
fn ventricle(u: [f64; 3], h: f64) -> f64 {
    let semi = [0.07, 0.24, 0.12];
    [-0.12, 0.12]
        .iter()
        .map(|&cx| {
            let c = [cx, 0.05, 0.08];
            let q: f64 = (0..3).map(|a| ((u[a] - c[a]) / semi[a]).powi(2)).sum();
            // Distance ≈ (√q − 1)·(smallest semi-axis): good enough for a smooth edge.
            coverage((q.sqrt() - 1.0) * semi[0], h)
        })
        .fold(0.0, f64::max)
}

/// The dense head on a grid of any shape: each voxel's value (before rounding) found from its
/// position alone, so any slab of it is made without the rest (`leapview generate --dims`
/// writes ones larger than memory). The head fills the box along each axis; voxels are
/// [`FIELD_OF_VIEW_MM`] over the axis's voxels.
pub struct DenseHead {
    dims: [u32; 3],
    seed: u64,
    /// A voxel's size in normalised units (2 over the longest axis).
    h: f64,
    sulci: ValueNoise,
    sulci_fine: ValueNoise,
    texture: ValueNoise,
    bias: ValueNoise,
}

impl DenseHead {
    /// The head on a grid of `dims` (each at least 1); `seed` decides the texture, the bias
    /// field and the noise.
    pub fn new(dims: [u32; 3], seed: u64) -> Self {
        let mut rng = SplitMix64::new(seed);
        let sulci = ValueNoise::new(&mut rng, SULCUS_CELLS);
        let sulci_fine = ValueNoise::new(&mut rng, SULCUS_CELLS * 3 / 2);
        let texture = ValueNoise::new(&mut rng, 8);
        let bias = ValueNoise::new(&mut rng, 2);
        let dims = dims.map(|d| d.max(1));
        Self {
            dims,
            seed,
            h: 2.0 / f64::from(dims.into_iter().max().unwrap_or(1)),
            sulci,
            sulci_fine,
            texture,
            bias,
        }
    }

    /// Spacing along x, y, z: the field of view over each axis's voxels.
    pub fn spacing_mm(&self) -> [f64; 3] {
        self.dims.map(|d| FIELD_OF_VIEW_MM / f64::from(d))
    }

    /// The value of voxel `(x, y, z)` before rounding (0 to 255 but for rare noise).
    fn value(&self, [x, y, z]: [usize; 3]) -> f64 {
        let [nx, ny, _] = self.dims.map(|d| d as usize);
        let h = self.h;
        let unit: [f64; 3] =
            std::array::from_fn(|a| ([x, y, z][a] as f64 + 0.5) / f64::from(self.dims[a]));
        let u = unit.map(|c| 2.0 * c - 1.0);
        let index = (x + nx * (y + ny * z)) as u64;
        let rho = outline_radius(u);
        if rho >= 1.0 + 0.5 * h {
            // Magnitude noise floor in air: |noise| · 2, at most 6.
            return 2.0 * unit_noise(self.seed, index).abs();
        }
        // Near the surface the outline's radius is close to a normalised distance, so the
        // layers get one-voxel partial-volume edges; each layer covers the one outside it.
        let mut value = 0.0;
        for (boundary, intensity) in LAYERS {
            value += (intensity - value) * coverage(rho - boundary, h);
        }
        let depth = BRAIN_SURFACE - rho;
        if depth > SULCUS_DEPTH + CORTEX + h {
            // Deep white matter: no sulcus reaches here, and none is within a cortex.
            value = WHITE_MATTER;
            value += (CSF - value) * ventricle(u, h);
        } else if depth > -h {
            // Sulci: sheets where the field is near zero, narrowing to their fundus 16 mm
            // below the surface. The field changes by about one per half cell, which turns
            // it into a distance; below the fundus the distance is at least the depth past it.
            let width = SULCUS_HALF_WIDTH * (1.0 - depth / SULCUS_DEPTH).max(0.0);
            let field = 0.6 * self.sulci.at(unit) + 0.4 * self.sulci_fine.at(unit);
            let to_sulcus = ((field.abs() - width) / SULCUS_CELLS as f64).max(depth - SULCUS_DEPTH);
            let in_brain = coverage(-depth, h);
            value += (CSF - value) * coverage(to_sulcus, h) * in_brain;
            // White matter lies deeper than one cortical thickness from any CSF.
            let to_csf = depth.min(to_sulcus);
            value += (WHITE_MATTER - value) * coverage(CORTEX - to_csf, h) * in_brain;
            value += (CSF - value) * ventricle(u, h);
        }
        let tissue = coverage(rho - 1.0, h);
        value +=
            tissue * (6.0 * self.texture.at(unit) + TISSUE_NOISE * unit_noise(self.seed, index));
        value * (1.0 + 0.08 * self.bias.at(unit))
    }

    /// Slices `z0..z1` (x fastest), each value `scale` times the 8-bit one, rounded.
    fn slab<T: Copy + Default + Send>(
        &self,
        z0: u32,
        z1: u32,
        convert: impl Fn(f64) -> T + Sync,
    ) -> Vec<T> {
        let [nx, ny, _] = self.dims.map(|d| d as usize);
        let plane = nx * ny;
        let mut out = vec![T::default(); plane * (z1 - z0) as usize];
        fill_slabs(&mut out, plane, |z_first, slab| {
            for (i, v) in slab.iter_mut().enumerate() {
                let z = z0 as usize + z_first + i / plane;
                *v = convert(self.value([i % nx, (i / nx) % ny, z]));
            }
        });
        out
    }

    /// Slices `z0..z1` as 8-bit samples (0–255).
    pub fn slab_u8(&self, z0: u32, z1: u32) -> Vec<u8> {
        // Adding ½ and truncating rounds the non-negative values like `round`, but cheaply.
        self.slab(z0, z1, |v| (v.clamp(0.0, 255.0) + 0.5) as u8)
    }

    /// Slices `z0..z1` as 16-bit samples: the 8-bit scale times 257 (0–65535), rounded.
    pub fn slab_u16(&self, z0: u32, z1: u32) -> Vec<u16> {
        self.slab(z0, z1, |v| (v.clamp(0.0, 255.0) * 257.0 + 0.5) as u16)
    }
}

/// The head's slices as a store is written from them ([`Slabs`]), 8- or 16-bit.
pub struct DenseHeadSlabs {
    /// The head.
    pub head: DenseHead,
    /// `U8` or `U16` (any other type is written as `U16`).
    pub scalar_type: crate::volume::samples::ScalarType,
}

impl Slabs for DenseHeadSlabs {
    fn dims(&self) -> [u32; 3] {
        self.head.dims
    }

    fn scalar_type(&self) -> crate::volume::samples::ScalarType {
        match self.scalar_type {
            crate::volume::samples::ScalarType::U8 => crate::volume::samples::ScalarType::U8,
            _ => crate::volume::samples::ScalarType::U16,
        }
    }

    fn read(&self, z0: u32, z1: u32) -> Result<Samples, VolumeError> {
        Ok(match self.scalar_type() {
            crate::volume::samples::ScalarType::U8 => Samples::U8(self.head.slab_u8(z0, z1)),
            _ => Samples::U16(self.head.slab_u16(z0, z1)),
        })
    }
}

/// A dense MR-like head on an `n³` grid (`u8`), spacing [`FIELD_OF_VIEW_MM`]` / n`; `seed`
/// decides the texture, the bias field and the noise.
///
/// Fails with [`VolumeError::ZeroDimension`] when `n` is zero.
pub fn dense_head(n: u32, seed: u64) -> Result<Volume, VolumeError> {
    cube_len(n, crate::volume::samples::ScalarType::U8)?;
    let head = DenseHead::new([n; 3], seed);
    Volume::new(
        format!("dense-head-{n}-seed-{seed}"),
        [n; 3],
        [FIELD_OF_VIEW_MM / n as f64; 3],
        Samples::U8(head.slab_u8(0, n)),
        ValueMapping::IDENTITY,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cube_root_matches_the_standard_library() {
        for s in [0.0, 1e-9, 0.3, 0.5, 1.0, 1.7, 3.0, 27.0] {
            let (ours, std) = (cube_root(s), f64::cbrt(s));
            // Four Newton steps from a 5 % guess leave only rounding: a few ulps.
            assert!(
                (ours - std).abs() <= 4.0 * f64::EPSILON * std.max(1e-300),
                "{s}"
            );
        }
    }

    #[test]
    fn tissue_fills_most_of_the_box_and_most_bricks() {
        let n = 64;
        let v = dense_head(n, 1).expect("valid size");
        let Samples::U8(s) = v.samples().expect("in memory") else {
            panic!("the dense head is stored as u8")
        };
        // The superellipsoid covers about 78 % of the box (Monte Carlo estimate); the air
        // floor is at most 2 · 3 = 6.
        let tissue = s.iter().filter(|&&x| x > 6).count() as f64 / s.len() as f64;
        assert!((0.72..0.84).contains(&tissue), "tissue fraction {tissue}");
        // A brain transfer function (mr-default starts at 12 % of the range, ≈ 30) must find
        // something in most 8³ bricks.
        let (nu, b) = (n as usize, 8);
        let bricks = nu / b;
        let mut busy = vec![false; bricks.pow(3)];
        for (i, &value) in s.iter().enumerate() {
            let (x, y, z) = (i % nu / b, i / nu % nu / b, i / (nu * nu) / b);
            if value > 30 {
                busy[x + bricks * (y + bricks * z)] = true;
            }
        }
        let busy = busy.iter().filter(|&&x| x).count() as f64 / busy.len() as f64;
        assert!(busy > 0.85, "only {busy} of the bricks hold tissue");
        assert!(v.value(0, 0, 0) <= 6.0, "corner {}", v.value(0, 0, 0));
    }

    #[test]
    fn centre_is_white_matter_and_layers_are_present() {
        let n = 64;
        let v = dense_head(n, 2).expect("valid size");
        // White matter 150, texture ±6, noise ±9, bias ±8 %: 124…178.
        let centre = v.value(n / 2, n / 2, n / 2);
        assert!((124.0..=178.0).contains(&centre), "centre {centre}");
        let Samples::U8(s) = v.samples().expect("in memory") else {
            panic!("the dense head is stored as u8")
        };
        let count_in = |lo: u8, hi: u8| s.iter().filter(|x| (lo..=hi).contains(*x)).count();
        // Scalp fat (185 ± 30) and dark skull or CSF (30–60) each hold a clear share.
        assert!(count_in(170, 230) > 1000, "no scalp");
        assert!(count_in(20, 60) > 1000, "no skull or CSF");
    }

    #[test]
    fn deterministic_per_seed() {
        let a = dense_head(24, 5).expect("valid size");
        let b = dense_head(24, 5).expect("valid size");
        let c = dense_head(24, 6).expect("valid size");
        assert_eq!(a.samples(), b.samples());
        assert_ne!(a.samples(), c.samples());
        assert!(matches!(
            dense_head(0, 1),
            Err(VolumeError::ZeroDimension { .. })
        ));
    }
}
