//! Rendered images on the CPU: linear RGBA f32 pixels, written as 8-bit PNG or f32 EXR, and
//! compared with each other (the metrics golden-image and reference tests use).

use std::path::Path;

/// A linear RGBA image, row 0 at the top.
#[derive(Clone, Debug, PartialEq)]
pub struct ImageF32 {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Pixels, row-major.
    pub pixels: Vec<[f32; 4]>,
}

/// Why an image could not be written or read.
#[derive(Debug, thiserror::Error)]
pub enum ImageError {
    /// Unknown extension.
    #[error("unsupported image format (use .png or .exr): {}", .0.display())]
    Format(std::path::PathBuf),
    /// The folder to write into does not exist (or is not a folder).
    #[error("the folder to write the image into does not exist: {}", .0.display())]
    NoFolder(std::path::PathBuf),
    /// Encoder or file error.
    #[error("cannot write or read the image ({error}): {}", path.display())]
    Io {
        /// The file.
        path: std::path::PathBuf,
        /// What failed (in the message, so not also a source to print twice).
        error: image::ImageError,
    },
}

/// Differences between two images of the same size, per channel in 0..1 units (RGB only).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImageDiff {
    /// Largest absolute difference of any channel.
    pub max_abs: f64,
    /// Root mean square difference over all RGB channels.
    pub rmse: f64,
    /// Share of pixels with any channel off by more than 1/255.
    pub share_over_1_255: f64,
    /// Peak signal-to-noise ratio in dB (peak 1.0); infinite for identical images.
    pub psnr_db: f64,
}

impl ImageF32 {
    /// An image filled with one colour.
    pub fn filled(width: u32, height: u32, rgba: [f32; 4]) -> Self {
        Self {
            width,
            height,
            pixels: vec![rgba; width as usize * height as usize],
        }
    }

    /// The pixel at `(x, y)`.
    pub fn get(&self, x: u32, y: u32) -> [f32; 4] {
        self.pixels[(y * self.width + x) as usize]
    }

    /// Quantises to 8-bit RGBA (no gamma: the values are stored as they are).
    pub fn to_rgba8(&self) -> image::RgbaImage {
        let bytes = self
            .pixels
            .iter()
            .flat_map(|p| p.map(|c| (c.clamp(0.0, 1.0) * 255.0).round() as u8))
            .collect();
        // The buffer has exactly width × height × 4 bytes by construction.
        image::RgbaImage::from_raw(self.width, self.height, bytes).unwrap_or_default()
    }

    /// Reads an 8-bit PNG back into linear f32 values (for golden images).
    pub fn read_png(path: &Path) -> Result<Self, ImageError> {
        let img = image::open(path).map_err(|source| ImageError::Io {
            path: path.to_path_buf(),
            error: source,
        })?;
        let rgba = img.to_rgba8();
        Ok(Self {
            width: rgba.width(),
            height: rgba.height(),
            pixels: rgba
                .pixels()
                .map(|p| p.0.map(|c| c as f32 / 255.0))
                .collect(),
        })
    }

    /// Writes `.png` (8-bit RGBA) or `.exr` (linear RGBA f32).
    pub fn save(&self, path: &Path) -> Result<(), ImageError> {
        check_output_path(path)?;
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        let io = |source| ImageError::Io {
            path: path.to_path_buf(),
            error: source,
        };
        match ext.as_deref() {
            Some("png") => self.to_rgba8().save(path).map_err(io),
            Some("exr") => {
                let data = self.pixels.iter().flatten().copied().collect();
                let img = image::Rgba32FImage::from_raw(self.width, self.height, data)
                    .unwrap_or_default();
                image::DynamicImage::ImageRgba32F(img)
                    .save(path)
                    .map_err(io)
            }
            _ => Err(ImageError::Format(path.to_path_buf())),
        }
    }

    /// RGB differences to `other`; `None` when the sizes differ.
    pub fn diff(&self, other: &Self) -> Option<ImageDiff> {
        if (self.width, self.height) != (other.width, other.height) {
            return None;
        }
        let (mut max_abs, mut sum_sq, mut over) = (0.0f64, 0.0f64, 0usize);
        for (a, b) in self.pixels.iter().zip(&other.pixels) {
            let mut pixel_max = 0.0f64;
            for c in 0..3 {
                let d = (a[c] as f64 - b[c] as f64).abs();
                pixel_max = pixel_max.max(d);
                sum_sq += d * d;
            }
            max_abs = max_abs.max(pixel_max);
            over += usize::from(pixel_max > 1.0 / 255.0);
        }
        let n = self.pixels.len().max(1) as f64;
        let rmse = (sum_sq / (3.0 * n)).sqrt();
        Some(ImageDiff {
            max_abs,
            rmse,
            share_over_1_255: over as f64 / n,
            psnr_db: if rmse > 0.0 {
                -20.0 * rmse.log10()
            } else {
                f64::INFINITY
            },
        })
    }

    /// An image of the absolute RGB difference to `other`, amplified by `gain`, on black.
    pub fn difference_image(&self, other: &Self, gain: f32) -> Self {
        Self {
            width: self.width,
            height: self.height,
            pixels: self
                .pixels
                .iter()
                .zip(&other.pixels)
                .map(|(a, b)| {
                    let d = |c: usize| ((a[c] - b[c]).abs() * gain).min(1.0);
                    [d(0), d(1), d(2), 1.0]
                })
                .collect(),
        }
    }

    /// Whether any channel of any pixel is NaN or infinite.
    pub fn has_non_finite(&self) -> bool {
        self.pixels.iter().flatten().any(|c| !c.is_finite())
    }
}

/// Whether an image can be written to `path` as far as can be told before rendering it: a `.png`
/// or `.exr` name in a folder that exists.
pub fn check_output_path(path: &Path) -> Result<(), ImageError> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    if !matches!(ext.as_deref(), Some("png" | "exr")) {
        return Err(ImageError::Format(path.to_path_buf()));
    }
    let folder = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    if !folder.is_dir() {
        return Err(ImageError::NoFolder(folder.to_path_buf()));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn diff_metrics() {
        let a = ImageF32::filled(2, 1, [0.5, 0.5, 0.5, 1.0]);
        let mut b = a.clone();
        b.pixels[1][0] = 0.6;
        let d = a.diff(&b).expect("same size");
        assert!((d.max_abs - 0.1).abs() < 1e-6);
        assert_eq!(d.share_over_1_255, 0.5);
        assert!((d.rmse - (0.01f64 / 6.0).sqrt()).abs() < 1e-6);
        assert_eq!(a.diff(&a).map(|d| d.psnr_db), Some(f64::INFINITY));
        assert!(a.diff(&ImageF32::filled(1, 1, [0.0; 4])).is_none());
    }
}
