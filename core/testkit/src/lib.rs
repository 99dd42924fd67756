//! Scratch folders for tests: the crates' unit tests, the CLI tests and the workspace's
//! integration tests share this one piece, as a dev-dependency only: no library writes temporary
//! files.
//!
//! Each folder is unique to the process and a name, emptied when made, and removed when
//! dropped, unless the thread is panicking: a failing test keeps its files for inspection and
//! says where, a passing one leaves nothing in the temporary folder.

use std::path::{Path, PathBuf};

pub struct Scratch(PathBuf);

impl Scratch {
    /// `phantogram-NAME-PID` in the temporary folder, empty. Panics if it cannot be made (tests
    /// only).
    pub fn new(name: &str) -> Self {
        let dir = std::env::temp_dir().join(format!("phantogram-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("create scratch folder");
        Self(dir)
    }
}

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
