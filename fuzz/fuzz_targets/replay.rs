//! A sensor log replayed through a session at 10 ms frames, as `phantogram replay` does:
//! whatever the time stamps and values, the replay ends (a handful of frames per minute of
//! recording: longer gaps are skipped) and nothing panics.
#![no_main]

use libfuzzer_sys::fuzz_target;
use phantogram_lab::replay::{Pace, replay};
use phantogram_lab::sensorlog::LogReader;
use phantogram_sensing::{Session, SessionConfig};

/// Counts the Rust heap (its own global allocator): one input may not grow it by more than 1 GiB.
#[path = "heap_limit.rs"]
mod heap_limit;

fuzz_target!(|data: &[u8]| {
    heap_limit::input_begins();
    let Ok(reader) = LogReader::from_reader(std::path::Path::new("fuzz.pglog"), std::io::Cursor::new(data.to_vec()))
    else {
        return;
    };
    let Ok(mut session) = Session::new(SessionConfig::default()) else {
        return;
    };
    let mut frames = 0u64;
    let _ = replay(
        reader,
        &mut session,
        10_000_000,
        Pace::AsFastAsPossible,
        |_, _, view| {
            frames += 1;
            // Frames are finite whatever the input.
            assert!(view.eyes.cyclopean_m.is_finite(), "non-finite eye at frame {frames}");
        },
    );
});
