//! JPEG 2000 (ISO 15444-1), decoded by hayro-jpeg2000: memory-safe Rust, chosen by measurement
//! over openjp2 (a Rust translation of OpenJPEG that broke a non-null precondition on every
//! decode) and OpenJPEG itself (C): on the team's two J2K series, 273 frames of 256², all three
//! gave the same samples, at 4.6, 4.3 and 3.8 ms a frame on this project's CPU machine
//! (`docs/benchmarks/j2k-decoders.md`). The codestream's SIZ segment is read here first and
//! checked against the DICOM header, so no size from a lying stream reaches the decoder; hayro
//! returns unsigned samples, so signed components are shifted back here.

use hayro_jpeg2000::{DecodeSettings, DecoderContext, Image};

use super::{Frame, FrameSpec, StreamShape, check_shape, put_sample};

/// What a codestream's SIZ segment says (ISO 15444-1 A.5.1).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Siz {
    /// Image width and height (reference grid less its offset).
    pub shape: StreamShape,
    /// Per component: signed, precision in bits, horizontal and vertical subsampling.
    pub components: Vec<(bool, u8, u8, u8)>,
}

fn be16(d: &[u8], at: usize) -> Option<u32> {
    Some(u32::from(u16::from_be_bytes([
        *d.get(at)?,
        *d.get(at + 1)?,
    ])))
}

fn be32(d: &[u8], at: usize) -> Option<u32> {
    Some(u32::from_be_bytes([
        *d.get(at)?,
        *d.get(at + 1)?,
        *d.get(at + 2)?,
        *d.get(at + 3)?,
    ]))
}

/// Reads the SIZ segment of a raw codestream (SOC then SIZ) or of the first codestream inside
/// a JP2 file (some writers wrap the stream so).
pub fn read_siz(stream: &[u8]) -> Result<Siz, String> {
    let start = if stream.starts_with(&[0xFF, 0x4F, 0xFF, 0x51]) {
        0
    } else {
        // A JP2 wrapper: the contiguous codestream box (`jp2c`) holds SOC SIZ.
        stream
            .windows(8)
            .position(|w| w == [b'j', b'p', b'2', b'c', 0xFF, 0x4F, 0xFF, 0x51])
            .map(|p| p + 4)
            .ok_or("the stream does not start with a JPEG 2000 codestream (SOC, SIZ)")?
    };
    let siz = &stream[start + 4..];
    let cut = || "the JPEG 2000 SIZ segment is cut short".to_string();
    let [xsiz, ysiz, xo, yo] = [4, 8, 12, 16].map(|at| be32(siz, at).ok_or_else(cut));
    let (xsiz, ysiz, xo, yo) = (xsiz?, ysiz?, xo?, yo?);
    let count = be16(siz, 36).ok_or_else(cut)? as usize;
    if count == 0 || xsiz <= xo || ysiz <= yo {
        return Err(format!(
            "the JPEG 2000 SIZ segment describes no image ({count} components, {xsiz} x {ysiz} \
             from {xo}, {yo})"
        ));
    }
    let components = (0..count)
        .map(|c| {
            let at = 38 + 3 * c;
            let s = *siz.get(at).ok_or_else(cut)?;
            let dx = *siz.get(at + 1).ok_or_else(cut)?;
            let dy = *siz.get(at + 2).ok_or_else(cut)?;
            Ok((s & 0x80 != 0, (s & 0x7F) + 1, dx, dy))
        })
        .collect::<Result<Vec<_>, String>>()?;
    Ok(Siz {
        shape: StreamShape {
            width: xsiz - xo,
            height: ysiz - yo,
            components: count.min(u16::MAX as usize) as u16,
            precision: u16::from(components.iter().map(|c| c.1).max().unwrap_or(0)),
        },
        components,
    })
}

/// Decodes one JPEG 2000 codestream of the frame `spec` describes into little-endian
/// containers (interleaved for colour; a multiple-component transform, YBR_RCT or YBR_ICT, is
/// undone by the decoder, so colour comes out as RGB).
pub(crate) fn decode_frame(stream: &[u8], spec: &FrameSpec) -> Result<Frame, String> {
    let siz = read_siz(stream)?;
    let mut note = check_shape("JPEG 2000", &siz.shape, spec)?;
    if siz.components.iter().any(|c| c.2 != 1 || c.3 != 1) {
        return Err("the JPEG 2000 stream's components are subsampled, which is not read".into());
    }
    let stream_signed = siz.components[0].0;
    if stream_signed != spec.signed {
        note = Some(format!(
            "the JPEG 2000 stream's samples are {} where PixelRepresentation says {}: read as \
             the header says",
            if stream_signed { "signed" } else { "unsigned" },
            if spec.signed { "signed" } else { "unsigned" }
        ));
    }
    let settings = DecodeSettings {
        resolve_palette_indices: false,
        strict: false,
        target_resolution: None,
    };
    let fail = |e: hayro_jpeg2000::DecodeError| format!("JPEG 2000: {e}");
    let image = Image::new(stream, &settings).map_err(fail)?;
    if (image.width(), image.height()) != (spec.columns, spec.rows) {
        return Err(format!(
            "the JPEG 2000 stream holds a {} x {} image; the header says {} x {} \
             (Columns x Rows)",
            image.width(),
            image.height(),
            spec.columns,
            spec.rows
        ));
    }
    let mut context = DecoderContext::default();
    let decoded = image.decode(&mut context).map_err(fail)?;
    let planes = decoded.components();
    let components = usize::from(spec.samples_per_pixel);
    let pixels = spec.pixels();
    if planes.len() < components || planes.iter().any(|p| p.samples().len() < pixels) {
        return Err(format!(
            "the JPEG 2000 stream decodes to {} component{} of {} samples; the frame needs {} of \
             {pixels}",
            planes.len(),
            if planes.len() == 1 { "" } else { "s" },
            planes.first().map_or(0, |p| p.samples().len()),
            components
        ));
    }
    // hayro shifts every component to unsigned (adds 2^(precision-1) to signed ones).
    let offsets: Vec<i64> = siz
        .components
        .iter()
        .map(|&(signed, precision, _, _)| if signed { 1i64 << (precision - 1) } else { 0 })
        .collect();
    let width = spec.bytes_per_sample();
    let mut bytes = vec![0u8; pixels * components * width];
    for (i, cell) in bytes.chunks_exact_mut(width).enumerate() {
        let (p, c) = (i / components, i % components);
        let v = planes[c].samples()[p].round() as i64 - offsets.get(c).copied().unwrap_or(0);
        put_sample(cell, v);
    }
    Ok(Frame { bytes, note })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// SOC, then a SIZ of `width` x `height` with `components` components of `ssiz`.
    fn siz(width: u32, height: u32, components: u16, ssiz: u8) -> Vec<u8> {
        let mut s = vec![0xFF, 0x4F, 0xFF, 0x51];
        s.extend((38 + 3 * components).to_be_bytes());
        s.extend(0u16.to_be_bytes());
        for v in [width, height, 0, 0, width, height, 0, 0] {
            s.extend(v.to_be_bytes());
        }
        s.extend(components.to_be_bytes());
        for _ in 0..components {
            s.extend([ssiz, 1, 1]);
        }
        s
    }

    #[test]
    fn the_siz_segment_gives_size_components_depth_and_sign() {
        let s = read_siz(&siz(512, 256, 1, 0x8F)).expect("SIZ");
        assert_eq!(
            s.shape,
            StreamShape {
                width: 512,
                height: 256,
                components: 1,
                precision: 16
            }
        );
        assert_eq!(s.components, vec![(true, 16, 1, 1)]);
        let mut wrapped = b"\0\0\0\x0cjP  \r\n\x87\n....jp2c".to_vec();
        wrapped.extend(siz(3, 2, 3, 7));
        assert_eq!(read_siz(&wrapped).expect("JP2").shape.components, 3);
    }

    #[test]
    fn a_stream_unlike_its_header_is_refused_before_decoding() {
        let spec = FrameSpec {
            rows: 128,
            columns: 128,
            samples_per_pixel: 1,
            bits_allocated: 8,
            bits_stored: 8,
            signed: false,
            rgb: false,
        };
        let e = decode_frame(&siz(64, 64, 1, 7), &spec).expect_err("size");
        assert!(e.contains("64 x 64") && e.contains("128 x 128"), "{e}");
        let e = decode_frame(&siz(128, 128, 1, 15), &spec).expect_err("depth");
        assert!(e.contains("16-bit") && e.contains("BitsAllocated 8"), "{e}");
        for bad in [
            &[][..],
            &[0xFF, 0x4F, 0xFF, 0x51, 0, 41][..],
            &siz(0, 0, 1, 7)[..],
        ] {
            assert!(read_siz(bad).is_err(), "{bad:?}");
        }
    }
}
