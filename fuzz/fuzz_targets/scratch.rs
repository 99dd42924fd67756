//! A per-process scratch folder for targets whose code under test reads files (shared by the
//! targets with `#[path]`): the input is written there under the name the target chooses.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// `$TMPDIR/phantogram-fuzz-<target>-<pid>`, made once.
pub fn dir(target: &str) -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let dir = std::env::temp_dir().join(format!("phantogram-fuzz-{target}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("scratch folder");
        dir
    })
}

/// Writes `bytes` to `dir/name` and returns the path.
pub fn write(dir: &Path, name: &str, bytes: &[u8]) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, bytes).expect("scratch write");
    path
}
