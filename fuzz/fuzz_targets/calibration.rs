//! The calibration file: parsed from any text, and loaded from any bytes (the loader never
//! fails: a damaged file gives the defaults and a warning).
#![no_main]

#[path = "scratch.rs"]
mod scratch;

use libfuzzer_sys::fuzz_target;
use phantogram_sensing::calibration::Calibration;

/// Counts the Rust heap (its own global allocator): one input may not grow it by more than 1 GiB.
#[path = "heap_limit.rs"]
mod heap_limit;

fuzz_target!(|data: &[u8]| {
    heap_limit::input_begins();
    if let Ok(text) = std::str::from_utf8(data)
        && let Ok(c) = Calibration::from_text(text)
    {
        // What parses is written back in a form that parses.
        assert!(Calibration::from_text(&c.to_text()).is_ok(), "{c:?}");
    }
    let path = scratch::write(scratch::dir("calibration"), "calibration.txt", data);
    let (_, _warning) = Calibration::load(&path);
});
