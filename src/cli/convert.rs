//! `leapview convert IN OUT`: any volume LeapView reads, written as a multiscale OME-Zarr store
//! (`leapview::volume::zarr::write`).

use std::io::IsTerminal;
use std::path::Path;
use std::sync::atomic::{AtomicU32, Ordering};

use leapview::volume::zarr::write::{WriteError, write_ome_zarr};

use super::Failure;
use super::args::{ConvertArgs, RawArgs};

/// Runs the command.
pub fn run(args: &ConvertArgs, raw: &RawArgs) -> Result<(), Failure> {
    let volume = super::load(&args.input, raw)?;
    let written = write(&volume, &args.out, &args.input)?;
    let stored = volume.sample_count() * volume.scalar_type().size_bytes() as u64;
    let levels: Vec<String> = written
        .levels
        .iter()
        .map(|[x, y, z]| format!("{x}x{y}x{z}"))
        .collect();
    println!(
        "wrote {}: OME-Zarr 0.5, {} levels ({}), {} on disk for {} of samples at level 0",
        args.out.display(),
        written.levels.len(),
        levels.join(", "),
        leapview::text::bytes(written.bytes),
        leapview::text::bytes(stored),
    );
    Ok(())
}

/// Writes `volume` to `out` with a progress report on standard error.
pub fn write(
    volume: &leapview::volume::Volume,
    out: &Path,
    source: &Path,
) -> Result<leapview::volume::zarr::write::Written, Failure> {
    with_progress(|progress| write_ome_zarr(volume, out, &source.display().to_string(), progress))
}

/// Runs `write` with a progress report on standard error (one rewritten line at a terminal,
/// else a line per tenth) and turns its error into a failure.
pub fn with_progress(
    write: impl FnOnce(
        &(dyn Fn(f64) + Sync),
    ) -> Result<leapview::volume::zarr::write::Written, WriteError>,
) -> Result<leapview::volume::zarr::write::Written, Failure> {
    let terminal = std::io::stderr().is_terminal();
    let shown = AtomicU32::new(0);
    let progress = |share: f64| {
        let percent = (share * 100.0).floor() as u32;
        let step = if terminal { 1 } else { 10 };
        let last = shown.load(Ordering::Relaxed);
        if percent >= last + step
            && shown
                .compare_exchange(last, percent, Ordering::Relaxed, Ordering::Relaxed)
                .is_ok()
        {
            if terminal {
                eprint!("\rwriting: {percent} %");
            } else {
                eprintln!("writing: {percent} %");
            }
        }
    };
    let written = write(&progress);
    if terminal && shown.load(Ordering::Relaxed) > 0 {
        eprintln!();
    }
    written.map_err(|e| match e {
        WriteError::Exists(_) | WriteError::NoFolder(_) => Failure::BadInput(e.into()),
        e => Failure::Other(e.into()),
    })
}
