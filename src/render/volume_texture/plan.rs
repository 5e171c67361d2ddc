//! Which layout a volume of a given shape takes on this adapter: one texture, or bricks of the
//! atlas whose slots the GPU memory budget and the adapter's 3D texture limit allow.

use crate::accel::bricks::{
    APRON, BrickError, BrickLayout, DEFAULT_BRICK_VOX, MAX_SLOTS_PER_AXIS, level_count, level_dims,
};
use crate::settings::Bricking;

/// An atlas of bricks: its slots per axis and how many of them a budget lets the bricks use.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Atlas {
    /// Brick edge in voxels (without the apron).
    pub brick_vox: u32,
    /// Slots per axis.
    pub slots: [u32; 3],
    /// Slots the bricks may use.
    pub capacity: u32,
}

impl Atlas {
    /// Edge of a slot: the brick and its apron.
    pub(super) fn slot_vox(&self) -> u32 {
        self.brick_vox + 2 * APRON
    }
}

/// How a volume is laid out on the GPU.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Plan {
    /// One texture of the volume's size.
    Single([u32; 3]),
    /// Bricks of any level in an atlas.
    Bricked(Atlas),
}

/// Why a volume has no layout on this adapter.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub(super) enum PlanError {
    /// One texture was asked for and an axis is past the limit.
    #[error("an axis is past the 3D texture limit of {max} texels")]
    TooLarge {
        /// The adapter's 3D texture limit.
        max: u32,
    },
    /// One texture was asked for and it is larger than the budget.
    #[error(
        "one texture of the volume takes {} but the GPU memory budget leaves it {}; let it be \
         bricked (--bricks auto)",
        crate::text::bytes(*bytes),
        crate::text::bytes(*budget)
    )]
    OverBudget {
        /// The texture's size.
        bytes: u64,
        /// The budget.
        budget: u64,
    },
    /// The bricks fit neither the atlas nor the budget at any level.
    #[error(transparent)]
    Bricks(BrickError),
}

impl Plan {
    /// Texels of the 3D texture (the volume's, or the atlas's).
    pub(super) fn extent(&self) -> [u32; 3] {
        match self {
            Self::Single(dims) => *dims,
            Self::Bricked(atlas) => atlas.slots.map(|s| s * atlas.slot_vox()),
        }
    }

    /// Bytes of those texels at `bytes_per_texel` (what the driver takes may be more).
    pub(super) fn bytes(&self, bytes_per_texel: u64) -> u64 {
        self.extent().iter().map(|&e| u64::from(e)).product::<u64>() * bytes_per_texel
    }
}

/// Why the volume's bricks are held at `level` rather than full resolution, as one line
/// (`None` at full resolution): the level, its size, and what full resolution would need.
pub(super) fn coarser_note(
    (dims, brick_vox, level): ([u32; 3], u32, u32),
    (max, budget): (u32, Option<u64>),
    bytes_per_texel: u64,
) -> Option<String> {
    if level == 0 {
        return None;
    }
    let [x, y, z] = level_dims(dims, level);
    let why = match BrickLayout::at_level(dims, brick_vox, 0, max) {
        Ok(full) => format!(
            "full resolution takes {}, more than the GPU memory budget of {}",
            crate::text::bytes(full.brick_bytes(bytes_per_texel)),
            crate::text::bytes(budget.unwrap_or(u64::MAX))
        ),
        Err(e) => format!("at full resolution {e}"),
    };
    Some(format!(
        "the volume is shown at 1/{} resolution ({x} x {y} x {z} voxels, level {level}): {why}",
        1u32 << level,
    ))
}

/// Why the finest bricks held are of `level` although finer ones fit the budget: at this zoom a
/// voxel of that level covers about a pixel (the footprint rule, `unseen::footprint_levels`).
pub(super) fn footprint_note(dims: [u32; 3], level: u32) -> String {
    let [x, y, z] = level_dims(dims, level);
    format!(
        "the volume is shown at 1/{} resolution ({x} x {y} x {z} voxels, level {level}): at this \
         zoom a voxel of it covers about a pixel; zooming in loads finer bricks",
        1u32 << level
    )
}

/// The atlas for a volume of `dims` in bricks of `brick_vox` under a 3D texture limit of `max`
/// and `budget` bytes (slots of `bytes_per_texel`): as many slots as every brick of level 0 and
/// the coarsest need, or as the budget and the limit allow, whichever is fewer.
fn atlas(
    dims: [u32; 3],
    brick_vox: u32,
    (max, budget): (u32, Option<u64>),
    bytes_per_texel: u64,
) -> Result<Atlas, BrickError> {
    let slot = brick_vox + 2 * APRON;
    let slot_bytes = u64::from(slot).pow(3) * bytes_per_texel;
    let full = BrickLayout::geometry(dims, brick_vox, 0).count() as u64;
    let levels = level_count(dims, brick_vox);
    let all = full + u64::from(levels > 1);
    let per_axis = u64::from((max / slot).min(MAX_SLOTS_PER_AXIS));
    let by_budget = budget.map_or(u64::MAX, |b| b / slot_bytes);
    if by_budget == 0 {
        return Err(BrickError::Budget {
            budget_bytes: budget.unwrap_or(0),
            coarsest_bytes: slot_bytes,
        });
    }
    let mut capacity = all.min(by_budget).min(per_axis.pow(3));
    let full = BrickError::AtlasFull {
        bricks: all,
        brick_vox,
        max,
    };
    let mut slots = arrange(capacity, per_axis).ok_or(full.clone())?;
    // The texture is a box of slots: where rounding up to one passes the budget, the largest
    // box within it (its slots all used), so the allocation itself stays inside the budget.
    if slot_count(slots) > by_budget {
        slots = arrange_within(by_budget, per_axis).ok_or(full)?;
        capacity = capacity.min(slot_count(slots));
    }
    Ok(Atlas {
        brick_vox,
        slots,
        capacity: capacity as u32,
    })
}

fn slot_count(slots: [u32; 3]) -> u64 {
    slots.iter().map(|&s| u64::from(s)).product()
}

/// Slots per axis for at most `count` slots, at most `per_axis` each: the box holding the most
/// (the most even of those), found by trying every x and y extent (`per_axis` is at most
/// [`MAX_SLOTS_PER_AXIS`]).
fn arrange_within(count: u64, per_axis: u64) -> Option<[u32; 3]> {
    let mut best: Option<(u64, u64, [u32; 3])> = None;
    for sx in 1..=per_axis.min(count) {
        for sy in 1..=per_axis.min(count / sx) {
            let sz = (count / (sx * sy)).min(per_axis);
            let (held, widest) = (sx * sy * sz, sx.max(sy).max(sz));
            if sz >= 1 && best.is_none_or(|(h, w, _)| held > h || (held == h && widest < w)) {
                best = Some((held, widest, [sx as u32, sy as u32, sz as u32]));
            }
        }
    }
    best.map(|(_, _, slots)| slots)
}

/// Slots per axis for `count` slots, about as many along each axis, at most `per_axis` each.
fn arrange(count: u64, per_axis: u64) -> Option<[u32; 3]> {
    if per_axis == 0 || count == 0 {
        return None;
    }
    let cube = (count as f64).cbrt().ceil() as u64;
    let sx = cube.clamp(1, per_axis);
    let sy = ((count.div_ceil(sx) as f64).sqrt().ceil() as u64).clamp(1, per_axis);
    let sz = count.div_ceil(sx * sy);
    (sz <= per_axis).then_some([sx as u32, sy as u32, sz as u32])
}

/// The layout of a volume of `dims` asked for by `bricking`, with texels of `bytes_per_texel`,
/// under a 3D texture limit of `max` and `budget` bytes: `Auto` bricks only a volume with an
/// axis past the limit or larger than the budget.
pub(super) fn plan(
    dims: [u32; 3],
    bricking: Bricking,
    (max, budget): (u32, Option<u64>),
    bytes_per_texel: u64,
) -> Result<Plan, PlanError> {
    let too_large = dims.iter().any(|&d| d > max);
    let bytes = dims.iter().map(|&d| u64::from(d)).product::<u64>() * bytes_per_texel;
    let over = budget.filter(|&b| bytes > b);
    let bricked = || {
        atlas(dims, DEFAULT_BRICK_VOX, (max, budget), bytes_per_texel)
            .map(Plan::Bricked)
            .map_err(PlanError::Bricks)
    };
    match bricking {
        Bricking::Off if too_large => Err(PlanError::TooLarge { max }),
        Bricking::Off => match over {
            Some(budget) => Err(PlanError::OverBudget { bytes, budget }),
            None => Ok(Plan::Single(dims)),
        },
        Bricking::Auto if !too_large && over.is_none() => Ok(Plan::Single(dims)),
        Bricking::Auto | Bricking::On => bricked(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::residency::Residency;

    #[test]
    fn auto_bricks_only_past_the_limit_or_the_budget() {
        let limit = (4096, None);
        assert_eq!(
            plan([64, 64, 4000], Bricking::Auto, limit, 2),
            Ok(Plan::Single([64, 64, 4000]))
        );
        // 2 × 2 × 141 bricks and the coarsest: 565 slots.
        assert!(matches!(
            plan([64, 64, 4500], Bricking::Auto, limit, 2),
            Ok(Plan::Bricked(Atlas { capacity: 565, .. }))
        ));
        assert!(matches!(
            plan([8, 8, 8], Bricking::On, limit, 2),
            Ok(Plan::Bricked(Atlas { capacity: 1, .. }))
        ));
        assert_eq!(
            plan([64, 64, 4500], Bricking::Off, limit, 2),
            Err(PlanError::TooLarge { max: 4096 })
        );
        // 256³ at 2 bytes is 33.6 MB: under 30 MB it is bricked in 381 slots of 34³ × 2 bytes
        // (full resolution's 512 bricks and the coarsest need 513), 380 of them a box (2 × 10 × 19).
        let budget = (4096, Some(30_000_000));
        assert!(matches!(
            plan([256; 3], Bricking::Auto, budget, 2),
            Ok(Plan::Bricked(Atlas { capacity: 380, .. }))
        ));
        assert!(matches!(
            plan([256; 3], Bricking::Off, budget, 2),
            Err(PlanError::OverBudget { .. })
        ));
        assert!(matches!(
            plan([256; 3], Bricking::Auto, (4096, Some(50_000)), 2),
            Err(PlanError::Bricks(BrickError::Budget { .. }))
        ));
    }

    #[test]
    fn the_atlas_texture_never_takes_more_slots_than_the_budget_holds() {
        let slot_bytes = 34u64.pow(3) * 2;
        for slots in [1, 2, 7, 30, 80, 81, 99, 1000, 12_345, 20_000] {
            let Ok(Plan::Bricked(atlas)) = plan(
                [2048, 2048, 1024],
                Bricking::On,
                (4096, Some(slots * slot_bytes)),
                2,
            ) else {
                panic!("bricked under {slots} slots");
            };
            let count = slot_count(atlas.slots);
            assert!(count <= slots, "{slots}: {atlas:?}");
            assert!(u64::from(atlas.capacity) <= count, "{slots}: {atlas:?}");
            // The best box within loses few slots.
            assert!(
                count * 100 >= slots * 95 || slots < 20,
                "{slots}: {atlas:?}"
            );
        }
    }

    #[test]
    fn a_volume_whose_bricks_overflow_the_atlas_opens_coarser_and_says_why() {
        // An atlas of 8 slots per axis (512) under a 272-texel limit: 320³ has 1000 bricks of
        // 32³ at full resolution, 125 at half.
        let limits = (8 * 34, None);
        let Ok(Plan::Bricked(atlas)) = plan([320; 3], Bricking::Auto, limits, 1) else {
            panic!("bricked");
        };
        assert_eq!((atlas.slots, atlas.capacity), ([8, 8, 8], 512));
        let residency = Residency::new([320; 3], 32, atlas.slots, atlas.capacity);
        let level = residency.decide(&[true; 1000], &[]).level;
        assert_eq!(level, 1);
        let note = coarser_note(([320; 3], 32, level), limits, 1).expect("a note");
        assert!(
            note.contains("1/2 resolution (160 x 160 x 160 voxels, level 1)")
                && note.contains("1000 bricks"),
            "{note}"
        );
        let budget = (4096, Some(10_000_000));
        let note = coarser_note(([320; 3], 32, 2), budget, 1).expect("a note");
        assert!(
            note.contains("takes 39.3 MB, more than the GPU memory budget of 10.0 MB"),
            "{note}"
        );
        assert_eq!(coarser_note(([4; 3], 32, 0), limits, 1), None);
    }
}
