//! `leapview render`: one frame to a PNG or EXR file, optionally with statistics.

use anyhow::Context;
use leapview::camera::Aabb;
use leapview::render::RenderError;
use leapview::render::labels::GpuLabels;
use leapview::render::raycast::{auto_path, auto_strategy};
use leapview::render::{FrameRequest, GpuContext, RefineRun, VolumeRenderer};
use leapview::settings::{RenderSettings, Strategy, Upload};
use leapview::transfer::blank::why_blank;
use leapview::transfer::fit::{self, DataKind};

use super::args::{RawArgs, RenderArgs};
use super::text::{outln, print_stdout};
use super::{Failure, camera_from_args};
use crate::cli::OrFail;

/// Frames timed for `--stats`, after one warm-up frame; the median is reported.
const TIMED_FRAMES: usize = 5;

/// Maps a renderer error to a failure: volumes or images past the GPU's limits are bad input.
fn render_failure(e: RenderError) -> Failure {
    if e.is_bad_input() {
        Failure::BadInput(e.into())
    } else {
        Failure::Other(e.into())
    }
}

/// Frames `render` averages soft shadows over where `--refine` is not given.
const SOFT_SHADOW_FRAMES: u32 = 16;

/// Reports a refinement's frames on standard error: on one rewritten line at a terminal, else a
/// line per tenth of the frames.
fn refine_progress() -> impl FnMut(u32, u32) {
    use std::io::IsTerminal;
    let terminal = std::io::stderr().is_terminal();
    move |done, frames| {
        if terminal {
            eprint!("\rrefining: {done}/{frames} frames");
            if done == frames {
                eprintln!();
            }
        } else if done == frames || done % frames.div_ceil(10) == 0 {
            eprintln!("refining: {done}/{frames} frames");
        }
    }
}

/// A 2D image (one slice, a radiograph, a photograph) has no depth to ray-cast: it is written as
/// the image itself, facing the viewer, as `leapview slice` draws it (in its own colours, or grey
/// through the window), and a note says so.
fn render_image(
    volume: &std::sync::Arc<leapview::volume::Volume>,
    plane: leapview::mpr::PlaneKind,
    args: &RenderArgs,
    ctx: GpuContext,
) -> Result<(), Failure> {
    let [w, h, d] = volume.dims();
    let size: Vec<String> = [w, h, d]
        .iter()
        .filter(|&&n| n > 1)
        .map(u32::to_string)
        .collect();
    eprintln!(
        "leapview: note: {} is a 2D image ({}): written facing the viewer, {}, as `leapview \
         slice --plane {}` draws it; the 3D modes and transfer functions apply to volumes",
        args.file.display(),
        size.join(" x "),
        if volume.colour().is_some() {
            "in its own colours"
        } else {
            "grey through the window"
        },
        plane.name()
    );
    let slice = super::args::SliceArgs {
        file: args.file.clone(),
        plane: plane.name().to_string(),
        at: None,
        out: args.out.clone(),
        window: args.effects.window,
        size: Some(args.size),
        nearest: false,
        invert: None,
        exact: false,
        no_leap: false,
        tf: None,
        slab: None,
        mode: leapview::mpr::SlabMode::Mip,
        repeat: 0,
        labels: args.segmentation.labels.clone(),
        label_names: args.segmentation.label_names.clone(),
        label_opacity: 0.5,
        no_label_outline: false,
        gpu: args.gpu,
    };
    super::slice::write_slice(volume, &slice, &ctx)
}

/// The render settings `args` ask for on `volume`: the knobs given, the quality preset over
/// them, the effects, the default window, the crop; checked.
fn settings_of(
    args: &RenderArgs,
    volume: &leapview::volume::Volume,
) -> Result<RenderSettings, Failure> {
    let mut settings = RenderSettings {
        mode: args.mode,
        strategy: args.strategy,
        path: args.path,
        step_vox: args.step,
        termination_alpha: args.termination,
        jitter: args.jitter,
        background: args.background,
        block_vox: args.block,
        preintegrated: args.preintegrate,
        ..RenderSettings::default()
    };
    if let Some(quality) = args.quality {
        quality.apply(&mut settings);
    }
    args.effects.apply(&mut settings);
    settings.labels = args.segmentation.label_view;
    settings.label_smoothing = args.segmentation.label_smoothing;
    // MIP, MinIP and X-ray without a window: the header's, else the data's, a few outliers left
    // out.
    settings.window = settings.window.or_else(|| fit::default_window_of(volume));
    if let Some(crop) = &args.crop {
        settings.crop =
            leapview::settings::CropBox::parse_voxels(crop, volume.dims()).bad_input()?;
    }
    settings.validate().bad_input()?;
    Ok(settings)
}

/// Runs the command.
pub fn run(args: RenderArgs, raw: &RawArgs) -> Result<(), Failure> {
    // Refused before anything is loaded or rendered.
    leapview::imaging::check_output_path(&args.out).bad_input()?;
    let ctx = GpuContext::headless().failed()?;
    let volume = std::sync::Arc::new(super::load_for_gpu(
        &args.file,
        raw,
        (&ctx, args.gpu.gpu_budget),
    )?);
    if let Some(plane) = leapview::mpr::frame::image_plane(&volume) {
        return render_image(&volume, plane, &args, ctx);
    }
    let kind = DataKind::of(&volume);
    let resolved = fit::resolve(&args.tf, &kind).bad_input()?;
    if let Some(note) = &resolved.note {
        eprintln!(
            "leapview: note: {note} ({})",
            kind.describe(volume.modality())
        );
    }
    let tf = resolved.tf;
    let settings = settings_of(&args, &volume)?;
    let bounds = Aabb::of_volume(volume.dims(), volume.spacing_mm());
    let orientation = volume
        .orientation()
        .unwrap_or(leapview::volume::Orientation::ASSUMED);
    let camera = camera_from_args(&args.camera, &bounds, orientation)?;
    let ctx = GpuContext::headless().failed()?;
    let adapter = ctx.adapter_summary();
    let mut renderer = VolumeRenderer::new(ctx).map_err(render_failure)?;
    renderer
        .set_volume_with(
            &volume,
            &Upload {
                precision: args.precision,
                bricking: args.bricks,
                gpu_budget: args.gpu.gpu_budget,
            },
        )
        .map_err(render_failure)?;
    renderer.set_transfer_function(&tf);
    let labelled = match args.segmentation.load(&volume)? {
        Some(map) => {
            let map = std::sync::Arc::new(map);
            let shown = args.segmentation.shown(&map)?;
            let ctx = renderer.context();
            let labels = GpuLabels::new(&ctx.device, &ctx.queue, map.clone()).bad_input()?;
            labels.show_styled(&ctx.queue, &map, |s| args.segmentation.style(&shown, s));
            let labels = std::sync::Arc::new(labels);
            renderer
                .set_labels(Some(std::sync::Arc::clone(&labels)))
                .map_err(render_failure)?;
            Some((map, labels, shown))
        }
        None => None,
    };
    auto_path::choose(&mut renderer, settings.path).map_err(render_failure)?;
    auto_strategy::choose(&mut renderer, &settings, args.size, &camera, true)
        .map_err(render_failure)?;
    let request = FrameRequest {
        camera: &camera,
        size: args.size,
        settings: &settings,
        stats: false,
    };
    let (submitted, first) = renderer.render_and_wait(&request).map_err(render_failure)?;
    // After the frame: the bricks it held follow its mode and transfer function.
    if let Some(texture) = renderer.volume_texture() {
        if let Some(note) = &texture.coarser {
            eprintln!("leapview: note: {note}");
        }
        log::info!("on the GPU: {}", texture.describe());
    }
    // Soft shadows are noise in one frame: their mean over frames is the picture.
    let soft = settings.shadows.on && settings.shadows.softness_deg > 0.0;
    let frames = if soft && args.refine <= 1 {
        eprintln!(
            "leapview: note: soft shadows refined over {SOFT_SHADOW_FRAMES} frames (--refine N to choose)"
        );
        SOFT_SHADOW_FRAMES
    } else {
        args.refine
    };
    let image = if frames > 1 {
        renderer
            .render_refined(
                &camera,
                args.size,
                &settings,
                RefineRun {
                    frames,
                    band_end: None,
                    done: Some(&mut refine_progress()),
                },
            )
            .map_err(render_failure)?
    } else {
        renderer.read_image().map_err(render_failure)?
    };
    image
        .save(&args.out)
        .context("writing the image")
        .map_err(Failure::Other)?;
    if let Some(why) = why_blank(&volume, &tf, &settings) {
        eprintln!("leapview: note: the image shows nothing: {why}");
    }
    if args.stats {
        let mut times = Vec::new();
        for _ in 0..TIMED_FRAMES {
            let (_, r) = renderer.render_and_wait(&request).map_err(render_failure)?;
            times.extend(r.gpu_ms);
        }
        times.sort_by(f64::total_cmp);
        let (_, counted) = renderer
            .render_and_wait(&FrameRequest {
                stats: true,
                ..request
            })
            .map_err(render_failure)?;
        let c = counted.counters.unwrap_or_default();
        let pixels = (args.size[0] as u64 * args.size[1] as u64) as f64;
        let mut out = String::new();
        outln!(out, "adapter: {adapter}");
        outln!(
            out,
            "volume: {} {:?} {}",
            volume.name(),
            volume.dims(),
            volume.scalar_type()
        );
        outln!(
            out,
            "image: {}x{}  mode: {}  strategy: {}  path: {:?}  step: {} voxel",
            args.size[0],
            args.size[1],
            settings.mode.label(),
            strategy_line(&renderer, &settings, args.size),
            submitted.key.path,
            settings.step_vox
        );
        match times.get(times.len() / 2) {
            Some(ms) => outln!(
                out,
                "gpu_ms: {ms:.3} (median of {} frames after a warm-up)",
                times.len()
            ),
            None => outln!(
                out,
                "gpu_ms: unavailable (the adapter has no timestamp queries)"
            ),
        }
        outln!(out, "rays: {}", c.rays);
        outln!(
            out,
            "samples: {} ({:.1} per pixel)",
            c.samples,
            c.samples as f64 / pixels
        );
        outln!(
            out,
            "visible_samples: {} (non-zero opacity; {:.1} % of samples)",
            c.visible_samples,
            100.0 * c.visible_samples as f64 / c.samples.max(1) as f64
        );
        outln!(
            out,
            "samples_over_oracle: {:.2} (samples taken / samples with non-zero opacity)",
            c.samples as f64 / c.visible_samples.max(1) as f64
        );
        if c.shadow_rays > 0 {
            outln!(
                out,
                "shadow rays: {} ({:.2} per ray), their samples: {} ({:.1} per shadow ray)",
                c.shadow_rays,
                c.shadow_rays as f64 / c.rays.max(1) as f64,
                c.shadow_samples,
                c.shadow_samples as f64 / c.shadow_rays as f64
            );
        }
        if submitted.key.strategy.leaps() {
            outln!(
                out,
                "leaps: {} (block {} voxels)",
                c.leaps,
                settings.leaf_block_vox()
            );
            outln!(
                out,
                "samples leapt: {} ({:.1} % of the grid samples before each ray's end)",
                c.leapt_samples,
                100.0 * c.share_leapt().unwrap_or(0.0)
            );
            outln!(
                out,
                "lookups: {} ({:.1} per ray: questions asked of the leaping structure)",
                c.lookups,
                c.lookups as f64 / c.rays.max(1) as f64
            );
            if let Some(ms) = first.rebuild_ms {
                outln!(
                    out,
                    "rebuild_ms: {ms:.3} (the leaping structures this frame built)"
                );
            }
        }
        if let Some((map, labels, shown)) = &labelled {
            outln!(
                out,
                "labels: {}: {} segments, {} shown, view {:?}, {:.1} MB on the GPU{}{}",
                map.name(),
                map.segments().len(),
                shown.len(),
                settings.labels,
                labels.gpu_bytes() as f64 / 1e6,
                renderer
                    .volume_texture()
                    .map(|t| t.label_atlas_bytes())
                    .filter(|&b| b > 0)
                    .map_or(String::new(), |b| format!(
                        " and {:.1} MB in the bricks' label atlas",
                        b as f64 / 1e6
                    )),
                labels
                    .neighbour_facts()
                    .map_or(String::new(), |(pairs, ms)| format!(
                        "; {pairs} neighbouring pairs found in {ms:.1} ms (on the first frame of \
                     surfaces)"
                    ))
            );
            // A typical label (the median by voxels) and the largest: the mask's rebuild
            // covers the toggled label's box.
            let mut by_size: Vec<&leapview::labels::Segment> = (map.segments().iter())
                .filter(|s| shown.contains(&(s.layer, s.value)))
                .collect();
            by_size.sort_by_key(|s| (s.voxels, s.layer, s.value));
            let picks = [
                (
                    "label_toggle_ms",
                    "the median shown label by voxels",
                    by_size.get(by_size.len() / 2),
                ),
                (
                    "label_toggle_largest_ms",
                    "the largest shown label",
                    // Not timed twice where the median is the largest.
                    by_size.last().filter(|_| by_size.len() > 2),
                ),
            ];
            for (key, which, segment) in picks {
                let Some(segment) = segment else { continue };
                let toggled = (segment.layer, segment.value);
                let times = label_toggles(
                    &mut renderer,
                    &request,
                    &args.segmentation,
                    (map, labels, shown),
                    toggled,
                )?;
                let Some(t) = times else { continue };
                let mask = match (t.mask, t.share) {
                    (Some(ms), Some(share)) => format!(
                        ", {ms:.3} remaking the surface mask over {:.2} % of the grid",
                        100.0 * share
                    ),
                    _ => String::new(),
                };
                outln!(
                    out,
                    "{key}: {:.3} (toggling {:?}, {which}, {} voxels; the GPU's work for the \
                     frame after the toggle: {:.3} rebuilding the leaping flags{mask} and \
                     {:.3} casting; {:.1} from the toggle to the frame done, on the clock; \
                     medians of {} toggles)",
                    t.total,
                    segment.name,
                    segment.voxels,
                    t.rebuild,
                    t.cast,
                    t.wall,
                    TIMED_FRAMES * 2
                );
            }
            let facts = renderer.label_surface_facts();
            if let Some(f) = facts {
                let grid = match f.grid {
                    (1, _) => String::new(),
                    (k, [x, y, z]) => format!(
                        ", found on the labels' grid reduced {k}-fold to {x} × {y} × {z} \
                         (they travel in bricks, past one texture)"
                    ),
                };
                outln!(
                    out,
                    "label_surfaces: smoothing {} voxels, {} classes (mask channels), {} \
                     touching pairs sharing a class (no wall between them), {:.1} MB on the \
                     GPU (the mask, its class table and its build's buffer){grid}",
                    settings.label_smoothing,
                    f.channels,
                    f.clashes,
                    f.bytes as f64 / 1e6
                );
            }
        }
        print_stdout(&out).failed()?;
    } else if let Some(ms) = first.gpu_ms {
        eprintln!(
            "rendered {}x{} in {ms:.2} ms GPU ({:?} path, first frame) on {adapter}",
            args.size[0], args.size[1], submitted.key.path
        );
    }
    Ok(())
}

/// Medians over toggles of one label, in milliseconds.
struct ToggleTimes {
    /// The GPU's rebuild of the leaping flags that read the shown labels.
    rebuild: f64,
    /// The GPU's remaking of the surface mask, where the frame drew surfaces.
    mask: Option<f64>,
    /// The share of the grid the mask's last rebuild covered.
    share: Option<f64>,
    /// The GPU's ray casting of the frame after the toggle.
    cast: f64,
    /// All three, per toggle (the timestamps time them apart).
    total: f64,
    /// On the clock from the toggle to the frame done.
    wall: f64,
}

/// Times toggling the shown label `toggled` (hidden, then shown again, and so on), each
/// followed by a frame; `None` without timestamps.
fn label_toggles(
    renderer: &mut VolumeRenderer,
    request: &FrameRequest<'_>,
    segmentation: &crate::cli::label_args::LabelArgs,
    (map, labels, shown): (
        &leapview::labels::LabelMap,
        &GpuLabels,
        &std::collections::BTreeSet<(u16, u16)>,
    ),
    toggled: (u16, u16),
) -> Result<Option<ToggleTimes>, Failure> {
    let (mut rebuilds, mut masks, mut casts, mut totals, mut walls) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for k in 0..TIMED_FRAMES * 2 {
        let started = std::time::Instant::now();
        let hide = k % 2 == 0;
        let queue = &renderer.context().queue;
        let mut now = shown.clone();
        if hide {
            now.remove(&toggled);
        }
        labels.show_styled(queue, map, |s| segmentation.style(&now, s));
        let (_, r) = renderer.render_and_wait(request).map_err(render_failure)?;
        walls.push(started.elapsed().as_secs_f64() * 1e3);
        let Some(cast) = r.gpu_ms else {
            return Ok(None);
        };
        let rebuild = r.rebuild_ms.unwrap_or(0.0);
        rebuilds.push(rebuild);
        masks.extend(r.mask_ms);
        casts.push(cast);
        totals.push(rebuild + r.mask_ms.unwrap_or(0.0) + cast);
    }
    let median = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    Ok(Some(ToggleTimes {
        rebuild: median(&mut rebuilds),
        mask: (!masks.is_empty()).then(|| median(&mut masks)),
        share: (renderer.label_surface_facts()).map(|f| f.last_build_share),
        cast: median(&mut casts),
        total: median(&mut totals),
        wall: median(&mut walls),
    }))
}

/// The strategy a frame ran with, for people: the name asked for, and for `auto` what it stood
/// for and why.
fn strategy_line(renderer: &VolumeRenderer, settings: &RenderSettings, size: [u32; 2]) -> String {
    let key = renderer.choice_key(settings, size);
    match renderer.strategy_choice() {
        Some(c) if settings.strategy == Strategy::Auto && c.key == key => {
            format!("auto: {}", c.describe())
        }
        _ => settings.strategy.untimed(settings.mode).label().to_string(),
    }
}
