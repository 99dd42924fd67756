//! The JNI bridge on the desktop JVM: `NativeBridge.java` (the app's own declaration, unchanged)
//! and a driver are compiled with `javac`, loaded into Java 17 with the host build of this
//! crate's cdylib, and replay the default sensor log through JNI into offscreen frames. The last
//! frame must equal, pixel for pixel, what the engine draws from the same events without JNI,
//! and errors must arrive as the documented Java exceptions.
//!
//! Needs a JDK (`$JAVA_HOME`, else Debian's OpenJDK 17, else `javac` on the PATH) and a Vulkan
//! driver; without them the test says so and passes, unless `PHANTOGRAM_REQUIRE_JAVA` is set
//! (`.ci/run` sets it, so CI cannot skip silently).

use std::path::{Path, PathBuf};
use std::process::Command;

use phantogram::engine::{Engine, EngineConfig};

#[path = "support/jdk.rs"]
mod jdk;
use phantogram::sensors::{SensorEvent, SensorKind};

const WIDTH: u32 = 108;
const HEIGHT: u32 = 240;
const STEP_NS: i64 = 100_000_000;

fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn tool(home: &Path, name: &str) -> PathBuf {
    home.join("bin").join(name)
}

/// The host build of the bridge: the cdylib cargo built for this test run.
fn bridge_library() -> PathBuf {
    let exe = std::env::current_exe().expect("test executable path");
    let deps = exe.parent().expect("deps folder");
    for dir in [deps, deps.parent().expect("profile folder")] {
        let p = dir.join("libphantogram_android.so");
        if p.is_file() {
            return p;
        }
    }
    panic!("libphantogram_android.so not found next to {}", exe.display());
}

/// The first misuse `-Xcheck:jni` reported, if any. It reports what it can go on from (such as a
/// JNI call made with an exception pending, checked to be caught here) as warnings on the JVM's
/// standard **output**, not its error stream (this test looked only at the latter until
/// 2026-12-03, so it could not fail).
fn jni_misuse<'a>(stdout: &'a str, stderr: &'a str) -> Option<&'a str> {
    stdout
        .lines()
        .chain(stderr.lines())
        .find(|l| l.contains("WARNING in native method") || l.contains("WARNING: JNI local refs"))
}

fn skip(reason: &str) -> bool {
    if std::env::var_os("PHANTOGRAM_REQUIRE_JAVA").is_some() {
        panic!("{reason}, and PHANTOGRAM_REQUIRE_JAVA is set");
    }
    eprintln!("{reason}: skipping the JVM test of the JNI bridge");
    true
}

/// Compiles `NativeBridge.java` (the app's own) and the driver `android/tests/java/NAME.java`
/// into a fresh folder `PREFIX-<pid>` in the temporary folder, returned.
fn compile_driver(home: &Path, name: &str, prefix: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("{prefix}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp folder");
    jdk::compile_driver(&workspace(), home, name, &dir);
    dir
}

/// The log's motion events, in file order (what the driver forwards).
fn log_events(path: &Path) -> Vec<SensorEvent> {
    let text = std::fs::read_to_string(path).expect("reading the log");
    text.lines()
        .filter_map(|line| {
            let f: Vec<&str> = line.split_whitespace().collect();
            let kind = match *f.first()? {
                "acc" => SensorKind::Accelerometer,
                "mag" => SensorKind::Magnetometer,
                "gyr" => SensorKind::Gyroscope,
                _ => return None,
            };
            let t: i64 = f[1].parse().ok()?;
            let v: Vec<f32> = f[2..5].iter().map(|s| s.parse().expect("a number")).collect();
            Some(SensorEvent::vector(
                kind,
                t,
                phantogram::glam::Vec3::new(v[0], v[1], v[2]),
            ))
        })
        .collect()
}

/// The driver's replay, without JNI: the same pushes and draws in the same order.
fn reference_frame(events: &[SensorEvent]) -> Option<Vec<u8>> {
    let mut engine = match Engine::new(EngineConfig::default()) {
        Ok(e) => e,
        Err(e) => {
            skip(&format!("no GPU engine ({e})"));
            return None;
        }
    };
    engine.resume_offscreen(WIDTH, HEIGHT).expect("offscreen target");
    let inbox = engine.inbox();
    let mut next = None;
    for e in events {
        let n = next.get_or_insert(e.t_ns + STEP_NS);
        while e.t_ns > *n {
            engine.draw(Some(*n)).expect("drawing");
            *n += STEP_NS;
        }
        let _ = inbox.push(*e);
    }
    engine.draw(events.last().map(|e| e.t_ns)).expect("drawing");
    Some(engine.last_frame().expect("a frame").2.to_vec())
}

#[test]
fn jni_bridge_replays_a_log_on_the_desktop_jvm() {
    let Some(home) = jdk::java_homes().next() else {
        skip("no JDK found");
        return;
    };
    let log = workspace().join("assets/logs/tilt-sweep.pglog");
    let events = log_events(&log);
    assert!(events.len() > 1000, "the default log has motion events");
    let Some(expected) = reference_frame(&events) else {
        return;
    };

    let dir = compile_driver(&home, "ReplayThroughJni", "phantogram-jvm");
    let out = dir.join("frame.argb");
    let output = Command::new(tool(&home, "java"))
        .arg("-Xcheck:jni")
        .arg("-cp")
        .arg(&dir)
        .arg("ReplayThroughJni")
        .arg(bridge_library())
        .arg(&log)
        .arg(&out)
        .arg(WIDTH.to_string())
        .arg(HEIGHT.to_string())
        .output()
        .expect("running java");
    let stdout = String::from_utf8_lossy(&output.stdout);
    let stderr = String::from_utf8_lossy(&output.stderr);
    println!("{stdout}");
    assert!(output.status.success(), "the JVM driver failed:\n{stdout}\n{stderr}");
    assert!(stdout.contains("done"), "{stdout}");
    if let Some(warning) = jni_misuse(&stdout, &stderr) {
        panic!("JNI misuse reported: {warning}\n{stdout}");
    }

    let bytes = std::fs::read(&out).expect("the driver's frame");
    assert_eq!(bytes.len(), (WIDTH * HEIGHT * 4) as usize);
    let mut worst = 0u8;
    for (argb, rgba) in bytes.chunks_exact(4).zip(expected.chunks_exact(4)) {
        // Big-endian 0xAARRGGBB from DataOutputStream.writeInt.
        let got = [argb[1], argb[2], argb[3], argb[0]];
        for c in 0..4 {
            worst = worst.max(got[c].abs_diff(rgba[c]));
        }
    }
    assert!(
        worst <= 1,
        "the frame through JNI differs from the direct one by up to {worst} levels"
    );
    // And it is a phantogram, not an empty frame: the left and right images differ, so the red
    // and cyan channels disagree somewhere.
    let stereo = expected
        .chunks_exact(4)
        .filter(|p| p[0].abs_diff(p[1]) > 20 || p[0].abs_diff(p[2]) > 20)
        .count();
    assert!(stereo > 100, "only {stereo} pixels show red/cyan disparity");
    let _ = std::fs::remove_dir_all(&dir);
}

/// `NativeBridge.java`'s native declarations, the library's exports and the bridge's list agree.
#[test]
fn java_declarations_match_the_exported_methods() {
    let java =
        std::fs::read_to_string(workspace().join("android/phantogram/src/main/java/org/phantogram/NativeBridge.java"))
            .expect("NativeBridge.java");
    let mut declared: Vec<String> = java
        .split("public static native ")
        .skip(1)
        .filter_map(|rest| {
            let head = rest.split('(').next()?;
            head.split_whitespace().last().map(str::to_owned)
        })
        .collect();
    declared.sort();
    let source = std::fs::read_to_string(workspace().join("android/src/jni_bridge.rs")).expect("jni_bridge.rs");
    let mut exported: Vec<String> = source
        .split("fn Java_org_phantogram_NativeBridge_")
        .skip(1)
        .filter_map(|rest| rest.split('<').next().map(str::to_owned))
        .collect();
    exported.sort();
    let mut listed: Vec<String> = phantogram_android::jni_bridge::NATIVE_METHODS
        .iter()
        .map(|s| s.to_string())
        .collect();
    listed.sort();
    assert_eq!(declared, exported, "NativeBridge.java and jni_bridge.rs disagree");
    assert_eq!(listed, exported, "NATIVE_METHODS is out of date");
}

/// `NativeBridge.AccessibilityNode`'s role and flag numbers are the core's.
#[test]
fn java_accessibility_constants_are_the_cores() {
    use phantogram::calibration_ui::accessibility::{self as a, AccessRole};
    let java =
        std::fs::read_to_string(workspace().join("android/phantogram/src/main/java/org/phantogram/NativeBridge.java"))
            .expect("NativeBridge.java");
    let constant = |name: &str| -> i64 {
        let at = java
            .find(&format!("int {name} = "))
            .unwrap_or_else(|| panic!("{name} not declared"));
        let rest = &java[at + name.len() + 7..];
        rest[..rest.find(';').expect("a value")]
            .trim()
            .parse()
            .expect("a number")
    };
    for (name, role) in [
        ("ROLE_TEXT", AccessRole::Text),
        ("ROLE_BUTTON", AccessRole::Button),
        ("ROLE_CHECK_BOX", AccessRole::CheckBox),
        ("ROLE_RADIO_BUTTON", AccessRole::RadioButton),
        ("ROLE_SLIDER", AccessRole::Slider),
        ("ROLE_IMAGE", AccessRole::Image),
    ] {
        assert_eq!(constant(name), role as i64, "{name}");
    }
    for (name, flag) in [
        ("FLAG_CLICKABLE", a::FLAG_CLICKABLE),
        ("FLAG_ADJUSTABLE", a::FLAG_ADJUSTABLE),
        ("FLAG_CHECKABLE", a::FLAG_CHECKABLE),
        ("FLAG_CHECKED", a::FLAG_CHECKED),
        ("FLAG_DISABLED", a::FLAG_DISABLED),
    ] {
        assert_eq!(constant(name), i64::from(flag), "{name}");
    }
}

/// Random call sequences through every native method (`android/tests/java/RandomCalls.java`):
/// only documented exceptions, no panic, no JNI error, no crash, and `-Xcheck:jni` silent.
/// `PHANTOGRAM_JNI_CALLS` sets the calls per seed (default 400; a long run: a few hundred
/// thousand), `PHANTOGRAM_JNI_SEEDS` the number of seeds (default 3). Then the same driver once
/// more with its choices drawn from 4 KiB of bytes, as the `jni` fuzz target draws them from
/// libFuzzer's (`RandomCalls.fuzz`): the calls run until the bytes are used up, and end.
#[test]
fn random_jni_call_sequences_end_only_in_documented_exceptions() {
    let Some(home) = jdk::java_homes().next() else {
        skip("no JDK found");
        return;
    };
    if let Err(e) = Engine::new(EngineConfig::default()) {
        skip(&format!("no GPU engine ({e})"));
        return;
    }
    let number = |var: &str, default: u64| {
        std::env::var(var)
            .ok()
            .and_then(|v| v.parse::<u64>().ok())
            .unwrap_or(default)
    };
    let (calls, seeds) = (number("PHANTOGRAM_JNI_CALLS", 400), number("PHANTOGRAM_JNI_SEEDS", 3));
    let dir = compile_driver(&home, "RandomCalls", "phantogram-jvm-random");
    let stream = dir.join("stream");
    // Bytes of no pattern a call could be tuned to: a multiplicative hash of the position.
    let bytes: Vec<u8> = (0u32..4096)
        .map(|i| (i.wrapping_mul(2_654_435_761) >> 24) as u8)
        .collect();
    std::fs::write(&stream, bytes).expect("writing the byte stream");
    let runs = (1..=seeds)
        .map(|seed| seed.to_string())
        .chain([format!("bytes:{}", stream.display())]);
    for (i, seed) in runs.enumerate() {
        let library = dir.join(format!("library-{i}"));
        let output = Command::new(tool(&home, "java"))
            .arg("-Xcheck:jni")
            .arg("-cp")
            .arg(&dir)
            .arg("RandomCalls")
            .arg(bridge_library())
            .arg(&seed)
            .arg(calls.to_string())
            .arg(&library)
            .output()
            .expect("running java");
        let stdout = String::from_utf8_lossy(&output.stdout);
        let stderr = String::from_utf8_lossy(&output.stderr);
        println!("{stdout}");
        assert!(output.status.success(), "seed {seed}:\n{stdout}\n{stderr}");
        assert!(stdout.contains("done"), "{stdout}");
        if let Some(warning) = jni_misuse(&stdout, &stderr) {
            panic!("seed {seed}: JNI misuse reported: {warning}\n{stdout}");
        }
        if seed.starts_with("bytes:") {
            // Many calls from the bytes, not one that swallowed them all (nor none): 60 with
            // today's driver; one call takes 8 to ~2100 bytes (an import's up to 2 KiB).
            let made: u64 = stdout
                .split(" bytes: ")
                .nth(1)
                .and_then(|rest| rest.split(' ').next())
                .and_then(|n| n.parse().ok())
                .unwrap_or(0);
            assert!(made >= 10, "only {made} calls from 4096 bytes:\n{stdout}");
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}
