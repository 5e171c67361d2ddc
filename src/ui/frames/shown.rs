//! The frame on screen: the last complete plain frame, copied out of the renderer's output (which
//! the next frame's bands overwrite while this one stays on screen), or the refinement mean once
//! it holds more than that frame; whether it is a reduced preview; and the egui texture it is
//! shown through.

use crate::imaging::ImageF32;
use crate::render::{RenderError, VolumeRenderer};
use crate::ui::view::viewport::ViewTexture;

/// The copy of the last complete plain frame.
struct PlainCopy {
    texture: wgpu::Texture,
    view: wgpu::TextureView,
    size: [u32; 2],
}

/// How far the refinement mean on screen has come.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Refinement {
    /// Frames in the mean on screen (0: the plain frame is on screen, not a mean).
    pub done: u32,
    /// Frames the mean aims at.
    pub target: u32,
}

impl Refinement {
    /// Whether another refinement frame is to come.
    pub(crate) fn under_way(self) -> bool {
        self.done > 0 && self.done < self.target
    }
}

/// What the view shows.
#[derive(Default)]
pub struct ShownFrame {
    plain: Option<PlainCopy>,
    /// The texture egui draws.
    texture: ViewTexture,
    /// The view's size when the frame on screen is a reduced preview of it.
    pub preview_of: Option<[u32; 2]>,
    /// The refinement mean's progress.
    pub refinement: Refinement,
}

impl ShownFrame {
    /// Copies the renderer's output (the plain frame just finished) to the texture the view
    /// shows, so that the next frame's bands do not show before it is complete. Call it under
    /// the pump's lock: no band of the next frame can go out before this copy.
    pub(crate) fn copy_plain(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        renderer: &VolumeRenderer,
        size: [u32; 2],
    ) {
        if self.plain.as_ref().is_none_or(|p| p.size != size) {
            use wgpu::TextureUsages as U;
            let texture = crate::render::texture::texture_2d(
                device,
                size,
                crate::render::texture::OUTPUT_FORMAT,
                U::TEXTURE_BINDING | U::COPY_DST | U::COPY_SRC,
                "view",
            );
            let view = crate::render::texture::full_view(&texture);
            self.plain = Some(PlainCopy {
                texture,
                view,
                size,
            });
        }
        let (Some(output), Some(plain)) = (renderer.output_texture(), &self.plain) else {
            return;
        };
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("show frame"),
        });
        encoder.copy_texture_to_texture(
            output.as_image_copy(),
            plain.texture.as_image_copy(),
            crate::render::texture::extent(size),
        );
        queue.submit([encoder.finish()]);
    }

    /// Points the view at the refinement mean when it holds more than the plain frame, else at
    /// the plain frame.
    pub fn show(
        &mut self,
        egui_renderer: &egui::mutex::RwLock<egui_wgpu::Renderer>,
        device: &wgpu::Device,
        renderer: &VolumeRenderer,
        size_px: [u32; 2],
    ) {
        let view = if self.refinement.done > 1 {
            renderer.refined_view().cloned()
        } else {
            self.plain.as_ref().map(|p| p.view.clone())
        };
        if let Some(view) = view {
            self.texture.sync(
                egui_renderer,
                device,
                &view,
                size_px,
                self.preview_of.is_some(),
            );
        }
    }

    /// The frame on screen, read back from the GPU.
    pub fn read(&self, renderer: &VolumeRenderer) -> Result<ImageF32, RenderError> {
        if self.refinement.done > 1 {
            return renderer.read_refined();
        }
        let plain = self.plain.as_ref().ok_or(RenderError::NoVolume)?;
        crate::render::readback::read_texture(renderer.context(), &plain.texture, plain.size)
            .map_err(RenderError::Gpu)
    }

    /// Draws the image with its top-left corner at `origin` (a preview stretched over the view
    /// it stands for).
    pub(crate) fn paint(&self, ui: &egui::Ui, origin: egui::Pos2) {
        self.texture.paint(ui, origin, self.preview_of);
    }

    /// The preview's scale (per axis) when the frame on screen is a reduced preview.
    pub(crate) fn preview_scale(&self) -> Option<f64> {
        let view = self.preview_of?;
        Some(f64::from(self.texture.size_px()[0]) / f64::from(view[0].max(1)))
    }
}
