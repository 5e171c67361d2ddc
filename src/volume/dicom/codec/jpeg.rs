//! JPEG, every process DICOM uses: baseline (8-bit), extended (12-bit: CT archives hold it, and
//! dicom-rs's decoder reads 8 bits only) and lossless (2 to 16 bits, processes 14 and SV1), grey
//! or colour. Decoded by libjpeg-turbo 3 (built from the sources bundled with turbojpeg-sys), the
//! library most DICOM toolkits use, after the frame header has been checked against the DICOM
//! header ([`super::markers`]). Colour comes out as RGB: libjpeg-turbo undoes the YCbCr transform
//! where the stream's markers say it was applied.

use std::ffi::CStr;
use std::os::raw::c_int;

use turbojpeg_sys as tj;

use super::{Frame, FrameSpec, check_shape, markers, put_sample};

/// Most memory libjpeg-turbo may take for one frame's decoder state, in MiB.
const MAX_MEMORY_MIB: c_int = 512;

/// A libjpeg-turbo decompressor, destroyed when dropped.
struct Decompressor(tj::tjhandle);

impl Decompressor {
    fn new() -> Result<Self, String> {
        // SAFETY: tj3Init has no preconditions; a null handle is checked.
        let handle = unsafe { tj::tj3Init(tj::TJINIT_TJINIT_DECOMPRESS as c_int) };
        if handle.is_null() {
            return Err("libjpeg-turbo could not start".into());
        }
        Ok(Self(handle))
    }

    fn set(&self, param: tj::TJPARAM, value: c_int) -> Result<(), String> {
        // SAFETY: the handle is live (owned by self).
        let rc = unsafe { tj::tj3Set(self.0, param as c_int, value) };
        if rc == 0 { Ok(()) } else { Err(self.error()) }
    }

    fn get(&self, param: tj::TJPARAM) -> c_int {
        // SAFETY: the handle is live.
        unsafe { tj::tj3Get(self.0, param as c_int) }
    }

    /// libjpeg-turbo's last message for this handle.
    fn error(&self) -> String {
        // SAFETY: the handle is live; tj3GetErrorStr returns a NUL-terminated string that lives
        // as long as the handle (copied out at once).
        unsafe {
            let text = tj::tj3GetErrorStr(self.0);
            if text.is_null() {
                "libjpeg-turbo failed".to_string()
            } else {
                CStr::from_ptr(text).to_string_lossy().into_owned()
            }
        }
    }
}

impl Drop for Decompressor {
    fn drop(&mut self) {
        // SAFETY: the handle is live and dropped once.
        unsafe { tj::tj3Destroy(self.0) };
    }
}

/// Decodes one JPEG codestream of the frame `spec` describes into little-endian containers
/// (interleaved RGB for colour).
pub(crate) fn decode_frame(stream: &[u8], spec: &FrameSpec) -> Result<Frame, String> {
    let header = markers::read_header(stream)?;
    if header.sof == 0xF7 {
        return Err("the stream is JPEG-LS, not the JPEG its transfer syntax names".into());
    }
    let note = check_shape("JPEG", &header.shape, spec)?;
    // A colour stream with no JFIF or Adobe segment leaves the decoder to guess whether it
    // holds YCbCr; where the DICOM header says RGB, an Adobe segment saying "no transform"
    // makes libjpeg-turbo read it so (as pydicom's decoders are told).
    let marked;
    let stream = if spec.rgb && header.shape.components == 3 && !header.colour_marked {
        marked = with_adobe_rgb_marker(stream);
        &marked[..]
    } else {
        stream
    };
    let precision = header.shape.precision;
    if !header.lossless() && !matches!(precision, 8 | 12) {
        return Err(format!(
            "a lossy JPEG stream of {precision}-bit precision (JPEG's DCT processes take 8 or 12)"
        ));
    }
    let format = match spec.samples_per_pixel {
        1 => tj::TJPF_TJPF_GRAY,
        3 => tj::TJPF_TJPF_RGB,
        n => return Err(format!("JPEG frames of {n} samples per pixel are not read")),
    };
    let d = Decompressor::new()?;
    // A corrupt or cut-short stream is an error, not a grey-filled picture.
    d.set(tj::TJPARAM_TJPARAM_STOPONWARNING, 1)?;
    d.set(tj::TJPARAM_TJPARAM_MAXMEMORY, MAX_MEMORY_MIB)?;
    d.set(
        tj::TJPARAM_TJPARAM_MAXPIXELS,
        c_int::try_from(spec.pixels())
            .map_err(|_| "the frame is too large for the JPEG decoder")?,
    )?;
    // SAFETY: the pointer and length describe `stream`, which outlives the call.
    let rc = unsafe { tj::tj3DecompressHeader(d.0, stream.as_ptr(), stream.len() as u64) };
    if rc != 0 {
        return Err(d.error());
    }
    let (width, height) = (
        d.get(tj::TJPARAM_TJPARAM_JPEGWIDTH),
        d.get(tj::TJPARAM_TJPARAM_JPEGHEIGHT),
    );
    if i64::from(width) != i64::from(spec.columns) || i64::from(height) != i64::from(spec.rows) {
        return Err(format!(
            "the JPEG stream holds a {width} x {height} image; the header says {} x {} \
             (Columns x Rows)",
            spec.columns, spec.rows
        ));
    }
    let samples = spec.pixels() * usize::from(spec.samples_per_pixel);
    // tj3Decompress8, 12 or 16 by the stream's precision, into cells of that width.
    macro_rules! decompress {
        ($function:ident, $cell:ty) => {{
            let mut out: Vec<$cell> = vec![0; samples];
            // SAFETY: `out` holds width x height pixels of `format` (pitch 0: packed rows) in
            // the function's cell type, which is what it writes; `stream` outlives the call.
            let rc = unsafe {
                tj::$function(
                    d.0,
                    stream.as_ptr(),
                    stream.len() as u64,
                    out.as_mut_ptr(),
                    0,
                    format as c_int,
                )
            };
            if rc != 0 {
                return Err(d.error());
            }
            out
        }};
    }
    let values: Vec<i64> = if precision <= 8 {
        decompress!(tj3Decompress8, u8)
            .into_iter()
            .map(i64::from)
            .collect()
    } else if precision <= 12 {
        // 12-bit samples in 16-bit signed cells.
        decompress!(tj3Decompress12, i16)
            .into_iter()
            .map(|v| i64::from(v as u16 & 0x0FFF))
            .collect()
    } else {
        decompress!(tj3Decompress16, u16)
            .into_iter()
            .map(i64::from)
            .collect()
    };
    let width = spec.bytes_per_sample();
    let mut bytes = vec![0u8; samples * width];
    for (cell, v) in bytes.chunks_exact_mut(width).zip(values) {
        put_sample(cell, v);
    }
    Ok(Frame { bytes, note })
}

/// `stream` with an Adobe APP14 segment of colour transform 0 (none: the components are RGB)
/// after its start-of-image marker.
fn with_adobe_rgb_marker(stream: &[u8]) -> Vec<u8> {
    const ADOBE_RGB: [u8; 16] = [
        0xFF, 0xEE, 0x00, 0x0E, b'A', b'd', b'o', b'b', b'e', 0x00, 0x64, 0x00, 0x00, 0x00, 0x00,
        0x00,
    ];
    let mut out = Vec::with_capacity(stream.len() + ADOBE_RGB.len());
    out.extend_from_slice(&stream[..2]);
    out.extend_from_slice(&ADOBE_RGB);
    out.extend_from_slice(&stream[2..]);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn what_is_not_a_jpeg_stream_is_an_error() {
        let spec = FrameSpec {
            rows: 8,
            columns: 8,
            samples_per_pixel: 1,
            bits_allocated: 16,
            bits_stored: 12,
            signed: false,
            rgb: false,
        };
        for stream in [&[][..], &[0xFF, 0xD8][..], &[0u8; 64][..]] {
            assert!(decode_frame(stream, &spec).is_err());
        }
    }
}
