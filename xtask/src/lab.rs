//! The xtask tasks that need the lab crate (log writing, recording names): built only with the
//! `lab` feature, which `with_lab` in `main.rs` turns on by running xtask again.

use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{Context, Result, bail};

use crate::{cargo, run, workspace_root};

pub(crate) fn run_task(args: &[&str]) -> Result<()> {
    match args {
        ["assets"] => assets(),
        ["bench", "orientation"] => bench_orientation(),
        other => bail!("{other:?} is not a lab task"),
    }
}

fn assets() -> Result<()> {
    use phantogram_sensing::synthetic::{ImuSpec, tilt_sweep, tilt_sweep_meta};
    let dir = workspace_root().join("assets/logs");
    std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
    let path = dir.join("tilt-sweep.pglog");
    let events = tilt_sweep(&ImuSpec::default());
    phantogram_lab::sensorlog::write_log(&path, &tilt_sweep_meta(), &events)?;
    println!("wrote {} ({} events)", path.display(), events.len());
    Ok(())
}

/// VQF as published on PyPI, for the comparison column (never a dependency of the project).
const VQF_PIP_PACKAGES: [&str; 2] = ["vqf==2.1.2", "numpy"];

/// The recordings `bench orientation` scores, in its table's order: every BROAD trial of
/// `imu/broad` and `imu/broad-extra`, and every phone recording folder of `imu/phone`.
fn orientation_recordings(imu: &Path) -> Result<Vec<(String, PathBuf)>> {
    let mut out = Vec::new();
    for group in ["broad", "broad-extra", "phone"] {
        let dir = imu.join(group);
        let mut found: Vec<(String, PathBuf)> = std::fs::read_dir(&dir)
            .with_context(|| format!("reading {}", dir.display()))?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| {
                if group == "phone" {
                    p.join("accelerometer.txt.gz").is_file()
                } else {
                    p.to_string_lossy().ends_with(".csv.gz")
                }
            })
            // Named as `phantogram eval orientation` names the trial, which finds VQF's track by it.
            .map(|p| (phantogram_lab::orientation_eval::trial_name(&p), p))
            .collect();
        if found.is_empty() {
            bail!("no recordings in {}", dir.display());
        }
        found.sort();
        out.extend(found);
    }
    Ok(out)
}

/// What follows the generated table in `benchmarks/orientation.md`: from its first `## ` heading
/// on, with the blank line before it; empty when there is none.
fn analyses_after_table(old: &str) -> &str {
    match old.find("\n## ") {
        Some(i) => &old[i..],
        None => "",
    }
}

fn bench_orientation() -> Result<()> {
    let data = std::env::var_os("PHANTOGRAM_DATA")
        .map(PathBuf::from)
        .context("set PHANTOGRAM_DATA to the external data folder (e.g. ../shared/data)")?;
    let data = std::fs::canonicalize(&data).with_context(|| format!("{} does not exist", data.display()))?;
    let imu = data.join("imu");
    let recordings = orientation_recordings(&imu)?;
    cargo(&["build", "--release", "-p", "phantogram"])?;
    let exe = workspace_root().join("target/release/phantogram");

    // VQF's tracks: each recording in the project's log format (same time stamps as our
    // estimators see), run through VQF by benchmarks/vqf/vqf_reference.py in a private virtual
    // environment under target/.
    let work = workspace_root().join("target/bench-orientation");
    if work.exists() {
        std::fs::remove_dir_all(&work).with_context(|| format!("clearing {}", work.display()))?;
    }
    let logs = work.join("logs");
    let tracks = work.join("vqf");
    std::fs::create_dir_all(&logs)?;
    let mut log_paths = Vec::new();
    for (name, path) in &recordings {
        let log = logs.join(format!("{name}.pglog.gz"));
        run(Command::new(&exe).arg("import").arg(path).arg("--out").arg(&log))
            .with_context(|| format!("importing {}", path.display()))?;
        log_paths.push(log);
    }
    let python = std::env::var("PYTHON").unwrap_or_else(|_| "python3".into());
    let venv = workspace_root().join("target/vqf-venv");
    if !venv.join("bin/python").is_file() {
        println!("creating a Python virtual environment in {}", venv.display());
        run(Command::new(&python).args(["-m", "venv"]).arg(&venv))
            .context("could not create a virtual environment for VQF; on Debian/Ubuntu install python3-venv")?;
        run(Command::new(venv.join("bin/pip"))
            .args(["install", "--quiet", "--disable-pip-version-check"])
            .args(VQF_PIP_PACKAGES))
        .context("pip could not install VQF (no network?)")?;
    }
    run(Command::new(venv.join("bin/python"))
        .arg(workspace_root().join("benchmarks/vqf/vqf_reference.py"))
        .arg(&tracks)
        .args(&log_paths))
    .context("benchmarks/vqf/vqf_reference.py failed")?;

    let output = Command::new(&exe)
        .args(["eval", "orientation"])
        .args(recordings.iter().map(|(_, p)| p))
        .arg("--reference")
        .arg(format!("VQF={}", tracks.display()))
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
         `phantogram eval orientation` on every recording of `$PHANTOGRAM_DATA/imu/broad`,\n\
         `imu/broad-extra` and `imu/phone` (release build), with a VQF column: VQF 2.1.2 (PyPI `vqf`,\n\
         default parameters, 9-D) run by `benchmarks/vqf/vqf_reference.py` on the same samples\n\
         (phones: accelerometer and magnetometer interpolated onto the gyroscope's time stamps) and\n\
         scored by the same code (`--reference VQF=DIR`). VQF needs one sample rate, so it steps\n\
         through a gap in the gyroscope as one sample: in `Guillaume_Nexus5_NoDist_AR` the gyroscope\n\
         stops for 23.7 s at 66.7 s, where VQF (and Android's rotation vector) lose the attitude;\n\
         the phone means of those two rest on that trial.\n\n\
         RMSE in degrees with BROAD's definitions: `incl`, `head`, `total` over the main rows (after the\n\
         first 5 s; BROAD: movement phases only), `c.incl`, `c.head` over the first 5 s (convergence).\n\
         Phone ground truth has the motion-capture room's heading, not north: there `head` and `total` are\n\
         scored after removing the constant turn between the room and the estimator's north (the circular\n\
         mean of its heading errors over the main rows), so they measure how steady the heading is.\n\
         Phone truth is also the marker body's attitude, 1–2° off the phone's IMU: that is the floor of ~2° every\n\
         estimator shows there. `phone_inclination_floor_is_the_marker_mounting` (tests/tests/integration/fusion_real.rs)\n\
         scores the phone trials against the truth turned onto the IMU as well.\n\
         `ns/evt`: wall time per sensor event (accelerometer, gyroscope or magnetometer) on the machine\n\
         that ran it (shared, noisy: compare within one run); none for VQF's replayed tracks.\n\n```text\n{table}```\n"
    );
    let out = workspace_root().join("benchmarks/orientation.md");
    std::fs::create_dir_all(out.parent().expect("has a parent"))?;
    // The sections written by hand below the table (analyses, parameter sweeps) are kept.
    let kept = match std::fs::read_to_string(&out) {
        Ok(old) => analyses_after_table(&old).to_owned(),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => String::new(),
        Err(e) => return Err(e).with_context(|| format!("reading {}", out.display())),
    };
    std::fs::write(&out, text + &kept).with_context(|| format!("writing {}", out.display()))?;
    println!("wrote {}", out.display());
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::analyses_after_table;

    #[test]
    fn the_hand_written_sections_below_the_table_are_kept() {
        let old = "# Orientation\n\nintro\n\n```text\ntable\n```\n\n## A sweep\n\nfigures\n\n## Another\n";
        assert_eq!(analyses_after_table(old), "\n## A sweep\n\nfigures\n\n## Another\n");
        assert_eq!(analyses_after_table("# Orientation\n\n```text\ntable\n```\n"), "");
    }
}
