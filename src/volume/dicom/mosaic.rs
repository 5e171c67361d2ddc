//! Siemens mosaics: an MR volume (fMRI, diffusion) stored as one image whose tiles are its
//! slices, `NumberOfImagesInMosaic` of them in a square grid, row by row. Each tile becomes a
//! frame of its own, placed as the standard places a slice: `ImagePositionPatient` of a mosaic
//! is where the top-left pixel of a mosaic-sized image centred on the slice would lie, so the
//! first slice's is moved by half the difference in size (as dcm2niix and nibabel do); slice t
//! lies t slice spacings along the CSA header's `SliceNormalVector` (else the image normal).
//! Pure: the headers in, the tiles' headers out.

use super::header::{FrameHeader, Mosaic};

/// What a mosaic says of itself beyond the image header.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MosaicFacts {
    /// `NumberOfImagesInMosaic`.
    pub images: u32,
    /// The CSA header's `SliceNormalVector` (LPS), where given.
    pub normal: Option<[f64; 3]>,
}

/// The headers of `mosaic`'s tiles (its one frame), each a slice of the volume it holds.
pub(crate) fn tiles(mosaic: &FrameHeader, facts: MosaicFacts) -> Result<Vec<FrameHeader>, String> {
    let images = facts.images;
    if images == 0 || images > 4096 {
        return Err(format!("NumberOfImagesInMosaic is {images}"));
    }
    let per_side = (images as f64).sqrt().ceil() as u32;
    if !mosaic.rows.is_multiple_of(per_side) || !mosaic.columns.is_multiple_of(per_side) {
        return Err(format!(
            "a mosaic of {images} images ({per_side} a side) cannot tile {} x {} pixels",
            mosaic.columns, mosaic.rows
        ));
    }
    let (rows, columns) = (mosaic.rows / per_side, mosaic.columns / per_side);
    let geometry = match (mosaic.orientation, mosaic.position, mosaic.pixel_spacing) {
        (Some(o), Some(p), Some([row_sp, col_sp])) => {
            let r = [o[0], o[1], o[2]];
            let c = [o[3], o[4], o[5]];
            let image_normal = [
                r[1] * c[2] - r[2] * c[1],
                r[2] * c[0] - r[0] * c[2],
                r[0] * c[1] - r[1] * c[0],
            ];
            let normal = facts.normal.unwrap_or(image_normal);
            let step = [mosaic.spacing_between_slices, mosaic.slice_thickness]
                .into_iter()
                .flatten()
                .find(|v| v.is_finite() && *v > 0.0)
                .unwrap_or(1.0);
            let dx = f64::from(mosaic.columns - columns) / 2.0 * col_sp;
            let dy = f64::from(mosaic.rows - rows) / 2.0 * row_sp;
            let first: [f64; 3] = std::array::from_fn(|a| p[a] + r[a] * dx + c[a] * dy);
            Some((first, normal, step))
        }
        _ => None,
    };
    Ok((0..images)
        .map(|t| FrameHeader {
            frame: t,
            label: format!("{} slice {}", mosaic.label, t + 1),
            frames_in_file: images,
            rows,
            columns,
            position: geometry.map(|(first, normal, step)| {
                std::array::from_fn(|a| first[a] + normal[a] * step * f64::from(t))
            }),
            mosaic: Some(Mosaic {
                rows: mosaic.rows,
                columns: mosaic.columns,
                per_side,
            }),
            ..mosaic.clone()
        })
        .collect())
}

/// The frames of a decoded mosaic image (`bytes`, `bytes_per_pixel` a pixel), tile by tile:
/// `images` frames of the tile's size, one after another.
pub fn cut(bytes: &[u8], mosaic: &Mosaic, images: u32, bytes_per_pixel: usize) -> Vec<u8> {
    let per_side = mosaic.per_side as usize;
    let (tile_rows, tile_columns) = (
        mosaic.rows as usize / per_side,
        mosaic.columns as usize / per_side,
    );
    let row_bytes = mosaic.columns as usize * bytes_per_pixel;
    let tile_row_bytes = tile_columns * bytes_per_pixel;
    let mut out = Vec::with_capacity(images as usize * tile_rows * tile_row_bytes);
    for t in 0..images as usize {
        let (ty, tx) = (t / per_side, t % per_side);
        for y in 0..tile_rows {
            let start = (ty * tile_rows + y) * row_bytes + tx * tile_row_bytes;
            if let Some(row) = bytes.get(start..start + tile_row_bytes) {
                out.extend_from_slice(row);
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::volume::dicom::series::tests::frame;

    #[test]
    fn tiles_are_slices_placed_at_their_centres_and_along_the_normal() {
        // A 4 x 3 "mosaic" of 2 x 2... here 8 x 6 pixels holding 4 tiles of 4 x 3.
        let mut m = frame("mosaic", 0, 10.0);
        m.columns = 8;
        m.rows = 6;
        m.spacing_between_slices = Some(3.0);
        let t = tiles(
            &m,
            MosaicFacts {
                images: 4,
                normal: None,
            },
        )
        .expect("tiles");
        assert_eq!(t.len(), 4);
        assert_eq!((t[0].columns, t[0].rows), (4, 3));
        // PixelSpacing 0.5 (rows) \ 0.25 (columns): the first tile's corner is half the size
        // difference in: 2 columns × 0.25 mm along x, 1.5 rows × 0.5 mm along y.
        assert_eq!(t[0].position, Some([-10.0 + 0.5, -20.0 + 0.75, 10.0]));
        assert_eq!(t[3].position, Some([-9.5, -19.25, 19.0]));
        assert_eq!(t[2].frame, 2);
        assert!(
            tiles(
                &m,
                MosaicFacts {
                    images: 5,
                    normal: None
                }
            )
            .is_err()
        );
    }

    #[test]
    fn a_mosaic_is_cut_tile_by_tile_row_by_row() {
        // 4 x 4 pixels, 4 tiles of 2 x 2: pixel value = its index.
        let bytes: Vec<u8> = (0..16).collect();
        let mosaic = Mosaic {
            rows: 4,
            columns: 4,
            per_side: 2,
        };
        assert_eq!(
            cut(&bytes, &mosaic, 4, 1),
            vec![0, 1, 4, 5, 2, 3, 6, 7, 8, 9, 12, 13, 10, 11, 14, 15]
        );
        // Three images in a 2 x 2 grid: the last tile is not read.
        assert_eq!(cut(&bytes, &mosaic, 3, 1).len(), 12);
    }
}
