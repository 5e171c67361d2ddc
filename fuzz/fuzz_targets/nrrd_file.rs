#![no_main]
//! The NRRD reader (header and data, raw and gzip) on arbitrary bytes.
#[path = "common.rs"]
mod common;

libfuzzer_sys::fuzz_target!(|data: &[u8]| common::load_bytes("f.nrrd", data));
