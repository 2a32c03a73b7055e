//! Feeds arbitrary bytes to the photo decoder (PNG, JPEG, TIFF, OpenEXR, Radiance HDR). Any
//! panic, out-of-memory or timeout is a bug: every input must give a photo or a clean error.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;
use streaklight::photo_in::decode;

fuzz_target!(|data: &[u8]| {
    let _ = decode(data, 1.0, Path::new("fuzz.png"));
});
