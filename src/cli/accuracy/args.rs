//! `leapview accuracy` flags.

use std::path::PathBuf;

use clap::Args;
use leapview::settings::RenderPath;

/// `leapview accuracy`: GPU time and error against a reference for every quality knob.
#[derive(Args, Debug)]
pub struct AccuracyArgs {
    /// Benchmark configuration (JSON): the datasets and their transfer functions.
    #[arg(long, default_value = "bench/config.json")]
    pub config: PathBuf,
    /// Folder holding the configuration's volume files.
    #[arg(long, default_value = "../shared/data")]
    pub data_dir: PathBuf,
    /// Output folder for the tables and plots.
    #[arg(long, default_value = "docs/accuracy")]
    pub out: PathBuf,
    /// Only these datasets (configuration names, comma-separated).
    ///
    /// phantom is the generated 48³ Shepp–Logan head, measured against the f64 CPU reference.
    #[arg(long, value_delimiter = ',')]
    pub datasets: Option<Vec<String>>,
    /// Image size WxH of the GPU datasets.
    ///
    /// The phantom renders at most 128×128: its reference runs on the CPU.
    #[arg(long, value_parser = crate::cli::parse::parse_size, default_value = "512x512")]
    pub size: [u32; 2],
    /// Views around each volume; times and errors are over all of them.
    #[arg(long, default_value_t = 4)]
    pub views: u32,
    /// Timed frames per view (after warm-up); the time is their median.
    #[arg(long, default_value_t = 5)]
    pub frames: u32,
    /// Where the ray loop runs.
    #[arg(long, value_enum, default_value = "compute")]
    pub path: RenderPath,
    /// One view, one frame, 96×96 images, the phantom only (for CPU drivers and CI).
    #[arg(long)]
    pub quick: bool,
    /// Render nothing: redraw the tables and plots of an earlier results.json into --out.
    #[arg(long, conflicts_with_all = ["quick", "datasets"])]
    pub redraw: Option<PathBuf>,
}
