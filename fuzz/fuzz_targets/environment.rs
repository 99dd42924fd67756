//! An environment image (Radiance HDR, OpenEXR, or anything) through `Environment::load`: the
//! EXR guard, the size check from the header and the decoder limits. May fail, never panic or
//! abort.
#![no_main]

#[path = "scratch.rs"]
mod scratch;

use libfuzzer_sys::fuzz_target;
use phantogram_assets::ibl::Environment;

/// Counts the Rust heap (its own global allocator): one input may not grow it by more than 1 GiB.
#[path = "heap_limit.rs"]
mod heap_limit;

fuzz_target!(|data: &[u8]| {
    heap_limit::input_begins();
    let path = scratch::write(scratch::dir("environment"), "environment", data);
    if let Ok(env) = Environment::load(&path) {
        assert!(env.texels.iter().flatten().all(|c| c.is_finite() && *c >= 0.0));
    }
});
