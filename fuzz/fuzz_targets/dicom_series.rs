#![no_main]
//! DICOM series assembly over arbitrary tag values: frames with any positions, orientations,
//! spacings, sizes, pixel formats and series (NaN, infinities, huge and tiny numbers included),
//! grouped, chosen and assembled as a folder's would be; what assembles is resampled. Checks the
//! plan's invariants: slices as the dimensions say, weights summing to 1, frames that exist.
use arbitrary::{Arbitrary, Unstructured};
use leapview::volume::dicom::geometry::{SlicePlan, assemble};
use leapview::volume::dicom::header::{FrameHeader, Photometric, PixelFormat, Rescale, SeriesFacts};
use leapview::volume::dicom::resample::resample_slice;
use leapview::volume::dicom::series::{SeriesChoice, choose, drop_copies, group};

/// A number from a small palette of hard cases, or any f64.
fn number(u: &mut Unstructured) -> arbitrary::Result<f64> {
    Ok(match u.int_in_range(0..=9)? {
        0 => 0.0,
        1 => 1.0,
        2 => -1.0,
        3 => f64::NAN,
        4 => f64::INFINITY,
        5 => 1e300,
        6 => 1e-300,
        7 => f64::from(u.int_in_range(-4i32..=4)?) * 0.5,
        _ => f64::arbitrary(u)?,
    })
}

fn option<T>(
    u: &mut Unstructured,
    f: impl FnOnce(&mut Unstructured) -> arbitrary::Result<T>,
) -> arbitrary::Result<Option<T>> {
    Ok(if bool::arbitrary(u)? {
        Some(f(u)?)
    } else {
        None
    })
}

fn frame(u: &mut Unstructured, file: usize) -> arbitrary::Result<FrameHeader> {
    let series = u.int_in_range(0..=2u8)?;
    let axial = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0];
    let orientation = match u.int_in_range(0..=3)? {
        0 => None,
        1 | 2 => Some(axial),
        _ => Some(std::array::from_fn(|_| number(u).unwrap_or(0.0))),
    };
    let position = option(u, |u| Ok([number(u)?, number(u)?, number(u)?]))?;
    let bits_allocated = *u.choose(&[1u16, 8, 16, 32])?;
    Ok(FrameHeader {
        file,
        frame: u.int_in_range(0..=3)?,
        label: format!("f{file}"),
        frames_in_file: 1,
        series: SeriesFacts {
            uid: format!("1.2.{series}"),
            frame_of_reference: "1".into(),
            ..SeriesFacts::default()
        },
        rows: u.int_in_range(0..=6)?,
        columns: u.int_in_range(0..=6)?,
        orientation,
        patient_orientation: None,
        position,
        pixel_spacing: option(u, |u| Ok([number(u)?, number(u)?]))?,
        slice_thickness: option(u, number)?,
        spacing_between_slices: option(u, number)?,
        pixel: PixelFormat {
            bits_allocated,
            bits_stored: u.int_in_range(1..=bits_allocated.max(1))?,
            high_bit: u.int_in_range(0..=31)?,
            signed: bool::arbitrary(u)?,
            samples_per_pixel: u.int_in_range(1..=3)?,
            photometric: Photometric::parse(
                ["MONOCHROME1", "MONOCHROME2", "RGB", "YBR_FULL", "PALETTE COLOR", "HSV"]
                    [u.int_in_range(0..=5usize)?],
            ),
            planar: bool::arbitrary(u)?,
        },
        rescale: Rescale {
            slope: number(u)?,
            intercept: number(u)?,
        },
        window: option(u, |u| Ok([number(u)?, number(u)?]))?,
        instance_number: None,
        instance_uid: format!("1.3.{}", u.int_in_range(0..=40u8)?),
        transfer_syntax: "1.2.840.10008.1.2.1".into(),
        implicit_vr: false,
        mosaic: None,
    })
}

fn run(data: &[u8]) -> arbitrary::Result<()> {
    let mut u = Unstructured::new(data);
    let count = u.int_in_range(0..=40usize)?;
    let mut frames = Vec::with_capacity(count);
    for file in 0..count {
        frames.push(frame(&mut u, file)?);
    }
    let named = option(&mut u, |u| u.int_in_range(0..=count))?;
    let frames = drop_copies(frames, named).kept;
    let series = group(frames);
    let choice = match u.int_in_range(0..=2)? {
        0 => None,
        1 => Some(SeriesChoice::Number(u.int_in_range(0..=5)?)),
        _ => Some(SeriesChoice::Uid(format!(
            "1.2.{}",
            u.int_in_range(0..=3u8)?
        ))),
    };
    let Ok(index) = choose(&series, choice.as_ref(), named) else {
        return Ok(());
    };
    let chosen = &series[index];
    let Ok(geometry) = assemble(&chosen.frames) else {
        return Ok(());
    };
    let [x, y, z] = geometry.dims;
    let plane = x as usize * y as usize;
    assert!(
        plane > 0 && z > 0,
        "an empty volume assembled: {:?} from {:#?}",
        geometry.dims,
        chosen.frames
    );
    match &geometry.plan {
        SlicePlan::Stack(order) => {
            assert_eq!(order.len(), z as usize);
            let mut seen = order.clone();
            seen.sort_unstable();
            seen.dedup();
            assert_eq!(seen.len(), order.len(), "a frame stacked twice");
            assert!(order.iter().all(|&f| f < chosen.frames.len()));
        }
        SlicePlan::Resample(plan) => {
            assert_eq!(plan.len(), z as usize);
            assert!(
                z as usize <= 4 * chosen.frames.len() + 16,
                "resampling blew up"
            );
            let stack: Vec<i16> = (0..chosen.frames.len() * plane)
                .map(|i| (i % 7) as i16)
                .collect();
            let mut out = vec![0i16; plane];
            for sources in plan {
                let total: f64 = sources.iter().map(|s| s.weight).sum();
                assert!((total - 1.0).abs() < 1e-6, "weights sum to {total}");
                assert!(sources.iter().all(|s| s.frame < chosen.frames.len()));
                resample_slice(&stack, [x as usize, y as usize], sources, -1, &mut out);
            }
        }
    }
    assert!(
        geometry
            .spacing_mm
            .iter()
            .all(|s| s.is_finite() && *s > 0.0),
        "spacing {:?}",
        geometry.spacing_mm
    );
    Ok(())
}

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let _ = run(data);
});
