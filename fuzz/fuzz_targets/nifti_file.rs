#![no_main]
//! The NIfTI-1 reader on arbitrary bytes.
#[path = "common.rs"]
mod common;

libfuzzer_sys::fuzz_target!(|data: &[u8]| common::load_bytes("f.nii", data));
