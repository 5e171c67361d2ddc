//! Size limits that every loader checks against a header's declared size before it allocates
//! anything, so that a corrupt or hostile header can neither exhaust memory nor make us read on
//! forever.
//!
//! The rule: never allocate more than the file can hold (uncompressed data: the bytes present;
//! gzip: [`MAX_DEFLATE_RATIO`] times the compressed bytes) and never more than the machine's
//! memory holds ([`max_volume_bytes`]).

use super::error::VolumeError;
use super::samples::ScalarType;

/// Cap on the decoded sample bytes of one volume where the machine does not say how much memory
/// it has: 8 GiB.
pub const MAX_VOLUME_BYTES: u64 = 8 << 30;

/// The most decoded sample bytes one volume may take: what this machine's memory holds
/// (`MemTotal`; the GPU takes any size, in bricks of a coarser level where it must), else
/// [`MAX_VOLUME_BYTES`]. Whether the memory is free when the samples are read is asked then.
pub fn max_volume_bytes() -> u64 {
    std::fs::read_to_string("/proc/meminfo")
        .ok()
        .and_then(|text| meminfo_bytes(&text, "MemTotal:"))
        .unwrap_or(MAX_VOLUME_BYTES)
}

/// Hard cap on the number of samples along one axis (GPU 3D textures are far smaller anyway).
pub const MAX_DIMENSION: u32 = 65536;

/// The most a deflate stream can expand: 1032:1. The longest match (258 bytes) costs at least two
/// bits, a 1-bit length code and a 1-bit distance code, so one compressed byte yields at most
/// 4 × 258 = 1032 bytes (zlib's technical details, "maximum compression factor"). Gzip framing
/// only adds compressed bytes, so the bound holds for whole gzip files too.
pub const MAX_DEFLATE_RATIO: u64 = 1032;

/// Asks `progress`'s admission check (if any) whether a volume of `dims` and `scalar_type` (a
/// colour one where `colour`) can be taken, before a sample is read.
pub(crate) fn admit(
    progress: Option<&super::progress::LoadProgress>,
    dims: [u32; 3],
    scalar_type: ScalarType,
    colour: bool,
) -> Result<(), VolumeError> {
    match progress {
        Some(p) => p.admit(super::progress::Shape {
            dims,
            scalar_type,
            colour,
        }),
        None => Ok(()),
    }
}

/// The memory a volume's samples may take by default (`--ram-budget`): half of what the system
/// has available (a volume larger is streamed), else 4 GiB where it does not say.
pub(crate) fn default_ram_budget() -> u64 {
    available_memory_bytes().map_or(4 << 30, |a| a / 2)
}

/// The memory the system can give without swapping (Linux `MemAvailable`), or `None` where it
/// does not say. A loader refuses samples larger than this before reading any.
pub(crate) fn available_memory_bytes() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    meminfo_bytes(&text, "MemAvailable:")
}

/// The value of `field` (`MemAvailable:`, `MemTotal:`) of a `/proc/meminfo` text, in bytes.
fn meminfo_bytes(meminfo: &str, field: &str) -> Option<u64> {
    let line = meminfo.lines().find(|l| l.starts_with(field))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    kib.checked_mul(1024)
}

/// Where the sample bytes come from, as far as bounding their size goes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DataSource {
    /// Uncompressed bytes; this many are present from the start of the samples to the end of the
    /// file.
    Uncompressed {
        /// Bytes available.
        available_bytes: u64,
    },
    /// A gzip stream of this many bytes; `skip_bytes` decompressed bytes precede the samples.
    Gzip {
        /// Size of the compressed data in the file.
        compressed_bytes: u64,
        /// Decompressed bytes skipped before the samples (NRRD `byte skip`).
        skip_bytes: u64,
    },
}

/// Checks declared dimensions against the per-axis cap and the size cap (the machine's memory);
/// returns the dimensions as `u32` and the number of sample bytes they call for.
pub(crate) fn check_dims(
    dims: [u64; 3],
    scalar_type: ScalarType,
) -> Result<([u32; 3], u64), VolumeError> {
    check_dims_within(dims, scalar_type, max_volume_bytes())
}

/// [`check_dims`] with a size cap of `limit_bytes`.
pub(crate) fn check_dims_within(
    dims: [u64; 3],
    scalar_type: ScalarType,
    limit_bytes: u64,
) -> Result<([u32; 3], u64), VolumeError> {
    if dims.iter().any(|&d| d > u64::from(MAX_DIMENSION)) {
        return Err(VolumeError::DimensionTooLarge {
            dims,
            max: MAX_DIMENSION,
        });
    }
    // Each axis fits u32 after the check above.
    let dims32 = dims.map(|d| d as u32);
    if dims.contains(&0) {
        return Err(VolumeError::ZeroDimension { dims: dims32 });
    }
    // At most 65536³ · 8 = 2^51: no overflow.
    let declared_bytes = dims.iter().product::<u64>() * scalar_type.size_bytes() as u64;
    if declared_bytes > limit_bytes {
        return Err(VolumeError::TooLarge {
            dims: dims32,
            scalar_type,
            declared_bytes,
            limit_bytes,
        });
    }
    Ok((dims32, declared_bytes))
}

/// Checks that the data can hold `declared_bytes` of samples at all.
///
/// Uncompressed data shorter than declared fails here, before anything is read; uncompressed data
/// longer than declared is left to the reader, which knows whether trailing bytes are allowed.
pub(crate) fn check_fits(
    dims: [u32; 3],
    scalar_type: ScalarType,
    declared_bytes: u64,
    source: DataSource,
) -> Result<(), VolumeError> {
    match source {
        DataSource::Uncompressed { available_bytes } if available_bytes < declared_bytes => {
            Err(VolumeError::DataTooShort {
                dims,
                scalar_type,
                declared_bytes,
                found_bytes: available_bytes,
            })
        }
        DataSource::Uncompressed { .. } => Ok(()),
        DataSource::Gzip {
            compressed_bytes,
            skip_bytes,
        } => {
            let max_bytes = compressed_bytes.saturating_mul(MAX_DEFLATE_RATIO);
            let needed = declared_bytes.saturating_add(skip_bytes);
            if needed > max_bytes {
                Err(VolumeError::CompressedDataTooSmall {
                    dims,
                    scalar_type,
                    declared_bytes: needed,
                    compressed_bytes,
                    max_bytes,
                })
            } else {
                Ok(())
            }
        }
    }
}

#[cfg(test)] // Only the tests ask.
/// Checks a declared size against every limit: [`check_dims`] then [`check_fits`]. Returns the
/// dimensions as `u32` and the sample bytes, which are then safe to allocate.
fn check_declared_size(
    dims: [u64; 3],
    scalar_type: ScalarType,
    source: DataSource,
) -> Result<([u32; 3], u64), VolumeError> {
    let (dims32, declared_bytes) = check_dims(dims, scalar_type)?;
    check_fits(dims32, scalar_type, declared_bytes, source)?;
    log::debug!(
        "declared {} {scalar_type} samples ({}) fit {source:?}",
        super::error::fmt_dims(&dims32),
        super::error::fmt_bytes(declared_bytes)
    );
    Ok((dims32, declared_bytes))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn available_memory_is_read_from_meminfo() {
        let text = "MemTotal:       24000000 kB\nMemFree:  1000 kB\nMemAvailable:   22000000 kB\n";
        assert_eq!(
            meminfo_bytes(text, "MemAvailable:"),
            Some(22_000_000 * 1024)
        );
        assert_eq!(meminfo_bytes("MemTotal: 5 kB\n", "MemAvailable:"), None);
    }

    const PLENTY: DataSource = DataSource::Uncompressed {
        available_bytes: u64::MAX,
    };

    #[test]
    fn absurd_dimensions_are_refused() {
        let r = check_declared_size([100_000; 3], ScalarType::U8, PLENTY);
        assert!(
            matches!(r, Err(VolumeError::DimensionTooLarge { .. })),
            "{r:?}"
        );
        // 16384² × 4096 bytes = 1 TiB, more than this machine holds, although every axis is
        // allowed.
        let r = check_declared_size([16384, 16384, 4096], ScalarType::U8, PLENTY);
        assert!(matches!(r, Err(VolumeError::TooLarge { .. })), "{r:?}");
        let r = check_declared_size([4, 0, 4], ScalarType::U8, PLENTY);
        assert!(matches!(r, Err(VolumeError::ZeroDimension { .. })), "{r:?}");
    }

    #[test]
    fn the_limit_itself_is_allowed() {
        // 2048 × 2048 × 1024 × 2 bytes = exactly 8 GiB.
        let r = check_dims_within([2048, 2048, 1024], ScalarType::U16, MAX_VOLUME_BYTES);
        assert_eq!(r.ok(), Some(([2048, 2048, 1024], MAX_VOLUME_BYTES)));
        let r = check_dims_within([2048, 2048, 1025], ScalarType::U16, MAX_VOLUME_BYTES);
        assert!(matches!(r, Err(VolumeError::TooLarge { .. })), "{r:?}");
    }

    #[test]
    fn the_cap_is_the_machines_memory() {
        let meminfo = "MemTotal:       24580084 kB\nMemAvailable:   20000000 kB\n";
        assert_eq!(meminfo_bytes(meminfo, "MemTotal:"), Some(24580084 * 1024));
        assert_eq!(
            meminfo_bytes(meminfo, "MemAvailable:"),
            Some(20000000 * 1024)
        );
        assert_eq!(meminfo_bytes("", "MemTotal:"), None);
        // Where /proc/meminfo says (Linux), a volume past 8 GiB passes the header check on a
        // machine with more memory.
        if let Some(total) = meminfo_bytes(
            &std::fs::read_to_string("/proc/meminfo").unwrap_or_default(),
            "MemTotal:",
        ) {
            assert_eq!(max_volume_bytes(), total);
        }
    }

    #[test]
    fn data_must_be_able_to_hold_the_declared_size() {
        let short = DataSource::Uncompressed {
            available_bytes: 63,
        };
        let r = check_declared_size([4; 3], ScalarType::U8, short);
        assert!(matches!(
            r,
            Err(VolumeError::DataTooShort {
                found_bytes: 63,
                ..
            })
        ));
        // 1 compressed byte expands to at most 1032 bytes; 1033 cannot fit, 1032 can.
        let gz = |skip_bytes| DataSource::Gzip {
            compressed_bytes: 1,
            skip_bytes,
        };
        assert!(check_declared_size([1032, 1, 1], ScalarType::U8, gz(0)).is_ok());
        let r = check_declared_size([1033, 1, 1], ScalarType::U8, gz(0));
        assert!(matches!(r, Err(VolumeError::CompressedDataTooSmall { .. })));
        let r = check_declared_size([1032, 1, 1], ScalarType::U8, gz(1));
        assert!(matches!(r, Err(VolumeError::CompressedDataTooSmall { .. })));
    }
}
