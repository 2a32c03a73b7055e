//! Feeds arbitrary bytes to the scene loader as a `.gltf` or `.glb` file. Any panic, overflow,
//! out-of-memory or timeout is a bug: every input must give a scene or a clean error.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;
use streaklight::scene_in::{load_from_bytes, LoadOptions};

fuzz_target!(|data: &[u8]| {
    // No base folder: a buffer URI naming a file is an error, so the fuzzer never reads files.
    // Errors are formatted too: a message (with the scene's names escaped) is part of what the
    // CLI gives for bad input.
    match load_from_bytes(data, None, Path::new("fuzz.gltf"), &LoadOptions::default()) {
        Ok(scene) => {
            std::hint::black_box(scene.warnings);
        }
        Err(e) => {
            std::hint::black_box(e.to_string());
        }
    }
});
