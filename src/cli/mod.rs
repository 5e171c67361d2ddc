//! The command line: `render`, `info`, `bench`, `accuracy`, `generate`, `slice` and `shaders` (the window
//! is opened from `main`).
//! Input problems (a bad volume or transfer-function file, a bad flag) are [`Failure::BadInput`]
//! and exit with status 2.

mod accuracy;
pub mod args;
mod bench;
mod convert;
mod datasets;
pub mod effect_args;
mod generate;
mod info;
mod label_args;
mod measuring;
pub mod parse;
mod plotting;
mod render;
mod shaders;
mod slice;
mod text;

use std::path::Path;

use glam::DVec3;
use leapview::camera::{Aabb, Camera, Projection, ProjectionKind, ViewPreset, orbit_direction};
use leapview::volume::raw::RawParams;
use leapview::volume::{LoadOptions, ScalarType, Volume, load_volume};

pub use args::{Cli, Command};

/// How a command failed, which decides the exit status.
#[derive(Debug)]
pub enum Failure {
    /// The input (volume, transfer function, arguments) is unusable: exit status 2.
    BadInput(anyhow::Error),
    /// Anything else (no GPU, a GPU error, an unwritable output): exit status 1.
    Other(anyhow::Error),
}

impl From<anyhow::Error> for Failure {
    fn from(e: anyhow::Error) -> Self {
        Self::Other(e)
    }
}

/// The one way a command turns an error into a [`Failure`]: `.bad_input()?` where the user's
/// input is at fault (exit status 2), `.failed()?` otherwise (exit status 1).
pub trait OrFail<T> {
    /// The error as bad input.
    fn bad_input(self) -> Result<T, Failure>;
    /// The error as any other failure.
    fn failed(self) -> Result<T, Failure>;
}

impl<T, E: Into<anyhow::Error>> OrFail<T> for Result<T, E> {
    fn bad_input(self) -> Result<T, Failure> {
        self.map_err(|e| Failure::BadInput(e.into()))
    }

    fn failed(self) -> Result<T, Failure> {
        self.map_err(|e| Failure::Other(e.into()))
    }
}

/// Runs a subcommand.
pub fn run(command: Command, raw: &args::RawArgs) -> Result<(), Failure> {
    match command {
        Command::Render(args) => render::run(*args, raw),
        Command::Info(args) => info::run(args, raw),
        Command::Bench(args) => bench::run(*args, raw),
        Command::Accuracy(args) => accuracy::run(*args),
        Command::Generate(args) => generate::run(&args, raw),
        Command::Convert(args) => convert::run(&args, raw),
        Command::Slice(args) => slice::run(&args, raw),
        Command::Shaders(args) => shaders::run(&args),
    }
}

/// Load options from the raw-file flags (`None` raw layout when `--dims` is absent) and
/// `--orientation`.
pub fn load_options(raw: &args::RawArgs) -> Result<LoadOptions, Failure> {
    let orientation = raw
        .orientation
        .as_deref()
        .map(leapview::volume::Orientation::parse_code)
        .transpose()
        .bad_input()?;
    let series = raw
        .series
        .as_deref()
        .map(leapview::volume::dicom::SeriesChoice::parse);
    // Counted from 1 on the command line, from 0 in LoadOptions.
    let volume = raw.volume.map(|n| n - 1);
    let channel = raw.channel.map(|n| n - 1);
    let ram_budget = raw.ram_budget;
    let Some(dims) = raw.dims else {
        return Ok(LoadOptions {
            orientation,
            series,
            volume,
            channel,
            ram_budget,
            ..LoadOptions::default()
        });
    };
    let name = raw.scalar_type.as_deref().ok_or_else(|| {
        Failure::BadInput(anyhow::anyhow!(
            "a raw volume needs --type as well as --dims (uint8, int16, float, …)"
        ))
    })?;
    let scalar_type = ScalarType::from_name(name)
        .ok_or_else(|| Failure::BadInput(anyhow::anyhow!("unknown sample type {name:?} (use uint8, int8, uint16, int16, uint32, int32, float or double)")))?;
    Ok(LoadOptions {
        raw: Some(RawParams {
            dims,
            scalar_type,
            spacing_mm: raw.spacing.unwrap_or([1.0; 3]),
            big_endian: raw.big_endian,
        }),
        orientation,
        series,
        volume,
        channel,
        ram_budget,
        ..LoadOptions::default()
    })
}

/// Loads a volume, turning any problem into a one-line bad-input failure.
pub fn load(path: &Path, raw: &args::RawArgs) -> Result<Volume, Failure> {
    let options = load_options(raw)?;
    load_volume(path, &options).bad_input()
}

/// [`load`] for the GPU of `ctx` within `gpu_budget`: the volume's shape is checked against it
/// (a layout within its limits and the budget, a texture of that size) before its samples are
/// read.
pub fn load_for_gpu(
    path: &Path,
    raw: &args::RawArgs,
    (ctx, gpu_budget): (&leapview::render::GpuContext, Option<u64>),
) -> Result<Volume, Failure> {
    let mut options = load_options(raw)?;
    options.progress = Some(std::sync::Arc::new(
        leapview::volume::LoadProgress::with_admission(
            leapview::render::volume_texture::admission(ctx, gpu_budget),
        ),
    ));
    load_volume(path, &options).bad_input()
}

/// The camera the flags describe, for a volume with bounds `bounds`.
pub fn camera_from_args(
    args: &args::CameraArgs,
    bounds: &Aabb,
    orientation: leapview::volume::Orientation,
) -> Result<Camera, Failure> {
    let bad = |msg: String| Failure::BadInput(anyhow::anyhow!(msg));
    let mut camera = if let Some(eye) = args.eye {
        let eye = DVec3::from_array(eye);
        let target = args.target.map_or(bounds.center(), DVec3::from_array);
        if (target - eye).length() == 0.0 {
            return Err(bad("--eye and --target are the same point".into()));
        }
        let dir = target - eye;
        let default_up = if dir.normalize().z.abs() > 0.99 {
            DVec3::NEG_Y
        } else {
            DVec3::Z
        };
        let up = args.up.map_or(default_up, DVec3::from_array);
        if up.cross(dir).length_squared() == 0.0 {
            return Err(bad("--up is parallel to the viewing direction".into()));
        }
        let mut camera = Camera::framing(bounds, dir, up, args.projection);
        camera.eye = eye;
        camera.target = target;
        camera.up = up;
        camera
    } else {
        let (dir, up) = match args.azimuth {
            Some(az) => (orbit_direction(az, args.elevation.unwrap_or(0.0)), DVec3::Z),
            None => match leapview::volume::Direction::parse(&args.view) {
                Some(side) => orientation.view_from(side),
                None => ViewPreset::parse(&args.view)
                    .ok_or_else(|| {
                        bad(format!(
                            "unknown view {:?} (use A, P, L, R, S, I, +x, -x, +y, -y, +z, -z or \
                             oblique)",
                            args.view
                        ))
                    })?
                    .direction_and_up(),
            },
        };
        Camera::framing(bounds, dir, up, args.projection)
    };
    if let Some(fov) = args.fov {
        if !(fov > 0.0 && fov < 180.0) {
            return Err(bad(format!(
                "--fov must be between 0 and 180 degrees, got {fov}"
            )));
        }
        if args.projection == ProjectionKind::Perspective {
            camera.projection = Projection::Perspective { fov_y_deg: fov };
        }
    }
    Ok(camera)
}
