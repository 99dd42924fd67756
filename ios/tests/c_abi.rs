//! The C ABI from C: `tests/c/replay.c` is compiled against the checked-in header and linked
//! with the static library (what the XCFramework packs), replays the default sensor log through
//! the Core Motion entry points and draws offscreen. Its last frame must equal what the engine
//! draws from the same samples without the ABI, and every error must come back as the
//! documented status with a message.
//!
//! Needs a C compiler (`$CC`, else `cc`) and a Vulkan driver; without them the test says so and
//! passes, unless `PHANTOGRAM_REQUIRE_CC` is set (`.ci/run` sets it).

use std::path::{Path, PathBuf};
use std::process::Command;

use phantogram::engine::{Engine, EngineConfig};

const WIDTH: u32 = 108;
const HEIGHT: u32 = 240;
const STEP_NS: i64 = 100_000_000;

fn crate_dir() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn skip(reason: &str) {
    if std::env::var_os("PHANTOGRAM_REQUIRE_CC").is_some() {
        panic!("{reason}, and PHANTOGRAM_REQUIRE_CC is set");
    }
    eprintln!("{reason}: skipping the C test of the ABI");
}

/// The static library cargo built for this test run: the newest of the copies in `deps/` and the
/// one uplifted beside it (a plain `cargo build` may have left an older uplifted copy).
fn static_library() -> PathBuf {
    let exe = std::env::current_exe().expect("test executable path");
    let deps = exe.parent().expect("deps folder");
    let uplifted = deps.parent().expect("profile folder").join("libphantogram_ios.a");
    std::fs::read_dir(deps)
        .expect("deps folder")
        .filter_map(Result::ok)
        .map(|e| e.path())
        .filter(|p| {
            p.extension().is_some_and(|x| x == "a")
                && p.file_name()
                    .is_some_and(|n| n.to_string_lossy().starts_with("libphantogram_ios"))
        })
        .chain(uplifted.is_file().then_some(uplifted))
        .max_by_key(|p| p.metadata().and_then(|m| m.modified()).ok())
        .expect("libphantogram_ios.a not built")
}

/// The C program's replay, without the ABI: the same conversions (f64 arithmetic, as in C) and
/// the same pushes and draws in the same order.
fn reference_frame(log: &Path) -> Option<Vec<u8>> {
    let mut engine = match Engine::new(EngineConfig::default()) {
        Ok(e) => e,
        Err(e) => {
            skip(&format!("no GPU engine ({e})"));
            return None;
        }
    };
    engine.resume_offscreen(WIDTH, HEIGHT).expect("offscreen target");
    let inbox = engine.inbox();
    let g = phantogram_ios::STANDARD_GRAVITY_M_S2;
    let text = std::fs::read_to_string(log).expect("reading the log");
    let (mut next, mut last) = (None, 0i64);
    for line in text.lines() {
        let f: Vec<&str> = line.split_whitespace().collect();
        if f.len() != 5 || !matches!(f[0], "acc" | "gyr" | "mag") {
            continue;
        }
        let t: i64 = f[1].parse().expect("time");
        let v: Vec<f64> = f[2..5].iter().map(|s| s.parse().expect("a number")).collect();
        let n = next.get_or_insert(t + STEP_NS);
        while t > *n {
            engine.draw(Some(*n)).expect("drawing");
            *n += STEP_NS;
        }
        let t_s = t as f64 * 1e-9;
        let event = match f[0] {
            "acc" => phantogram_ios::accelerometer_event(t_s, [-v[0] / g, -v[1] / g, -v[2] / g]),
            "gyr" => phantogram_ios::gyroscope_event(t_s, [v[0], v[1], v[2]]),
            _ => phantogram_ios::magnetometer_event(t_s, [v[0], v[1], v[2]]),
        };
        let _ = inbox.push(event.expect("finite time stamps"));
        last = t;
    }
    engine.draw(Some(last)).expect("drawing");
    Some(engine.last_frame().expect("a frame").2.to_vec())
}

#[test]
fn c_program_replays_a_log_through_the_abi() {
    let cc = std::env::var("CC").unwrap_or_else(|_| "cc".into());
    if Command::new(&cc).arg("--version").output().is_err() {
        skip(&format!("no C compiler ({cc})"));
        return;
    }
    let log = crate_dir().join("../assets/logs/tilt-sweep.pglog");
    let Some(expected) = reference_frame(&log) else { return };

    let dir = std::env::temp_dir().join(format!("phantogram-c-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp folder");
    let program = dir.join("replay");
    // The libraries rustc lists for a static library on Linux (`--print native-static-libs`),
    // and the C++ runtime for the mesh simplifier (meshoptimizer, in phantogram-detail).
    let output = Command::new(&cc)
        .args(["-std=c99", "-Wall", "-Wextra", "-Werror", "-o"])
        .arg(&program)
        .arg(crate_dir().join("tests/c/replay.c"))
        .arg("-I")
        .arg(crate_dir().join("include"))
        .arg(static_library())
        .args([
            "-lstdc++",
            "-lgcc_s",
            "-lutil",
            "-lrt",
            "-lpthread",
            "-lm",
            "-ldl",
            "-lc",
        ])
        .output()
        .expect("running the C compiler");
    assert!(
        output.status.success(),
        "compiling tests/c/replay.c failed:\n{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let out = dir.join("frame.rgba");
    let output = Command::new(&program)
        .arg(&log)
        .arg(&out)
        .arg(WIDTH.to_string())
        .arg(HEIGHT.to_string())
        .output()
        .expect("running the C program");
    let stdout = String::from_utf8_lossy(&output.stdout);
    println!("{stdout}");
    assert!(
        output.status.success(),
        "the C program failed:\n{stdout}\n{}",
        String::from_utf8_lossy(&output.stderr)
    );
    assert!(stdout.contains("done"), "{stdout}");
    let got = std::fs::read(&out).expect("the program's frame");
    assert_eq!(got.len(), expected.len());
    let worst = got
        .iter()
        .zip(&expected)
        .map(|(a, b)| a.abs_diff(*b))
        .max()
        .unwrap_or(0);
    assert!(
        worst <= 1,
        "the frame through the C ABI differs from the direct one by up to {worst} levels"
    );
    let stereo = expected
        .chunks_exact(4)
        .filter(|p| p[0].abs_diff(p[1]) > 20 || p[0].abs_diff(p[2]) > 20)
        .count();
    assert!(stereo > 100, "only {stereo} pixels show red/cyan disparity");
    let _ = std::fs::remove_dir_all(&dir);
}
