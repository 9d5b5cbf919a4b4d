//! Fuzz target: `.glb` bytes through the scene loader, then the render-scene build. The
//! input always starts with a GLB header (magic, version 2, the input's length), so the
//! fuzzer spends its time in the chunk and document parsing rather than on the magic.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    tesela_fuzz_common::check(data, true);
});

#[path = "common.rs"]
mod tesela_fuzz_common;
