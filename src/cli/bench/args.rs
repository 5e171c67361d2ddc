//! `leapview bench` flags.

use std::path::PathBuf;

use clap::Args;
use leapview::settings::effects::Shading;
use leapview::settings::{Mode, RenderPath, Strategy};

/// `leapview bench`: Tables 1 and 2 of the paper, rebuild times and an image check.
#[derive(Args, Debug)]
pub struct BenchArgs {
    /// Benchmark configuration (JSON).
    #[arg(long, default_value = "bench/config.json")]
    pub config: PathBuf,
    /// Folder holding the configuration's volume files.
    #[arg(long, default_value = "../shared/data")]
    pub data_dir: PathBuf,
    /// Output folder (default: docs/benchmarks/ADAPTER, or ADAPTER-quick with --quick).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Few views, small images, some datasets and modes (for CPU drivers and CI).
    #[arg(long)]
    pub quick: bool,
    /// Only these datasets (names from the configuration, comma-separated).
    #[arg(long, value_delimiter = ',')]
    pub datasets: Option<Vec<String>>,
    /// Only these modes, comma-separated.
    #[arg(long, value_enum, value_delimiter = ',')]
    pub modes: Option<Vec<Mode>>,
    /// Only these strategies, comma-separated.
    #[arg(long, value_enum, value_delimiter = ',')]
    pub strategies: Option<Vec<Strategy>>,
    /// Only these paths, comma-separated.
    #[arg(long, value_enum, value_delimiter = ',')]
    pub paths: Option<Vec<RenderPath>>,
    /// Leaping block edge in voxels: 4, 8, 16, 32, 64 or 128.
    ///
    /// For every run outside the block-size sweep, in place of the configuration's block_vox
    /// (absent there: each mode's default).
    #[arg(long)]
    pub block: Option<u32>,
    /// The volumes on the GPU as one 3D texture or as bricks in an atlas (auto: bricks only
    /// past the GPU's 3D texture limit): run twice to compare the two.
    #[arg(long, value_enum, default_value = "auto")]
    pub bricks: leapview::settings::Bricking,
    /// GPU memory.
    #[command(flatten)]
    pub gpu: crate::cli::args::GpuArgs,
    /// A segmentation of the one dataset measured (--datasets names it), shown in every run as
    /// --label-view says (NIfTI, NRRD, .seg.nrrd, MetaImage or DICOM SEG).
    #[arg(long, value_name = "FILE", requires = "datasets")]
    pub labels: Option<PathBuf>,
    /// With --labels: how the labels show (colour, inside, colour-inside, surfaces, off).
    #[arg(long, value_enum, default_value = "colour", requires = "labels")]
    pub label_view: leapview::settings::LabelView,
    /// With --labels: every label's opacity in 3D, 0 to 1 (see-through surfaces meet more
    /// walls).
    #[arg(
        long,
        value_name = "OPACITY",
        default_value_t = 1.0,
        value_parser = crate::cli::label_args::unit_interval,
        requires = "labels"
    )]
    pub label_opacity: f64,
    /// Lighting in DVR and isosurfaces, in place of the configuration's phong.
    #[arg(long, value_enum)]
    pub shading: Option<Shading>,
    /// Measure streaming instead: this volume file, orbited while its bricks stream as the
    /// window streams them, then still until complete (stream.csv and stream.md in --out).
    ///
    /// Takes --gpu-budget, --bricks, the first of --modes, --strategies (default rc-s-df) and
    /// --paths, and the --stream-* options below.
    #[arg(long, conflicts_with_all = ["quick", "datasets", "block", "shading", "merge", "labels"])]
    pub stream: Option<PathBuf>,
    /// With --stream: frames of the orbit.
    #[arg(long, default_value_t = 120, requires = "stream")]
    pub stream_frames: u32,
    /// With --stream: milliseconds each frame may spend uploading bricks (the window's 8).
    #[arg(long, default_value_t = 8.0, requires = "stream")]
    pub stream_ms: f64,
    /// With --stream: the image size WxH.
    #[arg(long, default_value = "1920x1080", value_parser = crate::cli::parse::parse_size, requires = "stream")]
    pub stream_size: [u32; 2],
    /// Render nothing: merge the results of these earlier output folders.
    ///
    /// The frames.json of each folder (comma-separated) is merged, and the report written into
    /// --out.
    #[arg(long, value_delimiter = ',', conflicts_with_all = ["quick", "datasets", "modes", "strategies", "paths", "block", "shading"])]
    pub merge: Option<Vec<PathBuf>>,
}
