//! The NIfTI header, version 1 (348 bytes) or 2 (540 bytes: 64-bit sizes, double precision),
//! read field by field from its documented offsets (`nifti1.h`, `nifti2.h`) in the byte order its
//! size field reveals. Both versions become one [`Header`] of the widest types.

/// The fields LeapView reads, in the widest types of either version.
#[derive(Clone, Debug, PartialEq)]
pub struct Header {
    /// 1 or 2.
    pub version: u8,
    /// Whether the file is big-endian.
    pub big_endian: bool,
    /// `dim`: the number of dimensions, then the size along each.
    pub dim: [i64; 8],
    /// `pixdim`: `qfac`, then the spacing along each dimension.
    pub pixdim: [f64; 8],
    /// `datatype` code.
    pub datatype: i16,
    /// `intent_code`: what the samples mean (1002, `NIFTI_INTENT_LABEL`: a label map).
    pub intent_code: i32,
    /// `bitpix`.
    pub bitpix: i16,
    /// `vox_offset`: where the samples start.
    pub vox_offset: f64,
    /// `scl_slope`.
    pub scl_slope: f64,
    /// `scl_inter`.
    pub scl_inter: f64,
    /// `qform_code`.
    pub qform_code: i32,
    /// `sform_code`.
    pub sform_code: i32,
    /// `quatern_b`, `quatern_c`, `quatern_d`.
    pub quatern: [f64; 3],
    /// `qoffset_x`, `qoffset_y`, `qoffset_z`.
    pub qoffset: [f64; 3],
    /// `srow_x`, `srow_y`, `srow_z`.
    pub srow: [[f64; 4]; 3],
    /// Whether the magic says the samples are in a separate `.img` file (`ni1`, `ni2`).
    pub pair: bool,
}

/// Bytes of a NIfTI-1 header.
pub const NIFTI1_BYTES: usize = 348;
/// Bytes of a NIfTI-2 header.
pub const NIFTI2_BYTES: usize = 540;

/// Little- or big-endian reads at offsets of a header.
struct Fields<'a> {
    bytes: &'a [u8],
    big_endian: bool,
}

impl Fields<'_> {
    fn take<const N: usize>(&self, at: usize) -> [u8; N] {
        let mut b = [0u8; N];
        b.copy_from_slice(&self.bytes[at..at + N]);
        if self.big_endian {
            b.reverse();
        }
        b
    }
    fn i16(&self, at: usize) -> i16 {
        i16::from_le_bytes(self.take(at))
    }
    fn i32(&self, at: usize) -> i32 {
        i32::from_le_bytes(self.take(at))
    }
    fn i64(&self, at: usize) -> i64 {
        i64::from_le_bytes(self.take(at))
    }
    fn f32(&self, at: usize) -> f64 {
        f64::from(f32::from_le_bytes(self.take(at)))
    }
    fn f64(&self, at: usize) -> f64 {
        f64::from_le_bytes(self.take(at))
    }
}

/// The header version and byte order the first four bytes (`sizeof_hdr`) give, or `None`.
pub(crate) fn version_of(first: [u8; 4]) -> Option<(u8, bool)> {
    let (le, be) = (i32::from_le_bytes(first), i32::from_be_bytes(first));
    match (le, be) {
        (348, _) => Some((1, false)),
        (_, 348) => Some((1, true)),
        (540, _) => Some((2, false)),
        (_, 540) => Some((2, true)),
        _ => None,
    }
}

/// Reads a header of `version` in the given byte order from `bytes` (at least its size), or
/// says why the magic is not NIfTI's.
pub fn parse(bytes: &[u8], version: u8, big_endian: bool) -> Result<Header, String> {
    let f = Fields { bytes, big_endian };
    if version == 1 {
        let magic = &bytes[344..348];
        let pair = match magic {
            b"n+1\0" => false,
            b"ni1\0" => true,
            _ => return Err("the header's magic is neither 'n+1' nor 'ni1'".into()),
        };
        Ok(Header {
            version,
            big_endian,
            dim: std::array::from_fn(|i| i64::from(f.i16(40 + 2 * i))),
            pixdim: std::array::from_fn(|i| f.f32(76 + 4 * i)),
            datatype: f.i16(70),
            intent_code: i32::from(f.i16(68)),
            bitpix: f.i16(72),
            vox_offset: f.f32(108),
            scl_slope: f.f32(112),
            scl_inter: f.f32(116),
            qform_code: i32::from(f.i16(252)),
            sform_code: i32::from(f.i16(254)),
            quatern: std::array::from_fn(|i| f.f32(256 + 4 * i)),
            qoffset: std::array::from_fn(|i| f.f32(268 + 4 * i)),
            srow: std::array::from_fn(|r| std::array::from_fn(|c| f.f32(280 + 16 * r + 4 * c))),
            pair,
        })
    } else {
        // "n+2\0" then "\r\n\032\n", which catches files mangled by text-mode transfers.
        let pair = match &bytes[4..12] {
            b"n+2\0\r\n\x1a\n" => false,
            b"ni2\0\r\n\x1a\n" => true,
            _ => {
                return Err(
                    "the header's magic is neither 'n+2' nor 'ni2' (with the bytes \\r\\n\\x1a\\n \
                     after it)"
                        .into(),
                );
            }
        };
        Ok(Header {
            version,
            big_endian,
            dim: std::array::from_fn(|i| f.i64(16 + 8 * i)),
            pixdim: std::array::from_fn(|i| f.f64(104 + 8 * i)),
            datatype: f.i16(12),
            intent_code: f.i32(504),
            bitpix: f.i16(14),
            vox_offset: f.i64(168) as f64,
            scl_slope: f.f64(176),
            scl_inter: f.f64(184),
            qform_code: f.i32(344),
            sform_code: f.i32(348),
            quatern: std::array::from_fn(|i| f.f64(352 + 8 * i)),
            qoffset: std::array::from_fn(|i| f.f64(376 + 8 * i)),
            srow: std::array::from_fn(|r| std::array::from_fn(|c| f.f64(400 + 32 * r + 8 * c))),
            pair,
        })
    }
}

impl Header {
    /// Bytes of this version's header.
    pub fn bytes(&self) -> usize {
        if self.version == 1 {
            NIFTI1_BYTES
        } else {
            NIFTI2_BYTES
        }
    }

    /// The format's name, for messages.
    pub fn format(&self) -> &'static str {
        if self.version == 1 {
            "NIfTI-1"
        } else {
            "NIfTI-2"
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_name_the_version_and_byte_order() {
        assert_eq!(version_of(348i32.to_le_bytes()), Some((1, false)));
        assert_eq!(version_of(348i32.to_be_bytes()), Some((1, true)));
        assert_eq!(version_of(540i32.to_le_bytes()), Some((2, false)));
        assert_eq!(version_of(540i32.to_be_bytes()), Some((2, true)));
        assert_eq!(version_of(352i32.to_le_bytes()), None);
    }

    #[test]
    fn a_nifti2_header_reads_its_64_bit_fields() {
        let mut b = vec![0u8; NIFTI2_BYTES];
        b[0..4].copy_from_slice(&540i32.to_le_bytes());
        b[4..12].copy_from_slice(b"n+2\0\r\n\x1a\n");
        b[12..14].copy_from_slice(&16i16.to_le_bytes());
        for (i, d) in [4i64, 70000, 3, 2, 5, 1, 1, 1].iter().enumerate() {
            b[16 + 8 * i..24 + 8 * i].copy_from_slice(&d.to_le_bytes());
        }
        b[168..176].copy_from_slice(&544i64.to_le_bytes());
        b[176..184].copy_from_slice(&2.5f64.to_le_bytes());
        b[348..352].copy_from_slice(&1i32.to_le_bytes());
        b[400 + 32 + 24..400 + 32 + 32].copy_from_slice(&(-7.25f64).to_le_bytes());
        let h = parse(&b, 2, false).expect("NIfTI-2");
        assert_eq!(h.dim[..5], [4, 70000, 3, 2, 5]);
        assert_eq!(
            (h.datatype, h.vox_offset, h.scl_slope, h.sform_code),
            (16, 544.0, 2.5, 1)
        );
        assert_eq!(h.srow[1][3], -7.25);
        assert!(!h.pair);
        b[4] = b'x';
        assert!(parse(&b, 2, false).is_err());
    }
}
