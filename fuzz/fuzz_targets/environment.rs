//! An environment image (Radiance HDR, OpenEXR, or anything) through `Environment::load`: the
//! EXR guard, the size check from the header and the decoder limits. May fail, never panic or
//! abort.
#![no_main]

#[path = "scratch.rs"]
mod scratch;

use libfuzzer_sys::fuzz_target;
use phantogram_assets::ibl::Environment;

fuzz_target!(|data: &[u8]| {
    let path = scratch::write(scratch::dir("environment"), "environment", data);
    if let Ok(env) = Environment::load(&path) {
        assert!(env.texels.iter().flatten().all(|c| c.is_finite() && *c >= 0.0));
    }
});
