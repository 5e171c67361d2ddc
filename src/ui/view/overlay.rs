//! The readout drawn over the 3D view. By default it says what a reader of the image needs: the
//! volume, what the picture shows (the preset or the window), a missing orientation, the frame
//! rate once frames are slow, and why nothing shows. The engineering lines (frames per second,
//! GPU time, strategy and path, adapter, sample counts, rebuild and edit latencies) are added
//! with Advanced › "developer readout" or "count samples". Plus the loading spinner.

use std::collections::VecDeque;
use std::time::{Duration, Instant};

use egui::{Align2, Color32, Frame, Rect, RichText, UiBuilder};

use crate::settings::ConcretePath;
use crate::ui::frames::frame_stats::CountedFrame;

use crate::ui::VolumeSummary;
use crate::ui::loading::LoadStatus;

/// The window the frame rate is measured over.
pub const FPS_WINDOW: Duration = Duration::from_secs(1);

/// Counts rendered volume frames over the last [`FPS_WINDOW`].
#[derive(Clone, Debug, Default)]
pub struct FpsCounter {
    frames: VecDeque<Instant>,
}

impl FpsCounter {
    /// Records a frame rendered at `at`.
    pub fn record(&mut self, at: Instant) {
        self.frames.push_back(at);
        self.forget_before(at);
    }

    /// Frames rendered in the second before `now`; `None` when there were none (idle).
    pub fn fps(&mut self, now: Instant) -> Option<usize> {
        self.forget_before(now);
        (!self.frames.is_empty()).then_some(self.frames.len())
    }

    /// How long until the count changes by itself (the oldest frame leaving the window), so that
    /// the readout can be refreshed then; `None` when idle.
    pub(crate) fn next_change(&self, now: Instant) -> Option<Duration> {
        self.frames
            .front()
            .map(|&oldest| (oldest + FPS_WINDOW).saturating_duration_since(now))
    }

    fn forget_before(&mut self, now: Instant) {
        while let Some(&oldest) = self.frames.front() {
            if now.saturating_duration_since(oldest) >= FPS_WINDOW {
                self.frames.pop_front();
            } else {
                break;
            }
        }
    }
}

/// Frames predicted to take longer than this (a frame rate under 20 per second) show their rate.
pub const SLOW_FRAME_MS: f64 = 50.0;

/// What the readout shows.
pub struct Readout<'a> {
    /// Whether to add the engineering lines.
    pub developer: bool,
    /// What the picture shows: the transfer function's preset, the iso value or the window.
    pub look: Option<String>,
    /// Predicted milliseconds of a full-resolution frame, once measured.
    pub frame_ms: Option<f64>,
    /// Said when the file gave no orientation and one is assumed.
    pub orientation_note: Option<&'static str>,
    /// Frames per second, `None` when idle.
    pub fps: Option<usize>,
    /// GPU milliseconds of the last measured frame.
    pub gpu_ms: Option<f64>,
    /// Whether the adapter has timestamp queries at all.
    pub has_timestamps: bool,
    /// Adapter name and backend.
    pub adapter: &'a str,
    /// The path the last frame used.
    pub path: Option<ConcretePath>,
    /// Strategy label of the last frame (RC, RC-t).
    pub strategy: &'a str,
    /// The volume on screen.
    pub volume: Option<&'a VolumeSummary>,
    /// What the last statistics frame counted.
    pub counters: Option<CountedFrame>,
    /// GPU time of the last rebuild of the leaping structures, ms.
    pub rebuild_ms: Option<f64>,
    /// Wall time from the last transfer-function change to its frame's completion, ms.
    pub tf_latency_ms: Option<f64>,
    /// Resolution scale of the frame on screen when it is an interaction preview.
    pub preview_scale: Option<f64>,
    /// The refinement mean on screen, while refining or refined.
    pub refined: Option<crate::ui::frames::shown::Refinement>,
    /// Why the picture shows nothing, when it cannot ([`crate::transfer::blank::why_blank`]).
    pub blank: Option<String>,
    /// Share of the next frame's rows rendered, while a frame takes more than one band.
    pub rendering: Option<f64>,
    /// Slow work before the next frame can start (compiling a shader, timing the ray loops).
    pub preparing: Option<&'static str>,
}

/// `1234567` as `1.23 M`.
fn compact(n: u64) -> String {
    match n {
        0..1_000 => n.to_string(),
        1_000..1_000_000 => format!("{:.1} k", n as f64 / 1e3),
        _ => format!("{:.2} M", n as f64 / 1e6),
    }
}

impl Readout<'_> {
    /// The lines of text, top to bottom.
    pub fn lines(&self) -> Vec<String> {
        let mut lines = Vec::new();
        if let Some(v) = self.volume {
            let [x, y, z] = v.dims;
            lines.push(format!("{} · {x}×{y}×{z}", v.name));
        }
        if let Some(look) = &self.look {
            lines.push(look.clone());
        }
        if let Some(note) = self.orientation_note {
            lines.push(note.to_string());
        }
        if let Some(note) = self.volume.and_then(|v| v.coarser.as_ref()) {
            lines.push(note.clone());
        }
        if let Some(line) = self.volume.and_then(|v| v.residency.as_ref()) {
            lines.push(line.clone());
        }
        if !self.developer
            && let Some(ms) = self.frame_ms.filter(|ms| *ms > SLOW_FRAME_MS)
        {
            lines.push(format!("{:.1} fps at full resolution", 1000.0 / ms));
        }
        if let Some(scale) = self.preview_scale {
            lines.push(format!(
                "preview at {:.0} % resolution (full quality once still)",
                100.0 * scale
            ));
        }
        if let Some(what) = self.preparing {
            lines.push(format!("preparing: {what}…"));
        }
        if let Some(done) = self.rendering {
            lines.push(format!("rendering the next frame: {:.0} %", 100.0 * done));
        }
        if let Some(why) = &self.blank {
            lines.push(format!("nothing shows: {why}"));
        }
        if self.developer {
            lines.extend(self.developer_lines());
        }
        lines
    }

    /// The engineering lines: rate, GPU time, strategy and path, adapter, refinement, sample
    /// counts, rebuild and edit latencies, the volume's layout.
    fn developer_lines(&self) -> Vec<String> {
        let fps = self
            .fps
            .map_or_else(|| "idle".to_string(), |n| format!("{n} fps"));
        let gpu = match (self.gpu_ms, self.has_timestamps) {
            (Some(ms), _) => format!("{ms:.2} ms GPU"),
            (None, true) => "… ms GPU".to_string(),
            (None, false) => "GPU time n/a (no reliable timestamp queries)".to_string(),
        };
        let path = match self.path {
            Some(ConcretePath::Fragment) => " fragment",
            Some(ConcretePath::Compute) => " compute",
            None => "",
        };
        let first = if self.path.is_none() && self.gpu_ms.is_none() {
            "no frame yet".to_string()
        } else {
            format!("{fps} · {gpu} · {}{path}", self.strategy)
        };
        let mut lines = vec![first, self.adapter.to_string()];
        if let Some(ms) = self.frame_ms {
            lines.push(format!("full frame predicted {ms:.1} ms"));
        }
        if let Some(crate::ui::frames::shown::Refinement { done: n, target }) = self.refined {
            lines.push(if n < target {
                format!("refining: mean of {n} of {target} frames")
            } else {
                format!("refined: mean of {n} frames (shifted sample grids)")
            });
        }
        if let Some(CountedFrame {
            counters: c,
            pixels,
        }) = self.counters
        {
            lines.push(format!(
                "{} samples ({:.1}/px) · {} visible · ×{:.2} oracle",
                compact(c.samples),
                c.samples as f64 / pixels.max(1) as f64,
                compact(c.visible_samples),
                c.samples as f64 / c.visible_samples.max(1) as f64,
            ));
            // What leaping skipped, and what it paid for that: questions asked of its structure
            // (a line of its own, only where the strategy leaps: every leap follows a lookup).
            if c.lookups > 0 {
                lines.push(format!(
                    "{} leaps, {:.1} % of samples leapt · {:.1} lookups/ray",
                    compact(c.leaps),
                    100.0 * c.share_leapt().unwrap_or(0.0),
                    c.lookups as f64 / c.rays.max(1) as f64,
                ));
            }
        }
        if let Some(ms) = self.rebuild_ms {
            lines.push(format!("leaping structures rebuilt in {ms:.3} ms GPU"));
        }
        if let Some(ms) = self.tf_latency_ms {
            lines.push(format!("TF edit to frame done: {ms:.1} ms"));
        }
        if let Some(layout) = self.volume.and_then(|v| v.gpu_layout.as_ref()) {
            lines.push(layout.clone());
        }
        if let Some(v) = self.volume {
            lines.push(v.line());
        }
        lines
    }
}

/// Draws the readout in the top-left corner of `view`; returns the rectangle it covers.
pub(crate) fn draw_readout(ui: &mut egui::Ui, view: Rect, readout: &Readout) -> Rect {
    let area = view.shrink(8.0);
    let mut child = ui.new_child(UiBuilder::new().max_rect(area));
    // Never over a neighbouring pane (a slice view in the 2 × 2 layout), however long a line.
    child.set_clip_rect(view.intersect(ui.clip_rect()));
    child.style_mut().interaction.selectable_labels = false;
    Frame::new()
        .fill(Color32::from_black_alpha(170))
        .corner_radius(4.0)
        .inner_margin(6.0)
        .show(&mut child, |ui| {
            ui.set_max_width(area.width() - 12.0);
            for line in readout.lines() {
                ui.label(
                    RichText::new(line)
                        .monospace()
                        .color(Color32::from_gray(230)),
                );
            }
        })
        .response
        .rect
}

/// Draws the load in progress in the top-right corner of `view`: a spinner, what and for how
/// long, a progress bar once the share read is known, and a Cancel button. Returns whether
/// Cancel was clicked.
pub fn draw_loading(ui: &mut egui::Ui, view: Rect, status: &LoadStatus) -> bool {
    let width = 300.0_f32.min(view.width() - 16.0).max(120.0);
    let rect = Align2::RIGHT_TOP.align_size_within_rect(egui::vec2(width, 60.0), view.shrink(8.0));
    let mut child = ui.new_child(UiBuilder::new().max_rect(rect));
    let mut cancel = false;
    Frame::new()
        .fill(Color32::from_black_alpha(170))
        .corner_radius(4.0)
        .inner_margin(6.0)
        .show(&mut child, |ui| {
            ui.set_width(width - 12.0);
            ui.horizontal(|ui| {
                ui.add(egui::Spinner::new().size(14.0));
                ui.label(
                    RichText::new(format!(
                        "Loading {}… {:.0} s",
                        status.label,
                        status.started.elapsed().as_secs_f64()
                    ))
                    .color(Color32::from_gray(230)),
                );
            });
            ui.horizontal(|ui| {
                cancel = ui.button("Cancel").clicked();
                if let Some(f) = status.fraction.filter(|f| *f < 1.0) {
                    ui.add(egui::ProgressBar::new(f as f32).show_percentage());
                } else if status.fraction.is_some() {
                    // Every sample is read; the reader is computing the range and histogram.
                    ui.label(RichText::new("read; computing the histogram…").weak());
                } else if status.generated {
                    ui.label(RichText::new("generating…").weak());
                } else {
                    ui.label(RichText::new("reading the header…").weak());
                }
            });
        });
    // The elapsed seconds and the bar change by themselves; the spinner asks for repaints.
    cancel
}

/// Centred over the view until its first frame is on screen: what the renderer is doing
/// (`preparing`, or rendering with `progress` of the frame's rows done), so that a slow first
/// frame (a shader compiling, the ray loops being timed, a second of work on a CPU driver) is
/// never a blank, seemingly frozen window.
pub(crate) fn draw_first_frame_status(
    ui: &mut egui::Ui,
    view: Rect,
    preparing: Option<&str>,
    progress: Option<f64>,
) {
    let text = match (preparing, progress) {
        (Some(what), _) => format!("Preparing the renderer: {what}…"),
        (None, Some(p)) => format!("Rendering the first frame… {:.0} %", 100.0 * p),
        (None, None) => return,
    };
    let painter = ui.painter();
    let galley = painter.layout(
        text,
        egui::FontId::proportional(16.0),
        Color32::from_gray(230),
        (view.width() - 32.0).max(100.0),
    );
    let rect = Align2::CENTER_CENTER
        .align_size_within_rect(galley.size(), view)
        .expand(10.0);
    painter.rect_filled(rect, 4.0, Color32::from_black_alpha(170));
    painter.galley(rect.min + egui::vec2(10.0, 10.0), galley, Color32::WHITE);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fps_counts_the_last_second_and_goes_idle() {
        let t0 = Instant::now();
        let mut fps = FpsCounter::default();
        assert_eq!(fps.fps(t0), None);
        assert_eq!(fps.next_change(t0), None);
        // 30 frames 1/30 s apart: all 30 lie within the second after the first.
        for i in 0..30 {
            fps.record(t0 + Duration::from_millis(33 * i));
        }
        let end = t0 + Duration::from_millis(33 * 29);
        assert_eq!(fps.fps(end), Some(30));
        // Half a second later the first half has left the window.
        assert_eq!(fps.fps(t0 + Duration::from_millis(1500)), Some(14));
        assert_eq!(
            fps.next_change(t0 + Duration::from_millis(1500)),
            Some(Duration::from_millis(33 * 16 + 1000 - 1500))
        );
        assert_eq!(fps.fps(end + FPS_WINDOW), None);
    }

    #[test]
    fn readout_shows_counts_against_the_oracle() {
        let counters = crate::counters::FrameCounters {
            samples: 2_000_000,
            visible_samples: 500_000,
            rays: 1000,
            leaps: 1500,
            leapt_samples: 6_000_000,
            lookups: 2500,
            ..Default::default()
        };
        let readout = Readout {
            developer: true,
            look: None,
            frame_ms: None,
            orientation_note: None,
            fps: Some(30),
            gpu_ms: Some(1.5),
            has_timestamps: true,
            adapter: "gpu",
            path: Some(ConcretePath::Compute),
            strategy: "RC-s",
            volume: None,
            counters: Some(CountedFrame {
                counters,
                pixels: 1_000_000,
            }),
            rebuild_ms: Some(0.25),
            tf_latency_ms: Some(3.5),
            preview_scale: None,
            refined: None,
            blank: None,
            rendering: None,
            preparing: None,
        };
        let lines = readout.lines();
        assert_eq!(
            lines[2],
            "2.00 M samples (2.0/px) · 500.0 k visible · ×4.00 oracle"
        );
        assert_eq!(
            lines[3],
            "1.5 k leaps, 75.0 % of samples leapt · 2.5 lookups/ray"
        );
        assert_eq!(lines[4], "leaping structures rebuilt in 0.250 ms GPU");
    }

    #[test]
    fn readout_says_idle_and_why_gpu_time_is_missing() {
        let readout = Readout {
            developer: true,
            look: None,
            frame_ms: None,
            orientation_note: None,
            fps: None,
            gpu_ms: None,
            has_timestamps: false,
            adapter: "llvmpipe",
            path: Some(ConcretePath::Compute),
            strategy: "RC-t",
            volume: None,
            counters: None,
            rebuild_ms: None,
            tf_latency_ms: None,
            preview_scale: None,
            refined: None,
            blank: None,
            rendering: None,
            preparing: None,
        };
        let nothing_yet = Readout {
            path: None,
            ..readout
        };
        assert_eq!(nothing_yet.lines()[0], "no frame yet");
        let readout = Readout {
            path: Some(ConcretePath::Compute),
            ..nothing_yet
        };
        let lines = readout.lines();
        assert!(lines[0].starts_with("idle"));
        assert!(lines[0].contains("n/a"));
        assert!(lines[0].contains("compute"));
        let busy = Readout {
            fps: Some(24),
            gpu_ms: Some(3.25),
            has_timestamps: true,
            ..readout
        };
        assert!(busy.lines()[0].starts_with("24 fps · 3.25 ms GPU"));
    }

    #[test]
    fn the_default_readout_speaks_to_the_reader() {
        let volume =
            VolumeSummary::of(&crate::volume::synthetic::shepp_logan(16).expect("phantom"));
        let readout = Readout {
            developer: false,
            look: Some("ct-bone".into()),
            frame_ms: Some(8.0),
            orientation_note: None,
            fps: Some(60),
            gpu_ms: Some(1.5),
            has_timestamps: true,
            adapter: "gpu",
            path: Some(ConcretePath::Compute),
            strategy: "RC-s",
            volume: Some(&volume),
            counters: None,
            rebuild_ms: Some(0.25),
            tf_latency_ms: Some(3.5),
            preview_scale: None,
            refined: Some(crate::ui::frames::shown::Refinement { done: 3, target: 8 }),
            blank: None,
            rendering: None,
            preparing: None,
        };
        let lines = readout.lines();
        assert_eq!(
            lines,
            [format!("{} · 16×16×16", volume.name), "ct-bone".into()]
        );
        // A slow frame shows its rate; the engineering lines only on request.
        let slow = Readout {
            frame_ms: Some(400.0),
            orientation_note: Some("no orientation in the file: RAS assumed"),
            ..readout
        };
        let lines = slow.lines();
        assert_eq!(lines.len(), 4, "{lines:?}");
        assert_eq!(lines[3], "2.5 fps at full resolution");
        let developer = Readout {
            developer: true,
            ..slow
        };
        let lines = developer.lines();
        assert!(
            lines.iter().any(|l| l.contains("RC-s compute")),
            "{lines:?}"
        );
        assert!(lines.iter().any(|l| l.contains("rebuilt")), "{lines:?}");
        assert!(
            !lines.iter().any(|l| l.contains("fps at full")),
            "{lines:?}"
        );
    }
}
