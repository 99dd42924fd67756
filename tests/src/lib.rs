//! Helpers shared by the integration tests in `tests/tests/`.
//!
//! External recordings live outside the repository; tests find them through the environment
//! variable [`DATA_ENV`] (`.ci/run` sets it to `../shared/data`). Without it, the tests that need
//! them print a notice and pass vacuously *only* when the variable is unset; when it is set but
//! wrong, they fail.

use std::path::{Path, PathBuf};

/// Environment variable naming the external data folder.
pub const DATA_ENV: &str = "PHANTOGRAM_DATA";

/// The external data folder, if configured. Panics (failing the test) if the variable is set but
/// does not name a folder, so a misconfigured CI cannot silently skip.
pub fn data_dir() -> Option<PathBuf> {
    let dir = PathBuf::from(std::env::var_os(DATA_ENV)?);
    assert!(dir.is_dir(), "{DATA_ENV}={} is not a folder", dir.display());
    Some(dir)
}

/// `$PHANTOGRAM_DATA/name`, or `None` after printing that the tests needing it are skipped.
pub fn data_subdir(name: &str) -> Option<PathBuf> {
    match data_dir() {
        Some(d) => Some(d.join(name)),
        None => {
            eprintln!("{DATA_ENV} is not set: skipping the tests on {name}");
            None
        }
    }
}

/// A scratch folder unique to this process and `name`, emptied first; see [`Scratch`].
pub fn scratch(name: &str) -> Scratch {
    let dir = std::env::temp_dir().join(format!("phantogram-it-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("create scratch folder");
    Scratch(dir)
}

/// A scratch folder that is removed when dropped, unless the thread is panicking: a failing
/// test keeps its files for inspection (and says where), a passing one leaves nothing behind.
#[derive(Debug)]
pub struct Scratch(PathBuf);

impl std::ops::Deref for Scratch {
    type Target = Path;
    fn deref(&self) -> &Path {
        &self.0
    }
}

impl AsRef<Path> for Scratch {
    fn as_ref(&self) -> &Path {
        &self.0
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        if std::thread::panicking() {
            eprintln!("kept {} for inspection", self.0.display());
        } else {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }
}

/// Decompresses a gzip stream.
pub fn gunzip(gz: &[u8]) -> std::io::Result<Vec<u8>> {
    use std::io::Read;
    let mut out = Vec::new();
    flate2::read::MultiGzDecoder::new(gz).read_to_end(&mut out)?;
    Ok(out)
}

/// Compresses bytes into a gzip stream.
pub fn gzip(bytes: &[u8]) -> Vec<u8> {
    use std::io::Write;
    let mut enc = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    enc.write_all(bytes).expect("writing to memory");
    enc.finish().expect("writing to memory")
}
