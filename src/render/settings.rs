//! What to render: mode, strategy, path and the quality knobs. Plain, serialisable values shared
//! by the GPU renderer, the CPU reference, the command line and the window.

use serde::{Deserialize, Serialize};

/// The visual effect computed along each ray.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, clap::ValueEnum)]
pub enum Mode {
    /// Direct volume rendering: front-to-back alpha compositing of the transfer function.
    Dvr,
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
    /// RC-s: RC-t plus empty-space leaping over the min/max octree, climbing to the coarsest
    /// empty node (the paper's hierarchical leaping).
    #[value(name = "rc-s")]
    RcS,
    /// RC-s with a distance field over blocks: one step clears the whole cube of blocks the
    /// field proves empty (beyond the paper).
    #[value(name = "rc-s-df")]
    RcSDistance,
}

impl Strategy {
    /// The short name used in tables and on the command line.
    pub fn label(self) -> &'static str {
        match self {
            Self::Rc => "RC",
            Self::RcT => "RC-t",
            Self::RcS => "RC-s",
            Self::RcSDistance => "RC-s-df",
        }
    }

    /// Whether rays stop once (nearly) opaque.
    pub fn terminates_early(self) -> bool {
        !matches!(self, Self::Rc)
    }

    /// Whether rays leap over empty space.
    pub fn leaps(self) -> bool {
        matches!(self, Self::RcS | Self::RcSDistance)
    }

    /// All strategies, plainest first.
    pub const ALL: [Self; 4] = [Self::Rc, Self::RcT, Self::RcS, Self::RcSDistance];
}

/// Which entry point runs the ray loop. Both share the same WGSL marching function.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, clap::ValueEnum)]
pub enum RenderPath {
    /// Time both on the adapter once and use the faster.
    Auto,
    /// The paper's single pass: the ray loop runs in the fragment shader of the front faces.
    Fragment,
    /// Entry and exit points are rasterised, then a compute shader runs the ray loop.
    Compute,
}

/// Default termination threshold: stop once accumulated opacity exceeds `1 - 1/255`, so the
/// remaining contribution is below one 8-bit level.
pub const DEFAULT_TERMINATION_ALPHA: f64 = 1.0 - 1.0 / 255.0;

/// Everything about a frame except the camera, the volume and the transfer function.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
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
    /// Linear RGB composited behind the volume.
    pub background: [f64; 3],
    /// Edge of the leaping blocks in voxels (a power of two from 4 to 128).
    pub block_vox: u32,
}

impl Default for RenderSettings {
    fn default() -> Self {
        Self {
            mode: Mode::Dvr,
            strategy: Strategy::RcT,
            path: RenderPath::Auto,
            step_vox: 0.5,
            termination_alpha: DEFAULT_TERMINATION_ALPHA,
            sample_offset: 0.5,
            background: [0.0; 3],
            block_vox: DEFAULT_BLOCK_VOX,
        }
    }
}

/// Default leaping block edge in voxels.
pub const DEFAULT_BLOCK_VOX: u32 = 8;

/// Smallest and largest step the renderer accepts, in voxels: below 1/1024 a ray through a 4096³
/// volume would need tens of millions of samples; above 1024 it would skip whole volumes.
pub const STEP_VOX_RANGE: (f64, f64) = (1.0 / 1024.0, 1024.0);

impl RenderSettings {
    /// Checks the numeric knobs, so no frame is ever rendered with a NaN or degenerate step.
    pub fn validate(&self) -> Result<(), SettingsError> {
        let (lo, hi) = STEP_VOX_RANGE;
        if !(self.step_vox.is_finite() && (lo..=hi).contains(&self.step_vox)) {
            return Err(SettingsError::Step(self.step_vox));
        }
        if !(self.termination_alpha > 0.0 && self.termination_alpha <= 1.0) {
            return Err(SettingsError::Termination(self.termination_alpha));
        }
        if !crate::accel::pyramid::BLOCK_SIZES.contains(&self.block_vox) {
            return Err(SettingsError::Block(self.block_vox));
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
    /// Sample offset outside [0, 1).
    #[error("the sample offset must be in [0, 1), got {0}")]
    Offset(f64),
    /// Background components outside [0, 1].
    #[error("background colour components must be in 0..1, got {0:?}")]
    Background([f64; 3]),
}
