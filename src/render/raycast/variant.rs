//! The ray-casting pipeline variants: one per key {mode, strategy, path, statistics, shading,
//! gradient, MIP colouring, pre-integration}, each composed from the WGSL modules its key
//! selects, so that no variant carries code it cannot run.

use crate::render::shader::{ShaderError, compose};
use crate::settings::effects::{GradientScheme, MipColor, Shading};
use crate::settings::{ConcretePath, Mode, RenderSettings, Strategy};

/// Identifies one ray-casting pipeline variant. Build it with [`PipelineKey::new`], which drops
/// what a mode does not use (lighting outside DVR and isosurfaces, MIP colouring outside MIP), so
/// equal scenes share one pipeline and no variant carries code it cannot run.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct PipelineKey {
    /// Visual effect.
    pub mode: Mode,
    /// Work-saving strategy.
    pub strategy: Strategy,
    /// Fragment or compute.
    pub path: ConcretePath,
    /// Whether the variant counts samples (atomics); normal variants carry no counting code.
    pub stats: bool,
    /// Lighting (always `Off` for modes that cannot light).
    pub shading: Shading,
    /// Gradient estimator (always `Central` when unlit).
    pub gradient: GradientScheme,
    /// MIP/MinIP colouring (always `Window` in other modes).
    pub mip_color: MipColor,
    /// Pre-integrated classification (DVR only).
    pub preintegrated: bool,
}

impl PipelineKey {
    /// The variant for `settings` on `path`.
    pub fn new(settings: &RenderSettings, path: ConcretePath, stats: bool) -> Self {
        let shading = if settings.mode.can_shade() {
            settings.shading
        } else {
            Shading::Off
        };
        Self {
            mode: settings.mode,
            strategy: settings.strategy.for_mode(settings.mode),
            path,
            stats,
            shading,
            gradient: if shading == Shading::Phong {
                settings.gradient
            } else {
                GradientScheme::Central
            },
            mip_color: if matches!(settings.mode, Mode::Mip | Mode::MinIp) {
                settings.mip_color
            } else {
                MipColor::Window
            },
            preintegrated: settings.preintegrated && settings.mode == Mode::Dvr,
        }
    }

    /// Every distinct variant, for validation tests.
    pub fn all() -> Vec<Self> {
        let mut keys = Vec::new();
        for mode in Mode::ALL {
            for strategy in Strategy::ALL {
                for path in [ConcretePath::Fragment, ConcretePath::Compute] {
                    for stats in [false, true] {
                        for shading in [Shading::Off, Shading::Phong] {
                            for gradient in [GradientScheme::Central, GradientScheme::FourthOrder] {
                                for (mip_color, preintegrated) in [
                                    (MipColor::Window, false),
                                    (MipColor::Tf, false),
                                    (MipColor::Window, true),
                                ] {
                                    let settings = RenderSettings {
                                        mode,
                                        strategy,
                                        shading,
                                        gradient,
                                        mip_color,
                                        preintegrated,
                                        ..RenderSettings::default()
                                    };
                                    if settings.validate().is_err() {
                                        continue;
                                    }
                                    let key = Self::new(&settings, path, stats);
                                    if !keys.contains(&key) {
                                        keys.push(key);
                                    }
                                }
                            }
                        }
                    }
                }
            }
        }
        keys
    }

    /// The preprocessor symbols this variant is compiled with.
    pub fn defines(&self) -> Vec<&'static str> {
        let mut defines = Vec::new();
        defines.push(match self.mode {
            Mode::Dvr => "MODE_DVR",
            Mode::Iso => "MODE_ISO",
            Mode::Mip => "MODE_MIP",
            Mode::MinIp => "MODE_MINIP",
            Mode::Xray => "MODE_XRAY",
            Mode::XrayAttenuation => "MODE_XRAY_ATTENUATION",
        });
        if self.shading == Shading::Phong {
            defines.push("SHADING");
        }
        if self.gradient == GradientScheme::FourthOrder {
            defines.push("GRADIENT_FOURTH_ORDER");
        }
        if self.mip_color == MipColor::Tf {
            defines.push("MIP_TF_COLOR");
        }
        if self.strategy.terminates_early() {
            defines.push("EARLY_TERMINATION");
        }
        if self.strategy.leaps() {
            defines.push("LEAP");
            // How the leaping loop walks (shaders/shared/march.wgsl), chosen by measurement on
            // an H200 (docs/benchmarks/nvidia-h200-leap-walk): block runs for the octree's MIP,
            // MinIP, isosurface and X-ray (MIP 1.1-2x faster); sample by sample for DVR (block
            // runs up to 1.55x slower: its rays end early, at different samples) and for the
            // distance field (X-ray up to 1.4x slower in runs). Never with PREINTEGRATED (DVR
            // only), and DVR's mode module has no acc_prime.
            if self.walks_in_runs() {
                defines.push("LEAP_RUNS");
            }
        }
        if self.batches_samples() {
            defines.push("SAMPLE_BATCH");
        }
        if self.strategy == Strategy::RcSDistance {
            defines.push("LEAP_DISTANCE");
        }
        if self.stats {
            defines.push("STATS");
        }
        if self.preintegrated {
            defines.push("PREINTEGRATED");
        }
        defines
    }

    /// Whether the loop takes samples four at a time, their texture reads issued together
    /// (`take_batch`, shaders/shared/march.wgsl): only in loops that take runs of samples with
    /// no per-sample leaping test, i.e. without leaping or in block runs.
    pub fn batches_samples(&self) -> bool {
        !self.strategy.leaps() || self.walks_in_runs()
    }

    /// Whether a leaping variant walks in block runs (LEAP_RUNS) rather than sample by sample.
    fn walks_in_runs(&self) -> bool {
        self.strategy.leaps() && self.mode != Mode::Dvr && self.strategy != Strategy::RcSDistance
    }

    /// The composed WGSL of this variant.
    pub fn source(&self) -> Result<String, ShaderError> {
        let entry = match self.path {
            ConcretePath::Fragment => "entry/raycast_fragment.wgsl",
            ConcretePath::Compute => "entry/raycast_compute.wgsl",
        };
        compose(entry, &self.defines())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The batched loop has no leaping test: a variant that leaps sample by sample must never
    /// batch, or it would stop leaping (march.wgsl takes the batch in place of that walk).
    #[test]
    fn only_loops_without_per_sample_leaping_batch() {
        let keys = PipelineKey::all();
        assert!(keys.iter().any(|k| k.defines().contains(&"SAMPLE_BATCH")));
        for key in keys {
            let defines = key.defines();
            let batches = defines.contains(&"SAMPLE_BATCH");
            let leaps = defines.contains(&"LEAP");
            let runs = defines.contains(&"LEAP_RUNS");
            assert_eq!(batches, !leaps || runs, "{key:?}: {defines:?}");
        }
    }
}
