//! The committed Gradle wrapper (`android/gradlew`, `gradle/wrapper/gradle-wrapper.properties`)
//! pins Gradle 8.9 by URL and SHA-256, and without the wrapper jar (not committed: see the
//! script) bootstraps it: fetches the pinned distribution, refuses it when the checksum differs,
//! lets it write the official wrapper, then runs the build with it. Checked offline with a fake
//! distribution served from a `file://` URL. Skipped with a notice where `sh`, `curl`, `zip`,
//! `unzip` or `sha256sum` is missing.

use std::path::{Path, PathBuf};
use std::process::Command;

fn android() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn have(tool: &str) -> bool {
    Command::new("sh")
        .args(["-c", &format!("command -v {tool}")])
        .output()
        .is_ok_and(|o| o.status.success())
}

fn sha256(path: &Path) -> String {
    let out = Command::new("sha256sum").arg(path).output().expect("sha256sum");
    String::from_utf8_lossy(&out.stdout)
        .split_whitespace()
        .next()
        .expect("a sum")
        .to_owned()
}

/// A copy of the wrapper in `dir` whose properties point at `zip` with checksum `sum`.
fn wrapper_copy(dir: &Path, zip: &Path, sum: &str) -> PathBuf {
    std::fs::create_dir_all(dir.join("gradle/wrapper")).unwrap();
    std::fs::copy(android().join("gradlew"), dir.join("gradlew")).unwrap();
    let committed = std::fs::read_to_string(android().join("gradle/wrapper/gradle-wrapper.properties")).unwrap();
    let props: String = committed
        .lines()
        .map(|l| match l.split_once('=') {
            Some(("distributionUrl", _)) => format!("distributionUrl=file\\://{}", zip.display()),
            Some(("distributionSha256Sum", _)) => format!("distributionSha256Sum={sum}"),
            _ => l.to_owned(),
        })
        .collect::<Vec<_>>()
        .join("\n");
    std::fs::write(dir.join("gradle/wrapper/gradle-wrapper.properties"), props).unwrap();
    dir.join("gradlew")
}

#[test]
fn the_committed_properties_pin_gradle_by_checksum() {
    let props = std::fs::read_to_string(android().join("gradle/wrapper/gradle-wrapper.properties")).unwrap();
    assert!(props.contains("distributionUrl=https\\://services.gradle.org/distributions/gradle-8.9-bin.zip"));
    let sum = props
        .lines()
        .find_map(|l| l.strip_prefix("distributionSha256Sum="))
        .expect("a pinned checksum");
    assert!(sum.len() == 64 && sum.chars().all(|c| c.is_ascii_hexdigit()), "{sum}");
}

#[test]
fn the_wrapper_bootstraps_the_pinned_distribution_and_refuses_another() {
    if !["sh", "curl", "zip", "unzip", "sha256sum"].iter().all(|t| have(t)) {
        eprintln!("sh, curl, zip, unzip or sha256sum missing: skipping");
        return;
    }
    let dir = std::env::temp_dir().join(format!("phantogram-gradlew-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    // A fake distribution: `gradle` logs its arguments.
    let log = dir.join("calls.log");
    let bin = dir.join("dist/gradle-8.9/bin");
    std::fs::create_dir_all(&bin).unwrap();
    std::fs::write(
        bin.join("gradle"),
        format!("#!/bin/sh\necho \"$*\" >> '{}'\n", log.display()),
    )
    .unwrap();
    let zip = dir.join("gradle-8.9-bin.zip");
    let made = Command::new("sh")
        .current_dir(dir.join("dist"))
        .args([
            "-c",
            &format!(
                "chmod +x gradle-8.9/bin/gradle && zip -qr '{}' gradle-8.9",
                zip.display()
            ),
        ])
        .status()
        .unwrap();
    assert!(made.success());
    let run = |project: &Path, home: &Path| {
        Command::new("sh")
            .arg(project.join("gradlew"))
            .arg("assembleRelease")
            .env("GRADLE_USER_HOME", home)
            .env_remove("JAVA_HOME")
            .output()
            .unwrap()
    };

    // The wrong checksum: refused, nothing run.
    let wrong = "0".repeat(64);
    let project = dir.join("refused");
    wrapper_copy(&project, &zip, &wrong);
    let out = run(&project, &dir.join("home-refused"));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && stderr.contains("not the pinned"), "{stderr}");
    assert!(!log.exists(), "a distribution that fails its checksum never runs");

    // The right one: unpacked, the official wrapper written by it, then the build run.
    let sum = sha256(&zip);
    let project = dir.join("fetched");
    wrapper_copy(&project, &zip, &sum);
    let out = run(&project, &dir.join("home"));
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let calls = std::fs::read_to_string(&log).unwrap();
    let calls: Vec<&str> = calls.lines().collect();
    assert_eq!(
        calls,
        [
            format!("--quiet wrapper --gradle-version 8.9 --gradle-distribution-sha256-sum {sum}").as_str(),
            "assembleRelease"
        ]
    );
    assert!(
        dir.join("home/wrapper/dists/gradle-8.9-bin/phantogram-bootstrap/gradle-8.9/bin/gradle")
            .is_file()
    );
    let _ = std::fs::remove_dir_all(&dir);
}
