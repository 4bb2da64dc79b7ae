//! Fuzz target: `obj` input through its shapecue loader (see `src/lib.rs`).
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    shapecue_fuzz::fuzz("obj", data);
});
