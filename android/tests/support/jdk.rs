//! Where a JDK is, and how the Java drivers are compiled: shared (with `#[path]`) by the JVM test
//! (`android/tests/jvm.rs`), the `jni` fuzz target (`fuzz/fuzz_targets/jni.rs`) and
//! `cargo xtask fuzz`, so that all three look in the same places.
#![allow(dead_code)] // Each includer uses part of it.

use std::path::{Path, PathBuf};
use std::process::Command;

/// The JDK homes found (folders with `bin/javac`), preferred first: `$JAVA_HOME`, Debian's
/// OpenJDK 17, the home of the `javac` on the PATH.
pub fn java_homes() -> impl Iterator<Item = PathBuf> {
    std::env::var_os("JAVA_HOME")
        .map(PathBuf::from)
        .into_iter()
        .chain([PathBuf::from("/usr/lib/jvm/java-17-openjdk-amd64")])
        .chain(std::iter::once_with(javac_on_path_home).flatten())
        .filter(|home| home.join("bin/javac").is_file())
}

/// The JDK the `javac` on the PATH belongs to (its links followed: `…/bin/javac`).
fn javac_on_path_home() -> Option<PathBuf> {
    let path = std::env::var_os("PATH")?;
    let javac = std::env::split_paths(&path)
        .map(|dir| dir.join("javac"))
        .find(|p| p.is_file())?;
    Some(std::fs::canonicalize(javac).ok()?.parent()?.parent()?.to_path_buf())
}

/// Compiles `NativeBridge.java` (the app's own, unchanged) and the driver
/// `android/tests/java/DRIVER.java` of the repository at `workspace` into `out`, with the JDK at
/// `home`. Panics if javac cannot run or fails (every caller is a test or a fuzz target's set-up).
pub fn compile_driver(workspace: &Path, home: &Path, driver: &str, out: &Path) {
    let status = Command::new(home.join("bin/javac"))
        .arg("-d")
        .arg(out)
        .arg(workspace.join("android/phantogram/src/main/java/org/phantogram/NativeBridge.java"))
        .arg(workspace.join(format!("android/tests/java/{driver}.java")))
        .status()
        .expect("running javac");
    assert!(status.success(), "javac failed");
}
