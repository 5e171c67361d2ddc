//! 12-bit JPEG (DCT, processes 2 and 4: "JPEG Extended", 1.2.840.10008.1.2.4.51), which CT
//! archives hold and dicom-rs's JPEG decoder (jpeg-decoder, 8-bit precision only) cannot read.
//! Decoded by libjpeg-turbo 3 (built from the sources bundled with turbojpeg-sys), the library
//! most DICOM toolkits use for it; bounded to the frame the header declares.

use std::ffi::CStr;
use std::os::raw::c_int;

use turbojpeg_sys as tj;

/// The JPEG Extended transfer syntax.
pub const JPEG_EXTENDED: &str = "1.2.840.10008.1.2.4.51";

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

/// Decodes one 12-bit grey JPEG codestream of `columns` x `rows` into 16-bit little-endian
/// samples (the 12 stored bits, as dicom-rs hands other codecs' output).
pub fn decode_frame(stream: &[u8], columns: u32, rows: u32) -> Result<Vec<u8>, String> {
    let d = Decompressor::new()?;
    // A corrupt or cut-short stream is an error, not a grey-filled picture.
    d.set(tj::TJPARAM_TJPARAM_STOPONWARNING, 1)?;
    d.set(tj::TJPARAM_TJPARAM_MAXMEMORY, MAX_MEMORY_MIB)?;
    let pixels = u64::from(columns) * u64::from(rows);
    d.set(
        tj::TJPARAM_TJPARAM_MAXPIXELS,
        c_int::try_from(pixels).map_err(|_| "the frame is too large for the JPEG decoder")?,
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
    if i64::from(width) != i64::from(columns) || i64::from(height) != i64::from(rows) {
        return Err(format!(
            "the JPEG stream is {width} x {height}; the header says {columns} x {rows}"
        ));
    }
    let precision = d.get(tj::TJPARAM_TJPARAM_PRECISION);
    if precision != 12 {
        return Err(format!(
            "the JPEG stream has {precision}-bit precision; 12 was expected"
        ));
    }
    let mut samples = vec![0i16; pixels as usize];
    // SAFETY: `samples` holds width x height samples of one grey channel (pitch = width
    // samples), which is what tj3Decompress12 writes for TJPF_GRAY; `stream` outlives the call.
    let rc = unsafe {
        tj::tj3Decompress12(
            d.0,
            stream.as_ptr(),
            stream.len() as u64,
            samples.as_mut_ptr(),
            width,
            tj::TJPF_TJPF_GRAY as c_int,
        )
    };
    if rc != 0 {
        return Err(d.error());
    }
    Ok(samples
        .iter()
        .flat_map(|s| (*s as u16 & 0x0FFF).to_le_bytes())
        .collect())
}

/// The codestream of each frame: one fragment per frame, or every fragment for a single frame.
pub fn frame_streams(fragments: &[Vec<u8>], frames: u32) -> Result<Vec<Vec<u8>>, String> {
    if frames == 1 {
        return Ok(vec![fragments.concat()]);
    }
    if fragments.len() == frames as usize {
        return Ok(fragments.to_vec());
    }
    Err(format!(
        "{} JPEG fragments for {frames} frames: a frame split over fragments is not read",
        fragments.len()
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fragments_map_to_frames_one_each_or_all_for_one_frame() {
        let f = vec![vec![1u8, 2], vec![3u8]];
        assert_eq!(
            frame_streams(&f, 1).expect("one frame"),
            vec![vec![1, 2, 3]]
        );
        assert_eq!(frame_streams(&f, 2).expect("two frames"), f);
        let e = frame_streams(&f, 3).expect_err("three frames in two fragments");
        assert!(e.contains("2 JPEG fragments for 3 frames"), "{e}");
    }

    #[test]
    fn what_is_not_a_jpeg_stream_is_an_error() {
        for stream in [&[][..], &[0xFF, 0xD8][..], &[0u8; 64][..]] {
            assert!(decode_frame(stream, 8, 8).is_err());
        }
    }
}
