//! Random call sequences through the C ABI on one engine made at start, guided by coverage. The
//! calls are `ios/tests/support/random_calls.rs`, which the ios crate's own seeded test also runs
//! (so it is compiled and linted with the workspace; only these few lines are not).
#![no_main]

use std::sync::OnceLock;

use libfuzzer_sys::fuzz_target;
use phantogram_ios::ffi::*;

#[path = "physics_panics.rs"]
mod physics_panics;
#[path = "../../ios/tests/support/random_calls.rs"]
mod random_calls;

/// The engine every input drives (creating one opens a GPU device: once per process).
struct Handle(*mut PgEngine);
// SAFETY: the C ABI allows every call but `pg_engine_destroy` from any thread; the handle is
// never destroyed.
unsafe impl Send for Handle {}
// SAFETY: as above: the engine synchronises internally.
unsafe impl Sync for Handle {}

fn engine() -> *const PgEngine {
    static ENGINE: OnceLock<Handle> = OnceLock::new();
    ENGINE
        .get_or_init(|| {
            physics_panics::tolerate();
            let mut engine = std::ptr::null_mut();
            // SAFETY: null config (defaults), valid out pointer.
            let status = unsafe { pg_engine_create(std::ptr::null(), &mut engine) };
            assert_eq!(status, PgStatus::Ok, "no engine: is there a GPU adapter (lavapipe)?");
            Handle(engine)
        })
        .0
}

/// Counts the Rust heap (its own global allocator): one input may not grow it by more than 1 GiB.
#[path = "heap_limit.rs"]
mod heap_limit;

fuzz_target!(|data: &[u8]| {
    heap_limit::input_begins();
    // SAFETY: the engine lives for the whole process.
    unsafe { random_calls::run(engine(), data) }
});
