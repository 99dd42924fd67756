//! The `phantogram` binary end to end: the README's replay, its numbers, and its errors.

use std::path::PathBuf;
use std::process::Command;

use phantogram_testkit::Scratch;

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_phantogram"))
}

fn default_log() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../assets/logs/tilt-sweep.pglog")
}

fn rows(stdout: &[u8]) -> Vec<Vec<f64>> {
    String::from_utf8_lossy(stdout)
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|f| f.parse().unwrap()).collect())
        .collect()
}

#[test]
fn replay_prints_the_eye_above_the_tilted_phone() {
    let out = bin()
        .args(["replay", "--csv", "--every-ms", "1000"])
        .arg(default_log())
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let rows = rows(&out.stdout);
    assert_eq!(rows.len(), 13, "0 to 12 s every second");
    // Held at 35° from horizontal: "up" in the device frame is (0, sin 35°, cos 35°), so with no
    // flat-angle calibration the eye is 300 mm along it.
    let (s, c) = 35f64.to_radians().sin_cos();
    let first = &rows[0];
    assert!(first[1].abs() < 1.0, "{first:?}");
    assert!((first[2] - 300.0 * s).abs() < 1.0, "{first:?}");
    assert!((first[3] - 300.0 * c).abs() < 1.0, "{first:?}");
    let light = (first[4].powi(2) + first[5].powi(2) + first[6].powi(2)).sqrt();
    assert!((light - 1.0).abs() < 1e-3);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("0 rejected"), "{stderr}");
}

/// `--tau-s` selects the paper's low-pass at any time constant, the paper's own value included
/// (that value once meant "the default, fused estimator").
#[test]
fn tau_s_selects_the_low_pass_even_at_the_papers_value() {
    let eyes = |extra: &[&str]| {
        let out = bin()
            .args(["replay", "--csv", "--every-ms", "50"])
            .args(extra)
            .arg(default_log())
            .output()
            .unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        rows(&out.stdout)
    };
    let fused = eyes(&[]);
    let lag = |rows: &[Vec<f64>]| {
        fused
            .iter()
            .zip(rows)
            .map(|(a, b)| (a[1] - b[1]).hypot(a[2] - b[2]).hypot(a[3] - b[3]))
            .fold(0.0, f64::max)
    };
    // The low-pass trails the tilt by its time constant: the eye is millimetres off while the
    // phone turns.
    for tau in ["0.095", "0.2"] {
        let off = lag(&eyes(&["--tau-s", tau]));
        assert!(
            off > 2.0,
            "--tau-s {tau}: the eye is at most {off:.2} mm from the fused one"
        );
    }
}

#[test]
fn flat_angle_calibration_makes_the_holding_pose_straight_on() {
    let out = bin()
        .args(["replay", "--csv", "--every-ms", "100", "--flat-at-s", "0.5"])
        .arg(default_log())
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let rows = rows(&out.stdout);
    let at_1s = rows.iter().find(|r| (r[0] - 1.0).abs() < 1e-6).unwrap();
    assert!(
        at_1s[1].abs() < 2.0 && at_1s[2].abs() < 2.0 && (at_1s[3] - 300.0).abs() < 1.0,
        "{at_1s:?}"
    );
}

#[test]
fn bad_input_is_a_clear_error() {
    let dir = Scratch::new("cli");
    let bad = dir.join("bad.pglog");
    std::fs::write(&bad, "phantogram-sensor-log 1\nacc 1 0 0 9.8\nacc 2 0 zero 9.8\n").unwrap();
    let out = bin().arg("replay").arg(&bad).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("bad.pglog:3:"), "{stderr}");

    let out = bin()
        .args(["replay", "--every-ms", "-5"])
        .arg(default_log())
        .output()
        .unwrap();
    assert!(!out.status.success());
    let out = bin()
        .args(["replay", "--flat-at-s", "99"])
        .arg(default_log())
        .output()
        .unwrap();
    assert!(String::from_utf8_lossy(&out.stderr).contains("beyond the end"));
    // Numbers that parse but mean nothing are refused by name, before any work.
    for (flag, expected) in [
        ("--every-ms=0.001", "at least 1"),
        ("--every-ms=NaN", "at least 1"),
        ("--flat-at-s=NaN", "seconds from the start of the log"),
        ("--flat-at-s=-3", "seconds from the start of the log"),
        ("--tau-s=NaN", "time constant of 0 seconds or more"),
        ("--tau-s=-0.1", "time constant of 0 seconds or more"),
    ] {
        let out = bin().args(["replay", flag]).arg(default_log()).output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success() && stderr.contains(expected), "{flag}: {stderr}");
    }
    // render knows the log's length before drawing: a flat time past it renders nothing.
    let frames = dir.join("never");
    let stderr = failed_render(&["--flat-at-s", "99"], &frames);
    assert!(stderr.contains("beyond the end"), "{stderr}");
    assert!(!frames.exists(), "no frames folder for a render that cannot finish");
    // The viewer takes render's scene options and checks them before it opens a window (so
    // these fail the same with or without a display).
    for (args, expected) in [
        (
            &["--protrude", "3"][..],
            "--protrude must be a fraction between 0 and 1",
        ),
        (&["--environment", "/nonexistent/sky.hdr"], "/nonexistent/sky.hdr"),
        (&["--material", "velvet"], "--material \"velvet\" is not a preset"),
        (&["--environment-from-camera", "/nonexistent/log"], "--environment"),
        (&["--rear-camera"], "--environment-from-camera"),
        (
            &[
                "--environment-from-camera",
                "/nonexistent/log",
                "--environment",
                "/nonexistent/room.hdr",
            ],
            "/nonexistent/room.hdr",
        ),
    ] {
        let out = bin().arg("view").args(args).output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success() && stderr.contains(expected), "{args:?}: {stderr}");
    }
    // A missing file is named, with the system's reason said once.
    let out = bin().args(["replay", "/nonexistent/log"]).output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("/nonexistent/log"), "{stderr}");
    assert_eq!(stderr.matches("os error 2").count(), 1, "{stderr}");
    let stderr = failed_render(&["/nonexistent/model.glb"], &dir.join("frames"));
    assert!(stderr.contains("/nonexistent/model.glb"), "{stderr}");
    assert_eq!(stderr.matches("os error 2").count(), 1, "{stderr}");
    // --out must be a folder (or not exist yet).
    let stderr = failed_render(&[], &bad);
    assert!(stderr.contains("exists and is not a folder"), "{stderr}");
}

/// `render ARGS --log <default log> --out OUT`, which must fail; its standard error.
fn failed_render(args: &[&str], out: &std::path::Path) -> String {
    let run = bin()
        .arg("render")
        .args(args)
        .arg("--log")
        .arg(default_log())
        .arg("--out")
        .arg(out)
        .output()
        .unwrap();
    assert!(!run.status.success(), "render {args:?} succeeded");
    String::from_utf8_lossy(&run.stderr).into_owned()
}

#[test]
fn import_then_info_round_trip() {
    let dir = Scratch::new("cli-import");
    let out_log = dir.join("copy.pglog.gz");
    let status = bin()
        .arg("import")
        .arg(default_log())
        .arg("--out")
        .arg(&out_log)
        .status()
        .unwrap();
    assert!(status.success());
    let info = bin().arg("info").arg(&out_log).output().unwrap();
    let text = String::from_utf8_lossy(&info.stdout);
    assert!(text.contains("Accelerometer") && text.contains("1201"), "{text}");
}

#[test]
fn replay_with_an_estimator_prints_one_orientation_per_sample_time() {
    let out = bin()
        .args(["replay", "--estimator", "fused", "--csv"])
        .arg(default_log())
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(text.lines().next(), Some("t_s,w,x,y,z"));
    let rows = rows(&out.stdout);
    // The synthetic log samples at 0, 10, 20, 30 ms… (100 Hz inertial, 50 Hz magnetometer): one
    // row per distinct time, 0 to 12 s.
    assert_eq!(rows.len(), 1201);
    assert!(rows.windows(2).all(|w| w[1][0] > w[0][0]));
    for r in &rows {
        let norm = (r[1] * r[1] + r[2] * r[2] + r[3] * r[3] + r[4] * r[4]).sqrt();
        assert!((norm - 1.0).abs() < 1e-4, "{r:?}");
    }
    // At rest at the end the phone is pitched 35° about x with north ahead: q ≈ (cos 17.5°, sin 17.5°, 0, 0).
    let last = rows.last().unwrap();
    let half = 17.5f64.to_radians();
    let dot = (last[1] * half.cos() + last[2] * half.sin()).abs();
    assert!(dot > 0.9998, "{last:?}"); // within about 2°
    let bad = bin()
        .args(["replay", "--estimator", "nonsense"])
        .arg(default_log())
        .output()
        .unwrap();
    assert!(!bad.status.success());
    // The synthetic log has no platform rotation vector: an error, not 1201 rows of NaN. And the
    // eye-table options do not apply to this output: refused rather than ignored.
    for (args, expected) in [
        (&["--estimator", "rotation-vector"][..], "has no rotation vector"),
        (&["--estimator", "fused", "--every-ms", "500"], "cannot be used with"),
        (&["--estimator", "fused", "--flat-at-s", "1"], "cannot be used with"),
    ] {
        let out = bin().arg("replay").args(args).arg(default_log()).output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success() && stderr.contains(expected), "{args:?}: {stderr}");
        assert!(out.stdout.is_empty(), "{args:?}: printed {} bytes", out.stdout.len());
    }
}

/// The window path end to end under a virtual X server: the surface lifecycle self-test
/// (suspend, a skipped draw, resume, resizes) and 20 presented frames. Needs `xvfb-run`; skipped
/// with a notice without it, except under CI, which installs it.
#[test]
fn viewer_runs_its_surface_lifecycle_in_a_window() {
    let xvfb = std::process::Command::new("xvfb-run").arg("--help").output();
    if xvfb.is_err() {
        assert!(std::env::var_os("CI").is_none(), "CI must provide xvfb-run");
        eprintln!("xvfb-run not found: skipping the window test");
        return;
    }
    let runtime = Scratch::new("cli-xdg");
    let out = Command::new("timeout")
        .args(["300", "xvfb-run", "-a", "-s", "-screen 0 800x1280x24"])
        .arg(env!("CARGO_BIN_EXE_phantogram"))
        .args(["view", "--frames", "20", "--lifecycle-test"])
        .env("XDG_RUNTIME_DIR", &*runtime)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    let line = stderr
        .lines()
        .find(|l| l.starts_with("presented"))
        .unwrap_or_else(|| panic!("{stderr}"));
    let number = |key: &str| -> u64 {
        let i = line.find(key).unwrap_or_else(|| panic!("{line}"));
        line[..i]
            .split_whitespace()
            .last()
            .unwrap()
            .trim_start_matches('(')
            .parse()
            .unwrap()
    };
    assert_eq!(number(" frames"), 20, "{line}");
    assert!(
        number(" skipped") >= 1,
        "the draw while suspended must be skipped: {line}"
    );
    let after = |key: &str| -> u64 {
        let i = line.find(key).unwrap_or_else(|| panic!("{line}")) + key.len();
        line[i..]
            .split(|c: char| !c.is_ascii_digit())
            .find(|s| !s.is_empty())
            .unwrap()
            .parse()
            .unwrap()
    };
    assert_eq!(after("resumed "), 2, "{line}");
    assert_eq!(after("suspended "), 1, "{line}");
    assert!(after("reconfigured ") >= 4, "{line}");
}

#[path = "../../../tests/tests/integration/golden.rs"]
mod golden;

/// The menu as the desktop viewer's window shows it, screenshotted from a virtual X server
/// (ImageMagick's `import`) once the viewer has presented its frames, against its golden image:
/// the window path (surface, presentation) shows what the offscreen goldens show. Needs
/// `xvfb-run` and `import`; skipped with a notice without them, except under CI.
#[test]
fn the_menu_in_a_window_matches_its_golden_screenshot() {
    let have = |tool: &str| {
        Command::new("sh")
            .args(["-c", &format!("command -v {tool}")])
            .output()
            .is_ok_and(|o| o.status.success())
    };
    if !have("xvfb-run") || !have("import") {
        assert!(std::env::var_os("CI").is_none(), "CI must provide xvfb-run and import");
        eprintln!("xvfb-run or import (ImageMagick) not found: skipping the window screenshot");
        return;
    }
    let dir = Scratch::new("cli-window-shot");
    let runtime = dir.join("runtime");
    std::fs::create_dir_all(&runtime).unwrap();
    let shot = dir.join("shot.png");
    // The viewer prints "ready" after its frames and keeps the last on screen; the screenshot
    // is taken then, and the viewer stopped.
    let script = r#"
        "$0" view --menu --frames 5 --linger-s 120 2> "$1/viewer.log" &
        pid=$!
        until grep -q ready "$1/viewer.log" || ! kill -0 $pid 2>/dev/null; do sleep 0.2; done
        import -window root "$1/shot.png"
        kill $pid 2>/dev/null
        wait $pid
        exit 0
    "#;
    let out = Command::new("timeout")
        .args([
            "300",
            "xvfb-run",
            "-a",
            "-s",
            "-screen 0 800x1280x24",
            "sh",
            "-c",
            script,
        ])
        .arg(env!("CARGO_BIN_EXE_phantogram"))
        .arg(&*dir)
        .env("XDG_RUNTIME_DIR", &runtime)
        .env("XDG_CONFIG_HOME", dir.join("config"))
        .env("XDG_DATA_HOME", dir.join("data"))
        .env_remove("PHANTOGRAM_CALIBRATION")
        .env_remove("PHANTOGRAM_LIBRARY")
        .output()
        .unwrap();
    let log = std::fs::read_to_string(dir.join("viewer.log")).unwrap_or_default();
    assert!(
        out.status.success() && log.contains("ready") && shot.is_file(),
        "{}\n{log}",
        String::from_utf8_lossy(&out.stderr)
    );
    // The window (405 × 900, no window manager: at the origin) out of the screen.
    let screen = image::open(&shot).unwrap().to_rgba8();
    let window = image::imageops::crop_imm(&screen, 0, 0, 405, 900).to_image();
    golden::check("xvfb-menu", 405, 900, window.as_raw(), 3, 0.003);
}

/// `eval face --json`: one object per image with the documented keys; a missing model folder is a
/// clear error naming `cargo xtask models`. Needs `PHANTOGRAM_MODELS` and `PHANTOGRAM_DATA` for
/// the positive part.
#[test]
fn eval_face_prints_json_per_image_and_names_the_missing_models() {
    let missing = bin()
        .args(["eval", "face", "--models", "/nonexistent-models", "x.png"])
        .output()
        .unwrap();
    assert!(!missing.status.success());
    let err = String::from_utf8_lossy(&missing.stderr);
    assert!(err.contains("cargo xtask models"), "{err}");

    let (Some(models), Some(data)) = (
        std::env::var_os("PHANTOGRAM_MODELS"),
        std::env::var_os("PHANTOGRAM_DATA"),
    ) else {
        eprintln!("PHANTOGRAM_MODELS or PHANTOGRAM_DATA unset: skipping the positive part");
        return;
    };
    let faces = PathBuf::from(data).join("faces");
    let out = bin()
        .args(["eval", "face", "--json", "--models"])
        .arg(&models)
        .arg(faces.join("astronaut.png"))
        .arg(faces.join("dogs.jpg"))
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let lines: Vec<serde_json::Value> = String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(|l| serde_json::from_str(l).expect("one JSON object per line"))
        .collect();
    assert_eq!(lines.len(), 2);
    assert!(lines[0]["image"].as_str().unwrap().ends_with("astronaut.png"));
    let face = &lines[0]["faces"][0];
    let (l, r) = (&face["left_eye"], &face["right_eye"]);
    assert!(
        l[0].as_f64().unwrap() < r[0].as_f64().unwrap(),
        "left as seen in the image"
    );
    assert!(face["distance_mm"].as_f64().unwrap() > 100.0);
    assert!((0.0..=1.0).contains(&face["confidence"].as_f64().unwrap()));
    assert_eq!(lines[1]["faces"].as_array().unwrap().len(), 0, "no face among the dogs");
    assert_eq!(face["distance_from"], "iris");
    assert!(face["glasses"].is_null(), "no glasses on the bare face");

    // Red/cyan glasses drawn over the same face, red over the subject's left eye (the image's
    // right): seen, named, and the distance taken from the eye distance.
    let eye = |v: &serde_json::Value| {
        phantogram::glam::Vec2::new(v[0].as_f64().unwrap() as f32, v[1].as_f64().unwrap() as f32)
    };
    let mut img = image::open(faces.join("astronaut.png")).unwrap().to_rgba8();
    let (w, h) = img.dimensions();
    let style = phantogram_lab::drawn_glasses::style_for(0);
    assert_eq!(
        style.filters,
        (
            phantogram::face::glasses::Filter::Cyan,
            phantogram::face::glasses::Filter::Red
        )
    );
    phantogram_lab::drawn_glasses::draw(&mut img, w, h, eye(l), eye(r), &style);
    let glasses_dir = Scratch::new("cli-glasses");
    let with = glasses_dir.join("astronaut-glasses.png");
    img.save(&with).unwrap();
    // `eval face --json` of one image: its one line.
    let eval_one = |image: &std::path::Path| -> serde_json::Value {
        let out = bin()
            .args(["eval", "face", "--json", "--models"])
            .arg(&models)
            .arg(image)
            .output()
            .unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        serde_json::from_str(String::from_utf8_lossy(&out.stdout).trim()).unwrap()
    };
    let line = eval_one(&with);
    let face = &line["faces"][0];
    assert_eq!(face["glasses"]["left"], "red", "{face}");
    assert_eq!(face["glasses"]["right"], "cyan");
    assert_eq!(face["glasses"]["swapped"], false);
    assert_eq!(face["distance_from"], "eye distance");

    // The same bare photo as a phone held upright stores it: the sensor's landscape pixels,
    // with EXIF Orientation 6 (turn 90° clockwise to show). Read upright, its eyes are where
    // they are in the upright photo, to the pixel.
    {
        use image::ImageEncoder as _;
        let upright = image::open(faces.join("astronaut.png")).unwrap().to_rgba8();
        let stored = image::imageops::rotate270(&upright);
        // Little-endian TIFF header, IFD0 at 8 with one entry: Orientation (0x0112), SHORT, 6.
        let mut exif = b"II*\0\x08\0\0\0\x01\0".to_vec();
        exif.extend_from_slice(&[0x12, 0x01, 3, 0, 1, 0, 0, 0, 6, 0, 0, 0, 0, 0, 0, 0]);
        let turned = glasses_dir.join("astronaut-as-stored.png");
        let mut enc = image::codecs::png::PngEncoder::new(std::fs::File::create(&turned).unwrap());
        enc.set_exif_metadata(exif).unwrap();
        enc.write_image(
            stored.as_raw(),
            stored.width(),
            stored.height(),
            image::ExtendedColorType::Rgba8,
        )
        .unwrap();
        let line = eval_one(&turned);
        let turned_face = &line["faces"][0];
        for side in ["left_eye", "right_eye"] {
            let d = eye(&turned_face[side]).distance(eye(&lines[0]["faces"][0][side]));
            assert!(d < 0.01, "{side} {d} px from the upright photo's: {turned_face}");
        }
    }

    // A PNG whose header claims 60000 × 60000 pixels (14 GB to decode) and a Radiance HDR are
    // refused by name; the photo between them is still read.
    let dir = Scratch::new("cli-faces");
    let mut header = Vec::new();
    for side in [60_000u32, 60_000] {
        header.extend_from_slice(&side.to_be_bytes());
    }
    header.extend_from_slice(&[8, 6, 0, 0, 0]); // 8-bit RGBA
    // Two rows of image data, then the end: the decoder reads this far before it allocates.
    let rows = {
        use std::io::Write;
        let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::fast());
        z.write_all(&vec![0u8; 2 * (1 + 4 * 60_000)]).unwrap();
        z.finish().unwrap()
    };
    let mut bomb = b"\x89PNG\r\n\x1a\n".to_vec();
    for (kind, data) in [(&b"IHDR"[..], &header[..]), (b"IDAT", &rows), (b"IEND", b"")] {
        bomb.extend_from_slice(&(data.len() as u32).to_be_bytes());
        let mut crc = flate2::Crc::new();
        crc.update(kind);
        crc.update(data);
        bomb.extend_from_slice(kind);
        bomb.extend_from_slice(data);
        bomb.extend_from_slice(&crc.sum().to_be_bytes());
    }
    std::fs::write(dir.join("bomb.png"), &bomb).unwrap();
    std::fs::write(
        dir.join("light.hdr"),
        b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 1 +X 2\n\x80\x80\x80\x81\x80\x80\x80\x81",
    )
    .unwrap();
    let out = bin()
        .args(["eval", "face", "--json", "--models"])
        .arg(&models)
        .arg(dir.join("bomb.png"))
        .arg(faces.join("astronaut.png"))
        .arg(dir.join("light.hdr"))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{err}");
    assert!(
        err.contains("60000×60000 pixels is more than this tool decodes"),
        "{err}"
    );
    assert!(err.contains("not a PNG, JPEG or WebP photo (Hdr)"), "{err}");
    assert_eq!(String::from_utf8_lossy(&out.stdout).lines().count(), 1, "{err}");
}

/// `eval orientation` on a folder: a recording that cannot be read is named and skipped, the
/// others are still scored, and the exit status says something was left out.
#[test]
fn eval_orientation_scores_what_it_can_and_names_what_it_cannot() {
    let dir = Scratch::new("cli-eval");
    // Ten seconds at rest, level, facing north, in BROAD's CSV layout; moving (for the scorer)
    // after 6 s.
    let mut good =
        String::from("t_s,acc_x,acc_y,acc_z,gyr_x,gyr_y,gyr_z,mag_x,mag_y,mag_z,gt_qw,gt_qx,gt_qy,gt_qz,movement\n");
    for i in 0..1000 {
        let moving = u8::from(i > 600);
        good += &format!("{:.3},0,0,9.81,0,0,0,0,20,-40,1,0,0,0,{moving}\n", f64::from(i) * 0.01);
    }
    std::fs::write(dir.join("a_good.csv"), &good).unwrap();
    std::fs::write(
        dir.join("b_bad.csv"),
        format!("{}\n0.0,1,2\n", good.lines().next().unwrap()),
    )
    .unwrap();
    let out = bin().args(["eval", "orientation"]).arg(&*dir).output().unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{stderr}");
    assert!(stderr.contains("b_bad.csv:2:"), "{stderr}");
    assert!(stderr.contains("1 of 2 recording(s) could not be scored"), "{stderr}");
    let fused = stdout
        .lines()
        .find(|l| l.starts_with("a_good") && l.contains("fused"))
        .unwrap_or_else(|| panic!("the good recording is scored:\n{stdout}"));
    // At rest and matching the truth: every error is (nearly) zero.
    let errors: Vec<f64> = fused.split_whitespace().filter_map(|w| w.parse().ok()).collect();
    assert!(errors.len() >= 3 && errors[..3].iter().all(|e| *e < 0.1), "{fused}");
}

/// `eval orientation --estimator … --reference NAME=DIR`: only the chosen estimators, plus another
/// program's track scored by the same rows; a missing track is named and fails the run.
#[test]
fn eval_orientation_scores_a_reference_track() {
    let dir = Scratch::new("cli-eval-reference");
    let mut csv =
        String::from("t_s,acc_x,acc_y,acc_z,gyr_x,gyr_y,gyr_z,mag_x,mag_y,mag_z,gt_qw,gt_qx,gt_qy,gt_qz,movement\n");
    // The track: the truth (level, north) tilted 3° about x.
    let half = 1.5f64.to_radians();
    let mut track = String::from("t_ns,w,x,y,z\n");
    for i in 0..1000 {
        csv += &format!(
            "{:.3},0,0,9.81,0,0,0,0,20,-40,1,0,0,0,{}\n",
            f64::from(i) * 0.01,
            u8::from(i > 600)
        );
        track += &format!("{},{},{},0,0\n", i64::from(i) * 10_000_000, half.cos(), half.sin());
    }
    std::fs::write(dir.join("still.csv"), &csv).unwrap();
    let tracks = dir.join("tracks");
    std::fs::create_dir_all(&tracks).unwrap();
    std::fs::write(tracks.join("still.csv"), &track).unwrap();
    let out = bin()
        .args(["eval", "orientation", "--estimator", "fused", "--reference"])
        .arg(format!("THREE={}", tracks.display()))
        .arg(dir.join("still.csv"))
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(!stdout.contains("low-pass"), "{stdout}");
    let row = |name: &str| -> Vec<f64> {
        let line = stdout
            .lines()
            .find(|l| l.starts_with("still") && l.contains(name))
            .unwrap_or_else(|| panic!("no {name} row:\n{stdout}"));
        line.split_whitespace().filter_map(|w| w.parse().ok()).collect()
    };
    // incl, head, total, c.incl, c.head and the time per event (ours only).
    let fused = row("fused");
    assert!(fused.len() == 6 && fused[0] < 0.1 && fused[5] > 0.0, "{stdout}");
    let three = row("THREE");
    assert!(three.len() == 5, "no time for a replayed track:\n{stdout}");
    assert!((three[0] - 3.0).abs() < 0.01 && three[1] < 0.01, "{stdout}");

    // A folder without the trial's track: named, and the run fails.
    let empty = dir.join("empty");
    std::fs::create_dir_all(&empty).unwrap();
    let out = bin()
        .args(["eval", "orientation", "--estimator", "fused", "--reference"])
        .arg(format!("NONE={}", empty.display()))
        .arg(dir.join("still.csv"))
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(
        stderr.contains("--reference NONE") && stderr.contains("still.csv"),
        "{stderr}"
    );
    assert!(stderr.contains("1 reference track(s) could not be read"), "{stderr}");
    let out = bin()
        .args(["eval", "orientation", "--reference", "nonsense"])
        .arg(dir.join("still.csv"))
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("expected NAME=DIR"));
}

/// `render` into a folder that holds an earlier, longer run: the old frames do not trail the new
/// ones, and files that are not frames stay. Skipped (with a notice) without a GPU adapter,
/// except under CI.
#[test]
fn render_replaces_an_earlier_runs_frames_and_nothing_else() {
    let dir = Scratch::new("cli-render");
    for stale in ["frame_00013.png", "frame_00500.png"] {
        std::fs::write(dir.join(stale), b"old").unwrap();
    }
    std::fs::write(dir.join("notes.txt"), b"mine").unwrap();
    std::fs::write(dir.join("frame_1.png"), b"not one of ours").unwrap();
    let out = bin()
        .args(["render", "--every", "1000", "--size", "108x240", "--log"])
        .arg(default_log())
        .arg("--out")
        .arg(&*dir)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    if stderr.contains("no GPU adapter") && std::env::var_os("CI").is_none() {
        eprintln!("no GPU adapter: skipping the render test");
        return;
    }
    assert!(out.status.success(), "{stderr}");
    assert!(stderr.contains("removed 2 frames of an earlier run"), "{stderr}");
    let mut names: Vec<String> = std::fs::read_dir(&*dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    let mut expected: Vec<String> = (0..13).map(|i| format!("frame_{i:05}.png")).collect();
    expected.extend(["frame_1.png".to_owned(), "notes.txt".to_owned()]);
    assert_eq!(names, expected, "0 to 12 s every second, and the user's files");
}

/// `render --side-by-side`: frames twice as wide, the left eye's image on the left. Checked
/// against the plain colour anaglyph of the same frame, which carries the left eye in its red
/// channel and the right eye in green and blue.
/// `render ARGS --every EVERY_MS --size 180x400 --log <default log> --out OUT`; its stderr. A
/// missing GPU adapter is for the caller to skip on (it says so); any other failure fails.
fn render_default_log(args: &[&str], every_ms: &str, out: &std::path::Path) -> String {
    let run = bin()
        .arg("render")
        .args(args)
        .args(["--every", every_ms, "--size", "180x400", "--log"])
        .arg(default_log())
        .arg("--out")
        .arg(out)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&run.stderr).into_owned();
    assert!(run.status.success() || stderr.contains("no GPU adapter"), "{stderr}");
    stderr
}

#[test]
fn render_side_by_side_puts_each_eye_in_its_half() {
    let dir = Scratch::new("cli-side-by-side");
    let render = |args: &[&str], out: &std::path::Path| render_default_log(args, "6000", out);
    let stderr = render(&["--side-by-side"], &dir.join("pair"));
    if stderr.contains("no GPU adapter") && std::env::var_os("CI").is_none() {
        eprintln!("no GPU adapter: skipping the render test");
        return;
    }
    assert!(stderr.contains("360x400, left and right eye side by side"), "{stderr}");
    render(&["--anaglyph", "color"], &dir.join("anaglyph"));
    let pair = image::open(dir.join("pair/frame_00000.png")).unwrap().to_rgb8();
    let anaglyph = image::open(dir.join("anaglyph/frame_00000.png")).unwrap().to_rgb8();
    assert_eq!(pair.dimensions(), (360, 400));
    // Mean difference of one channel between the anaglyph and a half of the pair.
    let mismatch = |channel: usize, x0: u32| {
        let mut sum = 0u64;
        for y in 0..400 {
            for x in 0..180 {
                sum += u64::from(anaglyph.get_pixel(x, y).0[channel].abs_diff(pair.get_pixel(x0 + x, y).0[channel]));
            }
        }
        sum as f64 / (180.0 * 400.0)
    };
    let (red_left, red_right) = (mismatch(0, 0), mismatch(0, 180));
    let (green_left, green_right) = (mismatch(1, 0), mismatch(1, 180));
    assert!(
        red_left < 0.5 && green_right < 0.5,
        "halves not the eyes: {red_left:.2} / {green_right:.2}"
    );
    assert!(
        red_right > 4.0 * red_left.max(0.05) && green_left > 4.0 * green_right.max(0.05),
        "the eyes' images hardly differ: {red_right:.2} / {green_left:.2}"
    );
    assert!(
        failed_render(&["--side-by-side", "--anaglyph", "gray"], &dir.join("x")).contains("--anaglyph"),
        "side by side is no anaglyph"
    );
}

/// `check-artifacts`: a curator's folder loaded as a phone will; every entry that would not
/// show is named, and the run fails.
#[test]
fn check_artifacts_names_every_entry_that_would_not_show() {
    let dir = Scratch::new("cli-check-artifacts");
    let good = dir.join("good");
    std::fs::create_dir_all(good.join("scan")).unwrap();
    std::fs::write(
        good.join("votive.glb"),
        phantogram_testkit::tetrahedron_glb(0.1, r#""extras":{"title":"Votive"}"#),
    )
    .unwrap();
    std::fs::write(good.join("scan/x.glb"), phantogram_testkit::tetrahedron_glb(0.2, "")).unwrap();
    let run = bin().arg("check-artifacts").arg(&good).output().unwrap();
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    assert!(
        stdout.contains("ok votive.glb: Votive (4 triangles, 0 images), 100 × 100 × 100 mm wide, tall and deep")
            && stdout.contains("ok scan:"),
        "{stdout}"
    );

    let bad = dir.join("bad");
    std::fs::create_dir_all(&bad).unwrap();
    std::fs::write(bad.join("broken.glb"), b"glTF\x02\0\0\0 not a model").unwrap();
    std::fs::write(bad.join("notes.txt"), "a curator's notes").unwrap();
    std::fs::write(bad.join("fine.glb"), phantogram_testkit::tetrahedron_glb(0.1, "")).unwrap();
    let run = bin().arg("check-artifacts").arg(&bad).output().unwrap();
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(!run.status.success());
    assert!(
        stderr.contains("2 entries would not show")
            && stderr.contains("broken.glb: ")
            && stderr.contains("notes.txt: not a model file"),
        "{stderr}"
    );
    assert!(String::from_utf8_lossy(&run.stdout).contains("ok fine.glb"));
}

/// `render --artifact diorama`: a recorded log replayed into the Diorama's frames; the bodies
/// move between the first and the last, and the same log gives the same frames.
#[test]
fn render_replays_a_log_into_the_diorama() {
    let dir = Scratch::new("cli-diorama");
    let render = |out: &std::path::Path| render_default_log(&["--artifact", "diorama"], "3000", out);
    let stderr = render(&dir.join("a"));
    if stderr.contains("no GPU adapter") && std::env::var_os("CI").is_none() {
        eprintln!("no GPU adapter: skipping the Diorama render test");
        return;
    }
    render(&dir.join("b"));
    let frames: Vec<_> = std::fs::read_dir(dir.join("a"))
        .unwrap()
        .flatten()
        .map(|e| e.path())
        .collect();
    assert!(frames.len() >= 3, "{stderr}");
    let read = |p: &std::path::Path| image::open(p).unwrap().to_rgba8().into_raw();
    let first = read(&dir.join("a/frame_00000.png"));
    let last = read(&dir.join(format!("a/frame_{:05}.png", frames.len() - 1)));
    let differ = first.chunks(4).zip(last.chunks(4)).filter(|(a, b)| a != b).count();
    assert!(differ > 2000, "the bodies did not move ({differ} pixels)");
    for f in &frames {
        let name = f.file_name().unwrap();
        assert!(
            read(f) == read(&dir.join("b").join(name)),
            "{name:?} differs between two runs"
        );
    }
}

/// `render --material` and `--environment-from-camera` change the frame: a preset over the
/// artifact, and the light of a room a synthetic camera swept along the log (with the external
/// data's HDR rooms; the engine's own tests cover generated rooms).
#[test]
fn render_takes_a_material_and_a_room_seen_by_the_camera() {
    let dir = Scratch::new("cli-material-room");
    let plain = render_default_log(&[], "100000", &dir.join("plain"));
    if plain.contains("no GPU adapter") && std::env::var_os("CI").is_none() {
        eprintln!("no GPU adapter: skipping the render test");
        return;
    }
    let read = |name: &str| image::open(dir.join(name).join("frame_00000.png")).unwrap().to_rgba8();
    let differing = |a: &image::RgbaImage, b: &image::RgbaImage| {
        a.pixels()
            .zip(b.pixels())
            .filter(|(p, q)| p.0.iter().zip(q.0.iter()).any(|(x, y)| x.abs_diff(*y) > 8))
            .count()
    };
    render_default_log(&["--material", "brushed-metal"], "100000", &dir.join("metal"));
    assert!(differing(&read("plain"), &read("metal")) > 1000);
    let Some(data) = std::env::var_os("PHANTOGRAM_DATA") else {
        eprintln!("PHANTOGRAM_DATA not set: the room part is skipped");
        return;
    };
    let room = std::path::Path::new(&data).join("env/venice_sunset_1k.hdr");
    let log = default_log();
    let stderr = render_default_log(
        &[
            "--environment",
            room.to_str().unwrap(),
            "--environment-from-camera",
            log.to_str().unwrap(),
        ],
        "100000",
        &dir.join("room"),
    );
    assert!(
        stderr.contains("room light: ") && stderr.contains("% of the room seen"),
        "{stderr}"
    );
    assert!(differing(&read("plain"), &read("room")) > 1000);
    // The rear camera too: twice the frames, more of the room seen, another light.
    let seen = |stderr: &str| -> f32 {
        let before = stderr.split(" % of the room seen").next().unwrap_or_default();
        before
            .rsplit(", ")
            .next()
            .and_then(|v| v.trim().parse().ok())
            .unwrap_or(f32::NAN)
    };
    let both = render_default_log(
        &[
            "--environment",
            room.to_str().unwrap(),
            "--environment-from-camera",
            log.to_str().unwrap(),
            "--rear-camera",
        ],
        "100000",
        &dir.join("both"),
    );
    assert!(both.contains(" front, ") && both.contains(" rear)"), "{both}");
    assert!(seen(&both) > seen(&stderr) + 10.0, "{stderr}\n{both}");
    assert!(differing(&read("room"), &read("both")) > 100);
}
