//! A per-process scratch folder for targets whose code under test reads files (shared by the
//! targets with `#[path]`): the input is written there under the name the target chooses.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// `<scratch>/phantogram-fuzz-<target>-<pid>`, made once: `<scratch>` is
/// `$PHANTOGRAM_FUZZ_SCRATCH` (the folder `cargo xtask fuzz` makes for a run), else the
/// temporary folder.
pub fn dir(target: &str) -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let root = std::env::var_os("PHANTOGRAM_FUZZ_SCRATCH").map_or_else(std::env::temp_dir, PathBuf::from);
        let dir = root.join(format!("phantogram-fuzz-{target}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("scratch folder");
        dir
    })
}

/// Writes `bytes` to `dir/name` and returns the path.
#[allow(dead_code)] // `jni` keeps only its compiled classes there.
pub fn write(dir: &Path, name: &str, bytes: &[u8]) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, bytes).expect("scratch write");
    path
}
