//! The command-line grammar (DESIGN.md, "The command line").

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand};
use leapview::camera::ProjectionKind;
use leapview::settings::{Mode, RenderPath, Strategy};

use super::parse::{parse_dims, parse_size, parse_vec3, parse_window};

/// LeapView: GPU volume ray casting for CT and MRI with empty-space leaping.
#[derive(Parser, Debug)]
#[command(
    version,
    about,
    args_conflicts_with_subcommands = true,
    after_help = "Formats: NRRD (.nrrd, .nhdr), NIfTI (.nii, .nii.gz), DICOM (file or folder),\n\
                  MetaImage (.mha, .mhd), OME-Zarr (a .zarr folder), TIFF (.tif, .tiff: stacks,\n\
                  OME-TIFF, or a folder of slices), raw (any file, with --dims and --type).\n\
                  Without a command, the viewer window opens: with FILE, else a generated head phantom.\n\
                  Run 'leapview <COMMAND> -h' for a command's options, --help for all of them."
)]
pub struct Cli {
    /// What to do; without a command, the viewer window opens.
    #[command(subcommand)]
    pub command: Option<Command>,
    /// Volume file or DICOM folder to open in the window (formats below).
    pub file: Option<PathBuf>,
    /// A segmentation of FILE, shown over the slices (as File › Open segmentation…).
    #[arg(long, value_name = "LABELS", requires = "file")]
    pub labels: Option<PathBuf>,
    /// Layout of a raw file.
    #[command(flatten)]
    pub raw: RawArgs,
    /// GPU memory.
    #[command(flatten)]
    pub gpu: GpuArgs,
}

/// The GPU memory a volume may take.
#[derive(Args, Debug, Clone, Copy, Default)]
pub struct GpuArgs {
    /// GPU memory the volume may take: 2GB, 512MiB, 800M… Past it, or past the GPU's 3D texture
    /// limit, the volume is shown from bricks of a coarser level (one line says which). It holds
    /// the volume's leaping structures (at most a quarter of it: coarser blocks where finer
    /// would take more), page tables, upload staging (a sixteenth, at most 32 MB), a frame's
    /// targets (a quarter, at most 50 MB: 1920 × 1080), what the driver holds for the process
    /// (56 MiB where it reports its memory) and the allocator's unused space (16 MB) too.
    ///
    /// Without it, only the GPU's limits bound it.
    #[arg(long, value_parser = parse_gpu_budget, help_heading = "GPU", hide_short_help = true)]
    pub gpu_budget: Option<u64>,
}

fn parse_gpu_budget(text: &str) -> Result<u64, String> {
    leapview::settings::upload::parse_size(text)
}

/// Subcommands.
#[derive(Subcommand, Debug)]
pub enum Command {
    /// Render a volume to a PNG or EXR image without a window.
    #[command(after_help = SHORT_AND_LONG_HELP)]
    Render(Box<RenderArgs>),
    /// Print a volume's dimensions, spacing, type, value range and histogram.
    ///
    /// For a DICOM folder, also every series found in it (numbered as --series takes them).
    Info(InfoArgs),
    /// Time strategies, modes and paths on the benchmark's datasets.
    ///
    /// Writes Tables 1 and 2 of the paper (frame times of each strategy, mode and path; the
    /// leaping structures' rebuild times), plots, and an image check into the output folder.
    Bench(Box<super::bench::BenchArgs>),
    /// Measure what each quality knob costs in GPU time and buys in error.
    ///
    /// The knobs: step, opacity correction, termination, gradients, iso refinement, jitter,
    /// pre-integration and texel precision. Errors are against a reference rendering; the
    /// results are written as tables and Pareto plots.
    Accuracy(Box<super::accuracy::AccuracyArgs>),
    /// Write a generated test volume to a NRRD file or a DICOM series.
    ///
    /// The window's phantom and vessel tree and the benchmark's scenes, to try every command
    /// without data of your own.
    Generate(GenerateArgs),
    /// Write any volume LeapView reads as a multiscale OME-Zarr store (NGFF 0.5).
    ///
    /// Levels halved down to one 32³ chunk, sharded, zstd-compressed; spacing and origin in the
    /// levels' transformations, the orientation and the source's facts in its attributes, which
    /// LeapView reads back. The store appears under OUT only once complete.
    Convert(ConvertArgs),
    /// Write a slice or a thick slab through a volume to a PNG.
    ///
    /// Axial, coronal, sagittal or oblique, in the patient's frame, grey through a window (what
    /// the window's slice views show), optionally coloured by a transfer function.
    #[command(after_help = SHORT_AND_LONG_HELP)]
    Slice(SliceArgs),
    /// Show the driver's statistics for each compiled ray-casting shader.
    ///
    /// Registers, instructions, spills and shared memory of each compute (and fragment) variant
    /// once compiled: why one strategy costs more per sample than another.
    Shaders(ShadersArgs),
}

/// Closing line of the help of the commands that hide their rarer options from `-h`.
const SHORT_AND_LONG_HELP: &str =
    "-h shows the common options; --help shows all of them, with details.";

/// `leapview shaders`.
#[derive(Args, Debug)]
pub struct ShadersArgs {
    /// Modes, comma-separated (default: all).
    #[arg(long, value_enum, value_delimiter = ',')]
    pub modes: Vec<Mode>,
    /// Strategies, comma-separated (default: rc-t, rc-s, rc-s-df).
    ///
    /// MIP and MinIP take rc-s for rc-s-df; auto stands for the two it chooses between, rc-t and
    /// the mode's leaping strategy.
    #[arg(long, value_enum, value_delimiter = ',')]
    pub strategies: Vec<Strategy>,
    /// Image sizes WxH, comma-separated.
    ///
    /// The compute variant depends on the size: the rays of images up to 2^19 pixels are split
    /// into parts.
    #[arg(long, value_delimiter = ',', value_parser = parse_size, default_values = ["512x512", "1920x1080"])]
    pub sizes: Vec<[u32; 2]>,
    /// Unlit DVR and isosurfaces (default: Phong lighting, as the window and the benchmark).
    #[arg(long)]
    pub unlit: bool,
    /// The variants for a bricked volume (the page-table reads of shaders/shared/volume.wgsl).
    #[arg(long)]
    pub bricked: bool,
    /// Ray-loop paths, comma-separated (auto is not a path here).
    ///
    /// The fragment variant does not depend on the image size.
    #[arg(long, value_enum, value_delimiter = ',', default_values = ["compute", "fragment"])]
    pub paths: Vec<leapview::settings::RenderPath>,
    /// Use the Vulkan device whose name contains this (default: a discrete GPU first).
    #[arg(long)]
    pub device: Option<String>,
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
}

/// `leapview slice`.
#[derive(Args, Debug)]
pub struct SliceArgs {
    /// Volume file or DICOM folder (any that leapview info opens).
    pub file: PathBuf,
    /// Plane: axial, coronal, sagittal, or an oblique plane's normal N1,N2,N3.
    ///
    /// The normal is in the patient's frame, LPS: x to the patient's left, y to the back, z to
    /// the head.
    #[arg(long, default_value = "axial", allow_hyphen_values = true)]
    pub plane: String,
    /// A point X,Y,Z (mm) the plane passes through (default: the volume's centre).
    ///
    /// In the file's patient millimetres, LPS, as leapview info reports the origin and extent.
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    pub at: Option<[f64; 3]>,
    /// Output PNG.
    #[arg(long)]
    pub out: PathBuf,
    /// Window LO,HI in data units (HU for CT) mapped to black..white.
    ///
    /// Default: the header's (DICOM), else the data's 0.1 to 99.9 percentile.
    #[arg(long, value_parser = parse_window, allow_hyphen_values = true)]
    pub window: Option<[f64; 2]>,
    /// Image size WxH (default: one pixel per voxel at the finest spacing).
    ///
    /// The slice's extent fills the image with square pixels.
    #[arg(long, value_parser = parse_size)]
    pub size: Option<[u32; 2]>,
    /// Take the nearest voxel's value instead of interpolating trilinearly.
    #[arg(long)]
    pub nearest: bool,
    /// Show the grey inverted, low values white (default: MONOCHROME1 files only).
    ///
    /// A radiograph stored as MONOCHROME1 is shown inverted unless --invert no; --invert yes
    /// inverts any other file.
    #[arg(long, value_name = "yes|no")]
    pub invert: Option<YesNo>,
    /// Interpolate with exact f32 weights from eight texel loads (as the tests do) instead of the
    /// texture unit's filter that the window uses, whose weights have 8 fractional bits on most
    /// GPUs.
    #[arg(long, hide_short_help = true)]
    pub exact: bool,
    /// A slab takes every sample instead of leaping over the blocks that cannot change it (to time
    /// what leaping saves).
    #[arg(long, hide_short_help = true)]
    pub no_leap: bool,
    /// Colour by a transfer function: auto, a preset name or a JSON file.
    ///
    /// auto is the one leapview render would choose. Its colour is blended over the grey by its
    /// opacity, so what it hides stays grey; the PNG is then RGB.
    #[arg(long)]
    pub tf: Option<String>,
    /// A thick slab of this many millimetres centred on the plane.
    ///
    /// Its samples are combined as --mode says.
    #[arg(long)]
    pub slab: Option<f64>,
    /// How a slab's samples combine.
    #[arg(long, value_enum, default_value_t = leapview::mpr::SlabMode::Mip)]
    pub mode: leapview::mpr::SlabMode,
    /// Also time the slice on the GPU, this many passes between timestamps: prints the median time
    /// per slice for passes of one slice and of 50 (what one more slice adds, without a pass's
    /// fixed cost). Needs an adapter with timestamp queries.
    #[arg(long, default_value_t = 0, value_parser = clap::value_parser!(u32).range(0..=1024), hide_short_help = true)]
    pub repeat: u32,
    /// A segmentation of the volume, filled over the slice in its segments' colours.
    ///
    /// NIfTI, NRRD or Slicer .seg.nrrd, MetaImage or DICOM SEG; put on the volume's grid by
    /// patient position. Names and colours as info --labels lists them.
    #[arg(long, value_name = "FILE")]
    pub labels: Option<PathBuf>,
    /// An ITK-SNAP label description file or a Slicer colour table naming the labels.
    #[arg(long, value_name = "FILE", requires = "labels")]
    pub label_names: Option<PathBuf>,
    /// How opaque the labels' fill is, 0 to 1 (0: outlines only).
    #[arg(long, default_value_t = 0.5, requires = "labels")]
    pub label_opacity: f32,
    /// Draw no outline around each label.
    #[arg(long, requires = "labels")]
    pub no_label_outline: bool,
    /// GPU memory.
    #[command(flatten)]
    pub gpu: GpuArgs,
}

/// A yes or a no.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum YesNo {
    // No doc comments: clap would list "yes: Yes" and "no: No" under --help.
    Yes,
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

/// `leapview convert`.
#[derive(Args, Debug)]
pub struct ConvertArgs {
    /// Volume file or DICOM folder (any input render takes; --volume, --channel and the other
    /// input options apply).
    pub input: PathBuf,
    /// The store to write: a new folder, by custom named NAME.ome.zarr.
    pub out: PathBuf,
}

/// `leapview generate`.
#[derive(Args, Debug)]
pub struct GenerateArgs {
    /// Which volume.
    #[arg(value_enum)]
    pub what: Generated,
    /// Output: a .nrrd or .nhdr file, a .zarr store, or a folder for a DICOM series.
    ///
    /// .nrrd: one gzip-compressed file. .nhdr: a header, with the samples raw and little-endian
    /// in a .raw file of the same name. .zarr (e.g. NAME.ome.zarr): a multiscale OME-Zarr store,
    /// as leapview convert writes it. A folder (created if missing, else empty) receives a
    /// DICOM series, one uncompressed file per slice.
    #[arg(long)]
    pub out: PathBuf,
    /// DICOM series only: this many slices (z resampled, its extent kept).
    ///
    /// E.g. --size 512 --slices 1000 for a long CT series.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=4096))]
    pub slices: Option<u32>,
    /// Samples along each axis (8 to 1024).
    #[arg(long, default_value_t = 256, value_parser = clap::value_parser!(u32).range(8..=1024))]
    pub size: u32,
    /// Seed of the vessel tree and the dense head (same seed, same volume).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
}

/// How to read a file beyond what its header says: the layout of a headerless raw file, and the
/// patient's orientation where the header has none or states it wrong.
#[derive(Args, Debug, Clone, Default)]
pub struct RawArgs {
    /// Raw files: samples along x, y, z, e.g. 256,256,128.
    #[arg(long, value_parser = parse_dims, global = true, help_heading = "Input file")]
    pub dims: Option<[u32; 3]>,
    /// Raw files: sample type (uint8, int8, uint16, int16, uint32, int32, float, double).
    #[arg(long = "type", global = true, help_heading = "Input file")]
    pub scalar_type: Option<String>,
    /// Raw files: voxel spacing in millimetres (default 1,1,1).
    #[arg(long, value_parser = parse_vec3, global = true, help_heading = "Input file", hide_short_help = true)]
    pub spacing: Option<[f64; 3]>,
    /// Raw files: samples are big-endian (default little-endian).
    #[arg(
        long,
        global = true,
        help_heading = "Input file",
        hide_short_help = true
    )]
    pub big_endian: bool,
    /// Where index axes i, j, k point in the patient, replacing the header's orientation: three
    /// letters, one each of R/L, A/P and S/I (RAI: i to the patient's right, j to the front, k, the
    /// slices, from the top of the head down).
    #[arg(
        long,
        global = true,
        help_heading = "Input file",
        value_name = "CODE",
        hide_short_help = true
    )]
    pub orientation: Option<String>,
    /// DICOM: which series of a folder to open, by number or SeriesInstanceUID.
    ///
    /// The number is the series' place in leapview info's listing. Default: the image series with
    /// the most slices, or the series of the file named.
    #[arg(long, global = true, help_heading = "Input file", value_name = "N|UID")]
    pub series: Option<String>,
    /// 4-D files (an fMRI time series, NIfTI diffusion directions, an OME-Zarr t axis): which
    /// volume (time point) to open, counted from 1 (default: the first; leapview info says how
    /// many there are).
    #[arg(long, global = true, help_heading = "Input file", value_name = "N", value_parser = clap::value_parser!(u32).range(1..), hide_short_help = true)]
    pub volume: Option<u32>,
    /// Images with channels (an OME-Zarr c axis): which channel to open, counted from 1
    /// (default: the first).
    #[arg(long, global = true, help_heading = "Input file", value_name = "N", value_parser = clap::value_parser!(u32).range(1..), hide_short_help = true)]
    pub channel: Option<u32>,
    /// Memory an OME-Zarr store's or a TIFF stack's samples may take: 8GiB, 512MiB… One larger
    /// is read brick by brick as the view needs them, its decoded chunks cached within this
    /// (default: half the memory available).
    #[arg(long, global = true, help_heading = "Input file", value_name = "SIZE", value_parser = parse_gpu_budget, hide_short_help = true)]
    pub ram_budget: Option<u64>,
}

/// `leapview render`.
#[derive(Args, Debug)]
pub struct RenderArgs {
    /// Volume file or DICOM folder.
    pub file: PathBuf,
    /// Output image: .png (8-bit RGBA) or .exr (linear RGBA, 32-bit float).
    #[arg(long, short)]
    pub out: PathBuf,
    /// Visual effect.
    #[arg(long, value_enum, default_value = "dvr")]
    pub mode: Mode,
    /// Ray-casting strategy: how rays save work.
    #[arg(long, value_enum, default_value = "auto")]
    pub strategy: Strategy,
    /// Where the ray loop runs.
    #[arg(long, value_enum, default_value = "auto", hide_short_help = true)]
    pub path: RenderPath,
    /// Image size WxH in pixels.
    #[arg(long, value_parser = parse_size, default_value = "512x512")]
    pub size: [u32; 2],
    /// Camera placement.
    #[command(flatten)]
    pub camera: CameraArgs,
    /// Effect parameters.
    #[command(flatten)]
    pub effects: super::effect_args::EffectArgs,
    /// Transfer function: auto, a preset name, or a JSON file.
    ///
    /// auto chooses from the data: a CT preset for CT (mapped onto the scanner's units where the
    /// file is not in HU), the MR default for MR. Presets: ct-bone, ct-skin, ct-soft-tissue,
    /// ct-angio, ct-brain, mr-default, mr-angio, object, grey-ramp.
    #[arg(long, default_value = "auto")]
    pub tf: String,
    /// Sample step, in units of the smallest voxel spacing.
    #[arg(long, default_value_t = 0.5, help_heading = "Quality")]
    pub step: f64,
    /// Jitter ray starts per pixel: fine noise instead of wood-grain rings.
    #[arg(long, help_heading = "Quality")]
    pub jitter: bool,
    /// Stop a ray (RC-t and the leaping strategies) once its opacity exceeds this.
    #[arg(long, default_value_t = leapview::settings::DEFAULT_TERMINATION_ALPHA, help_heading = "Quality", hide_short_help = true)]
    pub termination: f64,
    /// Pre-integrated classification (DVR): thin features survive large steps.
    #[arg(long, help_heading = "Quality")]
    pub preintegrate: bool,
    /// Quality preset: sets the step, jitter, gradients and more.
    ///
    /// It decides the step, termination, jitter, pre-integration, gradients, iso refinement and
    /// lighting threshold. --gradient, --iso-refine and --light-min-weight override it; --step,
    /// --termination, --jitter and --preintegrate cannot be combined with it.
    #[arg(long, value_enum, conflicts_with_all = ["step", "termination", "jitter", "preintegrate"], help_heading = "Quality")]
    pub quality: Option<leapview::settings::QualityPreset>,
    /// Texel precision of the volume texture.
    #[arg(
        long,
        value_enum,
        default_value = "auto",
        help_heading = "Quality",
        hide_short_help = true
    )]
    pub precision: leapview::settings::TexturePrecision,
    /// The volume on the GPU as one 3D texture or as bricks in an atlas (auto: bricks only past
    /// the GPU's 3D texture limit).
    #[arg(
        long,
        value_enum,
        default_value = "auto",
        help_heading = "Quality",
        hide_short_help = true
    )]
    pub bricks: leapview::settings::Bricking,
    /// GPU memory.
    #[command(flatten)]
    pub gpu: GpuArgs,
    /// Edge of the leaping blocks (RC-s, RC-s-df) in voxels: 4, 8, 16, 32, 64 or 128.
    ///
    /// Default: the edge measured fastest for the mode and strategy: 16 for the octree (RC-s) in
    /// isosurface, MIP, MinIP and X-ray modes, else 4.
    #[arg(long, help_heading = "Quality", hide_short_help = true)]
    pub block: Option<u32>,
    /// Background colour R,G,B, each in 0..1.
    #[arg(long, value_parser = parse_vec3, default_value = "0,0,0", hide_short_help = true)]
    pub background: [f64; 3],
    /// Crop to voxel edges x0:x1,y0:y1,z0:z1 (0:NX,0:NY,0:NZ keeps all).
    #[arg(long)]
    pub crop: Option<String>,
    /// Average this many frames with shifted sample grids (1: one frame).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=1024), help_heading = "Quality")]
    pub refine: u32,
    /// Print sample counts, leaps and the GPU time of the frame.
    #[arg(long)]
    pub stats: bool,
    /// A segmentation shown with the volume.
    #[command(flatten)]
    pub segmentation: super::label_args::LabelArgs,
}

/// Camera placement shared by `render` (and later `bench`).
#[derive(Args, Debug, Clone)]
pub struct CameraArgs {
    /// Perspective or orthographic projection.
    #[arg(
        long,
        value_enum,
        default_value = "perspective",
        help_heading = "Camera"
    )]
    pub projection: ProjectionKind,
    /// View from a patient side (A, P, L, R, S, I), a volume axis (+x … -z), or oblique.
    ///
    /// A, P, L, R, S and I look at the patient from the front, back, left, right, top and
    /// bottom, by the file's orientation (RAS where it has none); +x, -x, +y, -y, +z and -z
    /// look along an axis of the volume. A, the default, shows the patient from the front, head
    /// up, as the window opens.
    #[arg(
        long,
        allow_hyphen_values = true,
        default_value = "A",
        help_heading = "Camera"
    )]
    pub view: String,
    /// Orbit azimuth in degrees; 0 looks along +y (overrides --view).
    #[arg(long, allow_hyphen_values = true, help_heading = "Camera")]
    pub azimuth: Option<f64>,
    /// Orbit elevation in degrees, with --azimuth (default 0).
    #[arg(long, allow_hyphen_values = true, help_heading = "Camera")]
    pub elevation: Option<f64>,
    /// Eye position X,Y,Z in world millimetres, where voxel (i, j, k) lies at (i·sx, j·sy, k·sz).
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true, help_heading = "Camera", hide_short_help = true)]
    pub eye: Option<[f64; 3]>,
    /// Point looked at, with --eye (default: the volume's centre).
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true, help_heading = "Camera", hide_short_help = true)]
    pub target: Option<[f64; 3]>,
    /// Up direction, with --eye (default +z, or -y when looking along z).
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true, help_heading = "Camera", hide_short_help = true)]
    pub up: Option<[f64; 3]>,
    /// Vertical field of view in degrees (perspective projection only).
    #[arg(long, help_heading = "Camera")]
    pub fov: Option<f64>,
}

/// `leapview info`.
#[derive(Args, Debug)]
pub struct InfoArgs {
    /// Volume file or DICOM folder.
    pub file: PathBuf,
    /// Also report the share of voxels this transfer function makes transparent.
    ///
    /// A preset name or a JSON file; a voxel counts when the function gives its value no
    /// opacity at all.
    #[arg(long)]
    pub tf: Option<String>,
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
    /// A segmentation of the volume: list its segments (value, name, colour, voxels).
    ///
    /// NIfTI, NRRD or Slicer .seg.nrrd, MetaImage; put on the volume's grid by patient
    /// position (nearest label). Names and colours from the file, from --label-names, or from
    /// a .txt or .ctbl file beside it with its name.
    #[arg(long, value_name = "FILE")]
    pub labels: Option<PathBuf>,
    /// An ITK-SNAP label description file or a Slicer colour table naming the labels.
    #[arg(long, value_name = "FILE", requires = "labels")]
    pub label_names: Option<PathBuf>,
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
