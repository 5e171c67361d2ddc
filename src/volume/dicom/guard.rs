//! Checks a file's element lengths before dicom-rs reads it. dicom-rs allocates and zeroes each
//! value's declared length before reading it, so a corrupt length (a flipped bit, a cut file)
//! could make a few bytes take up to 4 GiB. Here the meta group is walked by hand (explicit VR
//! little endian, PS3.10 7.1) and the data set by dicom-rs's lazy reader, which reads headers and
//! skips values; any value longer than what is left of the file is refused.

use std::fs::File;
use std::io::{BufReader, Read, Seek, SeekFrom};
use std::path::Path;

use dicom_parser::dataset::LazyDataToken;
use dicom_parser::dataset::lazy_read::LazyDataSetReader;
use dicom_parser::stateful::decode::StatefulDecode;
use dicom_transfer_syntax_registry::{TransferSyntaxIndex, TransferSyntaxRegistry};

/// Most elements walked in one file: a bound on the time a corrupt file can take.
const MAX_ELEMENTS: usize = 1 << 20;

/// VRs whose explicit length is 4 bytes after 2 reserved ones.
const LONG_VRS: [&[u8; 2]; 13] = [
    b"OB", b"OW", b"OF", b"SQ", b"UT", b"UN", b"UC", b"UR", b"OD", b"OL", b"OV", b"SV", b"UV",
];

/// Reads the meta group; returns the transfer syntax UID and where the data set starts: where
/// the group length (0002,0000) says, as dicom-rs takes it, else after the last group-2 element.
fn meta_group(file: &mut impl Read, file_len: u64) -> Result<(String, u64), String> {
    let mut pos = 132u64;
    let mut ts = String::new();
    let mut head = [0u8; 8];
    let mut end: Option<u64> = None;
    loop {
        if let Some(end) = end
            && pos >= end
        {
            return Ok((ts, end));
        }
        if pos + 8 > file_len {
            return Err("the file ends inside its meta information".into());
        }
        file.read_exact(&mut head).map_err(|e| e.to_string())?;
        let group = u16::from_le_bytes([head[0], head[1]]);
        // Within the group length, dicom-rs reads whatever is there: so does this.
        if group != 0x0002 && end.is_none() {
            return Ok((ts, pos));
        }
        let element = u16::from_le_bytes([head[2], head[3]]);
        let vr = [head[4], head[5]];
        let (len, header) = if LONG_VRS.iter().any(|v| **v == vr) {
            let mut l = [0u8; 4];
            file.read_exact(&mut l).map_err(|e| e.to_string())?;
            (u64::from(u32::from_le_bytes(l)), 12)
        } else {
            (u64::from(u16::from_le_bytes([head[6], head[7]])), 8)
        };
        if pos + header + len > file_len {
            return Err(format!(
                "meta element (0002,{element:04X}) claims {len} bytes; the file has {} left",
                file_len.saturating_sub(pos + header)
            ));
        }
        let mut value = vec![0u8; len as usize];
        file.read_exact(&mut value).map_err(|e| e.to_string())?;
        if element == 0x0000 && value.len() == 4 && end.is_none() {
            let group_length = u32::from_le_bytes([value[0], value[1], value[2], value[3]]);
            end = Some(pos + header + len + u64::from(group_length));
        }
        if element == 0x0010 {
            ts = super::tags::trimmed(&String::from_utf8_lossy(&value));
        }
        pos += header + len;
    }
}

/// Checks every value length of the DICOM file at `path` against its size.
pub fn check_lengths(path: &Path) -> Result<(), String> {
    let mut file = BufReader::new(File::open(path).map_err(|e| e.to_string())?);
    let file_len = file.get_ref().metadata().map_err(|e| e.to_string())?.len();
    file.seek(SeekFrom::Start(132)).map_err(|e| e.to_string())?;
    let (uid, start) = meta_group(&mut file, file_len)?;
    let Some(ts) = TransferSyntaxRegistry.get(&uid) else {
        return Err(if uid.is_empty() {
            "the meta information names no transfer syntax".to_string()
        } else {
            format!("the transfer syntax {uid} is not one LeapView reads")
        });
    };
    // A deflated data set may inflate to more than the file: bound it as gzip is bounded.
    file.seek(SeekFrom::Start(start))
        .map_err(|e| e.to_string())?;
    if ts.uid() == DEFLATED {
        // The data set is one raw deflate stream: inflated (at most deflate's ratio times the
        // file), then walked as the explicit VR little endian it holds.
        let most = file_len.saturating_mul(super::super::limits::MAX_DEFLATE_RATIO);
        let mut inflated = Vec::new();
        flate2::read::DeflateDecoder::new(file)
            .take(most)
            .read_to_end(&mut inflated)
            .map_err(|e| format!("the deflated data set is corrupt ({e})"))?;
        let len = inflated.len() as u64;
        let explicit = TransferSyntaxRegistry
            .get("1.2.840.10008.1.2.1")
            .ok_or("no explicit VR little endian")?;
        return walk(std::io::Cursor::new(inflated), explicit, len);
    }
    // Positions are from the start of the file.
    walk(file, ts, file_len)
}

/// The deflated explicit VR little endian transfer syntax.
const DEFLATED: &str = "1.2.840.10008.1.2.1.99";

/// Walks a data set from `source`'s position; values must end by `limit` (a stream position).
fn walk<R: Read + Seek>(
    source: R,
    ts: &dicom_transfer_syntax_registry::TransferSyntax,
    limit: u64,
) -> Result<(), String> {
    let mut reader = LazyDataSetReader::new_with_ts(source, ts).map_err(|e| e.to_string())?;
    let mut walked = 0usize;
    while let Some(token) = reader.advance() {
        walked += 1;
        if walked > MAX_ELEMENTS {
            return Err("more than a million elements: not a file LeapView reads".into());
        }
        let token = token.map_err(|e| format!("cut short or corrupt: {e}"))?;
        let claim = match &token {
            LazyDataToken::LazyValue { header, decoder } => Some((
                header.tag.to_string(),
                u64::from(header.len.0),
                decoder.position(),
            )),
            LazyDataToken::LazyItemValue { len, decoder } => {
                Some(("an item".to_string(), u64::from(*len), decoder.position()))
            }
            _ => None,
        };
        if let Some((what, len, at)) = claim
            && len != u64::from(u32::MAX)
            && at.saturating_add(len) > limit
        {
            return Err(format!(
                "{what} claims {len} bytes; the file has {} left (cut short or corrupt)",
                limit.saturating_sub(at)
            ));
        }
        token.skip().map_err(|e| e.to_string())?;
    }
    Ok(())
}
