//! Fuzz target: `.gltf` JSON bytes through the scene loader, then the render-scene build.
//! External files are refused (no base directory), so only data URIs and the bytes count.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    tesela_fuzz_common::check(data, false);
});

#[path = "common.rs"]
mod tesela_fuzz_common;
