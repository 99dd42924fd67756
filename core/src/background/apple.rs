//! Apple platforms: the thread's quality of service, "utility" (long-running work the user
//! waits for, below the interactive classes the display link runs at).

pub fn lower_current_thread_priority() {
    // SAFETY: sets the calling thread's own QoS class; plain arguments, no pointers. A refusal
    // (non-zero result) is ignored on purpose.
    unsafe {
        libc::pthread_set_qos_class_self_np(libc::qos_class_t::QOS_CLASS_UTILITY, 0);
    }
}
