//! What to render: mode, strategy, path and the quality knobs. Plain, serialisable values shared
//! by the GPU renderer, the CPU reference, the benchmarks, the command line and the window; no
//! GPU code (the renderer turns them into pipelines and uniforms).

pub mod crop;
pub mod effects;
pub mod precision;
pub mod quality;
pub mod upload;

use serde::{Deserialize, Serialize};

pub use crop::{CropBox, CropError};
pub use effects::{
    GradientScheme, IsoSettings, LabelView, Light, MAX_ISO_REFINEMENT, MipColor, Occlusion, Phong,
    Shading, Shadows,
};
pub use precision::TexturePrecision;
pub use quality::QualityPreset;
pub use upload::{Bricking, Upload};

/// The visual effect computed along each ray.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, clap::ValueEnum)]
pub enum Mode {
    /// Direct volume rendering: front-to-back alpha compositing of the transfer function.
    Dvr,
    /// The first crossing of the iso value, refined, lit, coloured by the transfer function.
    Iso,
    /// Maximum intensity projection.
    Mip,
    /// Minimum intensity projection.
    #[value(name = "minip")]
    MinIp,
    /// Mean of the windowed values along the ray's path inside the volume.
    Xray,
    /// A radiograph: 1 − exp(−∫μ ds), with μ proportional to the windowed value.
    #[value(name = "xray-attenuation")]
    XrayAttenuation,
}

impl Mode {
    /// All modes.
    pub const ALL: [Self; 6] = [
        Self::Dvr,
        Self::Iso,
        Self::Mip,
        Self::MinIp,
        Self::Xray,
        Self::XrayAttenuation,
    ];

    /// Whether the mode can light its samples (and so needs gradients).
    pub(crate) fn can_shade(self) -> bool {
        matches!(self, Self::Dvr | Self::Iso)
    }

    /// The name used on the command line.
    pub fn label(self) -> &'static str {
        match self {
            Self::Dvr => "dvr",
            Self::Iso => "iso",
            Self::Mip => "mip",
            Self::MinIp => "minip",
            Self::Xray => "xray",
            Self::XrayAttenuation => "xray-attenuation",
        }
    }
}

/// How the ray loop saves work.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, clap::ValueEnum)]
pub enum Strategy {
    /// RC: every sample from entry to exit.
    #[value(name = "rc")]
    Rc,
    /// RC-t: stop once the accumulated opacity passes the termination threshold.
    #[value(name = "rc-t")]
    RcT,
    /// RC-s: RC-t plus leaping over empty space by a min/max octree (the paper's).
    ///
    /// A ray climbs to the coarsest empty node: the paper's hierarchical leaping.
    #[value(name = "rc-s")]
    RcS,
    /// RC-s with a distance field over blocks: one step clears a whole cube of empty blocks.
    ///
    /// Beyond the paper: one step clears the whole cube of blocks the field proves empty.
    /// Measured the fastest of the three on most volumes of the benchmark, but RC-t can be faster
    /// where little can be skipped (dense volumes, small images: docs/benchmarks; `auto` times
    /// both). The field is two-sided: a ray also takes every sample of a cube of blocks that all
    /// matter without asking about each. It leaps by the transfer function, the X-ray window or
    /// the iso value (one field per side of it); MIP and MinIP leap by the octree as RC-s does.
    #[value(name = "rc-s-df")]
    RcSDistance,
    /// RC-t or the mode's leaping strategy, whichever is timed faster on this GPU.
    ///
    /// The default: RC-t or the mode's leaping strategy ([`Strategy::leaping`]), whichever renders
    /// this volume, transfer function, mode and image size faster on this GPU, timed when they
    /// change (`render::raycast::auto_strategy`); both give the same image (within 1/255). A CPU
    /// driver, whose clock follows the machine's load, takes the leaping strategy untimed.
    #[value(name = "auto")]
    Auto,
}

impl Strategy {
    /// The short name used in tables and on the command line.
    pub fn label(self) -> &'static str {
        match self {
            Self::Rc => "RC",
            Self::RcT => "RC-t",
            Self::RcS => "RC-s",
            Self::RcSDistance => "RC-s-df",
            Self::Auto => "auto",
        }
    }

    /// Whether rays stop once (nearly) opaque.
    pub fn terminates_early(self) -> bool {
        !matches!(self, Self::Rc)
    }

    /// Whether rays leap over empty space (`auto`: where leaping was measured faster, so its
    /// leaping structures and block edge matter).
    pub fn leaps(self) -> bool {
        matches!(self, Self::RcS | Self::RcSDistance | Self::Auto)
    }

    /// The leaping strategy `mode` runs: RC-s-df where the mode has the distance field, else RC-s.
    pub fn leaping(mode: Mode) -> Self {
        Self::RcSDistance.for_mode(mode)
    }

    /// `auto`'s concrete strategy for `mode` until it has been timed: the leaping one (the
    /// faster on most volumes of the benchmark); any other strategy as [`Self::for_mode`] runs it.
    pub fn untimed(self, mode: Mode) -> Self {
        match self {
            Self::Auto => Self::leaping(mode),
            other => other.for_mode(mode),
        }
    }

    /// The strategy `mode` runs with: the distance field exists for DVR, isosurfaces and the
    /// X-ray modes; MIP and MinIP leap by the min/max octree (RC-s) instead.
    pub fn for_mode(self, mode: Mode) -> Self {
        let df_modes = matches!(
            mode,
            Mode::Dvr | Mode::Iso | Mode::Xray | Mode::XrayAttenuation
        );
        if self == Self::RcSDistance && !df_modes {
            Self::RcS
        } else {
            self
        }
    }

    /// The concrete strategies (all but `auto`, which stands for one of them), plainest first.
    pub const ALL: [Self; 4] = [Self::Rc, Self::RcT, Self::RcS, Self::RcSDistance];
}

/// Which entry point runs the ray loop. Both share the same WGSL marching function.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, clap::ValueEnum)]
pub enum RenderPath {
    /// Time both once on this GPU and use the faster (a CPU driver takes compute).
    ///
    /// Resolved by `render::raycast::auto_path`.
    Auto,
    /// The paper's single pass: the ray loop runs in the fragment shader of the front faces.
    Fragment,
    /// A compute shader runs the ray loop, each pixel's ray intersected with the volume's box.
    Compute,
}

/// Where the ray loop runs, once [`RenderPath::Auto`] has been resolved.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum ConcretePath {
    /// In the fragment shader of the front faces.
    Fragment,
    /// In a compute shader, one invocation per pixel, each intersecting its ray with the box.
    Compute,
}

/// Default termination threshold: stop once accumulated opacity exceeds `1 - 1/255`, so the
/// remaining contribution is below one 8-bit level.
pub const DEFAULT_TERMINATION_ALPHA: f64 = 1.0 - 1.0 / 255.0;

/// Everything about a frame except the camera, the volume and the transfer function.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct RenderSettings {
    /// Visual effect.
    pub mode: Mode,
    /// Work-saving strategy.
    pub strategy: Strategy,
    /// Fragment or compute ray loop.
    pub path: RenderPath,
    /// Distance between samples along a ray, in units of the smallest voxel spacing `d0`.
    pub step_vox: f64,
    /// RC-t stops once accumulated opacity exceeds this (in (0, 1]).
    pub termination_alpha: f64,
    /// Position of the first sample within the first step, in steps (0..1): sample `k` lies at
    /// `t_entry + (k + offset) * step`.
    pub sample_offset: f64,
    /// Jittered ray start: each pixel's offset comes from a stable hash of the pixel, rotated
    /// by `sample_offset − ½` ([`crate::sampling::jittered_offset`]), trading wood-grain rings
    /// for fine noise.
    pub jitter: bool,
    /// Scale each sample's opacity to the step (`1 − (1 − α)^(Δt/d₀)`), so the picture does not
    /// change with the step. Off only to show what it buys (the accuracy benchmark).
    pub opacity_correction: bool,
    /// Pre-integrated classification (Engel, Kraus, Ertl 2001) in DVR: each segment between two
    /// samples is classified by the transfer function integrated over the values between its
    /// ends, so thin features survive large steps (src/transfer/preintegration.rs).
    pub preintegrated: bool,
    /// Linear RGB composited behind the volume.
    pub background: [f64; 3],
    /// Edge of the leaping blocks in voxels (a power of two from 4 to 128); `None`: the edge
    /// measured fastest for the mode and the strategy in use ([`default_block_vox`]).
    pub block_vox: Option<u32>,
    /// Lighting (DVR and isosurface only).
    pub shading: Shading,
    /// Phong coefficients.
    pub phong: Phong,
    /// Light direction.
    pub light: Light,
    /// Gradient estimator for lighting.
    pub gradient: GradientScheme,
    /// Shadows cast towards the light (lit DVR and isosurfaces).
    pub shadows: Shadows,
    /// Ambient occlusion (lit DVR and isosurfaces).
    pub occlusion: Occlusion,
    /// DVR: a sample whose weight in the pixel, `α·(1 − A)` with `A` the opacity gathered in
    /// front of it, is below this is composited unlit (as if facing the light, without
    /// highlight), so its gradient and lighting are never computed; 0 lights every sample.
    pub light_min_weight: f64,
    /// Isosurface value and refinement.
    pub iso: IsoSettings,
    /// Data window `[lo, hi]` mapped to black..white by MIP, MinIP and X-ray; `None` = the whole
    /// value range.
    pub window: Option<[f64; 2]>,
    /// How MIP and MinIP colour their value.
    pub mip_color: MipColor,
    /// X-ray attenuation per millimetre at the window's top (attenuation mode).
    pub xray_density_per_mm: f64,
    /// The part of the volume rays are limited to (the whole volume by default).
    pub crop: crop::CropBox,
    /// How a segmentation loaded beside the volume shows (ignored without one).
    pub labels: LabelView,
    /// How much labels drawn as surfaces are smoothed: the Gaussian's standard deviation in
    /// voxels (0: none; at most [`crate::labels::surface::MOST_SMOOTHING`]).
    pub label_smoothing: f64,
}

impl Default for RenderSettings {
    fn default() -> Self {
        Self {
            mode: Mode::Dvr,
            strategy: Strategy::Auto,
            path: RenderPath::Auto,
            step_vox: 0.5,
            termination_alpha: DEFAULT_TERMINATION_ALPHA,
            sample_offset: 0.5,
            jitter: false,
            opacity_correction: true,
            preintegrated: false,
            background: [0.0; 3],
            block_vox: None,
            shading: Shading::Phong,
            phong: Phong::default(),
            light: Light::Headlight,
            gradient: GradientScheme::Central,
            shadows: Shadows::default(),
            occlusion: Occlusion::default(),
            light_min_weight: 0.0,
            iso: IsoSettings::default(),
            window: None,
            mip_color: MipColor::Window,
            xray_density_per_mm: effects::DEFAULT_XRAY_DENSITY_PER_MM,
            crop: crop::CropBox::FULL,
            labels: LabelView::Colour,
            label_smoothing: crate::labels::surface::DEFAULT_SMOOTHING,
        }
    }
}

/// Default leaping block edge in voxels for DVR and for the distance field: the fastest edge for
/// DVR RC-s-df on every dataset of the block-size sweeps, 8³ next (Table 2 in
/// docs/benchmarks/nvidia-h100-block-sweep-1080p and nvidia-h200-block-sweep-1080p).
pub const DEFAULT_BLOCK_VOX: u32 = 4;

/// Default leaping block edge in voxels for the octree (RC-s) in the modes that walk in block
/// runs (isosurface, MIP, MinIP, X-ray): larger blocks cost fewer octree climbs, which there
/// cost more than the samples they save (the sweeps in docs/benchmarks/nvidia-h200-block-edge).
pub const OCTREE_RUNS_BLOCK_VOX: u32 = 16;

/// The leaf block edge measured fastest for `mode` leaping with `strategy` (the strategy in use,
/// [`Strategy::for_mode`]): [`OCTREE_RUNS_BLOCK_VOX`] for the octree (RC-s) in every mode but
/// DVR, else [`DEFAULT_BLOCK_VOX`] (strategies that do not leap ignore it).
pub fn default_block_vox(mode: Mode, strategy: Strategy) -> u32 {
    if mode != Mode::Dvr && strategy.untimed(mode) == Strategy::RcS {
        OCTREE_RUNS_BLOCK_VOX
    } else {
        DEFAULT_BLOCK_VOX
    }
}

/// Smallest and largest step the renderer accepts, in voxels: below 1/1024 a ray through a 4096³
/// volume would need tens of millions of samples; above 1024 it would skip whole volumes.
pub const STEP_VOX_RANGE: (f64, f64) = (1.0 / 1024.0, 1024.0);

impl RenderSettings {
    /// The step, in units of `d₀`, that sample opacities are corrected for: the step itself, or 1
    /// with opacity correction off (each sample then counts as one voxel length).
    pub(crate) fn opacity_step_vox(&self) -> f64 {
        if self.opacity_correction {
            self.step_vox
        } else {
            1.0
        }
    }

    /// The leaf block edge the rays leap by: `block_vox`, or where it is `None` the measured
    /// default for the mode and strategy ([`default_block_vox`]).
    pub fn leaf_block_vox(&self) -> u32 {
        self.block_vox
            .unwrap_or_else(|| default_block_vox(self.mode, self.strategy))
    }

    /// Checks the numeric knobs, so no frame is ever rendered with a NaN or degenerate step.
    pub fn validate(&self) -> Result<(), SettingsError> {
        let (lo, hi) = STEP_VOX_RANGE;
        if !(self.step_vox.is_finite() && (lo..=hi).contains(&self.step_vox)) {
            return Err(SettingsError::Step(self.step_vox));
        }
        if !(self.termination_alpha > 0.0 && self.termination_alpha <= 1.0) {
            return Err(SettingsError::Termination(self.termination_alpha));
        }
        if let Some(block) = self.block_vox
            && !crate::accel::pyramid::BLOCK_SIZES.contains(&block)
        {
            return Err(SettingsError::Block(block));
        }
        let p = self.phong;
        if [p.ambient, p.diffuse, p.specular]
            .iter()
            .any(|c| !(c.is_finite() && *c >= 0.0 && *c <= 4.0))
            || !(p.shininess.is_finite() && (0.0..=1024.0).contains(&p.shininess))
        {
            return Err(SettingsError::Phong);
        }
        if !(0.0..=1.0).contains(&self.light_min_weight) {
            return Err(SettingsError::LightWeight(self.light_min_weight));
        }
        if let Light::Direction(d) = self.light
            && (d.iter().any(|c| !c.is_finite()) || d.iter().all(|c| *c == 0.0))
        {
            return Err(SettingsError::Light(d));
        }
        let (lo, hi) = effects::SHADOW_STEP_RANGE;
        if !(lo..=hi).contains(&self.shadows.step_vox) {
            return Err(SettingsError::ShadowStep(self.shadows.step_vox));
        }
        if !(self.shadows.reach > 0.0 && self.shadows.reach <= 1.0) {
            return Err(SettingsError::ShadowReach(self.shadows.reach));
        }
        if !(0.0..=effects::MOST_SHADOW_SOFTNESS).contains(&self.shadows.softness_deg) {
            return Err(SettingsError::ShadowSoftness(self.shadows.softness_deg));
        }
        let (lo, hi) = effects::OCCLUSION_RADIUS_RANGE;
        if !(lo..=hi).contains(&self.occlusion.radius_vox) {
            return Err(SettingsError::OcclusionRadius(self.occlusion.radius_vox));
        }
        if !self.shadows.sample.iter().all(|u| (0.0..1.0).contains(u)) {
            return Err(SettingsError::ShadowSample(self.shadows.sample));
        }
        if let Some(v) = self.iso.value.filter(|v| !v.is_finite()) {
            return Err(SettingsError::IsoValue(v));
        }
        if self.iso.refine_iterations > MAX_ISO_REFINEMENT {
            return Err(SettingsError::IsoRefinement(self.iso.refine_iterations));
        }
        if let Some([lo, hi]) = self.window
            && !(lo.is_finite() && hi.is_finite() && hi > lo)
        {
            return Err(SettingsError::Window(lo, hi));
        }
        if !(self.xray_density_per_mm.is_finite() && self.xray_density_per_mm >= 0.0) {
            return Err(SettingsError::Density(self.xray_density_per_mm));
        }
        if !(0.0..1.0).contains(&self.sample_offset) {
            return Err(SettingsError::Offset(self.sample_offset));
        }
        if self
            .background
            .iter()
            .any(|c| !c.is_finite() || !(0.0..=1.0).contains(c))
        {
            return Err(SettingsError::Background(self.background));
        }
        let most = crate::labels::surface::MOST_SMOOTHING;
        if !(0.0..=most).contains(&self.label_smoothing) {
            return Err(SettingsError::LabelSmoothing(self.label_smoothing));
        }
        self.crop.validate()?;
        Ok(())
    }
}

/// A render setting out of its valid range.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum SettingsError {
    /// Step outside [`STEP_VOX_RANGE`].
    #[error("the step must be between 1/1024 and 1024 voxels, got {0}")]
    Step(f64),
    /// Termination threshold outside (0, 1].
    #[error("the termination threshold must be in (0, 1], got {0}")]
    Termination(f64),
    /// Block size not a power of two from 4 to 128.
    #[error("the block size must be 4, 8, 16, 32, 64 or 128 voxels, got {0}")]
    Block(u32),
    /// A Phong coefficient out of range.
    #[error("Phong coefficients must be between 0 and 4 and the exponent between 0 and 1024")]
    Phong,
    /// A lighting weight threshold outside [0, 1] (or not a number).
    #[error("the lighting threshold must be a weight from 0 to 1, got {0}")]
    LightWeight(f64),
    /// A zero or non-finite light direction.
    #[error("the light direction must be a non-zero vector, got {0:?}")]
    Light([f64; 3]),
    /// A shadow step outside [`effects::SHADOW_STEP_RANGE`].
    #[error("the shadow step must be from 1/8 to 4 voxels, got {0}")]
    ShadowStep(f64),
    /// A shadow reach outside (0, 1].
    #[error("the shadow reach must be a share of the box's diagonal in (0, 1], got {0}")]
    ShadowReach(f64),
    /// A light's angular radius outside 0…[`effects::MOST_SHADOW_SOFTNESS`] degrees.
    #[error("the shadow softness must be from 0 to 20 degrees, got {0}")]
    ShadowSoftness(f64),
    /// An occlusion radius outside [`effects::OCCLUSION_RADIUS_RANGE`].
    #[error("the occlusion radius must be from 1 to 16 voxels, got {0}")]
    OcclusionRadius(f64),
    /// A light sample outside the unit square.
    #[error("the light sample must lie in [0, 1)², got {0:?}")]
    ShadowSample([f64; 2]),
    /// An iso value that is not a finite number.
    #[error("the iso value must be a finite number, got {0}")]
    IsoValue(f64),
    /// More isosurface refinement steps than [`MAX_ISO_REFINEMENT`].
    #[error("isosurface refinement takes at most {MAX_ISO_REFINEMENT} steps, got {0}")]
    IsoRefinement(u32),
    /// A window with hi ≤ lo.
    #[error("the window must have lo < hi, got {0}, {1}")]
    Window(f64, f64),
    /// A negative X-ray density.
    #[error("the X-ray density must be a non-negative number per mm, got {0}")]
    Density(f64),
    /// Sample offset outside [0, 1).
    #[error("the sample offset must be in [0, 1), got {0}")]
    Offset(f64),
    /// Label smoothing outside 0…[`crate::labels::surface::MOST_SMOOTHING`] voxels.
    #[error("the label smoothing must be from 0 to 1.5 voxels, got {0}")]
    LabelSmoothing(f64),
    /// Background components outside [0, 1].
    #[error("background colour components must be in 0..1, got {0:?}")]
    Background([f64; 3]),
    /// A cropping box outside the volume or empty.
    #[error(transparent)]
    Crop(#[from] crop::CropError),
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_block_edge_follows_the_mode_and_the_strategy_in_use() {
        let octree = OCTREE_RUNS_BLOCK_VOX;
        let cases = [
            (Mode::Mip, Strategy::RcS, octree),
            (Mode::MinIp, Strategy::RcS, octree),
            (Mode::Iso, Strategy::RcS, octree),
            (Mode::Xray, Strategy::RcS, octree),
            // MIP and MinIP leap by the octree whichever leaping strategy is asked for.
            (Mode::Mip, Strategy::RcSDistance, octree),
            (Mode::Iso, Strategy::RcSDistance, DEFAULT_BLOCK_VOX),
            (Mode::Dvr, Strategy::RcS, DEFAULT_BLOCK_VOX),
            (Mode::Mip, Strategy::RcT, DEFAULT_BLOCK_VOX),
            // `auto` leaps with the mode's leaping strategy, so it takes that one's edge.
            (Mode::Mip, Strategy::Auto, octree),
            (Mode::MinIp, Strategy::Auto, octree),
            (Mode::Iso, Strategy::Auto, DEFAULT_BLOCK_VOX),
            (Mode::Dvr, Strategy::Auto, DEFAULT_BLOCK_VOX),
        ];
        for (mode, strategy, edge) in cases {
            assert_eq!(
                default_block_vox(mode, strategy),
                edge,
                "{mode:?} {strategy:?}"
            );
        }
        assert_ne!(octree, DEFAULT_BLOCK_VOX);
    }

    #[test]
    fn auto_stands_for_the_modes_leaping_strategy_until_timed() {
        assert_eq!(RenderSettings::default().strategy, Strategy::Auto);
        for mode in Mode::ALL {
            let leaping = Strategy::leaping(mode);
            assert!(
                leaping.leaps() && Strategy::ALL.contains(&leaping),
                "{mode:?}"
            );
            assert_eq!(Strategy::Auto.untimed(mode), leaping, "{mode:?}");
            assert_eq!(Strategy::Auto.for_mode(mode), Strategy::Auto, "{mode:?}");
            for s in Strategy::ALL {
                assert_eq!(s.untimed(mode), s.for_mode(mode), "{mode:?} {s:?}");
            }
        }
        assert_eq!(Strategy::leaping(Mode::Mip), Strategy::RcS);
        assert_eq!(Strategy::leaping(Mode::Dvr), Strategy::RcSDistance);
        assert!(!Strategy::ALL.contains(&Strategy::Auto));
    }

    #[test]
    fn an_explicit_block_edge_wins_and_a_wrong_one_is_refused() {
        let mut settings = RenderSettings {
            mode: Mode::Mip,
            strategy: Strategy::RcS,
            ..RenderSettings::default()
        };
        assert_eq!(settings.leaf_block_vox(), OCTREE_RUNS_BLOCK_VOX);
        settings.block_vox = Some(8);
        assert_eq!(settings.leaf_block_vox(), 8);
        assert!(settings.validate().is_ok());
        settings.block_vox = Some(6);
        assert!(matches!(settings.validate(), Err(SettingsError::Block(6))));
    }
}
