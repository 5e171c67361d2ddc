//! Measuring one dataset: the reference images (f64 CPU reference for the phantom, 1/16-voxel
//! GPU renders for the scans), then every variant's GPU time and error over the same views.

use leapview::accuracy::{ErrorStats, KnobGroup, Measurement, Variant, plan, reference};
use leapview::camera::Camera;
use leapview::imaging::ImageF32;
use leapview::reference as cpu;
use leapview::render::raycast::auto_path;
use leapview::render::{FrameRequest, RenderError, VolumeRenderer};
use leapview::settings::{RenderSettings, TexturePrecision, Upload};
use leapview::transfer::TransferFunction;
use leapview::volume::Volume;

use crate::cli::measuring::timed_frame;

/// Warm-up frames after each change of variant (pipeline creation, structure rebuilds).
const WARMUP_FRAMES: u32 = 3;
/// Warm-up frames of the first variant after an upload: as in the benchmark, three were too few
/// right after a 512³ upload (docs/accuracy/README.md, "Figures moved from code comments").
const SETTLE_FRAMES: u32 = 30;
/// Passes over the variant list (see `measure`).
const PASSES: usize = 2;

/// One dataset to measure.
#[derive(Clone, Copy)]
pub struct Dataset<'a> {
    /// Name in the tables.
    pub name: &'a str,
    /// The voxels.
    pub volume: &'a Volume,
    /// Its transfer function.
    pub tf: &'a TransferFunction,
    /// Whether the reference is the f64 CPU ray caster (small volumes) instead of the GPU.
    pub cpu_reference: bool,
}

/// How to measure.
pub struct Method<'a> {
    /// Baseline settings (the app's defaults plus the dataset's iso value).
    pub base: RenderSettings,
    /// Views; times and errors cover all of them.
    pub cameras: &'a [Camera],
    /// Image size.
    pub size: [u32; 2],
    /// Timed frames per view.
    pub frames: u32,
}

/// A variant that could not be measured, and why.
#[derive(serde::Serialize, serde::Deserialize)]
pub struct NotMeasured {
    /// What.
    pub what: String,
    /// Why.
    pub why: String,
}

/// Measures every variant of [`plan`] on `data`; the renderer ends with the volume uploaded at
/// the default precision.
pub fn measure(
    renderer: &mut VolumeRenderer,
    data: &Dataset,
    method: &Method,
    progress: &mut dyn FnMut(&str),
) -> Result<(Vec<Measurement>, Vec<NotMeasured>), RenderError> {
    renderer.set_transfer_function(data.tf);
    if !renderer.has_volume() {
        renderer.set_volume(data.volume)?;
    }
    auto_path::choose(renderer, method.base.path)?;
    let mut skipped = Vec::new();
    let mut references = Vec::new();
    for group in KnobGroup::ALL {
        progress(&format!("{}: {} reference", data.name, group.label()));
        let (settings, precision) = reference(&method.base, group);
        let images = if data.cpu_reference {
            method
                .cameras
                .iter()
                .map(|c| cpu::render(data.volume, data.tf, c, method.size, &settings).image)
                .collect()
        } else {
            if let Err(e) = renderer.set_volume_with(
                &std::sync::Arc::new(data.volume.clone()),
                &Upload {
                    precision,
                    ..Upload::default()
                },
            ) {
                // Without f32 texels the reference keeps the default precision.
                skipped.push(NotMeasured {
                    what: format!("{} reference in f32 texels", group.label()),
                    why: e.to_string(),
                });
                renderer.set_volume(data.volume)?;
            }
            let mut images = Vec::new();
            for camera in method.cameras {
                images.push(renderer.render_image(camera, method.size, &settings)?);
            }
            images
        };
        references.push((group, images));
    }
    let mut variants = plan(&method.base);
    // Group by precision: one upload each.
    variants.sort_by_key(|v| v.precision != TexturePrecision::Auto);
    let mut uploaded = None;
    let mut settle = true;
    let mut out: Vec<Option<Measurement>> = vec![None; variants.len()];
    // Every variant twice, keeping the faster median: the first variants timed after an upload
    // came out slow even after the warm-up, and a second pass over the list agrees with itself
    // (docs/accuracy/README.md, "Caveats").
    for (index, variant) in (0..PASSES).flat_map(|_| variants.iter().enumerate()) {
        progress(&format!(
            "{}: {} {}",
            data.name,
            variant.knob.label(),
            variant.value
        ));
        if uploaded != Some(variant.precision) {
            if let Err(e) = renderer.set_volume_with(
                &std::sync::Arc::new(data.volume.clone()),
                &Upload {
                    precision: variant.precision,
                    ..Upload::default()
                },
            ) {
                let what = format!("{} {}", variant.knob.label(), variant.value);
                if !skipped.iter().any(|n| n.what == what) {
                    skipped.push(NotMeasured {
                        what,
                        why: e.to_string(),
                    });
                }
                uploaded = None;
                continue;
            }
            uploaded = Some(variant.precision);
            settle = true;
        }
        let Some((_, expected)) = references
            .iter()
            .find(|(group, _)| *group == variant.knob.group())
        else {
            continue;
        };
        let warmup = if settle { SETTLE_FRAMES } else { WARMUP_FRAMES };
        settle = false;
        let (ms, images) = time_and_render(renderer, variant, method, warmup)?;
        let diffs: Vec<_> = images
            .iter()
            .zip(expected)
            .filter_map(|(a, b)| a.diff(b))
            .collect();
        let measured = Measurement {
            dataset: data.name.to_string(),
            knob: variant.knob,
            value: variant.value.clone(),
            ms,
            error: ErrorStats::combine(&diffs),
        };
        out[index] = Some(match out[index].take() {
            Some(first) if first.ms <= ms => first,
            _ => measured,
        });
    }
    let out: Vec<Measurement> = out.into_iter().flatten().collect();
    if uploaded != Some(TexturePrecision::Auto) {
        renderer.set_volume(data.volume)?;
    }
    Ok((out, skipped))
}

/// Median GPU time over every view × frame after a warm-up, and each view's last image.
fn time_and_render(
    renderer: &mut VolumeRenderer,
    variant: &Variant,
    method: &Method,
    warmup: u32,
) -> Result<(f64, Vec<ImageF32>), RenderError> {
    let request = |camera| FrameRequest {
        camera,
        size: method.size,
        settings: &variant.settings,
        stats: false,
    };
    let Some(first) = method.cameras.first() else {
        return Err(RenderError::NoVolume);
    };
    for _ in 0..warmup {
        timed_frame(renderer, &request(first))?;
    }
    let mut times = Vec::new();
    let mut images = Vec::new();
    for camera in method.cameras {
        for _ in 0..method.frames.max(1) {
            times.push(timed_frame(renderer, &request(camera))?.0);
        }
        images.push(renderer.read_image()?);
    }
    times.sort_by(f64::total_cmp);
    Ok((times[times.len() / 2], images))
}
