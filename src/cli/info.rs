//! `leapview info`: what a volume holds.

use leapview::transfer::TransferFunction;
use leapview::volume::stats::quantile;
use leapview::volume::{ValueMapping, Volume};

use super::args::{InfoArgs, RawArgs};
use super::{Failure, load};

/// The share of voxels whose stored value is below `min + 0.1 * (P99.9 - min)` (the "air"
/// definition of ../shared/data/README.md), on stored values.
fn air_fraction(volume: &Volume) -> Option<(f64, f64)> {
    let samples = volume.samples();
    let min = quantile(samples, ValueMapping::IDENTITY, 0.0)?;
    let p999 = quantile(samples, ValueMapping::IDENTITY, 0.999)?;
    let t = min + 0.1 * (p999 - min);
    let mut below = 0u64;
    samples.for_each_f64(|s| below += u64::from(s < t));
    Some((t, below as f64 / volume.sample_count() as f64))
}

/// Share of voxels to which `tf` gives zero opacity.
fn transparent_fraction(volume: &Volume, tf: &TransferFunction) -> f64 {
    let range = volume.normalization_range();
    let mut zero = 0u64;
    volume.samples().for_each_f64(|s| {
        let v = volume.mapping().apply(s);
        zero += u64::from(!v.is_finite() || tf.opacity_at(v, range) <= 0.0);
    });
    zero as f64 / volume.sample_count() as f64
}

/// Runs the command.
pub fn run(args: InfoArgs, raw: &RawArgs) -> Result<(), Failure> {
    let volume = load(&args.file, raw)?;
    let tf = match &args.tf {
        Some(name) => Some(
            TransferFunction::from_preset_or_file(name).map_err(|e| Failure::BadInput(e.into()))?,
        ),
        None => None,
    };
    let q = |p| quantile(volume.samples(), volume.mapping(), p);
    let range = volume.value_range();
    let air = air_fraction(&volume);
    let transparent = tf.as_ref().map(|tf| transparent_fraction(&volume, tf));
    let m = volume.mapping();
    if args.json {
        let value = serde_json::json!({
            "name": volume.name(),
            "dims": volume.dims(),
            "spacing_mm": volume.spacing_mm(),
            "type": volume.scalar_type().name(),
            "slope": m.slope,
            "intercept": m.intercept,
            "range": range.map(|r| [r.min, r.max]),
            "non_finite": volume.non_finite_count(),
            "percentiles": {"p1": q(0.01), "p50": q(0.5), "p99": q(0.99), "p99_9": q(0.999)},
            "air_threshold": air.map(|a| a.0),
            "air_fraction": air.map(|a| a.1),
            "tf_transparent_fraction": transparent,
            "orientation": volume.orientation().map(|o| o.code()),
            "orientation_in_file": volume.file_orientation().map(|o| o.code()),
            "reversed_i": volume.reversed_i(),
        });
        println!("{value:#}");
        return Ok(());
    }
    let [x, y, z] = volume.dims();
    let [sx, sy, sz] = volume.spacing_mm();
    println!("file:        {}", args.file.display());
    println!(
        "dims:        {x} x {y} x {z} ({} voxels, {:.1} MB stored)",
        volume.sample_count(),
        volume.sample_count() as f64 * volume.scalar_type().size_bytes() as f64 / 1e6
    );
    println!(
        "spacing:     {sx} x {sy} x {sz} mm (extent {:.1} x {:.1} x {:.1} mm)",
        x as f64 * sx,
        y as f64 * sy,
        z as f64 * sz
    );
    println!("type:        {}", volume.scalar_type());
    match volume.orientation() {
        Some(o) if volume.reversed_i() => println!(
            "orientation: {} in the header, a mirror image of the patient: read reversed along i, \
             so renders show {} (voxel i is {} - i in the file)",
            o.with_axis_reversed(0).code(),
            o.code(),
            x.saturating_sub(1)
        ),
        Some(o) => println!(
            "orientation: {} (index axes i, j, k point to these)",
            o.code()
        ),
        None => println!("orientation: not in the header (views assume RAS)"),
    }
    if m != ValueMapping::IDENTITY {
        println!(
            "scaling:     value = stored x {} + {}",
            m.slope, m.intercept
        );
    }
    match range {
        Some(r) => println!("range:       {} .. {} (data units)", r.min, r.max),
        None => println!("range:       no finite value"),
    }
    if volume.non_finite_count() > 0 {
        println!(
            "non-finite:  {} voxels (NaN or infinite; rendered transparent)",
            volume.non_finite_count()
        );
    }
    let fmt = |v: Option<f64>| v.map_or("-".to_string(), |v| format!("{v}"));
    println!(
        "percentiles: P1 {}  P50 {}  P99 {}  P99.9 {}",
        fmt(q(0.01)),
        fmt(q(0.5)),
        fmt(q(0.99)),
        fmt(q(0.999))
    );
    if let Some((t, share)) = air {
        println!(
            "empty:       {:.1} % of voxels below {t} (stored min + 0.1 x (P99.9 - min))",
            100.0 * share
        );
    }
    if let (Some(share), Some(name)) = (transparent, &args.tf) {
        println!(
            "transparent: {:.1} % of voxels have zero opacity under {name}",
            100.0 * share
        );
    }
    Ok(())
}
