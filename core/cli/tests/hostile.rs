//! The `phantogram` binary on hostile and careless input: each case once ran for ever, panicked,
//! lost its output or replaced what it should not have. Every input is made here.

use std::io::Read as _;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use phantogram_testkit::Scratch;

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_phantogram"))
}

fn default_log() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../assets/logs/tilt-sweep.pglog")
}

/// Runs `command` to its end, or fails the test (after killing it) when it takes over `limit`.
fn run_within(mut command: Command, limit: Duration) -> (Option<i32>, String, String) {
    let mut child = command.stdout(Stdio::piped()).stderr(Stdio::piped()).spawn().unwrap();
    let mut stdout = child.stdout.take().unwrap();
    let mut stderr = child.stderr.take().unwrap();
    // Drained on threads, so that a full pipe cannot stall the child.
    let out = std::thread::spawn(move || {
        let mut v = Vec::new();
        let _ = stdout.by_ref().take(1 << 20).read_to_end(&mut v);
        // Keep reading (and discarding) so the child never blocks on a full pipe.
        let _ = std::io::copy(&mut stdout, &mut std::io::sink());
        v
    });
    let err = std::thread::spawn(move || {
        let mut v = Vec::new();
        let _ = stderr.read_to_end(&mut v);
        v
    });
    let start = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        if start.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            panic!("still running after {limit:?}: {command:?}");
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    let out = String::from_utf8_lossy(&out.join().unwrap()).into_owned();
    let err = String::from_utf8_lossy(&err.join().unwrap()).into_owned();
    (status.code(), out, err)
}

fn log_file(dir: &Path, name: &str, text: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

/// Two time stamps centuries apart once replayed "for ever": their difference wrapped and slipped
/// past the gap guard (`replay --csv` printed 1.16 GB in 30 s; `info` printed a negative
/// duration). The stamps at the ends of the accepted range replay in a moment; one past them is
/// refused by line.
#[test]
fn stamps_centuries_apart_replay_in_a_moment() {
    let dir = Scratch::new("hostile-time");
    let max = (1i64 << 62) - 1;
    let log = log_file(
        &dir,
        "far.pglog",
        &format!("phantogram-sensor-log 1\nacc -{max} 0 0 9.81\nacc {max} 0 0 9.81\n"),
    );
    let mut replay = bin();
    replay.args(["replay", "--csv"]).arg(&log);
    let (code, out, err) = run_within(replay, Duration::from_secs(60));
    assert_eq!(code, Some(0), "{err}");
    assert!(out.lines().count() <= 4, "{} rows", out.lines().count());
    let mut info = bin();
    info.arg("info").arg(&log);
    let (code, out, err) = run_within(info, Duration::from_secs(60));
    assert_eq!(code, Some(0), "{err}");
    let duration: f64 = out
        .lines()
        .find(|l| l.starts_with("Accelerometer"))
        .and_then(|l| l.split_whitespace().nth(2))
        .and_then(|d| d.parse().ok())
        .expect("a duration");
    assert!(duration > 9.2e9, "{out}");

    let beyond = log_file(
        &dir,
        "beyond.pglog",
        "phantogram-sensor-log 1\nacc -4611686018427387904 0 0 9.81\nacc 4611686018427387904 0 0 9.81\n",
    );
    let mut replay = bin();
    replay.arg("replay").arg(&beyond);
    let (code, _, err) = run_within(replay, Duration::from_secs(60));
    assert_eq!(code, Some(1));
    assert!(err.contains("beyond.pglog:2:") && err.contains("(2^62 - 1)"), "{err}");
}

/// Flags whose numbers parse but mean nothing are refused by name (one panicked in
/// `Duration::from_secs_f64`, one reported "invalid intrinsics Intrinsics { fx_px: inf … }").
#[test]
fn meaningless_numbers_are_refused_by_flag() {
    let out = bin()
        .args(["replay", "--realtime", "1e-30"])
        .arg(default_log())
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("--realtime must be a speed factor from 0.001 to 1000"),
        "{err}"
    );
    for hfov in ["0", "180", "NaN", "-5"] {
        let out = bin()
            .args(["eval", "face", &format!("--hfov-deg={hfov}"), "x.jpg"])
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success() && err.contains("--hfov-deg"), "{hfov}: {err}");
        assert!(!err.contains("Intrinsics {"), "{err}");
    }
}

/// A reader that goes away (`| head -c 10`) ends the program quietly with status 0; a full
/// device is an error with status 1. Neither panics.
#[test]
fn stdout_closed_or_full_is_handled_not_panicked() {
    for args in [
        vec!["replay", "--csv", "--every-ms", "1"],
        vec!["replay", "--estimator", "fused", "--csv"],
        vec!["info"],
    ] {
        let mut child = bin()
            .args(&args)
            .arg(default_log())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        // Read ten bytes, then hang up.
        let mut stdout = child.stdout.take().unwrap();
        let mut head = [0u8; 10];
        let _ = stdout.read_exact(&mut head);
        drop(stdout);
        let out = child.wait_with_output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(0), "{args:?}: {err}");
        assert!(!err.contains("panicked") && !err.contains("error"), "{args:?}: {err}");
    }
    let Ok(full) = std::fs::OpenOptions::new().write(true).open("/dev/full") else {
        eprintln!("no /dev/full here: skipping the full-device half");
        return;
    };
    for args in [vec!["replay", "--csv"], vec!["info"]] {
        let out = bin()
            .args(&args)
            .arg(default_log())
            .stdout(full.try_clone().unwrap())
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
        assert!(
            err.contains("No space left on device") && !err.contains("panicked"),
            "{args:?}: {err}"
        );
    }
}

/// `import --out` onto something that is not a regular file (a pipe here; `/dev/full` as root
/// was replaced by a regular file) is refused and the target stays what it was.
#[cfg(unix)]
#[test]
fn import_never_replaces_a_device_or_a_pipe() {
    use std::os::unix::fs::FileTypeExt as _;
    let dir = Scratch::new("hostile-import");
    let fifo = dir.join("out.pglog");
    if !Command::new("mkfifo").arg(&fifo).status().is_ok_and(|s| s.success()) {
        eprintln!("mkfifo failed: skipping");
        return;
    }
    let out = bin()
        .arg("import")
        .arg(default_log())
        .arg("--out")
        .arg(&fifo)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("not a regular file"), "{err}");
    assert!(std::fs::symlink_metadata(&fifo).unwrap().file_type().is_fifo());
}

/// A render that fails leaves the previous run's frames as they were, and no half-written
/// folder: the frames are written aside and swapped in only when all are there.
#[test]
fn a_failed_render_keeps_the_previous_frames() {
    let dir = Scratch::new("hostile-render");
    for name in ["frame_00000.png", "frame_00001.png"] {
        std::fs::write(dir.join(name), b"previous run").unwrap();
    }
    // The screen's aspect ratio, larger than any GPU's texture (and read-back) limit.
    let out = bin()
        .args(["render", "--every", "1000", "--size", "9000x20000", "--log"])
        .arg(default_log())
        .arg("--out")
        .arg(&*dir)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    if err.contains("no GPU adapter") && std::env::var_os("CI").is_none() {
        eprintln!("no GPU adapter: skipping the render test");
        return;
    }
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("9000×20000") && !err.contains("panicked"), "{err}");
    let mut names: Vec<String> = std::fs::read_dir(&*dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(names, ["frame_00000.png", "frame_00001.png"]);
    assert_eq!(std::fs::read(dir.join("frame_00001.png")).unwrap(), b"previous run");
}
