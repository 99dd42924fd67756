//! Linux and Android: a thread's nice value is its own (unlike POSIX's process-wide one), set by
//! `setpriority(PRIO_PROCESS, 0, …)` on the calling thread; 10 is Android's
//! `THREAD_PRIORITY_BACKGROUND`.

pub fn lower_current_thread_priority() {
    // SAFETY: `setpriority` takes plain integers and changes only the calling thread's nice
    // value; its result (an error where not permitted) is ignored on purpose.
    unsafe {
        libc::setpriority(libc::PRIO_PROCESS as _, 0, 10);
    }
}
