//! Automation for scripts and smoke tests, driven by environment variables:
//! `LEAPVIEW_EXIT_AFTER_FRAMES=N` closes the window after N rendered volume frames (when N > 1,
//! the camera turns a little after each frame so that every frame is a new one: an unchanged view
//! is never re-rendered), and `LEAPVIEW_SCREENSHOT=path.png` saves the whole window once the first
//! frame and its GPU time are on screen. The screenshot is also compared with the renderer's own
//! image, so a colour conversion between the renderer and the window would show up in the log.

use std::path::{Path, PathBuf};
use std::sync::{Arc, mpsc};

use egui::ColorImage;

/// Variable holding the number of frames after which the window closes.
pub const EXIT_AFTER_FRAMES_VAR: &str = "LEAPVIEW_EXIT_AFTER_FRAMES";
/// Variable holding the path of the window screenshot.
pub const SCREENSHOT_VAR: &str = "LEAPVIEW_SCREENSHOT";
/// Degrees the camera turns between automated frames.
pub const TURN_DEG_PER_FRAME: f64 = 3.0;

/// A malformed automation variable.
#[derive(Debug, thiserror::Error)]
#[error("{EXIT_AFTER_FRAMES_VAR} must be a positive whole number of frames, got {0:?}")]
pub struct AutomationError(String);

enum Shot {
    Waiting,
    Requested(mpsc::Receiver<Arc<ColorImage>>),
    Done,
}

/// The automation state.
pub struct Automation {
    exit_after_frames: Option<u64>,
    screenshot: Option<(PathBuf, Shot)>,
}

impl Automation {
    /// Reads the variables.
    pub fn from_env() -> Result<Self, AutomationError> {
        Self::new(
            std::env::var(EXIT_AFTER_FRAMES_VAR).ok().as_deref(),
            std::env::var_os(SCREENSHOT_VAR).map(PathBuf::from),
        )
    }

    /// From the variables' values.
    pub fn new(
        exit_after: Option<&str>,
        screenshot: Option<PathBuf>,
    ) -> Result<Self, AutomationError> {
        let exit_after_frames = exit_after
            .map(|s| match s.trim().parse::<u64>() {
                Ok(n) if n > 0 => Ok(n),
                _ => Err(AutomationError(s.to_string())),
            })
            .transpose()?;
        Ok(Self {
            exit_after_frames,
            screenshot: screenshot.map(|p| (p, Shot::Waiting)),
        })
    }

    /// Whether a script drives the window (then nothing is restored or saved between runs, so
    /// the same command gives the same pictures).
    pub(crate) fn is_active(&self) -> bool {
        self.exit_after_frames.is_some() || self.screenshot.is_some()
    }

    fn screenshot_settled(&self) -> bool {
        self.screenshot
            .as_ref()
            .is_none_or(|(_, shot)| matches!(shot, Shot::Done))
    }

    /// Whether the camera should turn now so that one more frame is rendered.
    pub(crate) fn wants_another_frame(&self, frames_rendered: u64) -> bool {
        frames_rendered >= 1
            && self.screenshot_settled()
            && self.exit_after_frames.is_some_and(|n| frames_rendered < n)
    }

    /// Whether the window should close now.
    pub(crate) fn should_close(&self, frames_rendered: u64) -> bool {
        self.screenshot_settled() && self.exit_after_frames.is_some_and(|n| frames_rendered >= n)
    }

    /// Whether the screenshot is still to be requested (the app then keeps passes coming until
    /// the view is settled).
    pub(crate) fn screenshot_waiting(&self) -> bool {
        matches!(self.screenshot, Some((_, Shot::Waiting)))
    }

    /// At the end of a pass: requests the screenshot when `ready` (a settled frame and its
    /// measurements are on screen), and hands it over once it has arrived.
    pub(crate) fn poll_screenshot(&mut self, ctx: &egui::Context, ready: bool) -> ShotEvent {
        let Some((path, shot)) = self.screenshot.as_mut() else {
            return ShotEvent::None;
        };
        match shot {
            Shot::Waiting if ready => {
                let (tx, rx) = mpsc::channel();
                let waker = ctx.clone();
                ctx.request_screenshot(move |image| {
                    let _ = tx.send(image);
                    waker.request_repaint();
                });
                *shot = Shot::Requested(rx);
                ShotEvent::Requested
            }
            Shot::Requested(rx) => match rx.try_recv() {
                Ok(image) => {
                    *shot = Shot::Done;
                    ShotEvent::Arrived(path.clone(), image)
                }
                Err(mpsc::TryRecvError::Empty) => ShotEvent::None,
                Err(mpsc::TryRecvError::Disconnected) => {
                    log::error!("the window screenshot never arrived");
                    *shot = Shot::Done;
                    ShotEvent::None
                }
            },
            _ => ShotEvent::None,
        }
    }
}

/// What [`Automation::poll_screenshot`] did.
pub enum ShotEvent {
    /// Nothing happened.
    None,
    /// The screenshot of this pass's paint was requested.
    Requested,
    /// The screenshot arrived; it goes to this path.
    Arrived(PathBuf, Arc<ColorImage>),
}

/// Writes a window screenshot as an opaque 8-bit RGB(A) PNG.
pub fn save(image: &ColorImage, path: &Path) -> Result<(), image::ImageError> {
    let bytes = image
        .pixels
        .iter()
        // The window is opaque on screen; its framebuffer alpha means nothing.
        .flat_map(|c| [c.r(), c.g(), c.b(), 255])
        .collect();
    let [w, h] = image.size;
    let rgba = image::RgbaImage::from_raw(w as u32, h as u32, bytes).ok_or_else(|| {
        image::ImageError::Parameter(image::error::ParameterError::from_kind(
            image::error::ParameterErrorKind::DimensionMismatch,
        ))
    })?;
    rgba.save(path)
}

/// How a region of a screenshot differs from the rendered image.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ViewComparison {
    /// Pixels compared.
    pub pixels: u64,
    /// Largest difference of any RGB channel, in 8-bit levels.
    pub max_levels: u8,
    /// Pixels with any channel differing.
    pub differing: u64,
}

/// How far from a line drawn over the view its pixels may be changed, physical pixels: half of a
/// 1.5-point stroke at up to 2 pixels per point, and egui's one-pixel feathering.
const LINE_REACH_PX: f32 = 2.5;

/// What is drawn over the view and so left out of the comparison, in physical pixels.
#[derive(Clone, Debug, Default)]
pub struct Overdrawn {
    /// Boxes `[x0, y0, x1, y1]` (the readout, the orientation marker).
    pub rects: Vec<[usize; 4]>,
    /// Line segments (the slice planes' outlines), each with `LINE_REACH_PX` around it.
    pub lines: Vec<[[f32; 2]; 2]>,
}

impl Overdrawn {
    fn covers(&self, x: usize, y: usize) -> bool {
        let in_rect = self
            .rects
            .iter()
            .any(|&[x0, y0, x1, y1]| x >= x0 && x < x1 && y >= y0 && y < y1);
        // The pixel's centre against each segment.
        let p = glam::Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
        in_rect
            || self.lines.iter().any(|&[a, b]| {
                let (a, b) = (glam::Vec2::from(a), glam::Vec2::from(b));
                let ab = b - a;
                let t = if ab.length_squared() > 0.0 {
                    ((p - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                p.distance(a + t * ab) <= LINE_REACH_PX
            })
    }
}

/// Compares the screenshot's pixels at `origin_px` (top-left of the view, physical pixels) with
/// `rendered`, skipping the pixels `skip` covers (what the window draws over the view).
pub(crate) fn compare_view(
    shot: &ColorImage,
    origin_px: [usize; 2],
    rendered: &image::RgbaImage,
    skip: &Overdrawn,
) -> ViewComparison {
    let mut out = ViewComparison {
        pixels: 0,
        max_levels: 0,
        differing: 0,
    };
    let [sw, sh] = shot.size;
    for (x, y, px) in rendered.enumerate_pixels() {
        let (sx, sy) = (origin_px[0] + x as usize, origin_px[1] + y as usize);
        if sx >= sw || sy >= sh || skip.covers(sx, sy) {
            continue;
        }
        let c = shot.pixels[sy * sw + sx];
        let diff = [c.r(), c.g(), c.b()]
            .iter()
            .zip(&px.0)
            .map(|(a, b)| a.abs_diff(*b))
            .max()
            .unwrap_or(0);
        out.pixels += 1;
        out.max_levels = out.max_levels.max(diff);
        out.differing += u64::from(diff > 0);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use egui::Color32;

    #[test]
    fn frame_count_must_be_positive() {
        assert!(Automation::new(Some("0"), None).is_err());
        assert!(Automation::new(Some("x"), None).is_err());
        let a = Automation::new(Some(" 3 "), None).expect("valid");
        assert!(!a.wants_another_frame(0));
        assert!(a.wants_another_frame(1));
        assert!(!a.should_close(2));
        assert!(a.should_close(3));
        assert!(!a.wants_another_frame(3));
        let idle = Automation::new(None, None).expect("valid");
        assert!(!idle.should_close(1000));
        assert!(!idle.wants_another_frame(1));
    }

    #[test]
    fn a_pending_screenshot_holds_the_exit_and_the_turning() {
        let a = Automation::new(Some("1"), Some(PathBuf::from("x.png"))).expect("valid");
        assert!(!a.should_close(5));
        assert!(!a.wants_another_frame(1));
    }

    #[test]
    fn comparison_finds_offsets_and_skips_the_readout() {
        let mut shot = ColorImage::filled([8, 6], Color32::from_rgb(10, 20, 30));
        let rendered = image::RgbaImage::from_pixel(4, 3, image::Rgba([10, 20, 30, 255]));
        let none = Overdrawn::default();
        let same = compare_view(&shot, [2, 2], &rendered, &none);
        assert_eq!((same.pixels, same.max_levels, same.differing), (12, 0, 0));
        shot.pixels[2 * 8 + 2] = Color32::from_rgb(13, 20, 30);
        let off = compare_view(&shot, [2, 2], &rendered, &none);
        assert_eq!((off.max_levels, off.differing), (3, 1));
        let boxed = Overdrawn {
            rects: vec![[0, 0, 3, 3]],
            lines: Vec::new(),
        };
        let skipped = compare_view(&shot, [2, 2], &rendered, &boxed);
        assert_eq!((skipped.pixels, skipped.max_levels), (11, 0));
    }

    #[test]
    fn comparison_skips_the_pixels_near_a_line_drawn_over_the_view() {
        let shot = ColorImage::filled([40, 10], Color32::from_rgb(10, 20, 30));
        let rendered = image::RgbaImage::from_pixel(40, 10, image::Rgba([10, 20, 30, 255]));
        // A vertical line at x = 20: columns 17 to 22 (centres 17.5 … 22.5, within 2.5 px) are
        // left out.
        let line = Overdrawn {
            rects: Vec::new(),
            lines: vec![[[20.0, 0.0], [20.0, 10.0]]],
        };
        let c = compare_view(&shot, [0, 0], &rendered, &line);
        assert_eq!(c.pixels, 400 - 6 * 10);
    }
}
