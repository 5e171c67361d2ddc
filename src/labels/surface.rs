//! Labels as surfaces without a mesh: the indicator of the shown labels (1 in a voxel whose label
//! in some layer is shown, else 0) smoothed by a separable Gaussian, one axis at a time, each
//! pass rounded to 8 bits as the GPU stores it (`shaders/build/label_surface.wgsl` builds the
//! same mask; this is its CPU twin, which the reference renders from and the tests check the GPU
//! against). The ray loop finds the surface where the mask, filtered trilinearly, rises through
//! one half, and lights it by the mask's gradient: no voxel staircase.

/// The smoothing a segmentation's surfaces get unless asked otherwise: the Gaussian's standard
/// deviation in voxels. At 0.7 a one-voxel sheet keeps its surface (its middle weighs 0.57) and
/// a staircase's steps are rounded away.
pub const DEFAULT_SMOOTHING: f64 = 0.7;

/// The most smoothing offered (voxels): the kernel's radius is capped at [`MOST_RADIUS`].
pub const MOST_SMOOTHING: f64 = 1.5;

/// The widest kernel: three voxels each side.
pub const MOST_RADIUS: u32 = 3;

/// The kernel of smoothing `sigma` (voxels; 0 or less: none): its weights for offsets 0, 1, 2
/// and 3 (0 past the radius), summing to 1 over −radius…radius, and the radius.
pub fn smoothing_kernel(sigma: f32) -> ([f32; 4], u32) {
    // NaN smooths nothing, as 0 does.
    if sigma.is_nan() || sigma <= 0.0 {
        return ([1.0, 0.0, 0.0, 0.0], 0);
    }
    let sigma = sigma.min(MOST_SMOOTHING as f32);
    let radius = ((2.0 * sigma).ceil() as u32).min(MOST_RADIUS);
    let mut w = [0.0f32; 4];
    for (o, weight) in w.iter_mut().enumerate().take(radius as usize + 1) {
        let o = o as f32;
        *weight = (-o * o / (2.0 * sigma * sigma)).exp();
    }
    let sum: f32 = w[0] + 2.0 * w[1..].iter().sum::<f32>();
    (w.map(|x| x / sum), radius)
}

/// One byte of the mask, as the GPU stores a value in 0…1.
pub fn quantise(v: f32) -> u8 {
    (v.clamp(0.0, 1.0) * 255.0 + 0.5) as u8
}

/// The smoothed mask of the voxels `shown` says are (1) or are not (0) inside a shown label, on
/// a grid of `dims` (x fastest), smoothed by `sigma` voxels; voxels past the grid count as 0.
pub fn smoothed_mask(dims: [u32; 3], shown: &[bool], sigma: f32) -> Vec<u8> {
    let (w, radius) = smoothing_kernel(sigma);
    let mut mask: Vec<u8> = shown.iter().map(|&s| if s { 255 } else { 0 }).collect();
    for axis in 0..3 {
        mask = smooth_along(dims, &mask, axis, &w, radius as i64, axis == 0);
    }
    mask
}

/// One pass along `axis`. The first pass reads the indicator itself (0 or 1), as the GPU's first
/// pass reads the labels; later ones read the stored bytes.
fn smooth_along(
    dims: [u32; 3],
    input: &[u8],
    axis: usize,
    w: &[f32; 4],
    radius: i64,
    first: bool,
) -> Vec<u8> {
    let d = dims.map(i64::from);
    let stride = [1, d[0], d[0] * d[1]][axis];
    let mut out = vec![0u8; input.len()];
    for (i, o) in out.iter_mut().enumerate() {
        let i = i as i64;
        let at = [i % d[0], (i / d[0]) % d[1], i / (d[0] * d[1])][axis];
        let mut sum = 0.0f32;
        for off in -radius..=radius {
            let j = at + off;
            if j < 0 || j >= d[axis] {
                continue;
            }
            let v = input[(i + off * stride) as usize];
            let v = if first {
                f32::from(u8::from(v != 0))
            } else {
                f32::from(v) / 255.0
            };
            sum += w[off.unsigned_abs() as usize] * v;
        }
        *o = quantise(sum);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kernels_sum_to_one_and_none_keeps_the_indicator() {
        for sigma in [0.3, 0.7, 1.0, 1.5, 9.0] {
            let (w, r) = smoothing_kernel(sigma);
            let sum = w[0] + 2.0 * w[1..=r as usize].iter().sum::<f32>();
            assert!((sum - 1.0).abs() < 1e-6, "sigma {sigma}: {sum}");
            assert!(r <= MOST_RADIUS && w[r as usize + 1..].iter().all(|&x| x == 0.0));
        }
        let dims = [3, 2, 2];
        let shown: Vec<bool> = (0..12).map(|i| i % 5 == 0).collect();
        let mask = smoothed_mask(dims, &shown, 0.0);
        assert!(mask.iter().zip(&shown).all(|(&m, &s)| (m == 255) == s));
    }

    #[test]
    fn a_flat_boundary_lies_halfway_and_a_thin_sheet_survives_the_default() {
        // Half the grid shown along x: the mask crosses one half between the last shown voxel
        // and the first hidden one, symmetric about that midpoint.
        let dims = [12, 9, 9];
        let shown: Vec<bool> = (0..12 * 81).map(|i| i % 12 < 6).collect();
        let mask = smoothed_mask(dims, &shown, DEFAULT_SMOOTHING as f32);
        // The row in the middle of y and z, far from the grid's other faces.
        let middle = 12 * (4 + 9 * 4);
        let row = &mask[middle..middle + 12];
        assert!(row[5] > 128 && row[6] < 128, "{row:?}");
        assert!((i32::from(row[5]) + i32::from(row[6]) - 255).abs() <= 1);
        // A sheet one voxel thick in x.
        let sheet: Vec<bool> = (0..12 * 81).map(|i| i % 12 == 6).collect();
        let mask = smoothed_mask(dims, &sheet, DEFAULT_SMOOTHING as f32);
        assert!(mask[middle + 6] > 128, "{}", mask[middle + 6]);
    }
}
