//! What [`Strategy::Auto`] stands for: the strategy chosen for one frame's inputs, kept by the
//! renderer and made by its caller (`auto_strategy`, which times RC-t against the mode's leaping
//! strategy). Pure: no GPU here.

use crate::settings::{RenderSettings, Strategy};

/// The inputs a choice holds for: everything a frame's cost depends on but the camera.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ChoiceKey {
    /// The frame's settings, with the sample offset left out (progressive refinement shifts it
    /// every frame, at the same cost).
    pub settings: RenderSettings,
    /// Image size in pixels.
    pub size: [u32; 2],
    /// The generation of the renderer's transfer function.
    pub transfer: u64,
}

impl ChoiceKey {
    /// The key of a frame with `settings` at `size` under transfer-function generation
    /// `transfer`.
    pub fn new(settings: &RenderSettings, size: [u32; 2], transfer: u64) -> Self {
        // Refinement's frames of one view are one input: each keyed as its frame 0.
        Self {
            settings: super::refine::frame_settings(settings, 0),
            size,
            transfer,
        }
    }
}

/// How a choice was made.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ChoiceBasis {
    /// Both strategies timed on these inputs: the median milliseconds of a frame of each.
    Timed {
        /// RC-t's frame time.
        rct_ms: f64,
        /// The leaping strategy's frame time.
        leaping_ms: f64,
    },
    /// Not timed: a CPU driver, whose wall clock (its only clock) follows the machine's load,
    /// takes the leaping strategy.
    CpuDriver,
    /// Not timed yet: the last choice carried over while the user is active (dragging the
    /// camera or a transfer-function point); timed once they are still.
    CarriedOver,
}

impl ChoiceBasis {
    /// Whether the choice is final for its inputs (a carried-over one is timed later).
    pub fn is_settled(self) -> bool {
        !matches!(self, Self::CarriedOver)
    }
}

/// A choice for [`Strategy::Auto`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StrategyChoice {
    /// The inputs it holds for.
    pub key: ChoiceKey,
    /// The concrete strategy: RC-t or [`Strategy::leaping`] of the key's mode.
    pub strategy: Strategy,
    /// How it was made.
    pub basis: ChoiceBasis,
}

impl StrategyChoice {
    /// How much faster than RC-t the leaping strategy must have been timed to be chosen: a
    /// fraction of RC-t's time. A choice holds for every view, and is timed on a few, so a
    /// near-tie goes to RC-t, which costs at most this much where leaping was really faster.
    /// Chosen by replaying the rule offline on a benchmark run's frames: timed on three views, a
    /// 5 % margin left fewer cases under 0.98× RC-t's fps over the orbit than none
    /// (docs/benchmarks/nvidia-h200-auto).
    pub const LEAPING_MARGIN: f64 = 0.05;

    /// The choice between RC-t and the leaping strategy of `key`'s mode timed at `rct_ms` and
    /// `leaping_ms`: leaping where it was faster by more than [`Self::LEAPING_MARGIN`], else
    /// RC-t; leaping, as untimed, where a time is not a number.
    pub fn timed(key: ChoiceKey, rct_ms: f64, leaping_ms: f64) -> Self {
        let leaping = Strategy::leaping(key.settings.mode);
        let untimed = rct_ms.is_nan() || leaping_ms.is_nan();
        let strategy = if untimed || leaping_ms < rct_ms * (1.0 - Self::LEAPING_MARGIN) {
            leaping
        } else {
            Strategy::RcT
        };
        Self {
            key,
            strategy,
            basis: ChoiceBasis::Timed { rct_ms, leaping_ms },
        }
    }

    /// One line for people: `RC-t (timed 0.310 ms against RC-s-df's 0.450 ms)`.
    pub fn describe(&self) -> String {
        let leaping = Strategy::leaping(self.key.settings.mode).label();
        match self.basis {
            ChoiceBasis::Timed { rct_ms, leaping_ms } => format!(
                "{} (timed: RC-t {rct_ms:.3} ms, {leaping} {leaping_ms:.3} ms a frame)",
                self.strategy.label()
            ),
            ChoiceBasis::CpuDriver => {
                format!("{} (a CPU driver: not timed)", self.strategy.label())
            }
            ChoiceBasis::CarriedOver => {
                format!("{} (carried over, not yet timed)", self.strategy.label())
            }
        }
    }
}

/// The concrete strategy a frame with `settings` runs, where `choice` is the renderer's last
/// choice and `key` the frame's [`ChoiceKey`]: for `auto`, the choice made for exactly these
/// inputs, else the leaping strategy ([`Strategy::untimed`]); any other strategy as the mode runs
/// it.
pub fn concrete(
    settings: &RenderSettings,
    key: &ChoiceKey,
    choice: Option<&StrategyChoice>,
) -> Strategy {
    match choice {
        Some(c) if settings.strategy == Strategy::Auto && c.key == *key => c.strategy,
        _ => settings.strategy.untimed(settings.mode),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::settings::Mode;

    fn key(mode: Mode, transfer: u64) -> ChoiceKey {
        let settings = RenderSettings {
            mode,
            ..RenderSettings::default()
        };
        ChoiceKey::new(&settings, [64, 48], transfer)
    }

    #[test]
    fn leaping_is_chosen_where_it_was_timed_clearly_faster() {
        let k = key(Mode::Dvr, 1);
        assert_eq!(StrategyChoice::timed(k, 0.3, 0.4).strategy, Strategy::RcT);
        assert_eq!(
            StrategyChoice::timed(k, 0.4, 0.3).strategy,
            Strategy::RcSDistance
        );
        // A tie, or a win by less than the margin, goes to RC-t; a time that is not a number
        // leaves the leaping strategy, as untimed.
        assert_eq!(StrategyChoice::timed(k, 0.3, 0.3).strategy, Strategy::RcT);
        assert_eq!(StrategyChoice::timed(k, 1.0, 0.96).strategy, Strategy::RcT);
        assert_eq!(
            StrategyChoice::timed(k, 1.0, 0.94).strategy,
            Strategy::RcSDistance
        );
        assert_eq!(
            StrategyChoice::timed(k, f64::NAN, 0.3).strategy,
            Strategy::RcSDistance
        );
        // MIP leaps by the octree.
        let mip = key(Mode::Mip, 1);
        assert_eq!(StrategyChoice::timed(mip, 0.4, 0.3).strategy, Strategy::RcS);
        let line = StrategyChoice::timed(k, 0.31, 0.45).describe();
        assert!(
            line.starts_with("RC-t") && line.contains("RC-s-df 0.450"),
            "{line}"
        );
    }

    #[test]
    fn a_choice_holds_for_its_own_inputs_only() {
        let k = key(Mode::Dvr, 1);
        let choice = StrategyChoice::timed(k, 0.3, 0.4);
        let auto = k.settings;
        assert_eq!(concrete(&auto, &k, Some(&choice)), Strategy::RcT);
        // Another transfer function, size or knob: not timed for those, so leaping.
        for other in [
            key(Mode::Dvr, 2),
            ChoiceKey::new(&auto, [65, 48], 1),
            ChoiceKey::new(
                &RenderSettings {
                    step_vox: 1.0,
                    ..auto
                },
                [64, 48],
                1,
            ),
        ] {
            assert_eq!(
                concrete(&other.settings, &other, Some(&choice)),
                Strategy::RcSDistance
            );
        }
        // Refinement's shifted sample offset and light sample are the same inputs.
        let shifted = RenderSettings {
            sample_offset: 0.125,
            shadows: crate::settings::Shadows {
                sample: crate::sampling::light_sample(3),
                ..auto.shadows
            },
            ..auto
        };
        let shifted_key = ChoiceKey::new(&shifted, [64, 48], 1);
        assert_eq!(shifted_key, k);
        assert_eq!(
            concrete(&shifted, &shifted_key, Some(&choice)),
            Strategy::RcT
        );
        // A strategy asked for by name is never replaced.
        let named = RenderSettings {
            strategy: Strategy::RcS,
            ..auto
        };
        assert_eq!(
            concrete(&named, &ChoiceKey::new(&named, [64, 48], 1), Some(&choice)),
            Strategy::RcS
        );
        assert_eq!(concrete(&auto, &k, None), Strategy::RcSDistance);
    }

    #[test]
    fn only_a_carried_over_choice_waits_for_timing() {
        assert!(
            ChoiceBasis::Timed {
                rct_ms: 1.0,
                leaping_ms: 2.0
            }
            .is_settled()
        );
        assert!(ChoiceBasis::CpuDriver.is_settled());
        assert!(!ChoiceBasis::CarriedOver.is_settled());
    }
}
