//! The Kotlin shell compiles: the viewer library's and the app's Kotlin
//! (`android/phantogram/src/main/kotlin`, `android/app/src/main/kotlin`) with Debian's `kotlinc`
//! against the real `NativeBridge.java` and the host stubs of the Android/AndroidX API in `android/stubs`
//! (what they do and do not prove: `android/stubs/README.md`). Skipped with a notice without
//! `kotlinc` and `javac`, unless `PHANTOGRAM_REQUIRE_KOTLIN` is set (`.ci/run` sets it).

use std::path::{Path, PathBuf};
use std::process::Command;

fn files(dir: &Path, ext: &str, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).expect("readable folder").flatten() {
        let p = entry.path();
        if p.is_dir() {
            files(&p, ext, out);
        } else if p.extension().is_some_and(|e| e == ext) {
            out.push(p);
        }
    }
}

#[test]
fn kotlin_shell_compiles_against_the_bridge_and_the_api_stubs() {
    let have = |tool: &str| Command::new(tool).arg("-version").output().is_ok();
    if !have("kotlinc") || !have("javac") {
        if std::env::var_os("PHANTOGRAM_REQUIRE_KOTLIN").is_some() {
            panic!("kotlinc or javac is missing, and PHANTOGRAM_REQUIRE_KOTLIN is set");
        }
        eprintln!("no kotlinc/javac (Debian: apt-get install kotlin openjdk-17-jdk-headless): skipping");
        return;
    }
    let android = Path::new(env!("CARGO_MANIFEST_DIR"));
    let dir = std::env::temp_dir().join(format!("phantogram-kotlin-{}", std::process::id()));
    let classes = dir.join("classes");
    let mut java = Vec::new();
    files(&android.join("stubs"), "java", &mut java);
    java.push(android.join("phantogram/src/main/java/org/phantogram/NativeBridge.java"));
    // Java 8 class files: what the old kotlinc reads, whichever JDK provides javac.
    let out = Command::new("javac")
        .args(["--release", "8", "-d"])
        .arg(&classes)
        .args(&java)
        .output()
        .expect("running javac");
    assert!(out.status.success(), "javac: {}", String::from_utf8_lossy(&out.stderr));
    let mut kotlin = Vec::new();
    files(&android.join("phantogram/src/main/kotlin"), "kt", &mut kotlin);
    files(&android.join("app/src/main/kotlin"), "kt", &mut kotlin);
    assert!(kotlin.len() >= 5, "the shell's Kotlin sources");
    let out = Command::new("kotlinc")
        .arg("-Werror")
        .arg("-cp")
        .arg(&classes)
        .arg("-d")
        .arg(dir.join("out"))
        .args(&kotlin)
        .output()
        .expect("running kotlinc");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "kotlinc:\n{stderr}");
    assert!(
        dir.join("out/org/phantogram/MainActivity.class").is_file(),
        "MainActivity was compiled"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
