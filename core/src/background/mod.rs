//! Background threads yield to the frames: the loaders (`artifact-loader`,
//! `artifact-thumbnails`) lower their own scheduling priority when they start, so that a scan
//! decoding on every core does not stretch the frames drawn meanwhile — on a phone the render
//! thread keeps its vsync, on two desktop cores lavapipe keeps its share (the frame drawn while
//! a Voyager thumb loads took 548 ms against 380 ms alone before this).
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
