//! `leapview slice`: one slice view written as an 8-bit PNG: the plane in the file's patient
//! frame, sampled on the GPU, grey through the window (or in a colour image's own colours).

use anyhow::anyhow;
use glam::DVec3;
use leapview::mpr::{PatientFrame, Plane, PlaneKind, Slab, SliceView};
use leapview::render::context::GpuContext;
use leapview::render::labels::GpuLabels;
use leapview::render::slice::{
    DisplayTarget, LabelLook, Output, SliceError, SliceLook, SliceRenderer, SliceSource,
    SliceTarget, slice_params,
};
use leapview::render::volume_texture::{VolumeTexture, VolumeTextureError};
use leapview::transfer::fit;

use super::Failure;
use super::args::{RawArgs, SliceArgs};
use super::parse::parse_vec3;
use super::text::number;
use crate::cli::OrFail;

/// Slices in one timed pass for the batched figure of `--repeat`.
const SLICES_PER_BATCH: u32 = 50;

/// The plane `name` (a standard plane or a normal `N1,N2,N3`) through `at`.
fn parse_plane(name: &str, at: DVec3) -> Result<Plane, String> {
    let standard = PlaneKind::STANDARD
        .into_iter()
        .find(|k| k.name().eq_ignore_ascii_case(name.trim()));
    if let Some(kind) = standard {
        return Ok(Plane::standard(kind, at));
    }
    let normal = parse_vec3(name)
        .map_err(|e| format!("--plane is axial, coronal, sagittal or a normal N1,N2,N3 ({e})"))?;
    Plane::with_normal(normal, at).map_err(|e| e.to_string())
}

/// Writes the slice `args` describes.
pub fn run(args: &SliceArgs, raw: &RawArgs) -> Result<(), Failure> {
    check_args(args)?;
    let ctx = GpuContext::headless().failed()?;
    let volume = std::sync::Arc::new(super::load_for_gpu(
        &args.file,
        raw,
        (&ctx, args.gpu.gpu_budget),
    )?);
    write_slice(&volume, args, &ctx)
}

/// Refuses what `args` cannot make before anything is loaded.
fn check_args(args: &SliceArgs) -> Result<(), Failure> {
    let bad = |e: String| Failure::BadInput(anyhow!(e));
    if !args
        .out
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("png"))
    {
        return Err(bad(format!(
            "--out must name a .png file, not {}",
            args.out.display()
        )));
    }
    leapview::imaging::check_output_path(&args.out).bad_input()?;
    if args.labels.is_some() && args.exact {
        return Err(bad(
            "--labels are drawn over the slice the window shows; --exact writes grey values".into(),
        ));
    }
    if !(0.0..=1.0).contains(&args.label_opacity) {
        return Err(bad(format!(
            "--label-opacity is 0 to 1, not {}",
            args.label_opacity
        )));
    }
    slab_of(args)?;
    Ok(())
}

/// The slab `args` ask for.
fn slab_of(args: &SliceArgs) -> Result<Option<Slab>, Failure> {
    let bad = |e: String| Failure::BadInput(anyhow!(e));
    Ok(match args.slab {
        None => None,
        Some(mm) if mm.is_finite() && mm > 0.0 => Some(Slab {
            thickness_mm: mm,
            mode: args.mode,
        }),
        Some(mm) => {
            return Err(bad(format!(
                "--slab must be a thickness above 0 mm, not {mm}"
            )));
        }
    })
}

/// What `args` ask of the slice of `volume`: the view (plane, point, size), the look (window,
/// sampling, slab, colour, inversion) and the transfer function that colours it; checked.
struct SliceSettings {
    view: SliceView,
    look: SliceLook,
    tf: Option<leapview::transfer::TransferFunction>,
}

/// Builds [`SliceSettings`] from the command's arguments.
fn settings_of(
    args: &SliceArgs,
    volume: &leapview::volume::Volume,
) -> Result<SliceSettings, Failure> {
    let bad = |e: String| Failure::BadInput(anyhow!(e));
    check_args(args)?;
    let slab = slab_of(args)?;
    let frame = PatientFrame::of(volume);
    let at = args.at.map_or(frame.centre(), DVec3::from);
    let plane = parse_plane(&args.plane, at).map_err(bad)?;
    if leapview::mpr::view::cut_polygon(&plane, &frame).is_empty() {
        let lo = frame
            .corners()
            .into_iter()
            .fold(DVec3::INFINITY, DVec3::min);
        let hi = frame
            .corners()
            .into_iter()
            .fold(DVec3::NEG_INFINITY, DVec3::max);
        return Err(bad(format!(
            "the {} plane through {} mm does not cut the volume, which spans x {} .. {}, y {} .. \
             {}, z {} .. {} mm (LPS)",
            plane.kind.name(),
            triple(at),
            number(lo.x),
            number(hi.x),
            number(lo.y),
            number(hi.y),
            number(lo.z),
            number(hi.z)
        )));
    }
    let view = SliceView::fit(plane, &frame, args.size);
    let window = args
        .window
        .or_else(|| fit::default_window_of(volume))
        .or_else(|| volume.value_range().map(|r| [r.min, r.max]))
        .unwrap_or([0.0, 1.0]);
    let tf = match &args.tf {
        Some(_) if args.exact => {
            return Err(bad(
                "--tf colours the slice the window shows; --exact writes grey values".into(),
            ));
        }
        Some(name) => {
            let resolved = fit::resolve(name, &fit::DataKind::of(volume)).bad_input()?;
            Some(resolved.tf)
        }
        None => None,
    };
    let look = SliceLook {
        window,
        nearest: args.nearest,
        slab,
        leap: !args.no_leap,
        colour: tf.is_some(),
        invert: match args.invert {
            Some(choice) => choice == super::args::YesNo::Yes,
            None => volume.provenance().invert_grey,
        },
        labels: LabelLook {
            opacity: args.label_opacity,
            outline: !args.no_label_outline,
        },
    };
    Ok(SliceSettings { view, look, tf })
}

/// Writes the slice `args` describe of `volume` (loaded from `args.file`) on the GPU of `ctx`.
pub fn write_slice(
    volume: &std::sync::Arc<leapview::volume::Volume>,
    args: &SliceArgs,
    ctx: &GpuContext,
) -> Result<(), Failure> {
    let SliceSettings { view, look, tf } = settings_of(args, volume)?;
    let slab = look.slab;
    let frame = PatientFrame::of(volume);
    let (plane, window) = (view.plane, look.window);
    let at = plane.point;
    let upload = leapview::settings::Upload {
        gpu_budget: args.gpu.gpu_budget,
        ..Default::default()
    };
    let mut texture = VolumeTexture::upload_with(ctx, volume, &upload).map_err(|e| match e {
        VolumeTextureError::TooLarge { .. }
        | VolumeTextureError::Layout { .. }
        | VolumeTextureError::OutOfMemory { .. } => Failure::BadInput(e.into()),
        other => Failure::Other(other.into()),
    })?;
    if let Some(note) = &texture.coarser {
        eprintln!("leapview: note: {note}");
    }
    let renderer = SliceRenderer::new(&ctx.device).failed()?;
    let colours = tf
        .as_ref()
        .map(|tf| renderer.colour_table(&ctx.device, &ctx.queue, tf, volume));
    let bricks = if slab.is_some() && !args.no_leap {
        renderer.bricks_of(ctx, volume, &texture)
    } else {
        None
    };
    let labels = match &args.labels {
        Some(path) => {
            let map = super::label_args::read_labels(path, args.label_names.as_ref(), volume)?;
            let gpu = GpuLabels::new(&ctx.device, &ctx.queue, map).bad_input()?;
            // Labels past one texture travel in the volume's bricks.
            texture
                .attach_labels(ctx, Some(&gpu))
                .map_err(|e| Failure::BadInput(e.into()))?;
            Some(gpu)
        }
        None => None,
    };
    let slice_failure = |e: SliceError| match e {
        SliceError::TooLarge(..) => Failure::BadInput(e.into()),
        other => Failure::Other(other.into()),
    };
    let [w, h] = view.size;
    let png: image::DynamicImage = if args.exact {
        let grey = renderer
            .render(ctx, volume, &texture, bricks.as_ref(), &view, look)
            .map_err(slice_failure)?
            .grey;
        image::GrayImage::from_raw(w, h, grey).map(Into::into)
    } else {
        let rgb = renderer
            .render_display(
                ctx,
                volume,
                &texture,
                bricks.as_ref(),
                colours.as_ref(),
                labels.as_ref(),
                &view,
                look,
            )
            .map_err(slice_failure)?;
        if look.colour || volume.colour().is_some() || labels.is_some() {
            image::RgbImage::from_raw(w, h, rgb.concat()).map(Into::into)
        } else {
            let grey = rgb.iter().map(|p| p[0]).collect();
            image::GrayImage::from_raw(w, h, grey).map(Into::into)
        }
    }
    .ok_or_else(|| Failure::Other(anyhow!("the slice image has the wrong size")))?;
    if args.repeat > 0 {
        let source = SliceSource {
            texture: &texture.view,
            bricks: bricks.as_ref(),
            colours: colours.as_ref(),
            labels: labels.as_ref(),
        };
        let format = texture.encoding.format;
        let other = |e: SliceError| Failure::Other(e.into());
        // Each slice in a pass of its own between two timestamps, then 50 in one pass: what one
        // more slice adds to a frame's commands, without a pass's fixed cost.
        for per_pass in [1, SLICES_PER_BATCH] {
            let ms = if args.exact {
                let target = SliceTarget::new(&ctx.device, view.size).map_err(other)?;
                let params = slice_params(&view, &frame, volume, format, look, target.pitch);
                let output = Output::Exact(&target);
                renderer.median_gpu_ms(ctx, source, output, &params, args.repeat, per_pass)
            } else {
                let target = DisplayTarget::new(&ctx.device, view.size).map_err(other)?;
                let params = slice_params(&view, &frame, volume, format, look, view.size[0]);
                let output = Output::Display(&target);
                renderer.median_gpu_ms(ctx, source, output, &params, args.repeat, per_pass)
            }
            .map_err(other)?;
            let what = if per_pass == 1 {
                format!("median of {} passes", args.repeat)
            } else {
                format!(
                    "{per_pass} slices per pass, median of {} passes",
                    args.repeat
                )
            };
            match ms {
                Some(ms) => println!(
                    "GPU time: {ms:.4} ms per slice ({what}; {})",
                    ctx.adapter_summary()
                ),
                None => println!(
                    "GPU time: not measured ({} has no timestamp queries)",
                    ctx.adapter_summary()
                ),
            }
        }
    }
    png.save(&args.out)
        .map_err(|e| Failure::Other(anyhow!("cannot write {}: {e}", args.out.display())))?;
    let [left, right, top, bottom] = plane.edge_labels();
    let stored = volume
        .orientation()
        .is_some_and(|o| o.source == leapview::volume::OrientationSource::AsStored);
    let edges = if stored {
        "as stored (row 0 at the top, column 0 at the left: the file has no patient orientation)"
            .to_string()
    } else {
        format!("left {left}, right {right}, top {top}, bottom {bottom}")
    };
    let mut slab_text = slab.map_or(String::new(), |s| {
        format!(", {} slab of {} mm", s.mode.name(), number(s.thickness_mm))
    });
    if let Some(name) = &args.tf {
        slab_text.push_str(&format!(", coloured by transfer function {name}"));
    }
    println!(
        "wrote {}: {} plane through {} mm (LPS), {w} x {h} pixels of {} mm, window {} .. {}{}{}; \
         edges: {edges}",
        args.out.display(),
        plane.kind.name(),
        triple(at),
        number(view.mm_per_pixel),
        number(window[0]),
        number(window[1]),
        if args.nearest {
            ", nearest voxel"
        } else if args.exact {
            ", exact trilinear"
        } else {
            ""
        },
        slab_text,
    );
    Ok(())
}

fn triple(p: DVec3) -> String {
    format!("{}, {}, {}", number(p.x), number(p.y), number(p.z))
}
