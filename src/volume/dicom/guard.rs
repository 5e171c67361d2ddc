//! Checks a file's element lengths before dicom-rs reads it. dicom-rs allocates and zeroes each
//! value's declared length before reading it, so a corrupt length (a flipped bit, a cut file)
//! could make a few bytes take up to 4 GiB.
//!
//! The walk takes the path dicom-rs's own reader takes, with dicom-rs's own parts, so that it
//! sees every length the reader will act on: the meta group as `FileMetaTable::read_from` walks
//! it (its header decoder; elements until the group length is read, the last one whole), then
//! the data set through dicom-rs's eager `DataSetReader`, which announces each element's header
//! before it reads the value. Every length must fit in what is left of the file (or of the
//! inflated data set); the first that does not is refused with its tag.

use std::cell::Cell;
use std::fs::File;
use std::io::{BufReader, Cursor, Read, Seek, SeekFrom};
use std::path::Path;
use std::rc::Rc;

use dicom_core::{Length, Tag};
use dicom_encoding::decode::Decode;
use dicom_encoding::transfer_syntax::Codec;
use dicom_object::meta::FileMetaTable;
use dicom_parser::dataset::read::DataSetReaderOptions;
use dicom_parser::dataset::{DataSetReader, DataToken};
use dicom_transfer_syntax_registry::{TransferSyntax, TransferSyntaxIndex, TransferSyntaxRegistry};

/// Most tokens walked in one file: a bound on the time a corrupt file can take.
const MAX_TOKENS: usize = 1 << 20;

/// Deepest nesting of sequences read. dicom-rs builds a nested sequence by recursion, so a file
/// nesting thousands deep overflows the stack and aborts the process; real objects nest a few
/// levels (enhanced images 3, structured reports rarely past 20).
pub const MAX_NESTING: usize = 64;

/// Where the meta group starts: after the 128-byte preamble (`scan::looks_like_dicom` asks for
/// "DICM" there, so dicom-rs skips it too).
const PREAMBLE: u64 = 128;

/// A reader that counts the bytes it hands out, readable while another owner reads through it.
struct Counted<R> {
    inner: R,
    count: Rc<Cell<u64>>,
}

impl<R: Read> Read for Counted<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        self.count.set(self.count.get() + n as u64);
        Ok(n)
    }
}

/// The transfer syntaxes as dicom-rs knows them, except that those in explicit VR little endian
/// read as implicit VR: for files whose meta information says explicit but whose data set is
/// written implicit (a writer's bug pydicom reads through, as LeapView does: see
/// [`check_lengths`]). Encapsulated pixel data stays encapsulated (LeapView's codecs decode it).
#[derive(Clone, Copy, Debug)]
pub struct ImplicitForExplicit;

/// Implicit VR little endian with encapsulated pixel data: no standard syntax, what some
/// writers produce.
static IMPLICIT_ENCAPSULATED: TransferSyntax = TransferSyntax::new(
    IMPLICIT_VR_LITTLE_ENDIAN,
    "Implicit VR Little Endian, encapsulated pixel data",
    dicom_encoding::transfer_syntax::Endianness::Little,
    false,
    Codec::EncapsulatedPixelData(None, None),
);

impl TransferSyntaxIndex for ImplicitForExplicit {
    fn get(&self, uid: &str) -> Option<&TransferSyntax> {
        let uid = uid.trim_end_matches(['\0', ' ']);
        let ts = TransferSyntaxRegistry.get(uid)?;
        // Every standard syntax but these two is explicit VR little endian.
        if uid == IMPLICIT_VR_LITTLE_ENDIAN || uid == super::header::EXPLICIT_VR_BIG_ENDIAN {
            return Some(ts);
        }
        match ts.codec() {
            Codec::None => TransferSyntaxRegistry.get(IMPLICIT_VR_LITTLE_ENDIAN),
            Codec::EncapsulatedPixelData(..) => Some(&IMPLICIT_ENCAPSULATED),
            // A deflated data set is not read so.
            Codec::Dataset(_) => Some(ts),
        }
    }
}

/// Implicit VR little endian.
const IMPLICIT_VR_LITTLE_ENDIAN: &str = "1.2.840.10008.1.2";

/// How a file's data set is to be read.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Encoding {
    /// As its meta information says.
    AsDeclared,
    /// Implicit VR, though the meta information says explicit VR little endian.
    ImplicitForExplicit,
}

/// Checks every value length and the nesting of the DICOM file at `path` against its size,
/// reading its data set as its meta information says or, where that fails for explicit VR little
/// endian, as implicit VR (which the caller then reads it as). The first failure's reason
/// otherwise.
pub(crate) fn check_lengths(path: &Path) -> Result<Encoding, String> {
    match check_lengths_as(path, Encoding::AsDeclared) {
        Ok(()) => Ok(Encoding::AsDeclared),
        Err(reason) => match check_lengths_as(path, Encoding::ImplicitForExplicit) {
            Ok(()) if declares_explicit_little_endian(path) => Ok(Encoding::ImplicitForExplicit),
            _ => Err(reason),
        },
    }
}

/// Whether the file's meta information names a syntax of explicit VR little endian.
fn declares_explicit_little_endian(path: &Path) -> bool {
    File::open(path)
        .and_then(|mut f| {
            f.seek(SeekFrom::Start(PREAMBLE))?;
            Ok(f)
        })
        .ok()
        .and_then(|f| FileMetaTable::from_reader(BufReader::new(f)).ok())
        .is_some_and(|m| {
            let uid = m.transfer_syntax().trim_end_matches(['\0', ' ']);
            uid != IMPLICIT_VR_LITTLE_ENDIAN
                && uid != super::header::EXPLICIT_VR_BIG_ENDIAN
                && TransferSyntaxRegistry
                    .get(uid)
                    .is_some_and(|ts| !matches!(ts.codec(), Codec::Dataset(_)))
        })
}

/// Checks `path` reading its data set as `encoding` says.
fn check_lengths_as(path: &Path, encoding: Encoding) -> Result<(), String> {
    let mut file = BufReader::new(File::open(path).map_err(|e| e.to_string())?);
    let file_len = file.get_ref().metadata().map_err(|e| e.to_string())?.len();
    file.seek(SeekFrom::Start(PREAMBLE + 4))
        .map_err(|e| e.to_string())?;
    check_meta(&mut file, file_len)?;

    // The meta group is safe to read now: read it with dicom-rs, counting where it ends.
    file.seek(SeekFrom::Start(PREAMBLE))
        .map_err(|e| e.to_string())?;
    let count = Rc::new(Cell::new(PREAMBLE));
    let mut counted = Counted {
        inner: file,
        count: Rc::clone(&count),
    };
    let meta = FileMetaTable::from_reader(&mut counted)
        .map_err(|e| format!("the meta information is unreadable ({e})"))?;
    let start = count.get();
    let uid = meta.transfer_syntax();
    let ts = match encoding {
        Encoding::AsDeclared => TransferSyntaxRegistry.get(uid),
        Encoding::ImplicitForExplicit => ImplicitForExplicit.get(uid),
    };
    let Some(ts) = ts else {
        return Err(if uid.is_empty() {
            "the meta information names no transfer syntax".to_string()
        } else {
            format!("the transfer syntax {uid} is not one LeapView reads")
        });
    };
    match ts.codec() {
        // A deflated data set may inflate to more than the file: at most deflate's ratio
        // times the file is inflated, then walked as dicom-rs walks it.
        Codec::Dataset(Some(adapter)) => {
            let most = file_len.saturating_mul(super::super::limits::MAX_DEFLATE_RATIO);
            let mut inflated = Vec::new();
            adapter
                .adapt_reader(Box::new(counted.inner))
                .take(most.saturating_add(1))
                .read_to_end(&mut inflated)
                .map_err(|e| format!("the deflated data set is corrupt ({e})"))?;
            if inflated.len() as u64 > most {
                return Err(format!(
                    "the deflated data set inflates to more than {most} bytes"
                ));
            }
            let len = inflated.len() as u64;
            walk(Cursor::new(inflated), ts, len)
        }
        Codec::Dataset(None) => Err(format!(
            "the transfer syntax {} ({uid}) is not one LeapView reads",
            ts.name()
        )),
        Codec::None | Codec::EncapsulatedPixelData(..) => {
            walk(counted.inner, ts, file_len.saturating_sub(start))
        }
    }
}

/// Walks the meta group from after "DICM" as dicom-object's `FileMetaTable::read_from` does and
/// checks each length against the file. What that reader refuses without allocating (a first
/// element other than the group length, an undefined length) is left to it.
fn check_meta(file: &mut BufReader<File>, file_len: u64) -> Result<(), String> {
    let decoder = dicom_encoding::decode::file_header_decoder();
    let cut = |e: dicom_encoding::decode::Error| format!("the meta information is cut short ({e})");
    let mut pos = PREAMBLE + 4;
    let (header, n) = decoder.decode_header(file).map_err(cut)?;
    pos += n as u64;
    if header.tag != Tag(0x0002, 0x0000) || header.len != Length(4) {
        return Ok(());
    }
    let mut value = [0u8; 4];
    file.read_exact(&mut value)
        .map_err(|e| format!("the meta information is cut short ({e})"))?;
    pos += 4;
    let group_length = u32::from_le_bytes(value);
    let mut total = 0u32;
    while total < group_length {
        let (header, n) = decoder.decode_header(file).map_err(cut)?;
        let Some(len) = header.len.get() else {
            return Ok(());
        };
        let value_at = pos + n as u64;
        if value_at + u64::from(len) > file_len {
            return Err(format!(
                "meta element {} claims {len} bytes; the file has {} left",
                header.tag,
                file_len.saturating_sub(value_at)
            ));
        }
        file.seek_relative(i64::from(len))
            .map_err(|e| e.to_string())?;
        pos = value_at + u64::from(len);
        total = total.saturating_add(n as u32).saturating_add(len);
    }
    Ok(())
}

/// Walks a data set from `source`'s position with dicom-rs's eager reader; each length it
/// announces (element values, sequences, items and pixel data fragments) must end within
/// `limit` bytes of the start.
fn walk<R: Read>(source: R, ts: &TransferSyntax, limit: u64) -> Result<(), String> {
    let count = Rc::new(Cell::new(0u64));
    let counted = Counted {
        inner: source,
        count: Rc::clone(&count),
    };
    let reader = DataSetReader::new_with_ts_options(counted, ts, DataSetReaderOptions::default())
        .map_err(|e| e.to_string())?;
    let mut depth = 0usize;
    for (walked, token) in reader.enumerate() {
        if walked >= MAX_TOKENS {
            return Err("more than a million elements: not a file LeapView reads".into());
        }
        let token = token.map_err(|e| format!("cut short or corrupt: {e}"))?;
        match &token {
            DataToken::SequenceStart { tag, .. } => {
                depth += 1;
                if depth > MAX_NESTING {
                    return Err(format!(
                        "sequences nest more than {MAX_NESTING} deep (at {tag}): not a file \
                         LeapView reads"
                    ));
                }
            }
            // An encapsulated pixel sequence ends with a sequence end too.
            DataToken::PixelSequenceStart => depth += 1,
            DataToken::SequenceEnd => depth = depth.saturating_sub(1),
            _ => {}
        }
        let claim = match &token {
            DataToken::ElementHeader(header) => Some((header.tag.to_string(), header.len)),
            DataToken::SequenceStart { tag, len } => Some((tag.to_string(), *len)),
            DataToken::ItemStart { len } => Some(("an item".to_string(), *len)),
            _ => None,
        };
        if let Some((what, len)) = claim
            && let Some(len) = len.get()
            && count.get().saturating_add(u64::from(len)) > limit
        {
            return Err(format!(
                "{what} claims {len} bytes; the file has {} left (cut short or corrupt)",
                limit.saturating_sub(count.get())
            ));
        }
    }
    Ok(())
}
