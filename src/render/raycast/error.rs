//! Why a frame could not be rendered, in words for the user, and whose fault it is.

use crate::render::shader::ShaderError;
use crate::render::volume_texture::VolumeTextureError;
use crate::settings::SettingsError;

/// Why a frame could not be rendered.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// `render` was called before any volume was set.
    #[error("no volume is loaded")]
    NoVolume,
    /// A setting is out of range.
    #[error(transparent)]
    Settings(#[from] SettingsError),
    /// The path is `auto` but no path was chosen for this renderer yet (a bug of the caller: run
    /// [`super::auto_path::choose`] first).
    #[error("the ray-loop path is 'auto' but the paths have not been timed on this GPU yet")]
    AutoPathNotChosen,
    /// The image is larger than the adapter's 2D texture limit (or empty).
    #[error(
        "an image of {width}×{height} pixels is not possible on this GPU ({adapter}): each side must be 1 to {max}"
    )]
    ImageSize {
        /// Requested width.
        width: u32,
        /// Requested height.
        height: u32,
        /// The adapter's `max_texture_dimension_2d`.
        max: u32,
        /// Adapter name.
        adapter: String,
    },
    /// The GPU refused the textures of an image this size (out of memory, or past a limit).
    #[error(
        "this GPU ({adapter}) cannot hold the textures of a {width}×{height} image (about \
         {megabytes:.0} MB): {reason}; render a smaller image"
    )]
    TargetsRefused {
        /// Requested width.
        width: u32,
        /// Requested height.
        height: u32,
        /// What the image's textures take.
        megabytes: f64,
        /// Adapter name.
        adapter: String,
        /// What wgpu said, first line.
        reason: String,
    },
    /// The volume could not be put on the GPU.
    #[error(transparent)]
    Volume(#[from] VolumeTextureError),
    /// A shader module is malformed (a bug).
    #[error("internal shader error: {0}")]
    Shader(#[from] ShaderError),
    /// A segmentation that cannot be shown over the volume loaded.
    #[error("{0}")]
    Labels(String),
    /// The GPU reported an error while rendering.
    #[error("the GPU reported an error: {0}")]
    Gpu(String),
}

impl RenderError {
    /// Whether the caller's input is at fault (a volume or an image past the GPU's limits, a
    /// setting out of range) rather than the GPU or the program: the command line's status 2.
    pub fn is_bad_input(&self) -> bool {
        matches!(
            self,
            Self::Volume(_)
                | Self::ImageSize { .. }
                | Self::TargetsRefused { .. }
                | Self::Settings(_)
                | Self::Labels(_)
        )
    }
}
