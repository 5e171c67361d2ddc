//! A sparse, CT-angiography-like vessel tree: three arteries enter through the bottom face (as
//! the carotid and basilar arteries enter a head CTA) and branch recursively upwards.
//!
//! Each root tree has 5 to 7 generations. A branch is a curved tube built from short tapered
//! capsules: it bends smoothly about a random axis, wiggles slightly, and is steered back when it
//! nears the edge of the field of view. At its end it forks, either symmetrically (both children
//! about 0.78 of the parent's radius, Murray's law `r³ = r₁³ + r₂³` gives 0.79) or into a main
//! continuation (≈ 0.86) and a thinner side branch (≈ 0.6) leaving at a steep angle.
//!
//! The geometry lives in millimetres inside a [`FIELD_OF_VIEW_MM`] cube, independent of the grid,
//! so `n` only changes the resolution. Voxels hold contrast-filled lumen (205–240 of 255, with
//! mild noise) with a one-voxel partial-volume edge; vessels thinner than [`MIN_RADIUS_VOX`] are
//! drawn that wide but proportionally dimmer (same cross-section integral), as a scanner's
//! point-spread function would show them, which also keeps them 26-connected. The background is
//! exactly 0, like the real AVM and MRA volumes (97–99 % of their voxels are the minimum).

use glam::{DQuat, DVec3};

use super::rng::{SplitMix64, unit_noise};
use super::{coverage, cube_len};
use crate::parallel::fill_slabs;
use crate::volume::{error::VolumeError, model::Volume, samples::Samples, samples::ValueMapping};

/// Edge of the cubic field of view, millimetres (a head CTA's; 0.70 mm voxels at `n = 256`).
pub const FIELD_OF_VIEW_MM: f64 = 180.0;
/// Number of arteries entering the volume.
pub const ROOTS: usize = 3;
/// Vessels thinner than this many voxels are widened to it and dimmed by the area ratio.
pub const MIN_RADIUS_VOX: f64 = 0.6;
/// Standard deviation of the noise inside the lumen, in stored units.
const LUMEN_NOISE: f64 = 3.0;
/// Capsules per branch: enough for smooth curves.
const STEPS_PER_BRANCH: usize = 8;

/// One tapered straight piece of a vessel, millimetres.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Capsule {
    /// Start of the centre line.
    pub a: DVec3,
    /// End of the centre line.
    pub b: DVec3,
    /// Radius at `a`.
    pub ra: f64,
    /// Radius at `b`.
    pub rb: f64,
    /// Lumen brightness, 0–255.
    pub intensity: f64,
}

/// A branch waiting to be grown.
struct Sprout {
    at: DVec3,
    dir: DVec3,
    radius: f64,
    intensity: f64,
    generation: u32,
    last_generation: u32,
}

/// A random unit vector perpendicular to the unit vector `d`.
fn perpendicular(rng: &mut SplitMix64, d: DVec3) -> DVec3 {
    loop {
        let z = rng.range(-1.0, 1.0);
        let phi = rng.range(0.0, std::f64::consts::TAU);
        let r = (1.0 - z * z).sqrt();
        let u = DVec3::new(r * phi.cos(), r * phi.sin(), z);
        let p = u - u.dot(d) * d;
        if p.length_squared() > 1e-4 {
            return p.normalize();
        }
    }
}

/// `dir` turned by `angle_deg` about `axis` (unit vectors).
fn turn(dir: DVec3, axis: DVec3, angle_deg: f64) -> DVec3 {
    (DQuat::from_axis_angle(axis, angle_deg.to_radians()) * dir).normalize()
}

/// The tree's centre lines for `seed`, as capsules in millimetres.
pub(crate) fn grow(seed: u64) -> Vec<Capsule> {
    let mut rng = SplitMix64::new(seed);
    let centre = DVec3::splat(FIELD_OF_VIEW_MM / 2.0);
    let mut sprouts = Vec::new();
    for root in 0..ROOTS {
        let angle = std::f64::consts::TAU * (root as f64 + rng.range(-0.15, 0.15)) / ROOTS as f64;
        let offset = DVec3::new(angle.cos(), angle.sin(), 0.0) * rng.range(15.0, 30.0);
        let up = turn(
            DVec3::Z,
            perpendicular(&mut rng, DVec3::Z),
            rng.range(5.0, 20.0),
        );
        sprouts.push(Sprout {
            // Start just below the bottom face, so the artery enters through it.
            at: DVec3::new(centre.x + offset.x, centre.y + offset.y, -2.0),
            dir: up,
            radius: rng.range(2.4, 3.2),
            intensity: rng.range(215.0, 240.0),
            generation: 0,
            last_generation: 4 + (rng.next_u64() % 3) as u32,
        });
    }
    let mut capsules = Vec::new();
    while let Some(s) = sprouts.pop() {
        grow_branch(&mut rng, s, centre, &mut capsules, &mut sprouts);
    }
    capsules
}

/// Grows one branch from `s` into `capsules` and queues its children in `sprouts`.
fn grow_branch(
    rng: &mut SplitMix64,
    s: Sprout,
    centre: DVec3,
    capsules: &mut Vec<Capsule>,
    sprouts: &mut Vec<Sprout>,
) {
    let length = s.radius * rng.range(10.0, 16.0) + rng.range(8.0, 14.0);
    let step = length / STEPS_PER_BRANCH as f64;
    let bend_axis = perpendicular(rng, s.dir);
    let bend_per_step = rng.range(-35.0, 35.0) / STEPS_PER_BRANCH as f64;
    let (mut at, mut dir, mut radius) = (s.at, s.dir, s.radius);
    // Beyond this distance from the centre a branch is pulled back towards it.
    let keep_within = 0.40 * FIELD_OF_VIEW_MM;
    for _ in 0..STEPS_PER_BRANCH {
        dir = turn(dir, bend_axis, bend_per_step);
        dir = turn(dir, perpendicular(rng, dir), rng.range(0.0, 6.0));
        let out = (at - centre).length() - keep_within;
        if out > 0.0 && s.generation > 0 {
            let inward = (centre - at).normalize();
            dir = (dir + inward * (out / 10.0).min(2.0)).normalize();
        }
        let next = at + dir * step;
        let next_radius = radius * (1.0 - 0.06 / STEPS_PER_BRANCH as f64);
        capsules.push(Capsule {
            a: at,
            b: next,
            ra: radius,
            rb: next_radius,
            intensity: s.intensity,
        });
        (at, radius) = (next, next_radius);
    }
    if s.generation >= s.last_generation {
        return;
    }
    let axis = perpendicular(rng, dir);
    let children = if rng.chance(0.55) {
        // Symmetric fork.
        [
            (rng.range(0.74, 0.82), rng.range(20.0, 40.0)),
            (rng.range(0.74, 0.82), -rng.range(20.0, 40.0)),
        ]
    } else {
        // Main continuation and a side branch.
        [
            (rng.range(0.82, 0.9), rng.range(5.0, 15.0)),
            (rng.range(0.55, 0.68), -rng.range(45.0, 75.0)),
        ]
    };
    for (ratio, angle) in children {
        sprouts.push(Sprout {
            at,
            dir: turn(dir, axis, angle),
            radius: radius * ratio,
            intensity: (s.intensity * rng.range(0.97, 1.0)).max(205.0),
            generation: s.generation + 1,
            last_generation: s.last_generation,
        });
    }
}

/// A sparse vessel tree on an `n³` grid (`u8`, 0 = background), spacing
/// [`FIELD_OF_VIEW_MM`]` / n`; the same `seed` always gives the same tree, at any `n`.
///
/// Fails with [`VolumeError::ZeroDimension`] when `n` is zero.
pub fn vessel_tree(n: u32, seed: u64) -> Result<Volume, VolumeError> {
    let len = cube_len(n, crate::volume::samples::ScalarType::U8)?;
    let nu = n as usize;
    let voxel = FIELD_OF_VIEW_MM / n as f64;
    let capsules = grow(seed);
    let min_radius = MIN_RADIUS_VOX * voxel;
    // Voxel ranges (inclusive, clamped to the grid) each capsule can touch.
    let reach = |c: &Capsule| c.ra.max(c.rb).max(min_radius) + voxel;
    let span = |lo: f64, hi: f64| {
        let first = (lo / voxel - 0.5).ceil().max(0.0);
        let last = (hi / voxel - 0.5).floor().min(nu as f64 - 1.0);
        (first <= last).then_some((first as usize, last as usize))
    };
    let mut samples = vec![0u8; len];
    fill_slabs(&mut samples, nu * nu, |z_first, slab| {
        let z_last = z_first + slab.len() / (nu * nu) - 1;
        for c in &capsules {
            let r = reach(c);
            let (lo, hi) = (c.a.min(c.b) - r, c.a.max(c.b) + r);
            let (Some(xs), Some(ys), Some(zs)) =
                (span(lo.x, hi.x), span(lo.y, hi.y), span(lo.z, hi.z))
            else {
                continue;
            };
            let (z0, z1) = (zs.0.max(z_first), zs.1.min(z_last));
            if z0 > z1 {
                continue;
            }
            let axis = c.b - c.a;
            let axis_len_sq = axis.length_squared().max(1e-12);
            for z in z0..=z1 {
                for y in ys.0..=ys.1 {
                    let row = (z - z_first) * nu * nu + y * nu;
                    for x in xs.0..=xs.1 {
                        let p = (DVec3::new(x as f64, y as f64, z as f64) + 0.5) * voxel;
                        let t = ((p - c.a).dot(axis) / axis_len_sq).clamp(0.0, 1.0);
                        let dist = (p - (c.a + axis * t)).length();
                        let radius = c.ra + (c.rb - c.ra) * t;
                        let drawn = radius.max(min_radius);
                        let f = coverage(dist - drawn, voxel);
                        if f <= 0.0 {
                            continue;
                        }
                        let index = (row + x + z_first * nu * nu) as u64;
                        let lumen = c.intensity + LUMEN_NOISE * unit_noise(seed, index);
                        let value = lumen * (radius / drawn).powi(2) * f;
                        let out = &mut slab[row + x];
                        // Lumen plus noise stays below 240 + 9, inside u8.
                        *out = (*out).max(value.round() as u8);
                    }
                }
            }
        }
    });
    Volume::new(
        format!("vessel-tree-{n}-seed-{seed}"),
        [n; 3],
        [voxel; 3],
        Samples::U8(samples),
        ValueMapping::IDENTITY,
    )
    .map(|v| v.with_modality(Some(crate::volume::modality::Modality::Mr { angio: true })))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Sizes of the 26-connected components of non-zero voxels, largest first.
    fn component_sizes(v: &Volume) -> Vec<usize> {
        let Samples::U8(s) = v.samples().expect("in memory") else {
            panic!("the vessel tree is stored as u8")
        };
        let n = v.dims()[0] as i64;
        let mut seen = vec![false; s.len()];
        let mut sizes = Vec::new();
        for start in 0..s.len() {
            if s[start] == 0 || seen[start] {
                continue;
            }
            let (mut size, mut stack) = (0, vec![start]);
            seen[start] = true;
            while let Some(i) = stack.pop() {
                size += 1;
                let (x, y, z) = (i as i64 % n, (i as i64 / n) % n, i as i64 / (n * n));
                for d in 0..27 {
                    let (a, b, c) = (x + d % 3 - 1, y + (d / 3) % 3 - 1, z + d / 9 - 1);
                    if [a, b, c].iter().any(|&q| q < 0 || q >= n) {
                        continue;
                    }
                    let j = (a + n * (b + n * c)) as usize;
                    if s[j] != 0 && !seen[j] {
                        seen[j] = true;
                        stack.push(j);
                    }
                }
            }
            sizes.push(size);
        }
        sizes.sort_unstable_by(|a, b| b.cmp(a));
        sizes
    }

    #[test]
    fn sparse_and_made_of_one_tree_per_root() {
        for seed in [1, 2] {
            let v = vessel_tree(64, seed).expect("valid size");
            let sizes = component_sizes(&v);
            let vessel: usize = sizes.iter().sum();
            let share = vessel as f64 / v.sample_count() as f64;
            // The real angiograms are 97–99 % background; a tree this thin must be sparser
            // still, yet not vanish.
            assert!(
                (0.001..0.05).contains(&share),
                "seed {seed}: {share} vessel"
            );
            // Gaps in the rasterisation would split the trees into many pieces; the roots'
            // trees (which may touch and merge) must hold nearly every vessel voxel.
            let main: usize = sizes.iter().take(ROOTS).sum();
            assert!(
                main as f64 > 0.95 * vessel as f64,
                "seed {seed}: components {:?}",
                &sizes[..sizes.len().min(8)]
            );
        }
    }

    #[test]
    fn deterministic_per_seed() {
        let a = vessel_tree(32, 7).expect("valid size");
        let b = vessel_tree(32, 7).expect("valid size");
        let c = vessel_tree(32, 8).expect("valid size");
        assert_eq!(a.samples(), b.samples());
        assert_ne!(a.samples(), c.samples());
    }

    #[test]
    fn lumen_is_bright_and_enters_through_the_bottom() {
        // At n = 128 (1.4 mm voxels) the roots (radius ≥ 2.4 mm) have voxels wholly inside
        // them, which hold the lumen value 215–240 less at most 3 · LUMEN_NOISE = 9.
        let n = 128;
        let v = vessel_tree(n, 3).expect("valid size");
        let range = v.value_range().expect("finite");
        assert_eq!(range.min, 0.0);
        assert!((206.0..=249.0).contains(&range.max), "max {}", range.max);
        let bright_in_bottom_slice = (0..n)
            .flat_map(|y| (0..n).map(move |x| (x, y)))
            .filter(|&(x, y)| v.value(x, y, 0) >= 206.0)
            .count();
        assert!(bright_in_bottom_slice > 0, "no artery enters through z = 0");
    }

    #[test]
    fn branches_have_five_to_seven_generations_and_stay_inside() {
        let capsules = grow(11);
        assert_eq!(capsules.len() % STEPS_PER_BRANCH, 0);
        // Every fork has two children, so a root with g generations has 2^g − 1 branches.
        let branches = capsules.len() / STEPS_PER_BRANCH;
        let possible = [31, 63, 127];
        let explained = possible.iter().any(|a| {
            possible
                .iter()
                .any(|b| possible.iter().any(|c| a + b + c == branches))
        });
        assert!(explained, "{branches} branches");
        let inside = capsules
            .iter()
            .filter(|c| {
                c.b.cmpge(DVec3::ZERO).all() && c.b.cmple(DVec3::splat(FIELD_OF_VIEW_MM)).all()
            })
            .count();
        assert!(
            inside as f64 > 0.95 * capsules.len() as f64,
            "{inside} inside"
        );
        let thickest = capsules.iter().map(|c| c.ra).fold(0.0, f64::max);
        let thinnest = capsules.iter().map(|c| c.rb).fold(f64::INFINITY, f64::min);
        assert!(
            thickest <= 3.2 && thinnest < 0.25 * thickest,
            "{thinnest}..{thickest}"
        );
    }

    #[test]
    fn zero_size_is_an_error() {
        assert!(matches!(
            vessel_tree(0, 1),
            Err(VolumeError::ZeroDimension { .. })
        ));
    }
}
