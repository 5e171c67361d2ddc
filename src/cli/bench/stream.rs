//! `leapview bench --stream FILE`: what the window does with a volume larger than its GPU
//! budget, without a window (the first of `--modes`, `--strategies` and `--paths`; DVR, RC-s-df
//! and the compute path by default). The volume is uploaded as the window uploads it (each frame spends
//! at most `--stream-ms` uploading bricks, then renders with what is resident), an orbit is
//! rendered while the bricks stream, then the view stays still until every brick it wants is
//! resident. Written: `stream.csv` (one line a frame) and `stream.md` (the figures the issue
//! asks for: the first picture, frame times while streaming, the time to complete, GPU memory
//! against the budget).

use std::fmt::Write as _;
use std::path::Path;
use std::sync::Arc;
use std::time::{Duration, Instant};

use leapview::camera::Aabb;
use leapview::render::raycast::auto_path;
use leapview::render::{FrameRequest, GpuContext, VolumeRenderer};
use leapview::settings::{Mode, RenderPath, RenderSettings, Strategy, Upload};
use leapview::transfer::fit::{self, DataKind};

use super::BenchArgs;
use crate::cli::args::RawArgs;
use crate::cli::measuring::orbit;
use crate::cli::{Failure, OrFail, load_for_gpu};

/// Frames of the still phase at most (each uploads for `--stream-ms`).
const STILL_FRAMES: u32 = 100_000;

/// One frame of the run.
struct Row {
    phase: &'static str,
    frame: u32,
    azimuth: f64,
    /// Wall clock of the frame: uploads, encoding, the GPU's work and the wait for it.
    wall_ms: f64,
    /// The GPU's time for the frame's passes (timestamp queries), where the adapter has them.
    gpu_ms: Option<f64>,
    /// The GPU's time for the leaping structures' rebuild (min/max pyramid, emptiness, distance
    /// field: what the frame built).
    rebuild_ms: Option<f64>,
    /// The CPU's time for the residency update (deciding, uploading, page tables).
    residency_ms: f64,
    since_upload_ms: f64,
    levels: String,
    resident: usize,
    wanted: usize,
    missing: usize,
    bytes: u64,
    /// What the GPU memory allocator held after the frame in its memory blocks, and of that
    /// what was allocated (bytes), where the backend reports it.
    held: Option<(u64, u64)>,
    /// The process's resident memory after the frame (bytes), where the system says.
    rss: Option<u64>,
}

/// The process's resident memory now and at its peak (`VmRSS`, `VmHWM` of /proc/self/status),
/// bytes.
fn resident_memory() -> Option<(u64, u64)> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let field = |name: &str| -> Option<u64> {
        let line = status.lines().find(|l| l.starts_with(name))?;
        let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
        Some(kib * 1024)
    };
    Some((field("VmRSS:")?, field("VmHWM:")?))
}

/// Runs the streaming measurement on `file`.
pub fn run(args: &BenchArgs, file: &Path, raw: &RawArgs) -> Result<(), Failure> {
    let out = args
        .out
        .clone()
        .ok_or_else(|| Failure::BadInput(anyhow::anyhow!("--stream needs --out")))?;
    let ctx = GpuContext::headless().failed()?;
    let adapter = ctx.adapter_summary();
    let load_start = Instant::now();
    // The input options (--ram-budget, --orientation, …) as any command takes them.
    let volume = Arc::new(load_for_gpu(file, raw, (&ctx, args.gpu.gpu_budget))?);
    let load_s = load_start.elapsed().as_secs_f64();
    let mode = args
        .modes
        .as_ref()
        .and_then(|m| m.first().copied())
        .unwrap_or(Mode::Dvr);
    let kind = DataKind::of(&volume);
    let tf = fit::resolve(fit::AUTO, &kind).bad_input()?.tf;
    // A fixed strategy: timing RC-t against leaping would render frames of its own while the
    // bricks stream.
    let strategy = args
        .strategies
        .as_ref()
        .and_then(|s| s.first().copied())
        .unwrap_or(Strategy::RcSDistance)
        .for_mode(mode);
    let mut settings = RenderSettings {
        mode,
        strategy,
        path: args
            .paths
            .as_ref()
            .and_then(|p| p.first().copied())
            .unwrap_or(RenderPath::Compute),
        ..RenderSettings::default()
    };
    settings.window = fit::default_window_of(&volume);
    let mut renderer = VolumeRenderer::new(ctx).failed()?;
    let budget = Duration::from_secs_f64(args.stream_ms / 1e3);
    renderer.set_residency_time(Some(budget));
    let upload_start = Instant::now();
    renderer
        .set_volume_with(
            &volume,
            &Upload {
                precision: Default::default(),
                bricking: args.bricks,
                gpu_budget: args.gpu.gpu_budget,
            },
        )
        .failed()?;
    renderer.set_transfer_function(&tf);
    auto_path::choose(&mut renderer, settings.path).failed()?;
    let bounds = Aabb::of_volume(volume.dims(), volume.spacing_mm());
    let cameras = orbit(&bounds, args.stream_frames, 20.0);
    let size = args.stream_size;
    let mut rows = Vec::new();
    let mut frame = 0u32;
    let mut render = |camera, azimuth, phase, renderer: &mut VolumeRenderer| {
        let start = Instant::now();
        let (_, results) = renderer
            .render_and_wait(&FrameRequest {
                camera,
                size,
                settings: &settings,
                stats: false,
            })
            .failed()?;
        let wall_ms = start.elapsed().as_secs_f64() * 1e3;
        let status = renderer.volume_texture().and_then(|t| t.residency());
        rows.push(Row {
            phase,
            frame,
            azimuth,
            wall_ms,
            gpu_ms: results.gpu_ms,
            rebuild_ms: results.rebuild_ms,
            residency_ms: renderer.residency_ms(),
            since_upload_ms: upload_start.elapsed().as_secs_f64() * 1e3,
            levels: status.map(|s| s.levels_read()).unwrap_or_default(),
            resident: status.map_or(0, |s| s.resident),
            wanted: status.map_or(0, |s| s.wanted),
            missing: status.map_or(0, |s| s.missing),
            bytes: status.map_or(0, |s| s.bytes),
            held: renderer
                .context()
                .device
                .generate_allocator_report()
                .map(|r| (r.total_reserved_bytes, r.total_allocated_bytes)),
            rss: resident_memory().map(|m| m.0),
        });
        frame += 1;
        Ok::<_, Failure>(renderer.residency_complete())
    };
    for (camera, azimuth) in &cameras {
        render(camera, *azimuth, "orbit", &mut renderer)?;
    }
    let (last, azimuth) = cameras
        .last()
        .ok_or_else(|| Failure::BadInput(anyhow::anyhow!("--stream-frames must be at least 1")))?;
    for _ in 0..STILL_FRAMES {
        if render(last, *azimuth, "still", &mut renderer)? {
            break;
        }
    }
    if let Some(report) = renderer.context().device.generate_allocator_report() {
        log::debug!("the GPU memory allocator at the end: {report:.24?}");
    }
    let texture = renderer.volume_texture().map(|t| t.describe());
    std::fs::create_dir_all(&out)
        .map_err(|e| Failure::Other(anyhow::anyhow!("creating {}: {e}", out.display())))?;
    write(&out.join("stream.csv"), &csv(&rows))?;
    let summary = summary(&Summary {
        adapter: &adapter,
        file,
        dims: volume.dims(),
        mode,
        strategy,
        size,
        upload_ms: args.stream_ms,
        budget: args.gpu.gpu_budget,
        load_s,
        texture: texture.as_deref().unwrap_or("no volume"),
        cache: volume.streaming().map(|s| s.cache_bytes()),
        allocated: Allocated {
            texture: renderer.volume_texture().map_or(0, |t| t.texture_bytes()),
            leap: renderer.leap_bytes().unwrap_or(0),
            pages: renderer
                .volume_texture()
                .map_or(0, |t| t.page_table_bytes()),
            staging: renderer.volume_texture().map_or(0, |t| t.reserved.0),
            targets: leapview::render::raycast::targets::Targets::bytes(size),
        },
        rows: &rows,
    });
    write(&out.join("stream.md"), &summary)?;
    print!("{summary}");
    Ok(())
}

fn write(path: &Path, text: &str) -> Result<(), Failure> {
    std::fs::write(path, text)
        .map_err(|e| Failure::Other(anyhow::anyhow!("writing {}: {e}", path.display())))
}

fn csv(rows: &[Row]) -> String {
    let mut s = String::from(
        "phase,frame,azimuth_deg,wall_ms,gpu_ms,rebuild_ms,residency_ms,since_upload_ms,levels,\
         resident,wanted,missing,bytes,allocator_bytes,rss_bytes\n",
    );
    for r in rows {
        let gpu = r.gpu_ms.map(|g| format!("{g:.3}")).unwrap_or_default();
        let rebuild = r.rebuild_ms.map(|g| format!("{g:.3}")).unwrap_or_default();
        let held = r.held.map(|h| h.0.to_string()).unwrap_or_default();
        let rss = r.rss.map(|m| m.to_string()).unwrap_or_default();
        let _ = writeln!(
            s,
            "{},{},{:.1},{:.3},{gpu},{rebuild},{:.3},{:.1},\"{}\",{},{},{},{},{held},{rss}",
            r.phase,
            r.frame,
            r.azimuth,
            r.wall_ms,
            r.residency_ms,
            r.since_upload_ms,
            r.levels,
            r.resident,
            r.wanted,
            r.missing,
            r.bytes
        );
    }
    s
}

struct Summary<'a> {
    adapter: &'a str,
    file: &'a Path,
    dims: [u32; 3],
    mode: Mode,
    strategy: Strategy,
    size: [u32; 2],
    upload_ms: f64,
    budget: Option<u64>,
    load_s: f64,
    texture: &'a str,
    /// A streamed store's cache of decoded chunks at the end, and its budget (bytes).
    cache: Option<(u64, u64)>,
    allocated: Allocated,
    rows: &'a [Row],
}

/// What the renderer allocated on the GPU (bytes): the count the budget is held to.
struct Allocated {
    /// The volume's 3D texture: the whole atlas, however many of its slots are used.
    texture: u64,
    /// The leaping structures.
    leap: u64,
    /// The page tables.
    pages: u64,
    /// The most the upload's staging copies hold before it waits for the GPU.
    staging: u64,
    /// The frame's targets.
    targets: u64,
}

/// A frame this long or shorter keeps a window at 60 Hz: the streaming figure the summary counts
/// frames above.
const SMOOTH_MS: f64 = 16.0;

/// The index of the frame that completes the stream: the one after the last with a brick
/// missing (0 where none missed one).
fn completing<R: std::borrow::Borrow<Row>>(rows: &[R]) -> usize {
    (rows.iter().rposition(|r| r.borrow().missing > 0)).map_or(0, |i| i + 1)
}

/// The `q` quantile (0..=1) of `v` (sorted here).
fn quantile(v: &mut [f64], q: f64) -> f64 {
    v.sort_by(f64::total_cmp);
    v.get(((v.len().max(1) - 1) as f64 * q).round() as usize)
        .copied()
        .unwrap_or(f64::NAN)
}

fn summary(s: &Summary) -> String {
    let mut t = String::new();
    let orbit: Vec<&Row> = s.rows.iter().filter(|r| r.phase == "orbit").collect();
    let mut wall: Vec<f64> = orbit.iter().map(|r| r.wall_ms).collect();
    let mut gpu: Vec<f64> = orbit.iter().filter_map(|r| r.gpu_ms).collect();
    let streaming = orbit.iter().filter(|r| r.missing > 0).count();
    let last = s.rows.last();
    let complete = last.is_some_and(|r| r.missing == 0);
    let most = s.rows.iter().map(|r| r.bytes).max().unwrap_or(0);
    let _ = writeln!(t, "# Streaming: {}", s.file.display());
    let _ = writeln!(t);
    let _ = writeln!(t, "- adapter: {}", s.adapter);
    let _ = writeln!(
        t,
        "- volume: {}×{}×{}, loaded in {:.2} s; {} mode, {}, {}×{}, {} ms of uploads a frame",
        s.dims[0],
        s.dims[1],
        s.dims[2],
        s.load_s,
        s.mode.label(),
        s.strategy.label(),
        s.size[0],
        s.size[1],
        s.upload_ms
    );
    let budget = s.budget.map_or("the default".to_string(), |b| {
        format!("{:.1} MB", b as f64 / 1e6)
    });
    let _ = writeln!(t, "- GPU budget: {budget}; at the end: {}", s.texture);
    if let Some((held, most)) = s.cache {
        let _ = writeln!(
            t,
            "- read from its store brick by brick: decoded chunks cached {} of {}",
            leapview::text::bytes(held),
            leapview::text::bytes(most)
        );
    }
    if let Some((now, peak)) = resident_memory() {
        let most = s.rows.iter().filter_map(|r| r.rss).max().unwrap_or(0);
        let _ = writeln!(
            t,
            "- process memory (resident): peak {} (VmHWM, loading included), largest after a \
             frame {}, at the end {}",
            leapview::text::bytes(peak),
            leapview::text::bytes(most),
            leapview::text::bytes(now)
        );
    }
    if let Some(first) = s.rows.first() {
        let _ = writeln!(
            t,
            "- first picture: {:.0} ms after the upload started (levels read: {}; {} bricks missing)",
            first.since_upload_ms,
            if first.levels.is_empty() {
                "–"
            } else {
                &first.levels
            },
            first.missing
        );
    }
    let _ = writeln!(
        t,
        "- orbit of {} frames, {} of them with bricks still missing: wall clock per frame median {:.2} ms, 95th percentile {:.2} ms, max {:.2} ms; GPU time median {:.2} ms, max {:.2} ms",
        orbit.len(),
        streaming,
        quantile(&mut wall, 0.5),
        quantile(&mut wall, 0.95),
        quantile(&mut wall, 1.0),
        quantile(&mut gpu, 0.5),
        quantile(&mut gpu, 1.0),
    );
    // The frames while bricks stream: the orbit's up to the one that completes (the frame after
    // the last with a brick missing), the first (the first picture) apart.
    let until = completing(&orbit) + 1;
    let mut after: Vec<f64> = (orbit.get(1..until.min(orbit.len())).unwrap_or_default())
        .iter()
        .map(|r| r.wall_ms)
        .collect();
    if !after.is_empty() {
        let slow = after.iter().filter(|&&ms| ms > SMOOTH_MS).count();
        let _ = writeln!(
            t,
            "- the {} orbit frames after the first {}: slowest {:.2} ms, {slow} above {SMOOTH_MS} ms; median {:.2} ms, 95th percentile {:.2} ms",
            after.len(),
            if until <= orbit.len() {
                "until complete"
            } else {
                "(all streaming: the orbit ended before the stream completed)"
            },
            quantile(&mut after, 1.0),
            quantile(&mut after, 0.5),
            quantile(&mut after, 0.95),
        );
    }
    let missing: Vec<&&Row> = orbit.iter().filter(|r| r.missing > 0).collect();
    let mut residency: Vec<f64> = missing.iter().map(|r| r.residency_ms).collect();
    let mut rebuild: Vec<f64> = missing.iter().filter_map(|r| r.rebuild_ms).collect();
    if !missing.is_empty() {
        let _ = writeln!(
            t,
            "- where a streaming frame's time goes (median, max): the residency update on the CPU (deciding, uploading, page tables) {:.2} ms, {:.2} ms; the leaping structures' rebuild on the GPU {:.2} ms, {:.2} ms",
            quantile(&mut residency, 0.5),
            quantile(&mut residency, 1.0),
            quantile(&mut rebuild, 0.5),
            quantile(&mut rebuild, 1.0),
        );
    }
    // Complete at the frame that completed (an orbit may go on past it).
    let completed = s.rows.get(completing(s.rows)).filter(|_| complete);
    if let (Some(r), Some(at)) = (last, completed.or(last)) {
        let _ = writeln!(
            t,
            "- {} at {:.0} ms after the upload started ({} frames): {} of {} wanted bricks resident ({} in the atlas, the others kept until their slots are needed)",
            if complete {
                "complete"
            } else {
                "still incomplete"
            },
            at.since_upload_ms,
            at.frame + 1,
            r.wanted.saturating_sub(r.missing),
            r.wanted,
            r.resident
        );
    }
    let a = &s.allocated;
    let total = a.texture + a.leap + a.pages + a.staging + a.targets;
    let mb = |b: u64| b as f64 / 1e6;
    let _ = writeln!(
        t,
        "- the renderer's allocations on the GPU: the volume's texture {:.1} MB (its bricks at \
         most {:.1} MB of it), leaping structures {:.1} MB, page tables {:.1} MB, upload staging \
         at most {:.1} MB, the frame's targets {:.1} MB: {:.1} MB{}",
        mb(a.texture),
        mb(most),
        mb(a.leap),
        mb(a.pages),
        mb(a.staging),
        mb(a.targets),
        mb(total),
        s.budget
            .map(|b| format!(
                " of the {:.1} MB budget ({})",
                mb(b),
                if total <= b { "within" } else { "OVER" }
            ))
            .unwrap_or_default()
    );
    if let Some((held, allocated)) = s.rows.iter().filter_map(|r| r.held).max() {
        let _ = writeln!(
            t,
            "- wgpu's memory allocator held at most {:.1} MB of the driver's memory after a frame \
             ({:.1} MB of it allocated){}",
            mb(held),
            mb(allocated),
            s.budget
                .map(|b| format!(
                    " ({})",
                    if held <= b {
                        "within the budget"
                    } else {
                        "OVER the budget"
                    }
                ))
                .unwrap_or_default()
        );
    }
    t
}
