//! Frames the caller waits for, and their pixels: what the command line and the tests use (the
//! window submits bands and reads nothing back, `ui::frames`).

use crate::camera::Camera;
use crate::imaging::ImageF32;
use crate::render::pack::Rgba8Reader;
use crate::render::probe::FrameResults;
use crate::render::readback::read_texture;
use crate::settings::RenderSettings;

use super::error::RenderError;
use super::renderer::VolumeRenderer;
use super::request::{FrameRequest, SubmittedFrame};

impl VolumeRenderer {
    /// Renders a frame and waits for its measurements.
    pub fn render_and_wait(
        &mut self,
        request: &FrameRequest,
    ) -> Result<(SubmittedFrame, FrameResults), RenderError> {
        let submitted = self.render(request)?;
        let results = self.wait_for_results(&submitted);
        Ok((submitted, results))
    }

    /// Waits for the measurements of `submitted` (empty where it had none).
    pub fn wait_for_results(&mut self, submitted: &SubmittedFrame) -> FrameResults {
        self.collect_results(true)
            .into_iter()
            .find(|r| r.frame == submitted.frame)
            .unwrap_or_default()
    }

    /// The rendered image (to copy it for display), once a frame was rendered.
    pub(crate) fn output_texture(&self) -> Option<&wgpu::Texture> {
        self.targets.as_ref().map(|t| &t.output)
    }

    /// Copies the last rendered image to the CPU (waits for the GPU).
    pub fn read_image(&self) -> Result<ImageF32, RenderError> {
        let targets = self.targets.as_ref().ok_or(RenderError::NoVolume)?;
        read_texture(&self.ctx, &targets.output, targets.size).map_err(RenderError::Gpu)
    }

    /// Copies the last rendered image to the CPU as 8-bit RGBA, quantised on the GPU (waits for
    /// the GPU): the same bytes as [`Self::read_image`] followed by [`ImageF32::to_rgba8`], in
    /// half the bytes and without the CPU's conversion. An image too large for one storage
    /// buffer takes that slower way.
    pub fn read_image_rgba8(&mut self) -> Result<image::RgbaImage, RenderError> {
        let targets = self.targets.as_ref().ok_or(RenderError::NoVolume)?;
        let reader = match &mut self.rgba8 {
            Some(reader) => reader,
            empty => empty.insert(Rgba8Reader::new(&self.ctx.device)?),
        };
        let packed = reader
            .read(&self.ctx, &targets.output_view, targets.size)
            .map_err(RenderError::Gpu)?;
        match packed {
            Some(image) => Ok(image),
            None => Ok(self.read_image()?.to_rgba8()),
        }
    }

    /// Renders `camera` at `size` and returns the image (waits for the GPU).
    pub fn render_image(
        &mut self,
        camera: &Camera,
        size: [u32; 2],
        settings: &RenderSettings,
    ) -> Result<ImageF32, RenderError> {
        self.render(&FrameRequest {
            camera,
            size,
            settings,
            stats: false,
        })?;
        self.read_image()
    }
}
