//! Sensor callbacks on foreign threads while the render loop runs, with 1000 suspend → resume →
//! resize cycles in between, all through the C ABI (the same `SharedEngine` is behind the JNI
//! bridge). No crash, no error, every cycle accounted for, and no leak.
//!
//! A leak is steady growth, so it is judged on the *median* growth of resident memory over
//! [`INTERVALS`] equal stretches of cycles after a short warm-up: it must stay under
//! [`MAX_LEAK_PER_CYCLE`]. A one-time step does not count, wherever it falls: the touch thread's
//! taps open the menu at some moment that depends on the machine's load, and its first opening
//! draws the gallery's pictures, for which the GPU allocator takes a new block (64 MiB, malloc'd
//! by Mesa's software driver) — on a loaded CI machine that step once fell after the old
//! half-run warm-up and read as a 44 MiB "leak". The whole trace is printed.
//!
//! The targets are offscreen images (no window system in CI): the cycles drop and recreate the
//! target and resize the renderer's per-size buffers each time, exactly as with a window; the
//! window-surface path itself is exercised by the desktop viewer's lifecycle test under Xvfb.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::Instant;

use phantogram_ios::ffi::*;

#[path = "support/engine.rs"]
mod engine;

const CYCLES: usize = 1000;
/// Cycles before resident memory is first read.
const WARM_UP: usize = 100;
/// Stretches of cycles after the warm-up whose growth is measured.
const INTERVALS: usize = 18;
/// The most the median stretch may grow, per cycle: 33 KiB (16 MiB over 500 cycles).
const MAX_LEAK_PER_CYCLE: f64 = 33.0 * 1024.0;
const SIZES: [(u32, u32); 3] = [(54, 120), (108, 240), (72, 160)];

/// The handle, shared by the threads as the C ABI allows (sensor calls from any thread).
#[derive(Clone, Copy)]
struct Handle(*mut PgEngine);
// SAFETY: the C ABI's contract: every function but `pg_engine_destroy` may be called from any
// thread; the engine is destroyed only after all threads are joined.
unsafe impl Send for Handle {}

fn resident_bytes() -> u64 {
    phantogram_testkit::resident_bytes().unwrap_or(0)
}

#[test]
fn foreign_sensor_threads_and_1000_lifecycle_cycles() {
    let Some(engine) = engine::created_or_skip("the stress test") else {
        return;
    };
    let handle = Handle(engine);
    let start = Instant::now();
    let stop = Arc::new(AtomicBool::new(false));
    let pushed = Arc::new(AtomicU64::new(0));
    let refused = Arc::new(AtomicU64::new(0));

    // Three sensor threads (as Core Motion's queues), one touch thread (as the main thread).
    let mut threads = Vec::new();
    for sensor in 0..3 {
        let (stop, pushed, refused) = (stop.clone(), pushed.clone(), refused.clone());
        threads.push(std::thread::spawn(move || {
            let h = handle;
            let mut i = 0u64;
            while !stop.load(Ordering::Relaxed) {
                let t = start.elapsed().as_secs_f64();
                let a = (t * 0.7).sin() * 0.4;
                // Every 97th sample is garbage, as a misbehaving driver would send.
                let x = if i % 97 == 13 { f64::NAN } else { a.sin() };
                // SAFETY: a live handle (destroyed after the join).
                let s = unsafe {
                    match sensor {
                        0 => pg_push_accelerometer(h.0, t, x * 0.1, -a.sin(), -a.cos()),
                        1 => pg_push_gyroscope(h.0, t, 0.28 * (t * 0.7).cos(), 0.0, 0.0),
                        _ => pg_push_magnetometer(h.0, t, 0.0, 20.0 * a.cos() + x, -40.0),
                    }
                };
                match s {
                    PgStatus::Ok => pushed.fetch_add(1, Ordering::Relaxed),
                    PgStatus::Rejected => refused.fetch_add(1, Ordering::Relaxed),
                    other => panic!("sensor push returned {other:?}"),
                };
                i += 1;
                std::thread::sleep(std::time::Duration::from_micros(500));
            }
        }));
    }
    {
        let stop = stop.clone();
        threads.push(std::thread::spawn(move || {
            let h = handle;
            let mut finger = 0;
            while !stop.load(Ordering::Relaxed) {
                let t = start.elapsed().as_secs_f64();
                for phase in [0, 2] {
                    // SAFETY: a live handle; null gesture out pointer is allowed.
                    let s = unsafe { pg_touch(h.0, phase, finger, 20.0, 30.0, t, std::ptr::null_mut()) };
                    assert_eq!(s, PgStatus::Ok);
                }
                finger = (finger + 1) % 3;
                std::thread::sleep(std::time::Duration::from_millis(7));
            }
        }));
    }

    // Resident memory at the end of the warm-up and of each stretch after it.
    let mut rss_trace = Vec::with_capacity(INTERVALS + 1);
    let stretch = (CYCLES - WARM_UP) / INTERVALS;
    let mut presented = 0u8;
    for cycle in 0..CYCLES {
        let (w, h) = SIZES[cycle % SIZES.len()];
        let (w2, h2) = SIZES[(cycle + 1) % SIZES.len()];
        let now = || start.elapsed().as_secs_f64();
        // SAFETY: a live handle and valid out pointers, on this (the render) thread.
        unsafe {
            assert_eq!(pg_resume_offscreen(engine, w, h), PgStatus::Ok);
            assert_eq!(pg_draw(engine, now(), &mut presented), PgStatus::Ok);
            assert_eq!(presented, 1, "cycle {cycle}: the frame after resume was skipped");
            assert_eq!(pg_resize(engine, w2, h2), PgStatus::Ok);
            assert_eq!(pg_draw(engine, now(), &mut presented), PgStatus::Ok);
            assert_eq!(presented, 1, "cycle {cycle}: the frame after resize was skipped");
            let (mut fw, mut fh) = (0, 0);
            assert_eq!(
                pg_read_frame(engine, std::ptr::null_mut(), 0, &mut fw, &mut fh),
                PgStatus::Ok
            );
            assert_eq!((fw, fh), (w2, h2), "cycle {cycle}: the frame has the resized size");
            assert_eq!(pg_suspend(engine), PgStatus::Ok);
            assert_eq!(pg_draw(engine, now(), &mut presented), PgStatus::Ok);
            assert_eq!(presented, 0, "cycle {cycle}: drawing while suspended must skip");
        }
        if cycle + 1 >= WARM_UP && (cycle + 1 - WARM_UP).is_multiple_of(stretch) {
            rss_trace.push(resident_bytes());
        }
    }
    stop.store(true, Ordering::Relaxed);
    for t in threads {
        t.join().expect("a producer thread panicked");
    }
    let mut stats = PgStats::default();
    // SAFETY: a live handle and a valid out pointer.
    assert_eq!(unsafe { pg_stats(engine, &mut stats) }, PgStatus::Ok);
    let elapsed = start.elapsed().as_secs_f64();
    let mut growth_per_cycle: Vec<f64> = rss_trace
        .windows(2)
        .map(|w| (w[1] as f64 - w[0] as f64) / stretch as f64)
        .collect();
    growth_per_cycle.sort_by(f64::total_cmp);
    let median_growth = growth_per_cycle[growth_per_cycle.len() / 2];
    let mib = |b: &u64| format!("{:.1}", *b as f64 / 1048576.0);
    println!(
        "{CYCLES} cycles in {elapsed:.1} s: {} frames drawn, {} skipped; {} sensor samples accepted from 3 threads \
         ({} pushed, {} garbage refused), {} touch gestures; resident memory (MiB) every {stretch} cycles from \
         cycle {WARM_UP}: {}; median growth {:+.2} KiB per cycle",
        stats.frames_drawn,
        stats.frames_skipped,
        stats.sensor_events_accepted,
        pushed.load(Ordering::Relaxed),
        refused.load(Ordering::Relaxed),
        stats.gestures,
        rss_trace.iter().map(mib).collect::<Vec<_>>().join(" "),
        median_growth / 1024.0,
    );
    assert_eq!(stats.resumed, CYCLES as u64);
    assert_eq!(stats.suspended, CYCLES as u64);
    assert_eq!(stats.frames_drawn, 2 * CYCLES as u64);
    assert!(stats.frames_skipped >= CYCLES as u64);
    assert_eq!(stats.sensor_events_accepted, pushed.load(Ordering::Relaxed));
    assert!(refused.load(Ordering::Relaxed) > 0, "the garbage samples were refused");
    assert!(
        pushed.load(Ordering::Relaxed) > 1000,
        "the producers ran alongside the render loop"
    );
    assert_eq!(
        rss_trace.len(),
        INTERVALS + 1,
        "resident memory read after each stretch"
    );
    assert!(
        median_growth < MAX_LEAK_PER_CYCLE,
        "resident memory grew steadily, by {:.1} KiB per cycle in the median stretch: a leak",
        median_growth / 1024.0
    );
    // SAFETY: all other threads are joined; the handle is destroyed once.
    unsafe { pg_engine_destroy(engine) };
}
