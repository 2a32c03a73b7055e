//! Feeds arbitrary bytes to the photo readers as `fit` runs them on a photo's file: its EXIF
//! (`--exposure auto`) and the decoder (PNG, JPEG, TIFF, OpenEXR, Radiance HDR). Any panic,
//! out-of-memory or timeout is a bug: every input must give a result or a clean error.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;
use streaklight::photo_exif::exposure_from_bytes;
use streaklight::photo_in::decode;

fuzz_target!(|data: &[u8]| {
    let path = Path::new("fuzz.png");
    // Errors are formatted too: a message is part of what the CLI gives for bad input.
    if let Err(e) = exposure_from_bytes(data, path) {
        std::hint::black_box(e.to_string());
    }
    match decode(data, 1.0, path) {
        Ok(photo) => {
            std::hint::black_box(photo.warnings);
        }
        Err(e) => {
            std::hint::black_box(e.to_string());
        }
    }
});
