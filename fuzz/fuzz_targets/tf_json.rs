#![no_main]
//! The transfer-function JSON parser and validation, then baking the lookup table of what
//! passed.
use leapview::transfer::TransferFunction;
use leapview::volume::ValueRange;

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(tf) = TransferFunction::from_json_str(text) {
        let range = ValueRange {
            min: -1000.0,
            max: 3000.0,
        };
        let lut = leapview::transfer::lut::bake(&tf, range, 0.5);
        assert!(
            lut.iter().flatten().all(|v| v.is_finite()),
            "non-finite LUT entry"
        );
    }
});
