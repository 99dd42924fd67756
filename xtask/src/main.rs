//! `cargo xtask <task>`: build automation that needs more than one cargo command.
//!
//! * `assets` — regenerate what the project generates itself into `assets/` (the synthetic tilt
//!   log). Deterministic: running it twice gives identical files.
//! * `bench core` — run the core benchmark (ns per sensor update and per frame).
//! * `bench render` — cold load-to-first-frame of the Draco turtle, stereo/mono frame-time ratio
//!   at 1080×2400, peak memory (`PHANTOGRAM_DATA` for the turtle).
//! * `bench orientation` — score the orientation estimators on the recordings in
//!   `$PHANTOGRAM_DATA/imu` and write the table to `benchmarks/orientation.md`.
//! * `ci` — what `.ci/run` runs after installing packages: fmt check, clippy, tests.

use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{Context, Result, bail};

fn main() -> Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    match args.as_slice() {
        ["assets"] => assets(),
        ["bench", "core"] | ["bench"] => cargo(&["bench", "-p", "phantogram", "--bench", "core"]),
        ["bench", "orientation"] => bench_orientation(),
        ["bench", "render"] => cargo(&["bench", "-p", "phantogram", "--bench", "render"]),
        ["ci"] => {
            cargo(&["fmt", "--all", "--check"])?;
            cargo(&["clippy", "--workspace", "--all-targets", "--", "-D", "warnings"])?;
            cargo(&["test", "--workspace"])
        }
        [] | ["help"] | ["--help"] => {
            println!("usage: cargo xtask <assets | bench core | bench render | bench orientation | ci>");
            Ok(())
        }
        other => bail!("unknown task {other:?}; try `cargo xtask help`"),
    }
}

fn workspace_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .map(Path::to_path_buf)
        .unwrap_or_else(|| PathBuf::from("."))
}

fn cargo(args: &[&str]) -> Result<()> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let status = Command::new(&cargo)
        .args(args)
        .current_dir(workspace_root())
        .status()
        .with_context(|| format!("could not run {cargo}"))?;
    if !status.success() {
        bail!("`cargo {}` failed ({status})", args.join(" "));
    }
    Ok(())
}

fn assets() -> Result<()> {
    use phantogram::synthetic::{ImuSpec, tilt_sweep, tilt_sweep_meta};
    let dir = workspace_root().join("assets/logs");
    std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
    let path = dir.join("tilt-sweep.pglog");
    let events = tilt_sweep(&ImuSpec::default());
    phantogram::sensorlog::write_log(&path, &tilt_sweep_meta(), &events)?;
    println!("wrote {} ({} events)", path.display(), events.len());
    Ok(())
}

fn bench_orientation() -> Result<()> {
    let data = std::env::var_os("PHANTOGRAM_DATA")
        .map(PathBuf::from)
        .context("set PHANTOGRAM_DATA to the external data folder (e.g. ../shared/data)")?;
    let data = std::fs::canonicalize(&data).with_context(|| format!("{} does not exist", data.display()))?;
    let broad = data.join("imu/broad");
    let phone = data.join("imu/phone");
    cargo(&["build", "--release", "-p", "phantogram"])?;
    let exe = workspace_root().join("target/release/phantogram");
    let output = Command::new(&exe)
        .args(["eval", "orientation"])
        .arg(&broad)
        .arg(&phone)
        .stderr(std::process::Stdio::inherit())
        .output()
        .with_context(|| format!("could not run {}", exe.display()))?;
    if !output.status.success() {
        bail!("`phantogram eval orientation` failed ({})", output.status);
    }
    let table = String::from_utf8_lossy(&output.stdout);
    let text = format!(
        "# Orientation estimators on the recorded trials\n\n\
         Made by `PHANTOGRAM_DATA=../shared/data cargo xtask bench orientation`, which runs\n\
         `phantogram eval orientation $PHANTOGRAM_DATA/imu/broad $PHANTOGRAM_DATA/imu/phone` (release build).\n\n\
         RMSE in degrees with BROAD's definitions: `incl`, `head`, `total` over the main rows (after the\n\
         first 5 s; BROAD: movement phases only), `c.incl`, `c.head` over the first 5 s (convergence).\n\
         Phone ground truth has the motion-capture room's heading, so only inclination is scored there.\n\
         `ns/evt`: wall time per sensor event (accelerometer, gyroscope or magnetometer) on the machine\n\
         that ran it (shared, noisy: compare within one run).\n\n```text\n{table}```\n"
    );
    let out = workspace_root().join("benchmarks/orientation.md");
    std::fs::create_dir_all(out.parent().expect("has a parent"))?;
    std::fs::write(&out, text).with_context(|| format!("writing {}", out.display()))?;
    println!("wrote {}", out.display());
    Ok(())
}
