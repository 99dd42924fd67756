//! Background threads yield to the frames: the loaders (`artifact-loader`,
//! `artifact-thumbnails`) lower their own scheduling priority when they start, so that a scan
//! decoding on every core does not stretch the frames drawn meanwhile — on a phone the render
//! thread keeps its vsync, on two desktop cores lavapipe keeps its share (the frame drawn while
//! a Voyager thumb loads took 548 ms against 380 ms alone before this).
//!
//! Their data-parallel work (`phantogram_assets::parallel::map`: decoding images, building mip
//! chains, simplifying levels) runs on a pool of its own whose threads lower their priority the
//! same way ([`in_background_pool`]); on rayon's global pool it would run at the priority of
//! whichever thread happened to start that pool first (a thread inherits its creator's).
//!
//! One file per platform: Linux and Android (`setpriority` on the calling thread, nice 10, as
//! Android's `THREAD_PRIORITY_BACKGROUND`), Apple (the "utility" quality of service), and a
//! no-op elsewhere. Failing to lower it is harmless and ignored. **Panics**: none.

#[cfg(any(target_os = "linux", target_os = "android"))]
#[path = "linux.rs"]
mod platform;

#[cfg(any(target_os = "ios", target_os = "macos"))]
#[path = "apple.rs"]
mod platform;

#[cfg(not(any(target_os = "linux", target_os = "android", target_os = "ios", target_os = "macos")))]
#[path = "other.rs"]
mod platform;

/// Lowers the calling thread's scheduling priority to that of background work.
pub fn lower_current_thread_priority() {
    platform::lower_current_thread_priority();
}

/// Runs `f` on the background pool: `f` and the data-parallel work it starts run on threads of
/// background priority, one per core, started on first use and kept for the process. Where that
/// pool cannot be made (no threads), `f` runs here. Panics in `f` reach the caller.
pub fn in_background_pool<R: Send>(f: impl FnOnce() -> R + Send) -> R {
    static POOL: std::sync::OnceLock<Option<rayon::ThreadPool>> = std::sync::OnceLock::new();
    let pool = POOL.get_or_init(|| {
        rayon::ThreadPoolBuilder::new()
            .thread_name(|i| format!("background-{i}"))
            .start_handler(|_| lower_current_thread_priority())
            .build()
            .ok()
    });
    match pool {
        Some(pool) => pool.install(f),
        None => f(),
    }
}

#[cfg(all(test, target_os = "linux"))]
mod tests {
    /// The calling thread's nice value.
    fn nice() -> i32 {
        // SAFETY: `getpriority` takes plain integers and only reads the calling thread's nice
        // value (Linux: per thread with `PRIO_PROCESS, 0`).
        unsafe { libc::getpriority(libc::PRIO_PROCESS as _, 0) }
    }

    #[test]
    fn the_background_pools_parallel_work_runs_at_background_priority() {
        let items: Vec<u32> = (0..64).collect();
        // Slow enough items that the pool's other threads take some of them.
        let work = |_: &u32| {
            std::thread::sleep(std::time::Duration::from_millis(2));
            (nice(), std::thread::current().name().map(str::to_owned))
        };
        let seen = super::in_background_pool(|| phantogram_assets::parallel::map(&items, work));
        for (nice, name) in &seen {
            assert!(*nice >= 10, "item on {name:?} ran at nice {nice}");
            assert!(
                name.as_deref().is_some_and(|n| n.starts_with("background-")),
                "{name:?}"
            );
        }
        // This (test) thread was not lowered by it.
        assert!(nice() < 10);
    }
}
