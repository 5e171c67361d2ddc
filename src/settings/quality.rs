//! Quality presets: Fast, Balanced and Reference, chosen from the Pareto front of the accuracy
//! benchmark (docs/accuracy/README.md gives the figures and the reasoning).

use serde::{Deserialize, Serialize};

use super::effects::GradientScheme;
use super::{DEFAULT_TERMINATION_ALPHA, RenderSettings};

/// A named set of the quality knobs.
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize, clap::ValueEnum,
)]
#[serde(rename_all = "lowercase")]
pub enum QualityPreset {
    /// One-voxel steps, early stop at 99 %, central gradients, jittered starts.
    ///
    /// The fast end of every accuracy front: much faster than Balanced for several times its
    /// RMSE on the scans (docs/accuracy/README.md).
    Fast,
    /// Half-voxel steps, fourth-order gradients, four iso refinements.
    ///
    /// On the Pareto front of every dataset: 1.4–3.1× less RMSE on the scans than the same step
    /// with central differences for 4–27 % more time.
    #[default]
    Balanced,
    /// Eighth-voxel pre-integrated steps, fourth-order gradients, eight iso refinements.
    ///
    /// 4–6× the time of Balanced for 1.7–4.1× less RMSE on the scans and 8–26× less on thin
    /// transfer-function features.
    Reference,
}

/// Early termination of the Fast preset: what is left behind a ray stopped at 99 % adds at most
/// 1 % (2.6 levels of 255); against 1 − 1/255 it barely changed the RMSE and saved a little time
/// (docs/accuracy/README.md).
pub const FAST_TERMINATION_ALPHA: f64 = 0.99;

/// Lighting threshold of Balanced: DVR samples weighing less than 10⁻³ of their pixel are left
/// unlit. Measured faster on the MR head, whose fog of faint samples is where lighting is wasted,
/// for a little more RMSE, and no worse elsewhere; 3·10⁻³ cost the MR head much more RMSE
/// (docs/accuracy/nvidia-h200-lighting).
pub const BALANCED_LIGHT_MIN_WEIGHT: f64 = 1e-3;

/// Lighting threshold of Fast: 3·10⁻³, 32 % faster on the MR head at its RMSE's cost (+54 %
/// against Balanced's step; Fast's own error is 2.5–4× Balanced's already).
pub const FAST_LIGHT_MIN_WEIGHT: f64 = 3e-3;

impl QualityPreset {
    /// All presets, fastest first.
    pub const ALL: [Self; 3] = [Self::Fast, Self::Balanced, Self::Reference];

    /// Name in the window and on the command line.
    pub fn label(self) -> &'static str {
        match self {
            Self::Fast => "Fast",
            Self::Balanced => "Balanced",
            Self::Reference => "Reference",
        }
    }

    /// Sets the knobs this preset decides, leaving the rest of `settings` alone.
    pub fn apply(self, settings: &mut RenderSettings) {
        settings.light_min_weight = match self {
            Self::Fast => FAST_LIGHT_MIN_WEIGHT,
            Self::Balanced => BALANCED_LIGHT_MIN_WEIGHT,
            Self::Reference => 0.0,
        };
        let (step, termination, gradient, refine, jitter, preintegrated) = match self {
            Self::Fast => (
                1.0,
                FAST_TERMINATION_ALPHA,
                GradientScheme::Central,
                1,
                true,
                false,
            ),
            Self::Balanced => (
                0.5,
                DEFAULT_TERMINATION_ALPHA,
                GradientScheme::FourthOrder,
                4,
                false,
                false,
            ),
            Self::Reference => (
                0.125,
                DEFAULT_TERMINATION_ALPHA,
                GradientScheme::FourthOrder,
                8,
                false,
                true,
            ),
        };
        settings.step_vox = step;
        settings.termination_alpha = termination;
        settings.gradient = gradient;
        settings.iso.refine_iterations = refine;
        settings.jitter = jitter;
        settings.preintegrated = preintegrated;
        settings.opacity_correction = true;
    }

    /// The preset whose knobs `settings` has, if any.
    pub fn of(settings: &RenderSettings) -> Option<Self> {
        Self::ALL.into_iter().find(|p| {
            let mut s = *settings;
            p.apply(&mut s);
            s == *settings
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_preset_is_recognised_and_valid_and_ordered_by_cost() {
        let mut last_step = f64::INFINITY;
        for p in QualityPreset::ALL {
            let mut s = RenderSettings::default();
            p.apply(&mut s);
            assert!(s.validate().is_ok(), "{p:?}");
            assert_eq!(QualityPreset::of(&s), Some(p));
            assert!(
                s.step_vox < last_step,
                "{p:?} is not finer than the one before"
            );
            last_step = s.step_vox;
        }
        let mut custom = RenderSettings::default();
        QualityPreset::Balanced.apply(&mut custom);
        custom.step_vox = 0.3;
        assert_eq!(QualityPreset::of(&custom), None);
    }
}
