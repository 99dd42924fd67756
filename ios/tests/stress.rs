//! Sensor callbacks on foreign threads while the render loop runs, with 1000 suspend → resume →
//! resize cycles in between, all through the C ABI (the same `SharedEngine` is behind the JNI
//! bridge). No crash, no error, every cycle accounted for, and no leak: resident memory after
//! the last cycle may exceed that after the warm-up's [`WARM_UP`] cycles by at most 16 MiB, i.e.
//! under 33 KiB per cycle; the figures are printed. The warm-up is half the run: the touch
//! thread's taps open the menu at some point, whose one-time work (the gallery's pictures, made
//! on a thread of their own whose allocator arena then stays) must be over before measuring —
//! on a loaded machine it was once not, after 100 cycles.
//!
//! The targets are offscreen images (no window system in CI): the cycles drop and recreate the
//! target and resize the renderer's per-size buffers each time, exactly as with a window; the
//! window-surface path itself is exercised by the desktop viewer's lifecycle test under Xvfb.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::Instant;

use phantogram_ios::ffi::*;

const CYCLES: usize = 1000;
/// Cycles before resident memory is first read.
const WARM_UP: usize = CYCLES / 2;
const SIZES: [(u32, u32); 3] = [(54, 120), (108, 240), (72, 160)];

/// The handle, shared by the threads as the C ABI allows (sensor calls from any thread).
#[derive(Clone, Copy)]
struct Handle(*mut PgEngine);
// SAFETY: the C ABI's contract: every function but `pg_engine_destroy` may be called from any
// thread; the engine is destroyed only after all threads are joined.
unsafe impl Send for Handle {}

fn resident_bytes() -> u64 {
    std::fs::read_to_string("/proc/self/statm")
        .ok()
        .and_then(|s| s.split_whitespace().nth(1)?.parse::<u64>().ok())
        .map_or(0, |pages| pages * 4096)
}

#[test]
fn foreign_sensor_threads_and_1000_lifecycle_cycles() {
    let mut engine: *mut PgEngine = std::ptr::null_mut();
    // SAFETY: null config (defaults) and a valid out pointer.
    let status = unsafe { pg_engine_create(std::ptr::null(), &mut engine) };
    if status == PgStatus::Render {
        eprintln!("no GPU adapter: skipping the stress test");
        return;
    }
    assert_eq!(status, PgStatus::Ok);
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

    let mut rss_after_warm_up = 0;
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
        if cycle + 1 == WARM_UP {
            rss_after_warm_up = resident_bytes();
        }
    }
    let rss_end = resident_bytes();
    stop.store(true, Ordering::Relaxed);
    for t in threads {
        t.join().expect("a producer thread panicked");
    }
    let mut stats = PgStats::default();
    // SAFETY: a live handle and a valid out pointer.
    assert_eq!(unsafe { pg_stats(engine, &mut stats) }, PgStatus::Ok);
    let elapsed = start.elapsed().as_secs_f64();
    let growth = rss_end as i64 - rss_after_warm_up as i64;
    println!(
        "{CYCLES} cycles in {elapsed:.1} s: {} frames drawn, {} skipped; {} sensor samples accepted from 3 threads \
         ({} pushed, {} garbage refused), {} touch gestures; resident memory {:.1} MiB after cycle {WARM_UP}, {:.1} MiB \
         after {CYCLES} ({:+.1} KiB per cycle)",
        stats.frames_drawn,
        stats.frames_skipped,
        stats.sensor_events_accepted,
        pushed.load(Ordering::Relaxed),
        refused.load(Ordering::Relaxed),
        stats.gestures,
        rss_after_warm_up as f64 / 1048576.0,
        rss_end as f64 / 1048576.0,
        growth as f64 / 1024.0 / (CYCLES - WARM_UP) as f64,
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
    assert!(
        growth < 16 << 20,
        "resident memory grew by {:.1} MiB over {} cycles: a leak",
        growth as f64 / 1048576.0,
        CYCLES - WARM_UP
    );
    // SAFETY: all other threads are joined; the handle is destroyed once.
    unsafe { pg_engine_destroy(engine) };
}
