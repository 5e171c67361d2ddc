//! Which layout a volume of a given shape takes on this adapter: one texture or bricks.

use crate::accel::bricks::{BrickError, BrickLayout, DEFAULT_BRICK_VOX};
use crate::settings::Bricking;

/// How a volume is laid out on the GPU.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Plan {
    /// One texture of the volume's size.
    Single([u32; 3]),
    /// Bricks in an atlas.
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
    /// The bricks do not fit an atlas.
    #[error(transparent)]
    Bricks(BrickError),
}

impl Plan {
    /// Texels of the 3D texture (the volume's or the atlas's).
    pub(super) fn extent(&self) -> [u32; 3] {
        match self {
            Self::Single(dims) => *dims,
            Self::Bricked(layout) => layout.atlas_texels(),
        }
    }
}

/// The layout of a volume of `dims` asked for by `bricking` under a 3D texture limit of `max`:
/// `Auto` bricks only a volume with an axis past the limit.
pub(super) fn plan(dims: [u32; 3], bricking: Bricking, max: u32) -> Result<Plan, PlanError> {
    let too_large = dims.iter().any(|&d| d > max);
    match bricking {
        Bricking::Off if too_large => Err(PlanError::TooLarge { max }),
        Bricking::Off => Ok(Plan::Single(dims)),
        Bricking::Auto if !too_large => Ok(Plan::Single(dims)),
        Bricking::Auto | Bricking::On => BrickLayout::new(dims, DEFAULT_BRICK_VOX, max)
            .map(Plan::Bricked)
            .map_err(PlanError::Bricks),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn auto_bricks_only_past_the_limit() {
        assert_eq!(
            plan([64, 64, 4000], Bricking::Auto, 4096),
            Ok(Plan::Single([64, 64, 4000]))
        );
        assert!(matches!(
            plan([64, 64, 4500], Bricking::Auto, 4096),
            Ok(Plan::Bricked(_))
        ));
        assert!(matches!(
            plan([8, 8, 8], Bricking::On, 4096),
            Ok(Plan::Bricked(_))
        ));
        assert_eq!(
            plan([64, 64, 4500], Bricking::Off, 4096),
            Err(PlanError::TooLarge { max: 4096 })
        );
    }
}
