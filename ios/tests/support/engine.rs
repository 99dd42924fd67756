//! An engine made through the C ABI for the crate's tests, or a skip where there is no GPU
//! adapter — never under CI (`CI` set), which has lavapipe: there a missing adapter fails the
//! test, as `phantogram_integration::engine_or_skip` does for the desktop tests.

use phantogram_ios::ffi::*;

/// `pg_engine_create` with the default configuration; `None` (saying so, with `what` for the
/// test's name) when no GPU adapter is found outside CI.
pub fn created_or_skip(what: &str) -> Option<*mut PgEngine> {
    let mut engine: *mut PgEngine = std::ptr::null_mut();
    // SAFETY: null config (defaults) and a valid out pointer.
    let status = unsafe { pg_engine_create(std::ptr::null(), &mut engine) };
    match status {
        PgStatus::Ok => Some(engine),
        PgStatus::Render if std::env::var_os("CI").is_none() => {
            eprintln!("no GPU adapter: skipping {what}");
            None
        }
        other => panic!("pg_engine_create: {other:?} (CI needs a GPU adapter: lavapipe)"),
    }
}
