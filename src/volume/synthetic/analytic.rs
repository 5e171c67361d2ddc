//! Tiny analytic volumes for the renderer's tests: every voxel is known in closed form, so a
//! test can predict what a ray must see (a constant, a slab, a sphere, a ramp, a checkerboard).

use super::coverage;
use crate::parallel::fill_slabs;
use crate::volume::{
    error::VolumeError, model::Volume, samples::Samples, samples::ScalarType, samples::ValueMapping,
};

/// An axis of the volume grid.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Axis {
    /// The x axis (fastest in memory).
    X,
    /// The y axis.
    Y,
    /// The z axis (slowest in memory).
    Z,
}

impl Axis {
    /// 0, 1 or 2.
    pub fn index(self) -> usize {
        match self {
            Self::X => 0,
            Self::Y => 1,
            Self::Z => 2,
        }
    }
}

/// Number of samples for `dims`, refusing zero dimensions and sizes past the loaders' limits
/// before anything is allocated.
fn sample_count(dims: [u32; 3], scalar_type: ScalarType) -> Result<usize, VolumeError> {
    let (dims, _) = crate::volume::limits::check_dims(dims.map(u64::from), scalar_type)?;
    Ok(dims.iter().map(|&d| d as usize).product())
}

/// Builds an `f32` volume whose voxel `(x, y, z)` holds `f(x, y, z)`.
fn from_fn_f32(
    name: String,
    dims: [u32; 3],
    spacing_mm: [f64; 3],
    f: impl Fn(u32, u32, u32) -> f32 + Sync,
) -> Result<Volume, VolumeError> {
    let mut samples = vec![0.0f32; sample_count(dims, ScalarType::F32)?];
    let [nx, ny, _] = dims.map(|d| d as usize);
    fill_slabs(&mut samples, nx * ny, |z_first, slab| {
        for (i, v) in slab.iter_mut().enumerate() {
            let (x, y, z) = (i % nx, (i / nx) % ny, z_first + i / (nx * ny));
            *v = f(x as u32, y as u32, z as u32);
        }
    });
    Volume::new(
        name,
        dims,
        spacing_mm,
        Samples::F32(samples),
        ValueMapping::IDENTITY,
    )
}

/// Every voxel holds `value` (`f32`). Useful for opacity-correction tests: a ray of length `L`
/// must composite exactly `1 − (1 − α)^(L/d0)`.
pub fn constant(dims: [u32; 3], spacing_mm: [f64; 3], value: f32) -> Result<Volume, VolumeError> {
    from_fn_f32(format!("constant-{value}"), dims, spacing_mm, |_, _, _| {
        value
    })
}

/// Voxels with `lo <= x <= hi` hold `value_inside`, all others `value_outside` (`f32`): a slab
/// perpendicular to x, with a sharp (not anti-aliased) edge so that the trilinear ramp between
/// voxel `lo − 1` and `lo` is exactly one voxel wide.
pub fn slab_x(
    dims: [u32; 3],
    spacing_mm: [f64; 3],
    lo: u32,
    hi: u32,
    value_inside: f32,
    value_outside: f32,
) -> Result<Volume, VolumeError> {
    from_fn_f32(format!("slab-x-{lo}-{hi}"), dims, spacing_mm, |x, _, _| {
        if (lo..=hi).contains(&x) {
            value_inside
        } else {
            value_outside
        }
    })
}

/// An anti-aliased sphere of radius `radius_vox` centred in an `n³` volume of 1 mm voxels
/// (`f32`): the centre sits at voxel coordinates `((n − 1)/2, …)`, and a voxel at distance `r`
/// from it holds `outside + (inside − outside) · clamp(0.5 − (r − radius_vox), 0, 1)`, the
/// partial-volume model used by every generated volume.
pub fn sphere(n: u32, radius_vox: f64, inside: f32, outside: f32) -> Result<Volume, VolumeError> {
    let c = (n as f64 - 1.0) / 2.0;
    from_fn_f32(
        format!("sphere-{n}-r{radius_vox}"),
        [n; 3],
        [1.0; 3],
        |x, y, z| {
            let r = [x, y, z]
                .map(|i| (i as f64 - c).powi(2))
                .iter()
                .sum::<f64>()
                .sqrt();
            let f = coverage(r - radius_vox, 1.0);
            (outside as f64 + (inside as f64 - outside as f64) * f) as f32
        },
    )
}

/// A linear ramp along `axis` (`u16`): voxel `i` holds `round(65535 · i / (n − 1))`, so the
/// first slice is 0 and the last 65535 (a single slice holds 0).
pub fn ramp(dims: [u32; 3], spacing_mm: [f64; 3], axis: Axis) -> Result<Volume, VolumeError> {
    let mut samples = vec![0u16; sample_count(dims, ScalarType::U16)?];
    let a = axis.index();
    let last = (dims[a] - 1).max(1) as f64;
    let [nx, ny, _] = dims.map(|d| d as usize);
    for (i, v) in samples.iter_mut().enumerate() {
        let coords = [i % nx, (i / nx) % ny, i / (nx * ny)];
        *v = (65535.0 * coords[a] as f64 / last).round() as u16;
    }
    Volume::new(
        format!("ramp-{axis:?}").to_lowercase(),
        dims,
        spacing_mm,
        Samples::U16(samples),
        ValueMapping::IDENTITY,
    )
}

/// A 3D checkerboard of boxes `cell_vox` voxels wide along x, y, z (`f32`): voxel `(x, y, z)`
/// holds `a` when `x / cx + y / cy + z / cz` is even, else `b`. Different cell sizes per axis
/// make an axis swap or a wrong spacing visible in any view; a cell size of 0 counts as 1.
pub fn checkerboard(
    dims: [u32; 3],
    spacing_mm: [f64; 3],
    cell_vox: [u32; 3],
    a: f32,
    b: f32,
) -> Result<Volume, VolumeError> {
    let cell = cell_vox.map(|c| c.max(1));
    from_fn_f32(
        format!("checkerboard-{}x{}x{}", cell[0], cell[1], cell[2]),
        dims,
        spacing_mm,
        |x, y, z| {
            if (x / cell[0] + y / cell[1] + z / cell[2]) % 2 == 0 {
                a
            } else {
                b
            }
        },
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn constant_and_slab_hold_exactly_their_values() {
        let c = constant([3, 4, 5], [1.0, 2.0, 0.5], 0.25).expect("valid");
        assert_eq!(c.value_range().map(|r| (r.min, r.max)), Some((0.25, 0.25)));
        assert_eq!(c.extent_mm(), [3.0, 8.0, 2.5]);
        let s = slab_x([8, 2, 3], [1.0; 3], 2, 4, 1.0, -1.0).expect("valid");
        for z in 0..3 {
            for y in 0..2 {
                for x in 0..8 {
                    let expected = if (2..=4).contains(&x) { 1.0 } else { -1.0 };
                    assert_eq!(s.value(x, y, z), expected, "({x}, {y}, {z})");
                }
            }
        }
        assert!(matches!(
            constant([0, 1, 1], [1.0; 3], 0.0),
            Err(VolumeError::ZeroDimension { .. })
        ));
    }

    #[test]
    fn sphere_is_solid_inside_empty_outside_and_partial_on_its_surface() {
        let (n, radius) = (21, 6.3);
        let v = sphere(n, radius, 1.0, 0.0).expect("valid");
        let c = (n - 1) / 2;
        assert_eq!(v.value(c, c, c), 1.0);
        assert_eq!(v.value(0, 0, 0), 0.0);
        // Symmetric under swapping and mirroring axes.
        assert_eq!(v.value(c + 3, c - 2, c + 5), v.value(c - 5, c + 3, c + 2));
        // Compare every partial voxel with its supersampled (8³) inside fraction. For a plane,
        // the ramp 0.5 − d differs from the exact cut of a cube by at most 0.043 (normal along
        // a face or body diagonal); the sphere bends away from its tangent plane by up to
        // (√½)² / 2R ≈ 0.04 voxel across a voxel at R = 6.3; sampling adds ~0.01: hence 0.1.
        let mut partial = 0;
        for z in 0..n {
            for y in 0..n {
                for x in 0..n {
                    let f = v.value(x, y, z);
                    if f == 0.0 || f == 1.0 {
                        continue;
                    }
                    partial += 1;
                    let mut inside = 0;
                    for s in 0..512 {
                        let sub =
                            [s % 8, (s / 8) % 8, s / 64].map(|k| (k as f64 + 0.5) / 8.0 - 0.5);
                        let p = [x, y, z].map(|i| i as f64 - c as f64);
                        let r2: f64 = (0..3).map(|a| (p[a] + sub[a]).powi(2)).sum();
                        if r2 <= radius * radius {
                            inside += 1;
                        }
                    }
                    let exact = inside as f64 / 512.0;
                    assert!((f - exact).abs() < 0.1, "({x}, {y}, {z}): {f} vs {exact}");
                }
            }
        }
        // A sphere of radius 6.3 has about 4π·6.3² ≈ 500 voxels on its surface.
        assert!(partial > 300, "only {partial} partial voxels");
    }

    #[test]
    fn ramp_runs_from_zero_to_full_scale_along_its_axis() {
        let v = ramp([4, 3, 6], [1.0; 3], Axis::Z).expect("valid");
        assert_eq!(v.scalar_type(), crate::volume::samples::ScalarType::U16);
        for z in 0..6 {
            let expected = (65535.0 * z as f64 / 5.0).round();
            assert_eq!(v.value(3, 2, z), expected);
            assert_eq!(v.value(0, 0, z), expected);
        }
        assert_eq!(v.value(0, 0, 5), 65535.0);
        let flat = ramp([1, 4, 4], [1.0; 3], Axis::X).expect("valid");
        assert_eq!(flat.value_range().map(|r| r.max), Some(0.0));
        let along_x = ramp([2, 4, 4], [1.0; 3], Axis::X).expect("valid");
        assert_eq!(
            (along_x.value(0, 3, 3), along_x.value(1, 0, 0)),
            (0.0, 65535.0)
        );
    }

    #[test]
    fn checkerboard_cells_differ_per_axis() {
        let v = checkerboard([8, 8, 8], [1.0; 3], [2, 3, 4], 1.0, 0.0).expect("valid");
        assert_eq!(v.value(0, 0, 0), 1.0);
        assert_eq!(v.value(1, 2, 3), 1.0);
        assert_eq!(v.value(2, 0, 0), 0.0);
        assert_eq!(v.value(0, 3, 0), 0.0);
        assert_eq!(v.value(0, 0, 4), 0.0);
        assert_eq!(v.value(2, 3, 0), 1.0);
        assert_eq!(v.value(2, 3, 4), 0.0);
    }
}
