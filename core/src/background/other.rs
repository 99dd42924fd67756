//! Other platforms: left at the default priority.

pub fn lower_current_thread_priority() {}
