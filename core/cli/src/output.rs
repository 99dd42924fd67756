//! Standard output for the commands, every write checked (`println!` panics when it cannot write).
//!
//! A closed pipe (`phantogram info LOG | head -c 10`) ends the program quietly with status 0: the
//! reader took what it wanted, as with `head` behind `cat` (Rust ignores `SIGPIPE`, so the write
//! returns `BrokenPipe` instead of killing the process with 141). Any other write error — a full
//! disk, `/dev/full` — is an error: status 1 and a message, never a silent loss.

/// `outln!(…)`: `writeln!` to standard output, with `?` — the enclosing function returns
/// `anyhow::Result`.
macro_rules! outln {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        writeln!(std::io::stdout().lock(), $($arg)*)?
    }};
}
pub(crate) use outln;

/// Whether `error` comes from writing into a pipe whose reader has gone.
pub fn is_broken_pipe(error: &anyhow::Error) -> bool {
    error
        .chain()
        .filter_map(|e| e.downcast_ref::<std::io::Error>())
        .any(|e| e.kind() == std::io::ErrorKind::BrokenPipe)
}

/// Flushes standard output (where `outln!` may have left a partial line).
pub fn flush() -> std::io::Result<()> {
    use std::io::Write as _;
    std::io::stdout().lock().flush()
}
