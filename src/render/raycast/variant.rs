//! The ray-casting pipeline variants: one per key {mode, strategy, path, statistics, shading,
//! gradient, MIP colouring, pre-integration}, each composed from the WGSL modules its key
//! selects, so that no variant carries code it cannot run.

use crate::render::shader::{ShaderError, compose};
use crate::settings::effects::{GradientScheme, LabelView, MipColor, Shading};
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
    /// Shadows towards the light (`SHADOWS`, shaders/shared/shadow.wgsl): lit DVR and
    /// isosurfaces only.
    pub shadows: bool,
    /// Ambient occlusion (`OCCLUSION`, shaders/shared/occlusion.wgsl): lit DVR and isosurfaces
    /// only.
    pub occlusion: bool,
    /// Whether each ray is split into `RAY_PARTS` parts marched by as many invocations
    /// ([`PipelineKey::new`] says when).
    pub split: bool,
    /// Whether the volume has non-finite voxels (`MISSING_VOXELS`): a sample where one takes
    /// part is taken from the finite ones alone. Set by the renderer from its volume
    /// ([`PipelineKey::for_volume`]); volumes without any carry no such code (its mere presence
    /// in the loop, never taken, cost lavapipe's fragment path accuracy on rays of tens of
    /// thousands of samples).
    pub missing: bool,
    /// Whether the volume is bricked (`BRICKED`): every sample finds its brick through the page
    /// table (shaders/shared/volume.wgsl). Set by the renderer from its volume.
    pub bricked: bool,
    /// How a segmentation shows (`LABELS`, `LABEL_COLOUR`, `LABEL_INSIDE`: shaders/shared/labels.wgsl):
    /// `Off` without one. Set by the renderer from the labels it holds
    /// ([`PipelineKey::with_labels`]).
    pub labels: LabelView,
}

/// The ray loops, one file each in `shaders/march/`, picked by [`PipelineKey::ray_loop`] as the
/// mode picks its mode file. Each was chosen by measurement on an H200 (the figures are in
/// `docs/benchmarks/`):
///
/// - [`Loop::Plain`], `march/plain.wgsl`: RC and RC-t; every sample, four texture reads at once
///   (faster than one by one: `nvidia-h200-sample-batch`).
/// - [`Loop::SampleWise`], `march/samplewise.wgsl`: leaping DVR (pre-integrated too); a lookup
///   where a sample passes the last region found. Its rays end early at different samples: block
///   runs measured up to 1.9× slower (`nvidia-h200-leap-walk`, `nvidia-h200-two-sided`).
/// - [`Loop::Runs`], `march/runs.wgsl`: leaping isosurface, MIP, MinIP and X-ray; one question
///   per block, then its samples four reads at once (faster than sample by sample:
///   `nvidia-h200-leap-walk`, `nvidia-h200-two-sided`, `nvidia-h200-iso-landing`).
///
/// Any loop may march a ray in parts (`RAY_SPLIT`, `march/parts.wgsl`) on the compute path of
/// small images: [`PipelineKey::new`] says where (`nvidia-h200-ray-split`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum Loop {
    /// RC and RC-t: every grid sample.
    Plain,
    /// Leaping, asking again where a sample passes the last region found.
    SampleWise,
    /// Leaping in block runs.
    Runs,
}

impl Loop {
    /// The preprocessor symbol that includes its file (shaders/march/march.wgsl).
    fn define(self) -> &'static str {
        match self {
            Self::Plain => "LOOP_PLAIN",
            Self::SampleWise => "LOOP_SAMPLEWISE",
            Self::Runs => "LOOP_RUNS",
        }
    }
}

/// The compute entry point of every ray-casting variant (shaders/entry/raycast_compute.wgsl).
pub const COMPUTE_ENTRY: &str = "cs_raycast";
/// The vertex entry point of the fragment path's proxy geometry (shaders/shared/proxy.wgsl).
pub const PROXY_VERTEX_ENTRY: &str = "vs_proxy";
/// The fragment entry point of every fragment-path ray-casting variant
/// (shaders/entry/raycast_fragment.wgsl).
pub const FRAGMENT_ENTRY: &str = "fs_raycast";

/// Images of at most this many pixels split their rays (see [`PipelineKey::new`]): 512 × 512
/// does (measured faster), 1024 × 1024 and 1920 × 1080 do not (measured slower); sizes between
/// were not measured.
pub const SPLIT_MAX_PIXELS: u64 = 1 << 19;

impl PipelineKey {
    /// The variant for `settings` on `path`, for an image of `size` pixels.
    ///
    /// On the compute path, images of at most [`SPLIT_MAX_PIXELS`] split each ray into
    /// `RAY_PARTS` parts marched by as many invocations and joined in order (`RAY_SPLIT`,
    /// shaders/entry/raycast_compute.wgsl): a small image has too few rays to fill a large GPU,
    /// so a frame lasts as long as its longest rays, and parts shorten those. Against one
    /// invocation per ray, splitting measured faster at 512² and slower at 1024² and
    /// 1920 × 1080 (more invocations, each paying for a ray's set-up, on a GPU already full;
    /// docs/benchmarks/nvidia-h200-ray-split). MinIP never splits (its rays mostly end at their
    /// first sample: splitting measured slower), nor does
    /// pre-integrated DVR (its segments would have to start across the parts' joints), nor DVR
    /// lit only where a sample's weight α·(1 − A) passes a threshold (a part does not know the
    /// A in front of it). Images are those of one invocation per ray, except DVR's with early
    /// termination: a part behind the one where the whole ray would stop adds what it took before
    /// it learnt of the stop, less than the 1 − `termination_alpha` of light the stop leaves.
    pub fn new(settings: &RenderSettings, path: ConcretePath, stats: bool, size: [u32; 2]) -> Self {
        let shading = if settings.mode.can_shade() {
            settings.shading
        } else {
            Shading::Off
        };
        // Whether DVR lights a sample by its weight in the pixel, α·(1 − A): a part of a split
        // ray would not know A in front of it.
        let lit_by_weight = shading == Shading::Phong && settings.light_min_weight > 0.0;
        // A headlight's shadow is the opacity in front of the sample: a part does not know it.
        let shadows = shading == Shading::Phong && settings.shadows.on;
        Self {
            mode: settings.mode,
            // `auto` is resolved before a frame; one that was not renders as it does untimed.
            strategy: settings.strategy.untimed(settings.mode),
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
            shadows,
            occlusion: shading == Shading::Phong && settings.occlusion.on,
            split: path == ConcretePath::Compute
                && settings.mode != Mode::MinIp
                && !(settings.mode == Mode::Dvr
                    && (settings.preintegrated || lit_by_weight || shadows))
                && u64::from(size[0]) * u64::from(size[1]) <= SPLIT_MAX_PIXELS,
            missing: false,
            bricked: false,
            labels: LabelView::Off,
        }
    }

    /// The same variant showing a segmentation as `view` says (`Off`: none loaded). X-ray, a
    /// density integral that no one sample colours, drops the colouring.
    /// A ray drawing surfaces is never split (its parts would each need the mask's side at
    /// their start).
    pub fn with_labels(self, view: LabelView) -> Self {
        let xray = matches!(self.mode, Mode::Xray | Mode::XrayAttenuation);
        let labels = match view {
            LabelView::Colour if xray => LabelView::Off,
            LabelView::ColourInside if xray => LabelView::Inside,
            view => view,
        };
        let split = self.split && !labels.surfaces();
        Self {
            labels,
            split,
            ..self
        }
    }

    /// The same variant for a volume that has non-finite voxels (`missing`) or not, bricked or
    /// not.
    pub fn for_volume(self, missing: bool, bricked: bool) -> Self {
        Self {
            missing,
            bricked,
            ..self
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
                                // MIP colouring, pre-integration, shadows, occlusion.
                                for (mip_color, preintegrated, on, occluded) in [
                                    (MipColor::Window, false, false, false),
                                    (MipColor::Tf, false, false, false),
                                    (MipColor::Window, true, false, false),
                                    (MipColor::Window, false, true, false),
                                    (MipColor::Window, true, true, false),
                                    (MipColor::Window, false, false, true),
                                    (MipColor::Window, false, true, true),
                                ] {
                                    let settings = RenderSettings {
                                        mode,
                                        strategy,
                                        shading,
                                        gradient,
                                        mip_color,
                                        preintegrated,
                                        shadows: crate::settings::Shadows {
                                            on,
                                            ..Default::default()
                                        },
                                        occlusion: crate::settings::Occlusion {
                                            on: occluded,
                                            ..Default::default()
                                        },
                                        ..RenderSettings::default()
                                    };
                                    if settings.validate().is_err() {
                                        continue;
                                    }
                                    for size in [[512, 512], [1920, 1080]] {
                                        let key = Self::new(&settings, path, stats, size);
                                        // Volumes with missing voxels, bricked volumes and
                                        // both: every mode, strategy, path and lighting (they
                                        // touch only the sampling all of them share).
                                        let sampled = !stats
                                            && gradient == GradientScheme::Central
                                            && mip_color == MipColor::Window;
                                        let others = [(true, false), (false, true), (true, true)]
                                            .map(|(m, b)| key.for_volume(m, b));
                                        let others = others.iter().filter(|_| sampled).copied();
                                        // Segmentations in every view, on the plain
                                        // volume and a bricked one.
                                        let labelled = [
                                            LabelView::Colour,
                                            LabelView::Inside,
                                            LabelView::ColourInside,
                                            LabelView::Surfaces,
                                        ]
                                        .map(|view| key.with_labels(view))
                                        .into_iter()
                                        .flat_map(|k| [k, k.for_volume(false, true)])
                                        .filter(|_| sampled);
                                        for key in
                                            std::iter::once(key).chain(others).chain(labelled)
                                        {
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
        }
        defines.push(self.ray_loop().define());
        if self.split {
            defines.push("RAY_SPLIT");
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
        if self.shadows {
            defines.push("SHADOWS");
        }
        if self.occlusion {
            defines.push("OCCLUSION");
        }
        if self.missing {
            defines.push("MISSING_VOXELS");
        }
        if self.bricked {
            defines.push("BRICKED");
        }
        if self.labels != LabelView::Off {
            defines.push("LABELS");
        }
        if self.labels.colours() {
            defines.push("LABEL_COLOUR");
        }
        if self.labels.cuts() {
            defines.push("LABEL_INSIDE");
        }
        if self.labels.surfaces() {
            defines.push("LABEL_SURFACES");
        }
        defines
    }

    /// The loop this variant's rays walk in ([`Loop`]).
    fn ray_loop(&self) -> Loop {
        match (self.strategy.leaps(), self.mode) {
            (false, _) => Loop::Plain,
            (true, Mode::Dvr) => Loop::SampleWise,
            (true, _) => Loop::Runs,
        }
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

    /// Rays split on the compute path of small images only, and never where the parts could
    /// not be joined exactly (MinIP: no gain; pre-integrated DVR; DVR lit by weight).
    #[test]
    fn rays_split_only_where_measured_faster_and_joined_exactly() {
        let small = [512, 512];
        let large = [1920, 1080];
        let key =
            |settings: &RenderSettings, path, size| PipelineKey::new(settings, path, false, size);
        let plain = RenderSettings::default();
        assert!(key(&plain, ConcretePath::Compute, small).split);
        assert!(key(&plain, ConcretePath::Compute, [724, 724]).split);
        assert!(!key(&plain, ConcretePath::Compute, [725, 725]).split);
        assert!(!key(&plain, ConcretePath::Compute, large).split);
        assert!(!key(&plain, ConcretePath::Fragment, small).split);
        for mode in Mode::ALL {
            let settings = RenderSettings { mode, ..plain };
            assert_eq!(
                key(&settings, ConcretePath::Compute, small).split,
                mode != Mode::MinIp,
                "{mode:?}"
            );
        }
        let preintegrated = RenderSettings {
            preintegrated: true,
            ..plain
        };
        assert!(!key(&preintegrated, ConcretePath::Compute, small).split);
        let by_weight = RenderSettings {
            shading: Shading::Phong,
            light_min_weight: 0.01,
            ..plain
        };
        assert!(!key(&by_weight, ConcretePath::Compute, small).split);
        let unlit = RenderSettings {
            shading: Shading::Off,
            ..by_weight
        };
        assert!(key(&unlit, ConcretePath::Compute, small).split);
    }

    /// Every variant walks exactly one loop: the plain one without leaping, block runs for every
    /// leaping mode but DVR, sample by sample for leaping DVR (pre-integrated included).
    #[test]
    fn every_variant_walks_one_loop() {
        let keys = PipelineKey::all();
        for key in &keys {
            let defines = key.defines();
            let loops: Vec<_> = defines.iter().filter(|d| d.starts_with("LOOP_")).collect();
            assert_eq!(loops.len(), 1, "{key:?}: {defines:?}");
            let leaps = defines.contains(&"LEAP");
            let expected = match (leaps, key.mode) {
                (false, _) => "LOOP_PLAIN",
                (true, Mode::Dvr) => "LOOP_SAMPLEWISE",
                (true, _) => "LOOP_RUNS",
            };
            assert_eq!(*loops[0], expected, "{key:?}");
        }
        for l in [Loop::Plain, Loop::SampleWise, Loop::Runs] {
            assert!(keys.iter().any(|k| k.ray_loop() == l), "{l:?} never used");
        }
    }
}
