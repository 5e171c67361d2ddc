//! What the accuracy benchmark renders: each quality knob swept on its own from a baseline (the
//! app's defaults), the step size additionally with pre-integration, jitter and without opacity
//! correction, and the reference each is compared with.

use serde::{Deserialize, Serialize};

use crate::settings::DEFAULT_TERMINATION_ALPHA;
use crate::settings::effects::{
    GradientScheme, Light, MAX_ISO_REFINEMENT, SHADOW_STEP_RANGE, Shading, Shadows,
};
use crate::settings::{Mode, QualityPreset, RenderSettings, Strategy, TexturePrecision};

/// One swept quality knob (a series on the plot).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Knob {
    /// Step size, post-classification (the baseline's series).
    Step,
    /// Step size with pre-integrated classification.
    StepPreintegrated,
    /// Step size with jittered ray starts.
    StepJittered,
    /// Step size without opacity correction.
    StepUncorrected,
    /// Early-termination threshold.
    Termination,
    /// Gradient estimator of the lighting.
    Gradient,
    /// The weight below which DVR samples are composited unlit.
    LightMinWeight,
    /// Secant refinement steps of the isosurface (isosurface mode).
    IsoRefinement,
    /// Texel precision of the volume texture.
    Precision,
    /// The window's quality presets (all their knobs at once).
    Preset,
    /// The shadow rays' step (DVR shadowed by a directional light).
    ShadowStep,
    /// The weight below which shadowed DVR's samples are neither lit nor shadowed: the
    /// culling of shadow rays where a sample cannot change the pixel.
    ShadowLightMinWeight,
}

/// The images a knob's variants are compared with: each group has its own reference.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum KnobGroup {
    /// DVR under the baseline's light.
    Dvr,
    /// The isosurface.
    Iso,
    /// DVR shadowed by the directional light [`SHADOW_LIGHT`].
    Shadows,
}

impl KnobGroup {
    /// Every group, in the order references are made.
    pub const ALL: [Self; 3] = [Self::Dvr, Self::Iso, Self::Shadows];

    /// The mode its images are rendered in.
    pub fn mode(self) -> Mode {
        match self {
            Self::Iso => Mode::Iso,
            Self::Dvr | Self::Shadows => Mode::Dvr,
        }
    }

    /// Name in progress lines and plots.
    pub fn label(self) -> &'static str {
        match self {
            Self::Dvr => "DVR",
            Self::Iso => "isosurface",
            Self::Shadows => "DVR with shadows",
        }
    }
}

impl Knob {
    /// All knobs, in table order.
    pub const ALL: [Self; 12] = [
        Self::Step,
        Self::StepPreintegrated,
        Self::StepJittered,
        Self::StepUncorrected,
        Self::Termination,
        Self::Gradient,
        Self::LightMinWeight,
        Self::IsoRefinement,
        Self::Precision,
        Self::Preset,
        Self::ShadowStep,
        Self::ShadowLightMinWeight,
    ];

    /// Name in tables and legends.
    pub fn label(self) -> &'static str {
        match self {
            Self::Step => "step",
            Self::StepPreintegrated => "step, pre-integrated",
            Self::StepJittered => "step, jittered",
            Self::StepUncorrected => "step, no opacity correction",
            Self::Termination => "termination threshold",
            Self::Gradient => "gradient",
            Self::LightMinWeight => "lighting threshold",
            Self::IsoRefinement => "iso refinement",
            Self::Precision => "texture precision",
            Self::Preset => "quality preset",
            Self::ShadowStep => "shadow step",
            Self::ShadowLightMinWeight => "shadows: lighting threshold",
        }
    }

    /// The reference its variants are compared with.
    pub fn group(self) -> KnobGroup {
        match self {
            Self::IsoRefinement => KnobGroup::Iso,
            Self::ShadowStep | Self::ShadowLightMinWeight => KnobGroup::Shadows,
            _ => KnobGroup::Dvr,
        }
    }

    /// The mode its images are rendered in.
    pub fn mode(self) -> Mode {
        self.group().mode()
    }
}

/// One setting to measure.
#[derive(Clone, Debug, PartialEq)]
pub struct Variant {
    /// The knob it belongs to.
    pub knob: Knob,
    /// The knob's value, for tables (e.g. `0.25`, `fourth-order`).
    pub value: String,
    /// Everything the frame uses.
    pub settings: RenderSettings,
    /// Texel precision of the upload.
    pub precision: TexturePrecision,
}

/// Steps swept, in voxels: the range, 1/8 to 4.
pub const STEPS: [f64; 6] = [0.125, 0.25, 0.5, 1.0, 2.0, 4.0];

/// Termination thresholds swept (1 = never stop early).
pub const TERMINATIONS: [f64; 5] = [0.9, 0.95, 0.99, DEFAULT_TERMINATION_ALPHA, 1.0];

/// Lighting thresholds swept: the weight in the pixel below which a DVR sample is left unlit.
pub const LIGHT_MIN_WEIGHTS: [f64; 6] = [0.0, 1e-4, 1e-3, 3e-3, 1e-2, 3e-2];

/// Iso refinement steps swept.
pub const ISO_REFINEMENTS: [u32; 6] = [0, 1, 2, 4, 6, 8];

/// Step of the reference images, in voxels.
pub const REFERENCE_STEP_VOX: f64 = 1.0 / 16.0;

/// The direction the shadow knobs' light shines along (world; from above one side and in
/// front, so that most views see shadows fall).
pub const SHADOW_LIGHT: [f64; 3] = [0.5, 0.6, 0.62];

/// `base` as DVR shadowed by [`SHADOW_LIGHT`] (shadow step 1 voxel): the shadow knobs' baseline.
fn shadowed(base: &RenderSettings) -> RenderSettings {
    RenderSettings {
        mode: Mode::Dvr,
        shading: Shading::Phong,
        light: Light::Direction(SHADOW_LIGHT),
        shadows: Shadows {
            on: true,
            ..Shadows::default()
        },
        ..*base
    }
}

/// Every variant, one knob at a time from `base` (whose mode is replaced by each knob's).
pub fn plan(base: &RenderSettings) -> Vec<Variant> {
    let dvr = RenderSettings {
        mode: Mode::Dvr,
        ..*base
    };
    let variant = |knob: Knob, value: String, settings: RenderSettings| Variant {
        knob,
        value,
        settings,
        precision: TexturePrecision::Auto,
    };
    let mut out = Vec::new();
    for step_vox in STEPS {
        let at = RenderSettings { step_vox, ..dvr };
        let value = format!("{step_vox}");
        out.push(variant(Knob::Step, value.clone(), at));
        out.push(variant(
            Knob::StepPreintegrated,
            value.clone(),
            RenderSettings {
                preintegrated: true,
                ..at
            },
        ));
        out.push(variant(
            Knob::StepJittered,
            value.clone(),
            RenderSettings { jitter: true, ..at },
        ));
        out.push(variant(
            Knob::StepUncorrected,
            value,
            RenderSettings {
                opacity_correction: false,
                ..at
            },
        ));
    }
    for termination_alpha in TERMINATIONS {
        out.push(variant(
            Knob::Termination,
            format!("{termination_alpha:.4}"),
            RenderSettings {
                termination_alpha,
                ..dvr
            },
        ));
    }
    for gradient in [GradientScheme::Central, GradientScheme::FourthOrder] {
        out.push(variant(
            Knob::Gradient,
            match gradient {
                GradientScheme::Central => "central",
                GradientScheme::FourthOrder => "fourth-order",
            }
            .to_string(),
            RenderSettings { gradient, ..dvr },
        ));
    }
    for light_min_weight in LIGHT_MIN_WEIGHTS {
        out.push(variant(
            Knob::LightMinWeight,
            format!("{light_min_weight}"),
            RenderSettings {
                light_min_weight,
                ..dvr
            },
        ));
    }
    for refine_iterations in ISO_REFINEMENTS {
        let mut settings = RenderSettings {
            mode: Mode::Iso,
            ..*base
        };
        settings.iso.refine_iterations = refine_iterations;
        out.push(variant(
            Knob::IsoRefinement,
            refine_iterations.to_string(),
            settings,
        ));
    }
    for preset in QualityPreset::ALL {
        let mut settings = dvr;
        preset.apply(&mut settings);
        out.push(variant(Knob::Preset, preset.label().to_string(), settings));
    }
    let lit = shadowed(base);
    for step_vox in STEPS {
        let mut settings = lit;
        settings.shadows.step_vox = step_vox;
        out.push(variant(Knob::ShadowStep, format!("{step_vox}"), settings));
    }
    for light_min_weight in LIGHT_MIN_WEIGHTS {
        out.push(variant(
            Knob::ShadowLightMinWeight,
            format!("{light_min_weight}"),
            RenderSettings {
                light_min_weight,
                ..lit
            },
        ));
    }
    for precision in TexturePrecision::ALL {
        out.push(Variant {
            knob: Knob::Precision,
            value: precision.label().to_string(),
            settings: dvr,
            precision,
        });
    }
    out
}

/// The reference for `group` under `base`: 1/16-voxel steps, no early termination or leaping,
/// pre-integrated classification (each 1/16-voxel segment integrated for the TF, so a feature
/// thinner than the step is not missed; at that step the value is linear along a segment to
/// within ~10⁻³ of a voxel's change), fourth-order gradients, the most iso refinement, f32
/// texels; for the shadows, shadow rays at the finest step offered (⅛ voxel).
pub fn reference(base: &RenderSettings, group: KnobGroup) -> (RenderSettings, TexturePrecision) {
    let base = match group {
        KnobGroup::Shadows => {
            let mut s = shadowed(base);
            s.shadows.step_vox = SHADOW_STEP_RANGE.0;
            s
        }
        _ => *base,
    };
    let mut settings = RenderSettings {
        mode: group.mode(),
        strategy: Strategy::Rc,
        step_vox: REFERENCE_STEP_VOX,
        termination_alpha: 1.0,
        light_min_weight: 0.0,
        jitter: false,
        opacity_correction: true,
        preintegrated: true,
        gradient: if base.shading == Shading::Phong {
            GradientScheme::FourthOrder
        } else {
            base.gradient
        },
        ..base
    };
    settings.iso.refine_iterations = MAX_ISO_REFINEMENT;
    (settings, TexturePrecision::Float32)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_variant_differs_from_the_baseline_only_in_its_knob() {
        let base = RenderSettings::default();
        let variants = plan(&base);
        assert_eq!(
            variants.len(),
            5 * STEPS.len() + 5 + 2 + 2 * LIGHT_MIN_WEIGHTS.len() + ISO_REFINEMENTS.len() + 4 + 3
        );
        let lit = shadowed(&base);
        for v in variants.iter().filter(|v| v.knob != Knob::Preset) {
            if v.knob.group() == KnobGroup::Shadows {
                let mut undo = v.settings;
                undo.shadows.step_vox = lit.shadows.step_vox;
                undo.light_min_weight = lit.light_min_weight;
                assert_eq!(undo, lit, "{:?} {}", v.knob, v.value);
                assert!(v.settings.validate().is_ok());
                continue;
            }
            let mut undo = v.settings;
            undo.mode = base.mode;
            undo.step_vox = base.step_vox;
            undo.preintegrated = false;
            undo.jitter = false;
            undo.opacity_correction = true;
            undo.termination_alpha = base.termination_alpha;
            undo.gradient = base.gradient;
            undo.light_min_weight = base.light_min_weight;
            undo.iso = base.iso;
            assert_eq!(undo, base, "{:?} {}", v.knob, v.value);
            assert_eq!(v.settings.mode, v.knob.mode());
            assert!(v.settings.validate().is_ok());
        }
    }

    #[test]
    fn the_reference_is_finer_than_every_variant() {
        let base = RenderSettings::default();
        for v in plan(&base) {
            let (r, _) = reference(&base, v.knob.group());
            assert!(r.step_vox < v.settings.step_vox);
            assert!(r.shadows.step_vox <= v.settings.shadows.step_vox);
            assert_eq!(r.shadows.on, v.settings.shadows.on);
            assert_eq!(r.strategy, Strategy::Rc);
            assert!(r.iso.refine_iterations >= v.settings.iso.refine_iterations);
        }
    }
}
