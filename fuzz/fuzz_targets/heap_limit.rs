//! The per-input memory limit: every target's Rust heap, counted by its global allocator, may
//! grow by at most 1 GiB (`PHANTOGRAM_FUZZ_HEAP_LIMIT_MB`, default 1024) while one input runs;
//! an allocation past that prints how much the input took and aborts, which libFuzzer reports as
//! a crash and saves the input for.
//!
//! Why not libFuzzer's `-rss_limit_mb` alone: the process's resident memory also holds
//! libFuzzer's own copy of the whole corpus, which for the targets with inputs up to 1 MiB grows
//! to hundreds of megabytes over a long run. A long `gltf` run stopped after 55 min on
//! "out-of-memory (used: 1031Mb)" with 832 MB of corpus in memory, on an input that alone peaks
//! at 172 MB. The issue's
//! bound is on what one input makes the code take, so that is what is counted here; `cargo xtask
//! fuzz` keeps `-rss_limit_mb` as a backstop above the corpus (for memory that is not Rust heap:
//! lavapipe's, the JVM's).
//!
//! Shared by the targets with `#[path]`: including the module installs the counting allocator
//! (`phantogram_testkit::heap`, shared with the engine's memory test) as the target's global one;
//! each target calls [`input_begins`] first thing.
//! Threads: the count is process-wide (atomics), so allocations on the engine's own threads
//! during an input count towards it too.

use phantogram_testkit::heap::CountingAllocator;

#[global_allocator]
static ALLOCATOR: CountingAllocator = CountingAllocator;

/// Marks the start of an input: its growth is counted from the heap as it is now.
pub fn input_begins() {
    // Read once; the allocator itself never reads it (reading the environment allocates).
    static LIMIT_BYTES: std::sync::OnceLock<usize> = std::sync::OnceLock::new();
    let limit = *LIMIT_BYTES.get_or_init(|| {
        let mb = std::env::var("PHANTOGRAM_FUZZ_HEAP_LIMIT_MB")
            .ok()
            .and_then(|v| v.parse::<usize>().ok())
            .filter(|&mb| mb > 0)
            .unwrap_or(1024);
        mb << 20
    });
    phantogram_testkit::heap::limit_growth_from_now(limit);
}
