//! Bounded reading of sample bytes into typed storage, shared by every loader: reads exactly the
//! declared number of bytes straight into a vector of the stored type, checks that no more follow
//! (reading at most one byte more), and fixes the byte order.

use std::fs::File;
use std::io::{ErrorKind, Read};
use std::path::Path;

use super::error::VolumeError;
use super::progress::{CHUNK_BYTES, LoadProgress};
use super::{samples::Samples, samples::ScalarType};

/// What the loaders know about the samples before reading them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SampleLayout {
    /// Samples along x, y, z.
    pub dims: [u32; 3],
    /// Stored type.
    pub scalar_type: ScalarType,
    /// Whether multi-byte samples are stored big-endian.
    pub big_endian: bool,
}

impl SampleLayout {
    /// Number of samples.
    pub fn sample_count(&self) -> u64 {
        self.dims.iter().map(|&d| u64::from(d)).product()
    }

    /// Number of bytes the samples take.
    pub(crate) fn byte_len(&self) -> u64 {
        self.sample_count() * self.scalar_type.size_bytes() as u64
    }
}

/// How the bytes handed to [`read_samples_with`] were encoded, for reporting read errors.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Encoding {
    /// Uncompressed bytes straight from a file.
    Raw,
    /// Bytes decompressed from a gzip stream.
    Gzip,
}

/// A stored sample type: plain bytes plus a byte swap.
trait Stored: bytemuck::Pod {
    fn swap_bytes(self) -> Self;
    fn into_samples(values: Vec<Self>) -> Samples;
}

macro_rules! stored_int {
    ($t:ty, $variant:ident) => {
        impl Stored for $t {
            fn swap_bytes(self) -> Self {
                <$t>::swap_bytes(self)
            }
            fn into_samples(values: Vec<Self>) -> Samples {
                Samples::$variant(values)
            }
        }
    };
}

macro_rules! stored_float {
    ($t:ty, $variant:ident) => {
        impl Stored for $t {
            fn swap_bytes(self) -> Self {
                <$t>::from_bits(self.to_bits().swap_bytes())
            }
            fn into_samples(values: Vec<Self>) -> Samples {
                Samples::$variant(values)
            }
        }
    };
}

stored_int!(u8, U8);
stored_int!(i8, I8);
stored_int!(u16, U16);
stored_int!(i16, I16);
stored_int!(u32, U32);
stored_int!(i32, I32);
stored_float!(f32, F32);
stored_float!(f64, F64);

/// Reads the samples of `layout` from `reader`, which must be positioned at the first sample and
/// must end right after the last one.
///
/// The caller has already checked the declared size against [`super::limits`]; this allocates
/// exactly that size (failing cleanly when memory is short), never grows it, and reads at most one
/// byte past it to detect more data than declared.
///
/// With `progress`, reports to it (and stops with [`VolumeError::Cancelled`] when it is
/// cancelled) after each chunk of at most [`CHUNK_BYTES`]; first, `progress`'s admission
/// check is asked whether a volume of this layout can be taken.
pub(crate) fn read_samples_with(
    reader: &mut impl Read,
    layout: SampleLayout,
    encoding: Encoding,
    progress: Option<&LoadProgress>,
) -> Result<Samples, VolumeError> {
    super::limits::admit(progress, layout.dims, layout.scalar_type, false)?;
    match layout.scalar_type {
        ScalarType::U8 => read_typed::<u8>(reader, layout, encoding, progress),
        ScalarType::I8 => read_typed::<i8>(reader, layout, encoding, progress),
        ScalarType::U16 => read_typed::<u16>(reader, layout, encoding, progress),
        ScalarType::I16 => read_typed::<i16>(reader, layout, encoding, progress),
        ScalarType::U32 => read_typed::<u32>(reader, layout, encoding, progress),
        ScalarType::I32 => read_typed::<i32>(reader, layout, encoding, progress),
        ScalarType::F32 => read_typed::<f32>(reader, layout, encoding, progress),
        ScalarType::F64 => read_typed::<f64>(reader, layout, encoding, progress),
    }
}

/// The error of a stream that ended after `found_bytes` of the samples `layout` declares.
fn too_short(layout: SampleLayout, found_bytes: u64) -> VolumeError {
    VolumeError::DataTooShort {
        dims: layout.dims,
        scalar_type: layout.scalar_type,
        declared_bytes: layout.byte_len(),
        found_bytes,
    }
}

/// An empty vector with room for `count` samples, reserved, not touched: memory is taken only as
/// samples arrive, so a stream that stops short (or is cancelled) never held more than it
/// delivered.
fn reserved<T>(count: u64) -> Result<Vec<T>, VolumeError> {
    let out_of_memory = || VolumeError::OutOfMemory {
        bytes: count.saturating_mul(size_of::<T>() as u64),
    };
    let count = usize::try_from(count).map_err(|_| out_of_memory())?;
    let mut values = Vec::new();
    values
        .try_reserve_exact(count)
        .map_err(|_| out_of_memory())?;
    Ok(values)
}

/// Checks that nothing follows the samples, puts them in the machine's byte order and types them.
fn finish<T: Stored>(
    reader: &mut impl Read,
    layout: SampleLayout,
    encoding: Encoding,
    mut values: Vec<T>,
) -> Result<Samples, VolumeError> {
    check_nothing_follows(reader, layout, encoding)?;
    if layout.big_endian != cfg!(target_endian = "big") && size_of::<T>() > 1 {
        values.iter_mut().for_each(|v| *v = v.swap_bytes());
    }
    Ok(T::into_samples(values))
}

fn read_typed<T: Stored>(
    reader: &mut impl Read,
    layout: SampleLayout,
    encoding: Encoding,
    progress: Option<&LoadProgress>,
) -> Result<Samples, VolumeError> {
    let declared_bytes = layout.byte_len();
    if let Some(available) = super::limits::available_memory_bytes()
        && declared_bytes > available
    {
        return Err(VolumeError::NotEnoughMemory {
            bytes: declared_bytes,
            available,
        });
    }
    let stride = progress.map_or(1, LoadProgress::slice_stride);
    if stride > 1 && layout.dims[2] > 1 {
        return read_strided::<T>(reader, layout, encoding, progress, stride);
    }
    let mut values: Vec<T> = reserved(layout.sample_count())?;
    // `reserved` checked that the count fits in memory, so in a usize.
    let count = layout.sample_count() as usize;
    let chunk_len = (CHUNK_BYTES / size_of::<T>()).max(1);
    let mut chunk: Vec<T> = vec![T::zeroed(); chunk_len.min(count)];
    if let Some(p) = progress {
        p.start(declared_bytes);
    }
    let mut read = 0u64;
    while values.len() < count {
        if progress.is_some_and(LoadProgress::is_cancelled) {
            return Err(VolumeError::Cancelled);
        }
        let want = chunk_len.min(count - values.len());
        let bytes: &mut [u8] = bytemuck::cast_slice_mut(&mut chunk[..want]);
        let filled = fill(reader, bytes, encoding).map_err(|e| match e {
            Short(n) => too_short(layout, read + n as u64),
            Failed(e) => e,
        })?;
        debug_assert_eq!(filled, bytes.len());
        read += filled as u64;
        values.extend_from_slice(&chunk[..want]);
        if let Some(p) = progress {
            p.advance(filled as u64);
        }
    }
    finish(reader, layout, encoding, values)
}

/// Every `stride`-th slice of `layout` (the first included), the others read past: at most
/// a slice of them in memory at once.
fn read_strided<T: Stored>(
    reader: &mut impl Read,
    layout: SampleLayout,
    encoding: Encoding,
    progress: Option<&LoadProgress>,
    stride: u32,
) -> Result<Samples, VolumeError> {
    let plane = u64::from(layout.dims[0]) * u64::from(layout.dims[1]);
    let kept = u64::from(layout.dims[2].div_ceil(stride));
    let mut values: Vec<T> = reserved(plane * kept)?;
    let plane_len = usize::try_from(plane).map_err(|_| too_short(layout, 0))?;
    let mut slice: Vec<T> = vec![T::zeroed(); plane_len];
    if let Some(p) = progress {
        p.start(layout.byte_len());
    }
    let mut read = 0u64;
    for z in 0..layout.dims[2] {
        if progress.is_some_and(LoadProgress::is_cancelled) {
            return Err(VolumeError::Cancelled);
        }
        let bytes: &mut [u8] = bytemuck::cast_slice_mut(&mut slice[..]);
        let filled = fill(reader, bytes, encoding).map_err(|e| match e {
            Short(n) => too_short(layout, read + n as u64),
            Failed(e) => e,
        })?;
        read += filled as u64;
        if z % stride == 0 {
            values.extend_from_slice(&slice);
        }
        if let Some(p) = progress {
            p.advance(filled as u64);
        }
    }
    finish(reader, layout, encoding, values)
}

/// Why [`fill`] stopped short.
enum FillError {
    /// The stream ended after this many bytes.
    Short(usize),
    /// The stream failed.
    Failed(VolumeError),
}
use FillError::{Failed, Short};

/// Reads exactly `bytes.len()` bytes.
fn fill(reader: &mut impl Read, bytes: &mut [u8], encoding: Encoding) -> Result<usize, FillError> {
    let mut filled = 0;
    while filled < bytes.len() {
        match reader.read(&mut bytes[filled..]) {
            Ok(0) => return Err(Short(filled)),
            Ok(n) => filled += n,
            Err(e) if e.kind() == ErrorKind::Interrupted => {}
            Err(e) if encoding == Encoding::Gzip && e.kind() == ErrorKind::UnexpectedEof => {
                return Err(Short(filled));
            }
            Err(e) => return Err(Failed(read_error(e, encoding))),
        }
    }
    Ok(filled)
}

/// After the declared samples: the data must end. Gzip data that goes on is decoded to its end
/// (at most [`TRAILING_GZIP_CHECK_BYTES`]) first: a corrupt stream is reported as corrupt, not as
/// a header whose sizes are wrong.
fn check_nothing_follows(
    reader: &mut impl Read,
    layout: SampleLayout,
    encoding: Encoding,
) -> Result<(), VolumeError> {
    let too_long = || VolumeError::DataTooLong {
        dims: layout.dims,
        scalar_type: layout.scalar_type,
        declared_bytes: layout.byte_len(),
        found_bytes: layout.byte_len() + 1,
        exact: false,
    };
    let mut one = [0u8; 1];
    loop {
        match reader.read(&mut one) {
            Ok(0) => return Ok(()),
            Ok(_) => break,
            Err(e) if e.kind() == ErrorKind::Interrupted => {}
            Err(e) => return Err(read_error(e, encoding)),
        }
    }
    if encoding == Encoding::Gzip {
        let mut rest = reader.take(TRAILING_GZIP_CHECK_BYTES);
        if let Err(e) = std::io::copy(&mut rest, &mut std::io::sink()) {
            return Err(read_error(e, encoding));
        }
    }
    Err(too_long())
}

/// How much of the decoded data past the declared samples is decoded to tell a corrupt gzip
/// stream from a header whose sizes are too small.
const TRAILING_GZIP_CHECK_BYTES: u64 = 64 << 20;

/// A read error in the user's terms: a decompressor error means corrupt data.
pub(crate) fn read_error(e: std::io::Error, encoding: Encoding) -> VolumeError {
    match encoding {
        Encoding::Gzip if e.kind() == ErrorKind::UnexpectedEof => VolumeError::CorruptGzip {
            reason: "the stream ends before its end marker; the file may be truncated".into(),
        },
        Encoding::Gzip if matches!(e.kind(), ErrorKind::InvalidInput | ErrorKind::InvalidData) => {
            VolumeError::CorruptGzip {
                reason: e.to_string(),
            }
        }
        _ => VolumeError::Io { source: e },
    }
}

/// Opens a file for reading and returns it with its length, telling a missing file, a folder and
/// an empty file apart from other failures.
pub fn open_file(path: &Path) -> Result<(File, u64), VolumeError> {
    let open_error = |e: std::io::Error| match e.kind() {
        ErrorKind::NotFound => VolumeError::NotFound,
        _ => VolumeError::Io { source: e },
    };
    // Asked before opening: opening a named pipe blocks until someone writes to it.
    let metadata = std::fs::metadata(path).map_err(open_error)?;
    if metadata.is_dir() {
        return Err(VolumeError::IsDirectory);
    }
    if let Some(kind) = special_kind(&metadata) {
        return Err(VolumeError::NotRegularFile { kind });
    }
    let file = File::open(path).map_err(open_error)?;
    let len = file.metadata()?.len();
    if len == 0 {
        return Err(VolumeError::EmptyFile);
    }
    Ok((file, len))
}

/// What a file that is neither a regular file nor a folder is (`None` for those two).
pub(crate) fn special_kind(metadata: &std::fs::Metadata) -> Option<&'static str> {
    let kind = metadata.file_type();
    if kind.is_file() || kind.is_dir() {
        return None;
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if kind.is_fifo() {
            return Some("named pipe");
        }
        if kind.is_char_device() || kind.is_block_device() {
            return Some("device");
        }
        if kind.is_socket() {
            return Some("socket");
        }
    }
    Some("special file")
}

/// Skips `count` bytes of `reader` (decompressed bytes for gzip), reporting a short stream.
pub(crate) fn skip_bytes(
    reader: &mut impl Read,
    count: u64,
    encoding: Encoding,
) -> Result<u64, VolumeError> {
    std::io::copy(&mut reader.take(count), &mut std::io::sink())
        .map_err(|e| read_error(e, encoding))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The samples of `layout` read from raw bytes, without progress.
    fn raw(reader: &mut impl Read, layout: SampleLayout) -> Result<Samples, VolumeError> {
        read_samples_with(reader, layout, Encoding::Raw, None)
    }

    fn layout(n: u32, scalar_type: ScalarType, big_endian: bool) -> SampleLayout {
        SampleLayout {
            dims: [n, 1, 1],
            scalar_type,
            big_endian,
        }
    }

    /// A reader that cancels `progress` once it has handed out `after` bytes.
    struct CancelAfter<'a> {
        data: &'a [u8],
        after: usize,
        given: usize,
        progress: &'a LoadProgress,
    }

    impl Read for CancelAfter<'_> {
        fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
            let n = self.data.read(buf)?;
            self.given += n;
            if self.given >= self.after {
                self.progress.cancel();
            }
            Ok(n)
        }
    }

    #[test]
    fn progress_reaches_the_whole_and_cancel_stops_between_chunks() {
        // Three chunks' worth of bytes.
        let n = 3 * CHUNK_BYTES;
        let data = vec![7u8; n];
        let progress = LoadProgress::default();
        let s = read_samples_with(
            &mut &data[..],
            layout(n as u32, ScalarType::U8, false),
            Encoding::Raw,
            Some(&progress),
        );
        assert!(matches!(s, Ok(Samples::U8(ref v)) if v.len() == n));
        assert_eq!(progress.fraction(), Some(1.0));
        let progress = LoadProgress::default();
        let mut reader = CancelAfter {
            data: &data,
            after: CHUNK_BYTES,
            given: 0,
            progress: &progress,
        };
        let s = read_samples_with(
            &mut reader,
            layout(n as u32, ScalarType::U8, false),
            Encoding::Raw,
            Some(&progress),
        );
        assert!(matches!(s, Err(VolumeError::Cancelled)), "{s:?}");
        // It stopped after the chunk that cancelled, not at the end.
        assert!(reader.given < n, "read {} of {n}", reader.given);
    }

    #[test]
    fn both_byte_orders_decode() {
        let le = [1u8, 2, 3, 4];
        let s = raw(&mut &le[..], layout(2, ScalarType::U16, false));
        assert_eq!(s.ok(), Some(Samples::U16(vec![0x0201, 0x0403])));
        let s = raw(&mut &le[..], layout(2, ScalarType::I16, true));
        assert_eq!(s.ok(), Some(Samples::I16(vec![0x0102, 0x0304])));
        let be = (-1.5f64).to_be_bytes();
        let s = raw(&mut &be[..], layout(1, ScalarType::F64, true));
        assert_eq!(s.ok(), Some(Samples::F64(vec![-1.5])));
    }

    #[test]
    fn short_and_long_data_are_reported() {
        let bytes = [0u8; 7];
        let r = raw(&mut &bytes[..], layout(4, ScalarType::U16, false));
        assert!(
            matches!(r, Err(VolumeError::DataTooShort { found_bytes: 7, .. })),
            "{r:?}"
        );
        let r = raw(&mut &bytes[..], layout(3, ScalarType::U16, false));
        assert!(
            matches!(r, Err(VolumeError::DataTooLong { exact: false, .. })),
            "{r:?}"
        );
    }

    #[test]
    fn at_most_one_byte_past_the_data_is_read() {
        // An endless reader: the read must stop right after the declared bytes plus one.
        let mut endless = std::io::repeat(7).take(u64::MAX);
        let r = raw(&mut endless, layout(5, ScalarType::U8, false));
        assert!(matches!(r, Err(VolumeError::DataTooLong { .. })), "{r:?}");
        assert_eq!(endless.limit(), u64::MAX - 6);
    }
}
