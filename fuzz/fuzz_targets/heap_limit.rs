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
//! Shared by the targets with `#[path]`: including the module installs its allocator as the
//! target's global one; each target calls [`input_begins`] first thing.
//! Threads: the count is process-wide (atomics), so allocations on the engine's own threads
//! during an input count towards it too.

use std::alloc::{GlobalAlloc, Layout, System};
use std::io::Write;
use std::sync::atomic::{AtomicUsize, Ordering};

/// Bytes of Rust heap live now, and when the current input began.
static LIVE: AtomicUsize = AtomicUsize::new(0);
static AT_INPUT_START: AtomicUsize = AtomicUsize::new(0);
/// The limit, bytes; 0 until the first input (libFuzzer's own set-up is not counted).
static LIMIT: AtomicUsize = AtomicUsize::new(0);

/// Marks the start of an input: its growth is counted from the heap as it is now.
pub fn input_begins() {
    if LIMIT.load(Ordering::Relaxed) == 0 {
        // Read here, never in the allocator (reading the environment allocates).
        let mb = std::env::var("PHANTOGRAM_FUZZ_HEAP_LIMIT_MB")
            .ok()
            .and_then(|v| v.parse::<usize>().ok())
            .filter(|&mb| mb > 0)
            .unwrap_or(1024);
        LIMIT.store(mb << 20, Ordering::Relaxed);
    }
    AT_INPUT_START.store(LIVE.load(Ordering::Relaxed), Ordering::Relaxed);
}

/// The system allocator, counting.
struct Counting;

#[global_allocator]
static ALLOCATOR: Counting = Counting;

impl Counting {
    fn grew(size: usize) {
        let live = LIVE.fetch_add(size, Ordering::Relaxed) + size;
        let limit = LIMIT.load(Ordering::Relaxed);
        let took = live.saturating_sub(AT_INPUT_START.load(Ordering::Relaxed));
        if limit > 0 && took > limit {
            // Nothing allocated from here on: the message is put together in a fixed buffer.
            let mut line = [0u8; 128];
            let mut n = 0;
            for part in [
                &b"heap limit: this input took "[..],
                &digits(took >> 20),
                b" MiB of Rust heap\n",
            ] {
                let part = &part[..part.iter().position(|&b| b == 0).unwrap_or(part.len())];
                line[n..n + part.len()].copy_from_slice(part);
                n += part.len();
            }
            let _ = std::io::stderr().write_all(&line[..n]);
            std::process::abort();
        }
    }
}

/// `v` in decimal, padded with zeros (NUL bytes) after the digits.
fn digits(mut v: usize) -> [u8; 20] {
    let mut reversed = [0u8; 20];
    let mut k = 0;
    loop {
        reversed[k] = b'0' + (v % 10) as u8;
        k += 1;
        v /= 10;
        if v == 0 {
            break;
        }
    }
    let mut out = [0u8; 20];
    for (o, d) in out.iter_mut().zip(reversed[..k].iter().rev()) {
        *o = *d;
    }
    out
}

// SAFETY: every call is passed on to the system allocator unchanged; the counting only reads and
// writes atomics and, past the limit, writes to stderr without allocating and aborts.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        // SAFETY: the caller's contract for `alloc`, passed on.
        let p = unsafe { System.alloc(layout) };
        if !p.is_null() {
            Self::grew(layout.size());
        }
        p
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        // SAFETY: the caller's contract for `alloc_zeroed`, passed on.
        let p = unsafe { System.alloc_zeroed(layout) };
        if !p.is_null() {
            Self::grew(layout.size());
        }
        p
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: the caller's contract for `dealloc`, passed on.
        unsafe { System.dealloc(ptr, layout) };
        LIVE.fetch_sub(layout.size(), Ordering::Relaxed);
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        // SAFETY: the caller's contract for `realloc`, passed on.
        let p = unsafe { System.realloc(ptr, layout, new_size) };
        if !p.is_null() {
            if new_size >= layout.size() {
                Self::grew(new_size - layout.size());
            } else {
                LIVE.fetch_sub(layout.size() - new_size, Ordering::Relaxed);
            }
        }
        p
    }
}
