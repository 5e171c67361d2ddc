//! Labels as surfaces without a mesh: the indicator of the shown labels (1 in a voxel whose label
//! in some layer is shown, else 0) smoothed by a separable Gaussian, one axis at a time, each
//! pass rounded to 8 bits as the GPU stores it (`shaders/build/label_surface.wgsl` builds the
//! same mask; this is its CPU twin, which the reference renders from and the tests check the GPU
//! against). The ray loop finds the surface where the mask, filtered trilinearly, rises through
//! one half, and lights it by the mask's gradient: no voxel staircase.

use rayon::prelude::*;

use super::LabelMap;

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

/// The smoothed mask of one class's `occupancy` (bytes, 255: all; [`occupancy`]) on a grid of
/// `dims`, as the GPU makes it for labels in bricks: every pass reads stored bytes.
pub fn smoothed_occupancy(dims: [u32; 3], occupancy: &[u8], sigma: f32) -> Vec<u8> {
    let (w, radius) = smoothing_kernel(sigma);
    let mut mask = occupancy.to_vec();
    for axis in 0..3 {
        mask = smooth_along(dims, &mask, axis, &w, radius as i64, false);
    }
    mask
}

/// The grid a segmentation's surfaces are found on where its labels travel in bricks: each
/// axis of `dims` reduced `factor`-fold (rounded up), the least power of two whose every axis
/// is at most `most` (the GPU's 3D textures); `(factor, reduced dims)`.
pub fn reduced_grid(dims: [u32; 3], most: u32) -> (u32, [u32; 3]) {
    let mut factor = 1u32;
    while dims.iter().any(|&d| d.div_ceil(factor) > most.max(1)) && factor < 1 << 16 {
        factor *= 2;
    }
    (factor, dims.map(|d| d.div_ceil(factor)))
}

/// Over `region` (first, end: half open) of the grid reduced `factor`-fold, per reduced voxel
/// and class (channel, `channels` of them interleaved), the share of its `factor`³ voxels that
/// hold a label of that class (`codes[value]`: class + 1 where shown, else 0) in some layer,
/// as bytes (255: all). Voxels past the grid count as outside: at factor 1 it is the indicator
/// the mask's first pass smooths.
pub fn occupancy(
    map: &LabelMap,
    codes: &[u8],
    (factor, channels): (u32, u32),
    region: ([u32; 3], [u32; 3]),
) -> Vec<u8> {
    let dims = map.dims();
    let (first, end) = region;
    let extent: [u32; 3] = std::array::from_fn(|a| end[a].saturating_sub(first[a]));
    let (c, f) = (channels as usize, factor);
    let block = f64::from(f).powi(3);
    let slice_bytes = extent[0] as usize * extent[1] as usize * c;
    let mut out = vec![0u8; slice_bytes * extent[2] as usize];
    out.par_chunks_mut(slice_bytes.max(1))
        .enumerate()
        .for_each(|(z, slice)| {
            let rz = first[2] + z as u32;
            let mut counts = vec![0u32; c];
            for ry in first[1]..end[1] {
                for rx in first[0]..end[0] {
                    counts.iter_mut().for_each(|n| *n = 0);
                    let span = |r: u32, a: usize| r * f..((r + 1) * f).min(dims[a]);
                    for z in span(rz, 2) {
                        for y in span(ry, 1) {
                            for x in span(rx, 0) {
                                let i = x as usize
                                    + dims[0] as usize
                                        * (y as usize + dims[1] as usize * z as usize);
                                let mut held = 0u8;
                                for layer in map.layers().iter().take(4) {
                                    let code = codes.get(usize::from(layer[i])).copied();
                                    if let Some(code @ 1..) = code {
                                        held |= 1 << (code - 1).min(3);
                                    }
                                }
                                for (k, n) in counts.iter_mut().enumerate() {
                                    *n += u32::from(held >> k & 1);
                                }
                            }
                        }
                    }
                    let at = ((ry - first[1]) as usize * extent[0] as usize
                        + (rx - first[0]) as usize)
                        * c;
                    for (k, &n) in counts.iter().enumerate() {
                        slice[at + k] = quantise((f64::from(n) / block) as f32);
                    }
                }
            }
        });
    out
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

    /// At factor 1 each class's occupancy is its indicator; at factor 2 (an odd grid, two
    /// layers, a hidden label) each byte is the share of the block's voxels in the grid that
    /// hold a shown label of that class, counted by brute force; over a region, the same bytes.
    #[test]
    fn occupancy_counts_each_blocks_voxels_of_each_class() {
        let dims = [7u32, 5, 3];
        let n = (dims[0] * dims[1] * dims[2]) as usize;
        let first: Vec<u16> = (0..n).map(|i| (i * 7 % 5) as u16).collect();
        let second: Vec<u16> = (0..n).map(|i| if i % 4 == 0 { 9 } else { 0 }).collect();
        let map = LabelMap::bare(dims, vec![first.clone(), second.clone()]);
        // Labels 1 and 9 in class 0, 2 in class 1, 3 in class 3; 4 hidden.
        let mut codes = vec![0u8; 1 << 16];
        codes[1] = 1;
        codes[9] = 1;
        codes[2] = 2;
        codes[3] = 4;
        let class_at = |i: usize, c: u8| {
            [first[i], second[i]]
                .iter()
                .any(|&l| codes[usize::from(l)] == c + 1)
        };
        let whole = occupancy(&map, &codes, (1, 4), ([0; 3], dims));
        for i in 0..n {
            for c in 0..4u8 {
                let want = if class_at(i, c) { 255 } else { 0 };
                assert_eq!(whole[i * 4 + usize::from(c)], want, "voxel {i} class {c}");
            }
        }
        let (factor, reduced) = reduced_grid(dims, 4);
        assert_eq!((factor, reduced), (2, [4, 3, 2]));
        let halved = occupancy(&map, &codes, (2, 4), ([0; 3], reduced));
        for rz in 0..2 {
            for ry in 0..3 {
                for rx in 0..4 {
                    for c in 0..4u8 {
                        let mut count = 0;
                        for z in (2 * rz..2 * rz + 2).filter(|&z| z < dims[2]) {
                            for y in (2 * ry..2 * ry + 2).filter(|&y| y < dims[1]) {
                                for x in (2 * rx..2 * rx + 2).filter(|&x| x < dims[0]) {
                                    let i = (x + dims[0] * (y + dims[1] * z)) as usize;
                                    count += u32::from(class_at(i, c));
                                }
                            }
                        }
                        let at = ((rx + 4 * (ry + 3 * rz)) * 4) as usize + usize::from(c);
                        assert_eq!(
                            halved[at],
                            quantise(count as f32 / 8.0),
                            "{rx} {ry} {rz} {c}"
                        );
                    }
                }
            }
        }
        // A region: the same bytes as the whole grid's there.
        let part = occupancy(&map, &codes, (2, 4), ([1, 1, 1], [3, 3, 2]));
        for (j, chunk) in part.chunks(4).enumerate() {
            let (x, y) = (1 + j as u32 % 2, 1 + j as u32 / 2);
            let at = ((x + 4 * (y + 3)) * 4) as usize;
            assert_eq!(chunk, &halved[at..at + 4]);
        }
    }

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
