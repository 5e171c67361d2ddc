//! Refined images: frames of one view at shifted sample grids, averaged on the GPU
//! ([`super::refine`]), through one entry point, [`VolumeRenderer::render_refined`], for the
//! command line, a saved image and the tests.

use crate::camera::Camera;
use crate::imaging::ImageF32;
use crate::render::readback::read_texture;
use crate::settings::RenderSettings;

use super::error::RenderError;
use super::refine::{self, Accumulator};
use super::renderer::VolumeRenderer;
use super::request::{Accumulate, FrameRequest};

/// How a refined image goes out: how many frames, in bands or whole, reported or not.
pub struct RefineRun<'a> {
    /// Frames in the mean (one plain frame for 0 or 1).
    pub frames: u32,
    /// Each frame in bands of rows `[first, band_end(first))`, each waited for before the next
    /// goes out, so that whatever else shares the queue (a window's drawing) waits for at most
    /// one band; `None`: whole frames.
    pub band_end: Option<&'a mut dyn FnMut(u32) -> u32>,
    /// Told `(frames done, frames)` after each frame, waited for (a long refinement's progress).
    pub done: Option<&'a mut dyn FnMut(u32, u32)>,
}

impl RefineRun<'_> {
    /// `frames` whole frames, nobody told.
    pub fn frames(frames: u32) -> Self {
        Self {
            frames,
            band_end: None,
            done: None,
        }
    }
}

impl VolumeRenderer {
    /// Whether any frame was ever added to a refinement mean.
    pub(crate) fn has_accumulated(&self) -> bool {
        self.refinement().is_some_and(|a| a.count() > 0)
    }

    /// The refinement mean's view (for display), once a frame was added to it.
    pub(crate) fn refined_view(&self) -> Option<&wgpu::TextureView> {
        self.refinement()?.mean().map(|(_, view, _)| view)
    }

    /// Copies the refinement mean to the CPU (waits for the GPU).
    pub fn read_refined(&self) -> Result<ImageF32, RenderError> {
        let (texture, _, size) = self
            .refinement()
            .and_then(Accumulator::mean)
            .ok_or(RenderError::NoVolume)?;
        read_texture(self.context(), texture, size).map_err(RenderError::Gpu)
    }

    /// Renders `run.frames` frames of the view at the offsets of [`refine::offset`] and returns
    /// their mean (one plain frame for one frame or none, or when the image is too large for
    /// the per-pixel sums: then with a warning in the log).
    pub fn render_refined(
        &mut self,
        camera: &Camera,
        size: [u32; 2],
        settings: &RenderSettings,
        run: RefineRun,
    ) -> Result<ImageF32, RenderError> {
        let RefineRun {
            frames,
            band_end,
            mut done,
        } = run;
        let height = size[1];
        let mut whole = |_| height;
        let band_end: &mut dyn FnMut(u32) -> u32 = match band_end {
            Some(f) => f,
            None => &mut whole,
        };
        let refine = frames > 1;
        for k in 0..frames.max(1) {
            let shifted = if refine {
                refine::frame_settings(settings, k)
            } else {
                *settings
            };
            let request = FrameRequest {
                camera,
                size,
                settings: &shifted,
                stats: false,
            };
            let accumulate = refine.then_some(if k == 0 {
                Accumulate::Restart
            } else {
                Accumulate::Add
            });
            let mean = self.render_bands(&request, accumulate, band_end)?;
            if refine && mean.is_none() {
                log::warn!(
                    "a {}×{} image is too large to refine; rendered once",
                    size[0],
                    size[1]
                );
                let once = RefineRun {
                    frames: 1,
                    band_end: Some(band_end),
                    done: None,
                };
                return self.render_refined(camera, size, settings, once);
            }
            if let Some(report) = done.as_mut() {
                self.collect_results(true);
                report(k + 1, frames);
            }
        }
        // The frames' timings are nobody's: free their probes for the frames that follow.
        self.collect_results(true);
        if refine {
            self.read_refined()
        } else {
            self.read_image()
        }
    }

    /// Renders `request`'s frame in bands `[first, band_end(first))` (see
    /// [`Self::render_band`]), waiting for each but the last; returns the frames the
    /// refinement mean then holds.
    fn render_bands(
        &mut self,
        request: &FrameRequest,
        accumulate: Option<Accumulate>,
        band_end: &mut dyn FnMut(u32) -> u32,
    ) -> Result<Option<u32>, RenderError> {
        let height = request.size[1];
        let (mut first, mut mean) = (0, None);
        while first < height {
            let end = band_end(first).clamp(first + 1, height);
            mean = self.render_band(request, [first, end], accumulate)?.1;
            if end < height {
                self.collect_results(true);
            }
            first = end;
        }
        Ok(mean)
    }
}
