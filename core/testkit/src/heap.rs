//! The Rust heap, counted: [`CountingAllocator`] is the system allocator keeping a process-wide
//! count of the bytes it has handed out and not had back ([`live_bytes`]), and optionally
//! aborting an allocation that grows the heap past a limit ([`limit_growth_from_now`]).
//!
//! A binary opts in by declaring it its global allocator:
//! `#[global_allocator] static A: phantogram_testkit::heap::CountingAllocator = CountingAllocator;`
//! (the memory test counts the engine's heap with it; every fuzz target bounds what one input may
//! take with it). Threads: the counts are atomics, so every thread's allocations count. Never
//! panics; past the limit it writes one line to stderr without allocating and aborts.

use std::alloc::{GlobalAlloc, Layout, System};
use std::io::Write;
use std::sync::atomic::{AtomicUsize, Ordering};

/// Bytes of Rust heap live now.
static LIVE: AtomicUsize = AtomicUsize::new(0);
/// Live bytes when the limit was set.
static AT_LIMIT_START: AtomicUsize = AtomicUsize::new(0);
/// The most the heap may grow from [`AT_LIMIT_START`], bytes; 0: no limit.
static LIMIT: AtomicUsize = AtomicUsize::new(0);

/// Bytes of Rust heap handed out and not given back, over every thread (0 unless
/// [`CountingAllocator`] is the global allocator).
pub fn live_bytes() -> usize {
    LIVE.load(Ordering::Relaxed)
}

/// From now on an allocation that grows the heap by more than `limit_bytes` over what is live
/// now prints "heap limit: this input took N MiB of Rust heap" and aborts the process. 0 lifts
/// the limit.
pub fn limit_growth_from_now(limit_bytes: usize) {
    AT_LIMIT_START.store(LIVE.load(Ordering::Relaxed), Ordering::Relaxed);
    LIMIT.store(limit_bytes, Ordering::Relaxed);
}

/// The system allocator, counting (see the module docs).
pub struct CountingAllocator;

impl CountingAllocator {
    fn grew(size: usize) {
        let live = LIVE.fetch_add(size, Ordering::Relaxed) + size;
        let limit = LIMIT.load(Ordering::Relaxed);
        let took = live.saturating_sub(AT_LIMIT_START.load(Ordering::Relaxed));
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
unsafe impl GlobalAlloc for CountingAllocator {
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
