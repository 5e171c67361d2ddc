//! The NRRD header as text: reads lines up to the first blank line (or the end of a detached
//! header), checks the magic, and collects `field: value` and `key:=value` lines.

use std::collections::HashMap;
use std::io::{BufRead, Read};

use crate::volume::error::VolumeError;

/// A header longer than this is not a header: the file is probably not NRRD at all.
pub const MAX_HEADER_BYTES: u64 = 1 << 20;

/// How the header text ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HeaderEnd {
    /// A blank line; attached data may follow.
    BlankLine,
    /// The end of the file (allowed for detached headers only).
    EndOfFile,
}

/// The header's lines, sorted into fields and key/value pairs.
#[derive(Clone, Debug, Default)]
pub struct HeaderText {
    /// `field: value` lines, with the field name in lower case.
    pub fields: HashMap<String, String>,
    /// `key:=value` lines, keys as written.
    pub key_values: HashMap<String, String>,
}

/// Reads the header from the start of `reader`, leaving it at the first byte after the blank line.
/// Returns the text, how it ended, and the number of bytes it took.
pub(crate) fn read_header_text(
    reader: &mut impl BufRead,
) -> Result<(HeaderText, HeaderEnd, u64), VolumeError> {
    let mut text = HeaderText::default();
    let mut consumed = 0u64;
    let mut line = Vec::new();
    let mut line_number = 0usize;
    loop {
        line.clear();
        // One byte more than the budget, so that an over-long header is noticed.
        let budget = MAX_HEADER_BYTES + 1 - consumed;
        let n = Read::take(&mut *reader, budget).read_until(b'\n', &mut line)?;
        if n == 0 {
            return Ok((text, HeaderEnd::EndOfFile, consumed));
        }
        consumed += n as u64;
        line_number += 1;
        if line_number == 1 {
            check_magic(&line)?;
            continue;
        }
        if consumed > MAX_HEADER_BYTES {
            return Err(bad_header(format!(
                "no blank line ends the header within its first {} bytes",
                MAX_HEADER_BYTES
            )));
        }
        let trimmed = trim_line_end(&line);
        if trimmed.is_empty() {
            return Ok((text, HeaderEnd::BlankLine, consumed));
        }
        // A comment may hold any bytes (a Latin-1 name, say): nothing in it is read.
        if trimmed.starts_with(b"#") {
            continue;
        }
        let Ok(line_text) = std::str::from_utf8(trimmed) else {
            return Err(bad_header(format!(
                "header line {line_number} holds bytes that are not text; a blank line must \
                 separate the header from binary data"
            )));
        };
        parse_line(line_text, line_number, &mut text)?;
        // `data file: LIST`: the rest of a detached header names files, one per line, not
        // fields; the field's reader says the form is not supported.
        let list = ["data file:", "datafile:"].iter().any(|field| {
            line_text
                .strip_prefix(field)
                .is_some_and(|v| v.trim() == "LIST" || v.trim().starts_with("LIST "))
        });
        if list {
            return Ok((text, HeaderEnd::EndOfFile, consumed));
        }
    }
}

/// Accepts `NRRD0001` to `NRRD0005` (and the early `NRRD00.01`).
fn check_magic(line: &[u8]) -> Result<(), VolumeError> {
    let magic = trim_line_end(line);
    let known = matches!(
        magic,
        b"NRRD0001" | b"NRRD0002" | b"NRRD0003" | b"NRRD0004" | b"NRRD0005" | b"NRRD00.01"
    );
    if known {
        Ok(())
    } else if magic.starts_with(b"NRRD") {
        Err(bad_header(format!(
            "unknown format version '{}' (LeapView reads NRRD0001 to NRRD0005)",
            String::from_utf8_lossy(&magic[..magic.len().min(16)])
        )))
    } else {
        Err(bad_header(
            "the file does not start with 'NRRD000x'".to_string(),
        ))
    }
}

fn parse_line(line: &str, line_number: usize, text: &mut HeaderText) -> Result<(), VolumeError> {
    if line.starts_with('#') {
        return Ok(());
    }
    // `key:=value` is checked first: a key may not hold ":=", but a value may hold ": ".
    if let Some((key, value)) = line.split_once(":=") {
        text.key_values.insert(key.to_string(), value.to_string());
        return Ok(());
    }
    if let Some((field, value)) = line.split_once(':') {
        let field = field.trim().to_ascii_lowercase();
        if !field.is_empty() {
            text.fields.insert(field, value.trim().to_string());
            return Ok(());
        }
    }
    let shown: String = line.chars().take(40).collect();
    Err(bad_header(format!(
        "header line {line_number} ('{shown}') is neither 'field: value' nor 'key:=value'"
    )))
}

fn trim_line_end(line: &[u8]) -> &[u8] {
    let line = line.strip_suffix(b"\n").unwrap_or(line);
    line.strip_suffix(b"\r").unwrap_or(line)
}

/// A [`VolumeError::BadHeader`] for NRRD.
pub(crate) fn bad_header(reason: String) -> VolumeError {
    VolumeError::BadHeader {
        format: "NRRD",
        reason,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read(bytes: &[u8]) -> Result<(HeaderText, HeaderEnd, u64), VolumeError> {
        read_header_text(&mut &bytes[..])
    }

    #[test]
    fn fields_key_values_and_comments_are_sorted_out() {
        let bytes = b"NRRD0004\r\n# a comment: not a field\nType: uint8\nsizes: 1 2 3\n\
                      nifti_scl_slope:=2.5\nnote:=a: b\n\r\nDATA";
        let (text, end, consumed) = read(bytes).expect("valid header");
        assert_eq!(end, HeaderEnd::BlankLine);
        assert_eq!(&bytes[consumed as usize..], b"DATA");
        assert_eq!(text.fields["type"], "uint8");
        assert_eq!(text.fields["sizes"], "1 2 3");
        assert_eq!(text.fields.len(), 2);
        assert_eq!(text.key_values["nifti_scl_slope"], "2.5");
        assert_eq!(text.key_values["note"], "a: b");
    }

    #[test]
    fn a_detached_header_may_end_with_the_file() {
        let (_, end, _) = read(b"NRRD0005\ntype: float\n").expect("valid header");
        assert_eq!(end, HeaderEnd::EndOfFile);
    }

    #[test]
    fn garbage_is_refused() {
        for bytes in [
            &b"\x89PNG\r\n\x1a\n"[..],
            b"NRRD0009\n\n",
            b"NRRD0004\ntype: uint8\n\xff\xfe\x00\x01\n\n",
            b"NRRD0004\njust words\n\n",
        ] {
            let r = read(bytes);
            assert!(matches!(r, Err(VolumeError::BadHeader { .. })), "{r:?}");
        }
    }

    #[test]
    fn an_endless_header_is_cut_off() {
        let mut endless =
            std::io::BufReader::new((&b"NRRD0004\n"[..]).chain(std::io::repeat(b'a')));
        let r = read_header_text(&mut endless);
        assert!(matches!(r, Err(VolumeError::BadHeader { .. })), "{r:?}");
    }
}
