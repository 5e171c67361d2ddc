//! Which layout a volume of a given shape takes on this adapter: one texture, or bricks of the
//! finest level that fits the GPU memory budget and the adapter's 3D texture limit.

use crate::accel::bricks::{BrickError, BrickLayout, DEFAULT_BRICK_VOX};
use crate::settings::Bricking;

/// How a volume is laid out on the GPU.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Plan {
    /// One texture of the volume's size.
    Single([u32; 3]),
    /// Bricks of one level in an atlas.
    Bricked(BrickLayout),
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
        "one texture of the volume takes {} but the GPU memory budget is {}; let it be bricked \
         (--bricks auto)",
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
            Self::Bricked(layout) => layout.atlas_texels(),
        }
    }
}

/// Why `plan` holds a coarser level than the volume's own, as one line (`None` at full
/// resolution): which level, its size, and what full resolution would need.
pub(super) fn coarser_note(
    plan: &Plan,
    (max, budget): (u32, Option<u64>),
    bytes_per_texel: u64,
) -> Option<String> {
    let Plan::Bricked(layout) = plan else {
        return None;
    };
    if layout.level == 0 {
        return None;
    }
    let [x, y, z] = layout.level_dims();
    let why = match BrickLayout::at_level(layout.dims, layout.brick_vox, 0, max) {
        Ok(full) => format!(
            "full resolution takes {}, more than the GPU memory budget of {}",
            crate::text::bytes(full.brick_bytes(bytes_per_texel)),
            crate::text::bytes(budget.unwrap_or(u64::MAX))
        ),
        Err(e) => format!("at full resolution {e}"),
    };
    Some(format!(
        "the volume is shown at 1/{} resolution ({x} x {y} x {z} voxels, level {}): {why}",
        1u32 << layout.level,
        layout.level
    ))
}

/// The layout of a volume of `dims` asked for by `bricking`, with texels of `bytes_per_texel`,
/// under a 3D texture limit of `max` and `budget` bytes: `Auto` bricks only a volume with an
/// axis past the limit or larger than the budget; bricks are of the finest level that fits.
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
        BrickLayout::finest_within(
            dims,
            DEFAULT_BRICK_VOX,
            max,
            (budget.unwrap_or(u64::MAX), bytes_per_texel),
        )
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

    #[test]
    fn auto_bricks_only_past_the_limit_or_the_budget() {
        let limit = (4096, None);
        assert_eq!(
            plan([64, 64, 4000], Bricking::Auto, limit, 2),
            Ok(Plan::Single([64, 64, 4000]))
        );
        assert!(matches!(
            plan([64, 64, 4500], Bricking::Auto, limit, 2),
            Ok(Plan::Bricked(BrickLayout { level: 0, .. }))
        ));
        assert!(matches!(
            plan([8, 8, 8], Bricking::On, limit, 2),
            Ok(Plan::Bricked(_))
        ));
        assert_eq!(
            plan([64, 64, 4500], Bricking::Off, limit, 2),
            Err(PlanError::TooLarge { max: 4096 })
        );
        // 256³ at 2 bytes is 33.6 MB: under 30 MB it is bricked, at half resolution (64 bricks
        // of 34³ × 2 bytes: 5 MB; full resolution's 512 need 40 MB).
        let budget = (4096, Some(30_000_000));
        assert!(matches!(
            plan([256; 3], Bricking::Auto, budget, 2),
            Ok(Plan::Bricked(BrickLayout { level: 1, .. }))
        ));
        assert!(matches!(
            plan([256; 3], Bricking::Off, budget, 2),
            Err(PlanError::OverBudget { .. })
        ));
    }

    #[test]
    fn a_volume_whose_bricks_overflow_the_atlas_opens_coarser_and_says_why() {
        // An atlas of 8 slots per axis (512 bricks) under a 272-texel limit: 320³ has 1000
        // bricks of 32³ at full resolution, 125 at half.
        let limits = (8 * 34, None);
        let atlas_bound = plan([320; 3], Bricking::Auto, limits, 1).expect("coarser");
        assert!(matches!(
            atlas_bound,
            Plan::Bricked(BrickLayout { level: 1, .. })
        ));
        let note = coarser_note(&atlas_bound, limits, 1).expect("a note");
        assert!(
            note.contains("1/2 resolution (160 x 160 x 160 voxels, level 1)")
                && note.contains("1000 bricks"),
            "{note}"
        );
        let budget = (4096, Some(10_000_000));
        let budget_bound = plan([320; 3], Bricking::Auto, budget, 1).expect("coarser");
        let note = coarser_note(&budget_bound, budget, 1).expect("a note");
        assert!(
            note.contains("takes 39.3 MB, more than the GPU memory budget of 10.0 MB"),
            "{note}"
        );
        assert_eq!(coarser_note(&Plan::Single([4; 3]), limits, 1), None);
    }
}
