//! `leapview info`: what a volume holds.

use leapview::labels::LabelMap;
use leapview::transfer::TransferFunction;
use leapview::transfer::fit::{self, DataKind};
use leapview::volume::progress::Shape;
use leapview::volume::stats::quantile;
use leapview::volume::{LoadProgress, OrientationSource, ValueMapping, Volume};

use super::args::{InfoArgs, RawArgs};
use super::label_args::read_labels;
use super::text::{number, outln, print_stdout};
use super::{Failure, load};
use crate::cli::OrFail;

/// The share of voxels whose stored value is below `min + 0.1 * (P99.9 - min)` (the "air"
/// definition of ../shared/data/README.md), on stored values.
fn air_fraction(volume: &Volume) -> Option<(f64, f64)> {
    let samples = volume.held().0;
    let min = quantile(samples, ValueMapping::IDENTITY, 0.0)?;
    let p999 = quantile(samples, ValueMapping::IDENTITY, 0.999)?;
    let t = min + 0.1 * (p999 - min);
    let mut below = 0u64;
    samples.for_each_f64(|s| below += u64::from(s < t));
    Some((t, below as f64 / samples.len() as f64))
}

/// Share of voxels to which `tf` gives zero opacity.
fn transparent_fraction(volume: &Volume, tf: &TransferFunction) -> f64 {
    let range = volume.normalization_range();
    let mut zero = 0u64;
    let samples = volume.held().0;
    samples.for_each_f64(|s| {
        let v = volume.mapping().apply(s);
        zero += u64::from(!v.is_finite() || tf.opacity_at(v, range) <= 0.0);
    });
    zero as f64 / samples.len() as f64
}

/// Volumes of more sample bytes than this are read every few slices for `info`'s statistics:
/// reading all of an 8 GiB volume took minutes and 8.4 GB of memory for a few numbers.
const FULL_READ_BYTES: u64 = 1 << 30;

/// What the header says of the volume `raw` opens at `path`, asked of its reader before it
/// reads a sample (the load is stopped there).
fn shape_of(path: &std::path::Path, raw: &RawArgs) -> Result<Option<Shape>, Failure> {
    let seen = std::sync::Arc::new(std::sync::Mutex::new(None));
    let record = std::sync::Arc::clone(&seen);
    let mut options = super::load_options(raw)?;
    options.progress = Some(std::sync::Arc::new(LoadProgress::with_admission(Box::new(
        move |shape: &Shape| {
            if let Ok(mut s) = record.lock() {
                *s = Some(*shape);
            }
            Err("stopped after the header".into())
        },
    ))));
    match leapview::volume::load_volume(path, &options) {
        Err(e) if matches!(e.problem, leapview::volume::VolumeError::NotAdmitted { .. }) => {
            Ok(seen.lock().ok().and_then(|s| *s))
        }
        Err(e) => Err(Failure::BadInput(e.into())),
        Ok(_) => Ok(None),
    }
}

/// Loads the volume for `info`: whole, or, past [`FULL_READ_BYTES`], every few slices (the
/// stride returned) for its statistics, with the header's dimensions.
fn load_sampled(
    path: &std::path::Path,
    raw: &RawArgs,
) -> Result<(Volume, u32, Option<[u32; 3]>), Failure> {
    let shape = shape_of(path, raw)?;
    let bytes = shape.map_or(0, |s| {
        s.dims.iter().map(|&d| u64::from(d)).product::<u64>()
            * if s.colour {
                4
            } else {
                s.scalar_type.size_bytes() as u64
            }
    });
    let stride = bytes
        .div_ceil(FULL_READ_BYTES)
        .max(1)
        .min(u64::from(u32::MAX)) as u32;
    if stride <= 1 {
        return Ok((load(path, raw)?, 1, None));
    }
    let mut options = super::load_options(raw)?;
    options.progress = Some(std::sync::Arc::new(
        LoadProgress::default().with_slice_stride(stride),
    ));
    let volume = leapview::volume::load_volume(path, &options).bad_input()?;
    // A reader that reads every slice anyway (an OME-Zarr store: whole, or a preview level of
    // it where it is streamed) leaves the volume as the header said.
    if shape.is_some_and(|s| s.dims == volume.dims()) {
        return Ok((volume, 1, None));
    }
    Ok((volume, stride, shape.map(|s| s.dims)))
}

/// Runs the command.
pub fn run(args: InfoArgs, raw: &RawArgs) -> Result<(), Failure> {
    let (volume, stride, header_dims) = load_sampled(&args.file, raw)?;
    let kind = DataKind::of(&volume);
    let tf = match &args.tf {
        Some(name) => Some(fit::resolve(name, &kind).bad_input()?.tf),
        None => None,
    };
    let q = |p| quantile(volume.held().0, volume.mapping(), p);
    let range = volume.value_range();
    let dims = header_dims.unwrap_or(volume.dims());
    let spacing = {
        let [sx, sy, sz] = volume.spacing_mm();
        [sx, sy, sz / f64::from(stride)]
    };
    let air = air_fraction(&volume);
    let transparent = tf.as_ref().map(|tf| transparent_fraction(&volume, tf));
    let labels = match &args.labels {
        Some(path) => Some(read_labels(path, args.label_names.as_ref(), &volume)?),
        None => None,
    };
    let m = volume.mapping();
    if args.json {
        let labels_json = labels.as_ref().map(labels_value);
        let value = serde_json::json!({
            "name": volume.name(),
            "dims": dims,
            "spacing_mm": spacing,
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
            "orientation_source": volume.orientation().map(|o| match o.source {
                OrientationSource::Header => "header",
                OrientationSource::User => "user",
                OrientationSource::Assumed => "assumed",
                OrientationSource::AsStored => "as stored",
            }),
            "orientation_in_header": volume.header_orientation().map(|o| o.code()),
            "reversed_i": volume.reversed_i(),
            "modality": volume.modality().map(|m| m.label()),
            "values": kind.describe(volume.modality()),
            "hu_calibration": match &kind {
                DataKind::CtCalibrated { to_hu, .. } => Some([to_hu.scale, to_hu.offset]),
                _ => None,
            },
            "default_tf": kind.default_preset(),
            "default_window": fit::default_window_of(&volume),
            "header_window": volume.provenance().window,
            "notes": volume.provenance().notes,
            "series": volume.provenance().series.as_ref().map(|s| serde_json::json!({
                "uid": s.uid,
                "number": s.number,
                "modality": s.modality,
                "description": s.description,
                "date": s.date,
                "frame_of_reference": s.frame_of_reference,
            })),
            "series_found": volume.provenance().listing,
            "series_opened": volume.provenance().chosen.map(|i| i + 1),
            "volume_opened": volume.provenance().volumes.map(|v| [v.chosen + 1, v.count]),
            "channel_opened": volume.provenance().channels.map(|c| [c.chosen + 1, c.count]),
            "skipped": volume.provenance().skipped,
            "origin_lps_mm": volume.provenance().origin_lps,
            "patient_box_lps_mm": patient_box(&volume, dims[2], stride),
            "slices_read_every": stride,
            "labels": labels_json,
        });
        return print_stdout(&format!("{value:#}\n")).failed();
    }
    let mut out = String::new();
    // The header's dimensions and spacing, where only every few slices were read.
    let [x, y, z] = dims;
    let [sx, sy, sz] = spacing;
    let voxels = u64::from(x) * u64::from(y) * u64::from(z);
    outln!(out, "file:        {}", args.file.display());
    series_text(&mut out, &volume);
    outln!(
        out,
        "dims:        {x} x {y} x {z} ({voxels} voxels, {:.1} MB stored)",
        voxels as f64 * volume.scalar_type().size_bytes() as f64 / 1e6
    );
    if stride > 1 {
        outln!(
            out,
            "sampled:     one slice in {stride} ({} of {z}) read for the values below, which are \
             estimates: the volume is past {} GiB",
            volume.dims()[2],
            FULL_READ_BYTES >> 30
        );
    }
    // Microscopy's voxels (an OME-Zarr or OME-TIFF in micrometres) in micrometres.
    let (per_mm, unit) = if sx.max(sy).max(sz) < 0.1 {
        (1000.0, "µm")
    } else {
        (1.0, "mm")
    };
    outln!(
        out,
        "spacing:     {} x {} x {} {unit} (extent {:.1} x {:.1} x {:.1} {unit})",
        number(sx * per_mm),
        number(sy * per_mm),
        number(sz * per_mm),
        x as f64 * sx * per_mm,
        y as f64 * sy * per_mm,
        z as f64 * sz * per_mm
    );
    outln!(out, "type:        {}", volume.scalar_type());
    outln!(out, "orientation: {}", orientation_text(&volume));
    let [lo, hi] = patient_box(&volume, z, stride);
    outln!(
        out,
        "patient box: x {} .. {}, y {} .. {}, z {} .. {} mm (LPS, voxel centres; `slice --at`)",
        number(lo[0]),
        number(hi[0]),
        number(lo[1]),
        number(hi[1]),
        number(lo[2]),
        number(hi[2])
    );
    if m != ValueMapping::IDENTITY {
        outln!(
            out,
            "scaling:     value = stored x {} + {}",
            number(m.slope),
            number(m.intercept)
        );
    }
    match range {
        Some(r) => outln!(
            out,
            "range:       {} .. {} (data units)",
            number(r.min),
            number(r.max)
        ),
        None => outln!(out, "range:       no finite value"),
    }
    if volume.non_finite_count() > 0 {
        outln!(
            out,
            "non-finite:  {} voxels (NaN or infinite; rendered transparent)",
            volume.non_finite_count()
        );
    }
    let fmt = |v: Option<f64>| v.map_or("-".to_string(), number);
    // A streamed volume's percentiles are its preview's (averages of 2^k voxels a side).
    let of_preview = volume.streaming().map_or(String::new(), |s| {
        let [px, py, pz] = s.preview().dims;
        format!(" (of level {}, {px} x {py} x {pz})", s.preview_level())
    });
    outln!(
        out,
        "percentiles: P1 {}  P50 {}  P99 {}  P99.9 {}{of_preview}",
        fmt(q(0.01)),
        fmt(q(0.5)),
        fmt(q(0.99)),
        fmt(q(0.999))
    );
    if let Some((t, share)) = air {
        outln!(
            out,
            "empty:       {:.1} % of voxels below {} (stored min + 0.1 x (P99.9 - min)){of_preview}",
            100.0 * share,
            number(t)
        );
    }
    outln!(out, "values:      {}", kind.describe(volume.modality()));
    outln!(out, "default tf:  {}", kind.default_preset());
    if let Some([lo, hi]) = volume.provenance().window {
        outln!(
            out,
            "window:      {} .. {} (MIP, MinIP, X-ray by default: the header's window)",
            number(lo),
            number(hi)
        );
    } else if let Some([lo, hi]) = fit::default_window(volume.histogram()) {
        outln!(
            out,
            "window:      {} .. {} (MIP, MinIP, X-ray by default: 0.1 to 99.9 percentile)",
            number(lo),
            number(hi)
        );
    }
    for note in &volume.provenance().notes {
        outln!(out, "note:        {note}");
    }
    if let (Some(share), Some(name)) = (transparent, &args.tf) {
        outln!(
            out,
            "transparent: {:.1} % of voxels have zero opacity under {name}",
            100.0 * share
        );
    }
    if let Some(labels) = &labels {
        labels_text(&mut out, labels, stride);
    }
    print_stdout(&out).failed()
}

/// The segments of `labels` and their notes, as JSON.
fn labels_value(labels: &LabelMap) -> serde_json::Value {
    let segments: Vec<serde_json::Value> = labels
        .segments()
        .iter()
        .map(|s| {
            serde_json::json!({
                "value": s.value,
                "layer": s.layer,
                "name": s.name,
                "colour": hex(s.colour),
                "voxels": s.voxels,
            })
        })
        .collect();
    serde_json::json!({
        "file": labels.name(),
        "segments": segments,
        "notes": labels.notes(),
    })
}

/// `#rrggbb`.
fn hex([r, g, b]: [u8; 3]) -> String {
    format!("#{r:02x}{g:02x}{b:02x}")
}

/// The segments of `labels`, a line each; `stride`: the volume's slices were read every so
/// many, and the voxels counted on those.
fn labels_text(out: &mut String, labels: &LabelMap, stride: u32) {
    let layers = labels.layers().len();
    outln!(
        out,
        "labels:      {}: {} segments{}",
        labels.name(),
        labels.segments().len(),
        if layers > 1 {
            format!(" in {layers} layers")
        } else {
            String::new()
        }
    );
    for s in labels.segments() {
        let layer = if layers > 1 {
            format!(" (layer {})", s.layer)
        } else {
            String::new()
        };
        outln!(
            out,
            "  {:>5}  {}  {:>10} voxels  {}{layer}",
            s.value,
            hex(s.colour),
            s.voxels,
            s.name
        );
    }
    for note in labels.notes() {
        outln!(out, "labels note: {note}");
    }
    if stride > 1 {
        outln!(
            out,
            "labels note: voxels counted on every {stride}th slice read"
        );
    }
}

/// A DICOM series' facts, and the other series found beside it.
/// The smallest and largest patient coordinates (LPS, mm) of the voxel centres: where
/// `leapview slice --at` points can lie (the header's origin, else the first voxel at 0).
/// The patient-frame box of the voxel centres of `volume`, whose header has `slices` slices, of
/// which every `stride`-th was read.
fn patient_box(volume: &Volume, slices: u32, stride: u32) -> [[f64; 3]; 2] {
    let frame = leapview::mpr::PatientFrame::of(volume);
    let [x, y, _] = volume.dims().map(|n| f64::from(n - 1));
    // Read slice k is header slice k × stride: the header's last at (slices − 1) / stride.
    let z = f64::from(slices - 1) / f64::from(stride);
    let corners = (0..8).map(|c| {
        let pick = |a: usize, n: f64| if c >> a & 1 == 1 { n } else { 0.0 };
        frame.to_patient(glam::DVec3::new(pick(0, x), pick(1, y), pick(2, z)))
    });
    let (lo, hi) = corners.fold(
        (glam::DVec3::INFINITY, glam::DVec3::NEG_INFINITY),
        |(lo, hi), p| (lo.min(p), hi.max(p)),
    );
    [lo.to_array(), hi.to_array()]
}

fn series_text(out: &mut String, volume: &Volume) {
    let p = volume.provenance();
    if let Some(s) = &p.series {
        let mut what = s.modality_or_unknown().to_string();
        if let Some(n) = s.number {
            what.push_str(&format!(", series #{n}"));
        }
        if !s.description.is_empty() {
            what.push_str(&format!(", \"{}\"", s.description));
        }
        if s.date.len() == 8 && s.date.bytes().all(|b| b.is_ascii_digit()) {
            what.push_str(&format!(
                ", {}-{}-{}",
                &s.date[..4],
                &s.date[4..6],
                &s.date[6..]
            ));
        } else if !s.date.is_empty() {
            what.push_str(&format!(", {}", s.date));
        }
        outln!(out, "series:      {what}");
        outln!(out, "series uid:  {}", s.uid);
    }
    if p.listing.len() > 1 {
        outln!(
            out,
            "found:       {} series (pick one with --series N or --series UID):",
            p.listing.len()
        );
        for (i, line) in p.listing.iter().enumerate() {
            let mark = if p.chosen == Some(i) { "*" } else { " " };
            outln!(out, "           {mark} {line}");
        }
        if let Some(i) = p.chosen {
            outln!(out, "opened:      series {} (marked *)", i + 1);
        }
    }
    if let Some(v) = p.volumes {
        let (n, count) = (v.chosen + 1, v.count);
        outln!(
            out,
            "volume:      {n} of {count} (pick one with --volume N)"
        );
    }
    if let Some(c) = p.channels {
        let (n, count) = (c.chosen + 1, c.count);
        outln!(
            out,
            "channel:     {n} of {count} (pick one with --channel N)"
        );
    }
    if let Some(skipped) = &p.skipped {
        outln!(out, "skipped:     {skipped}");
    }
    if let Some([x, y, z]) = p.origin_lps {
        outln!(
            out,
            "origin:      {}, {}, {} mm (LPS, centre of the first voxel)",
            number(x),
            number(y),
            number(z)
        );
    }
}

/// Where the index axes point, who said so, and whether the samples were reversed along i.
fn orientation_text(volume: &Volume) -> String {
    let Some(o) = volume.orientation() else {
        return "not in the header (views assume RAS; set it with --orientation CODE)".into();
    };
    let in_file = volume.file_orientation().unwrap_or(o).code();
    let said = match (o.source, volume.header_orientation()) {
        (OrientationSource::User, Some(h)) => {
            format!(
                "{in_file} as given with --orientation (the header says {})",
                h.code()
            )
        }
        (OrientationSource::User, None) => {
            format!("{in_file} as given with --orientation (the header has none)")
        }
        (OrientationSource::AsStored, _) => {
            return "none in the file: shown as stored, row 0 at the top and column 0 at the left \
                    (set it with --orientation CODE)"
                .into();
        }
        _ => format!("{in_file} in the header"),
    };
    if volume.reversed_i() {
        format!(
            "{said}, a mirror image of the patient: read reversed along i, so renders show {} \
             (voxel i is {} - i in the file)",
            o.code(),
            volume.dims()[0].saturating_sub(1)
        )
    } else {
        format!("{said} (index axes i, j, k point to these)")
    }
}
