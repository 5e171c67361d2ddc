#![no_main]
//! The MetaImage header parser on arbitrary text, and the reader on arbitrary bytes.
#[path = "common.rs"]
mod common;

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        let _ = leapview::volume::metaimage::parse_header(text);
    }
    common::load_bytes("f.mha", data);
});
