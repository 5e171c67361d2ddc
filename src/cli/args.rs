//! The command-line grammar (DESIGN.md, "The command line").

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand};
use leapview::camera::ProjectionKind;
use leapview::settings::{Mode, RenderPath, Strategy};

use super::parse::{parse_dims, parse_size, parse_vec3, parse_window};

/// LeapView: GPU volume ray casting for CT and MRI with empty-space leaping.
#[derive(Parser, Debug)]
#[command(version, about, args_conflicts_with_subcommands = true)]
pub struct Cli {
    /// What to do; without a command, the viewer window opens.
    #[command(subcommand)]
    pub command: Option<Command>,
    /// Volume to open in the window (NRRD, NIfTI, raw); without one, a generated Shepp–Logan head
    /// phantom opens.
    pub file: Option<PathBuf>,
    /// Layout of a raw file.
    #[command(flatten)]
    pub raw: RawArgs,
}

/// Subcommands.
#[derive(Subcommand, Debug)]
pub enum Command {
    /// Render a volume to a PNG or EXR file without a window.
    Render(Box<RenderArgs>),
    /// Print a volume's dimensions, spacing, type, value range and histogram summary.
    Info(InfoArgs),
    /// Benchmark strategies, modes and paths on the configured datasets (Tables 1 and 2).
    Bench(Box<super::bench::BenchArgs>),
    /// What each quality knob (step, opacity correction, termination, gradients, iso refinement,
    /// jitter, pre-integration, texel precision) costs in GPU time and buys in error against a
    /// reference; tables and Pareto plots.
    Accuracy(Box<super::accuracy::AccuracyArgs>),
    /// Write one of the generated volumes (the window's phantom and vessel tree, the benchmark's
    /// scenes) to a NRRD file, to try every command without data of your own.
    Generate(GenerateArgs),
    /// Write a slice through a volume to a PNG: axial, coronal, sagittal or oblique, in the
    /// patient's frame, grey through a window (what a slice view shows).
    Slice(SliceArgs),
    /// What the GPU's driver says of each compute ray-casting variant once compiled (registers,
    /// instructions, spills, shared memory): why one strategy costs more per sample than another.
    Shaders(ShadersArgs),
}

/// `leapview shaders`.
#[derive(Args, Debug)]
pub struct ShadersArgs {
    /// Modes (default: all).
    #[arg(long, value_enum, value_delimiter = ',')]
    pub modes: Vec<Mode>,
    /// Strategies (default: rc-t, rc-s, rc-s-df; MIP and MinIP take rc-s for rc-s-df; auto
    /// stands for the two it chooses between, rc-t and the mode's leaping one).
    #[arg(long, value_enum, value_delimiter = ',')]
    pub strategies: Vec<Strategy>,
    /// Image sizes: the variant depends on the size (rays of images up to 2^19 pixels are split
    /// into parts).
    #[arg(long, value_delimiter = ',', value_parser = parse_size, default_values = ["512x512", "1920x1080"])]
    pub sizes: Vec<[u32; 2]>,
    /// Unlit DVR and isosurfaces (default: Phong, as the window and the benchmark).
    #[arg(long)]
    pub unlit: bool,
    /// Ray-loop paths: the compute shader, the fragment shader of the paper's single pass (its
    /// variant does not depend on the image size), or both (`auto` is not a path here).
    #[arg(long, value_enum, value_delimiter = ',', default_values = ["compute", "fragment"])]
    pub paths: Vec<leapview::settings::RenderPath>,
    /// The Vulkan device whose name contains this (default: a discrete GPU first).
    #[arg(long)]
    pub device: Option<String>,
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
}

/// How a thick slab's samples combine (`leapview slice --mode`).
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum SlabModeArg {
    /// The largest value (maximum intensity projection).
    Mip,
    /// The smallest value (minimum intensity projection).
    Minip,
    /// The mean value.
    Mean,
}

/// `leapview slice`.
#[derive(Args, Debug)]
pub struct SliceArgs {
    /// The volume (any file or folder `leapview info` opens).
    pub file: PathBuf,
    /// The plane: `axial`, `coronal`, `sagittal`, or its normal `N1,N2,N3` in the patient's
    /// frame (LPS: x to the patient's left, y to the back, z to the head) for an oblique plane.
    #[arg(long, default_value = "axial", allow_hyphen_values = true)]
    pub plane: String,
    /// A point the plane passes through, `X,Y,Z` in the file's patient millimetres (LPS, as
    /// `leapview info` reports the origin and extent). Default: the volume's centre.
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    pub at: Option<[f64; 3]>,
    /// Output PNG.
    #[arg(long)]
    pub out: PathBuf,
    /// Window `LO,HI` in data units (HU for CT) mapped to black..white. Default: the header's
    /// (DICOM), else the data's (0.1 to 99.9 percentile).
    #[arg(long, value_parser = parse_window, allow_hyphen_values = true)]
    pub window: Option<[f64; 2]>,
    /// Image size `WxH`: the slice's extent fills it with square pixels. Default: one pixel per
    /// voxel at the volume's finest spacing.
    #[arg(long, value_parser = parse_size)]
    pub size: Option<[u32; 2]>,
    /// The nearest voxel's value instead of trilinear interpolation.
    #[arg(long)]
    pub nearest: bool,
    /// Grey inverted (low values white), as a radiograph stored MONOCHROME1 is shown by default;
    /// `--invert no` shows such a file the other way.
    #[arg(long, value_name = "yes|no")]
    pub invert: Option<YesNo>,
    /// Trilinear interpolation with exact f32 weights from eight texel loads (the tests'
    /// variant) instead of the texture unit's filter, which the window shows (its weights have
    /// 8 fractional bits on most GPUs).
    #[arg(long)]
    pub exact: bool,
    /// A slab takes every sample instead of leaping over the bricks that cannot change it (for
    /// timing the difference).
    #[arg(long)]
    pub no_leap: bool,
    /// Colour the slice by a transfer function (`auto`: the one `render` would choose, a preset
    /// name or a JSON file): its colour blended over the grey by its opacity, so what it hides
    /// stays grey; writes an RGB PNG.
    #[arg(long)]
    pub tf: Option<String>,
    /// A thick slab of this many millimetres centred on the plane, its samples combined by
    /// `--mode`.
    #[arg(long)]
    pub slab: Option<f64>,
    /// How a slab's samples combine.
    #[arg(long, value_enum, default_value_t = SlabModeArg::Mip)]
    pub mode: SlabModeArg,
    /// Also time the slice on the GPU: this many passes between timestamps, the median per
    /// slice printed for passes of one slice and of 50 (what one more slice adds, without a
    /// pass's fixed cost); needs an adapter with timestamp queries.
    #[arg(long, default_value_t = 0, value_parser = clap::value_parser!(u32).range(0..=1024))]
    pub repeat: u32,
}

/// A yes or a no.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum YesNo {
    /// Yes.
    Yes,
    /// No.
    No,
}

/// The volumes `leapview generate` writes.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Generated {
    /// The 3D Shepp–Logan head phantom in Hounsfield units (int16, CT), the window's default.
    Phantom,
    /// A sparse vessel tree on a black background (uint8, like an MR angiogram).
    Vessels,
    /// A head-sized volume that fills its box: skull, brain folds, noise (uint8).
    DenseHead,
    /// The scene the peers were benchmarked on (uint8): soft shells and a noisy core.
    PeerScene,
}

/// `leapview generate`.
#[derive(Args, Debug)]
pub struct GenerateArgs {
    /// Which volume.
    #[arg(value_enum)]
    pub what: Generated,
    /// Output file: `.nrrd` (gzip, one file), or `.nhdr` (a header, and the samples raw and
    /// little-endian in a `.raw` file of the same name), or a folder (created if missing, empty
    /// otherwise) to receive a DICOM series, one uncompressed file per slice.
    #[arg(long)]
    pub out: PathBuf,
    /// DICOM series only: this many slices (the volume's z axis resampled to them, its extent
    /// kept), e.g. `--size 512 --slices 1000` for a long CT series.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=4096))]
    pub slices: Option<u32>,
    /// Samples along each axis (8 to 1024).
    #[arg(long, default_value_t = 256, value_parser = clap::value_parser!(u32).range(8..=1024))]
    pub size: u32,
    /// Seed of the vessel tree and the dense head (the same seed, the same volume).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
}

/// How to read a file beyond what its header says: the layout of a headerless raw file, and the
/// patient's orientation where the header has none or states it wrong.
#[derive(Args, Debug, Clone, Default)]
pub struct RawArgs {
    /// Raw files: samples along x, y, z (e.g. `256,256,128`).
    #[arg(long, value_parser = parse_dims, global = true)]
    pub dims: Option<[u32; 3]>,
    /// Raw files: sample type (uint8, int8, uint16, int16, uint32, int32, float, double).
    #[arg(long = "type", global = true)]
    pub scalar_type: Option<String>,
    /// Raw files: voxel spacing in millimetres (default 1,1,1).
    #[arg(long, value_parser = parse_vec3, global = true)]
    pub spacing: Option<[f64; 3]>,
    /// Raw files: samples are big-endian (default little).
    #[arg(long, global = true)]
    pub big_endian: bool,
    /// Where index axes i, j, k point in the patient, in place of the header's orientation: three
    /// letters, one each of R/L, A/P and S/I (`RAI`: slices run from the top of the head down).
    #[arg(long, global = true, value_name = "CODE")]
    pub orientation: Option<String>,
    /// DICOM: which series of a folder to open, by its number in `leapview info`'s listing or by
    /// its SeriesInstanceUID (default: the image series with the most slices, or the series of the
    /// file named).
    #[arg(long, global = true, value_name = "N|UID")]
    pub series: Option<String>,
    /// 4-D files (an fMRI time series, diffusion directions in NIfTI): which volume to open,
    /// counted from 1 (default: the first; `leapview info` says how many there are).
    #[arg(long, global = true, value_name = "N", value_parser = clap::value_parser!(u32).range(1..))]
    pub volume: Option<u32>,
}

/// `leapview render`.
#[derive(Args, Debug)]
pub struct RenderArgs {
    /// The volume file.
    pub file: PathBuf,
    /// Output image: `.png` (8-bit RGBA) or `.exr` (linear RGBA f32).
    #[arg(long, short)]
    pub out: PathBuf,
    /// Visual effect.
    #[arg(long, value_enum, default_value = "dvr")]
    pub mode: Mode,
    /// Ray-casting strategy; `auto` times RC-t and leaping on this frame and renders with the
    /// faster (a CPU driver takes leaping untimed).
    #[arg(long, value_enum, default_value = "auto")]
    pub strategy: Strategy,
    /// Where the ray loop runs; `auto` times both once and picks the faster.
    #[arg(long, value_enum, default_value = "auto")]
    pub path: RenderPath,
    /// Image size `WxH`.
    #[arg(long, value_parser = parse_size, default_value = "512x512")]
    pub size: [u32; 2],
    /// Camera placement.
    #[command(flatten)]
    pub camera: CameraArgs,
    /// Effect parameters.
    #[command(flatten)]
    pub effects: super::effect_args::EffectArgs,
    /// Transfer function: `auto` (chosen from the data: a CT preset for CT, mapped onto scanner
    /// units where the file is not in HU; the MR default for MR), a preset name, or a JSON file.
    #[arg(long, default_value = "auto")]
    pub tf: String,
    /// Sample step in units of the smallest voxel spacing.
    #[arg(long, default_value_t = 0.5)]
    pub step: f64,
    /// Jittered ray starts: each pixel's first sample at a stable per-pixel offset (against
    /// wood-grain rings at coarse steps).
    #[arg(long)]
    pub jitter: bool,
    /// RC-t stops once accumulated opacity exceeds this.
    #[arg(long, default_value_t = leapview::settings::DEFAULT_TERMINATION_ALPHA)]
    pub termination: f64,
    /// Pre-integrated classification (DVR): thin transfer-function features survive large steps.
    #[arg(long)]
    pub preintegrate: bool,
    /// A quality preset (docs/accuracy): sets the step, termination, jitter, pre-integration,
    /// gradients and iso refinement (--gradient and --iso-refine still override it).
    #[arg(long, value_enum, conflicts_with_all = ["step", "termination", "jitter", "preintegrate"])]
    pub quality: Option<leapview::settings::QualityPreset>,
    /// Texel precision of the volume texture (auto: exact integers, f32 for floats).
    #[arg(long, value_enum, default_value = "auto")]
    pub precision: leapview::settings::TexturePrecision,
    /// Edge of the leaping blocks in voxels (RC-s, RC-s-df): 4, 8, 16, 32, 64 or 128 (default:
    /// the edge measured fastest for the mode and strategy, 16 for the octree in isosurface,
    /// MIP, MinIP and X-ray modes, else 4).
    #[arg(long)]
    pub block: Option<u32>,
    /// Background colour `R,G,B` in 0..1.
    #[arg(long, value_parser = parse_vec3, default_value = "0,0,0")]
    pub background: [f64; 3],
    /// Cropping box in voxel edges `x0:x1,y0:y1,z0:z1` (voxel i spans i..i+1, so
    /// `0:NX,0:NY,0:NZ` is the whole volume): rays see only what lies inside it.
    #[arg(long)]
    pub crop: Option<String>,
    /// Progressive refinement: the mean of this many frames with their sample grids shifted
    /// along the rays (as the window's "Refine when still"); 1 renders one frame.
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=1024))]
    pub refine: u32,
    /// Print samples taken, samples with non-zero opacity (what any leaping scheme must still
    /// take), empty regions leapt, rays, and GPU milliseconds (median of several frames after a
    /// warm-up) including the leaping structures' rebuild.
    #[arg(long)]
    pub stats: bool,
}

/// Camera placement shared by `render` (and later `bench`).
#[derive(Args, Debug, Clone)]
pub struct CameraArgs {
    /// Perspective or orthographic projection.
    #[arg(long, value_enum, default_value = "perspective")]
    pub projection: ProjectionKind,
    /// Look at the patient from a side (`A`, `P`, `L`, `R`, `S`, `I`, by the file's orientation,
    /// RAS where it has none), along an axis of the volume (`+x`, `-x`, `+y`, `-y`, `+z`, `-z`),
    /// or `oblique`. The default, `A`, is the patient from the front, superior up, as the window
    /// opens.
    #[arg(long, allow_hyphen_values = true, default_value = "A")]
    pub view: String,
    /// Orbit azimuth in degrees (0 looks along +y; overrides --view).
    #[arg(long, allow_hyphen_values = true)]
    pub azimuth: Option<f64>,
    /// Orbit elevation in degrees (with --azimuth; default 0).
    #[arg(long, allow_hyphen_values = true)]
    pub elevation: Option<f64>,
    /// Explicit eye position `X,Y,Z` in world millimetres (voxel centre (i,j,k) at (i·sx, j·sy, k·sz)).
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    pub eye: Option<[f64; 3]>,
    /// Point looked at, with --eye (default: the volume's centre).
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    pub target: Option<[f64; 3]>,
    /// Up direction, with --eye (default +z, or −y when looking along z).
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    pub up: Option<[f64; 3]>,
    /// Vertical field of view in degrees (perspective).
    #[arg(long)]
    pub fov: Option<f64>,
}

/// `leapview info`.
#[derive(Args, Debug)]
pub struct InfoArgs {
    /// The volume file.
    pub file: PathBuf,
    /// Also report the share of voxels this transfer function (preset or JSON file) makes
    /// fully transparent.
    #[arg(long)]
    pub tf: Option<String>,
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grammar_is_consistent() {
        use clap::CommandFactory;
        Cli::command().debug_assert();
    }
}
