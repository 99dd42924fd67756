//! Every recording in `$PHANTOGRAM_DATA/imu` imports and replays through the whole core, and a
//! corrupted copy of each file the importers read fails with an error naming that file and line.
//!
//! Needs the external data: set `PHANTOGRAM_DATA` (`.ci/run` sets it to `../shared/data`). Without
//! the variable these tests print a notice and return; with a wrong one they fail.

use std::collections::BTreeSet;
use std::io::Write;
use std::path::{Path, PathBuf};

use phantogram::sensors::SensorKind;
use phantogram::{Session, SessionConfig};
use phantogram_integration::{Scratch, data_subdir, scratch};
use phantogram_lab::replay::{Pace, replay};
use phantogram_lab::sensorlog::import::{ImportedLog, import};

/// Files in the data folders that are not sensor streams, with the reason they are not read.
const NOT_SENSOR_DATA: &[(&str, &str)] = &[
    ("madgwick.json", "published per-trial results, not a recording"),
    ("mahony.json", "published per-trial results, not a recording"),
    ("record.properties", "device description"),
    ("LICENSE", "licence text"),
    (
        "imu_orientation.csv",
        "derived output with an undocumented angle convention",
    ),
];

fn imu_dir() -> Option<PathBuf> {
    data_subdir("imu")
}

fn sorted_entries(dir: &Path) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.unwrap().path())
        .collect();
    v.sort();
    v
}

/// Each recording: a BROAD trial file, or a folder of an Android dump / app export.
fn recordings(imu: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for group in ["broad", "phone", "phyphox", "sensorlogger"] {
        for p in sorted_entries(&imu.join(group)) {
            let name = p.file_name().unwrap().to_string_lossy().into_owned();
            if p.is_dir() || name.ends_with(".csv.gz") {
                out.push(p);
            } else {
                assert!(
                    NOT_SENSOR_DATA.iter().any(|(n, _)| *n == name),
                    "unexpected file {}",
                    p.display()
                );
            }
        }
    }
    out
}

/// Files of a recording that its importer must read (all but the known non-sensor files).
fn sensor_files(recording: &Path) -> Vec<PathBuf> {
    if recording.is_file() {
        return vec![recording.to_path_buf()];
    }
    sorted_entries(recording)
        .into_iter()
        .filter(|p| {
            let name = p.file_name().unwrap().to_string_lossy();
            !NOT_SENSOR_DATA.iter().any(|(n, _)| *n == name)
        })
        .collect()
}

fn read_names(log: &ImportedLog) -> BTreeSet<String> {
    log.meta
        .iter()
        .filter(|(k, _)| k == "read")
        .map(|(_, v)| v.clone())
        .collect()
}

#[test]
fn every_recording_imports_and_replays() {
    let Some(imu) = imu_dir() else { return };
    let recs = recordings(&imu);
    assert!(
        recs.len() >= 22,
        "expected the 14 BROAD trials and 8 recording folders, found {}",
        recs.len()
    );
    for rec in recs {
        let log = import(&rec).unwrap_or_else(|e| panic!("{e}"));
        let name = rec.file_name().unwrap().to_string_lossy().into_owned();
        assert!(log.events.len() > 1000, "{name}: only {} events", log.events.len());
        assert!(
            log.events.windows(2).all(|w| w[0].t_ns <= w[1].t_ns),
            "{name}: not time-ordered"
        );
        // Nothing in the folder was silently left out.
        if rec.is_dir() {
            let files: BTreeSet<String> = sensor_files(&rec)
                .iter()
                .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
                .collect();
            assert_eq!(read_names(&log), files, "{name}: files read vs present");
        }
        let has_gravity = log.count(SensorKind::Accelerometer) > 0;
        let mut session = Session::new(SessionConfig::default()).unwrap();
        let mut frames = 0u32;
        let mut moved = 0u32;
        let summary = replay(
            log.events.iter().copied().map(Ok),
            &mut session,
            100_000_000,
            Pace::AsFastAsPossible,
            |_, _, view| {
                frames += 1;
                assert!(view.eyes.cyclopean_m.is_finite() && view.toward_light_device.is_finite());
                assert!(view.left.view_proj.is_finite() && view.right.view_proj.is_finite());
                // The eye leaves the straight-on default once gravity is known.
                moved += u32::from(view.eyes.cyclopean_m.distance(phantogram::glam::Vec3::Z * 0.3) > 1e-4);
            },
        )
        .unwrap_or_else(|e| panic!("{name}: {e}"));
        let s = summary.stats;
        println!(
            "{name}: {} events, {frames} frames, rejected {} (non-finite {}, duplicate {}, backward {})",
            summary.events_read,
            s.rejected(),
            s.rejected_non_finite,
            s.rejected_duplicate,
            s.rejected_backward
        );
        assert!(frames > 50, "{name}: {frames} frames");
        assert_eq!(
            s.accepted + s.rejected(),
            summary.events_read,
            "{name}: every event accounted for"
        );
        if has_gravity {
            assert!(moved > frames / 2, "{name}: the viewpoint did not follow gravity");
        }
    }
}

fn gunzip_if_needed(bytes: Vec<u8>) -> (Vec<u8>, bool) {
    if bytes.starts_with(&[0x1f, 0x8b]) {
        (
            phantogram_integration::gunzip(&bytes).expect("valid gzip in the shared data"),
            true,
        )
    } else {
        (bytes, false)
    }
}

/// Copies `recording` into a scratch folder with line `line` of `victim` replaced by garbage;
/// returns the path to import, and the folder (removed when dropped).
fn corrupted_copy(recording: &Path, victim: &Path, line: usize, tag: &str) -> (PathBuf, Scratch) {
    let dir = scratch(tag);
    let files = if recording.is_dir() {
        sorted_entries(recording)
    } else {
        vec![recording.to_path_buf()]
    };
    for f in files {
        let target = dir.join(f.file_name().unwrap());
        if f != victim {
            std::fs::copy(&f, &target).unwrap();
            continue;
        }
        let (text, gz) = gunzip_if_needed(std::fs::read(&f).unwrap());
        let text = String::from_utf8(text).unwrap();
        let mut lines: Vec<&str> = text.lines().collect();
        assert!(lines.len() >= line, "{} has too few lines", f.display());
        lines[line - 1] = "garbage;?";
        let new = lines.join("\n") + "\n";
        let bytes = if gz {
            phantogram_integration::gzip(new.as_bytes())
        } else {
            new.into_bytes()
        };
        std::fs::File::create(&target).unwrap().write_all(&bytes).unwrap();
    }
    let path = if recording.is_dir() {
        dir.to_path_buf()
    } else {
        dir.join(recording.file_name().unwrap())
    };
    (path, dir)
}

#[test]
fn every_corrupted_file_fails_with_file_and_line() {
    let Some(imu) = imu_dir() else { return };
    let mut checked = 0;
    for rec in recordings(&imu) {
        for (i, victim) in sensor_files(&rec).into_iter().enumerate() {
            let name = victim.file_name().unwrap().to_string_lossy().into_owned();
            let (text, _) = gunzip_if_needed(std::fs::read(&victim).unwrap());
            // Line 3 is a data line in every format here; single-line files get line 1.
            let line = if text.iter().filter(|&&b| b == b'\n').count() >= 3 {
                3
            } else {
                1
            };
            let (copy, _dir) = corrupted_copy(&rec, &victim, line, &format!("corrupt-{checked}-{i}"));
            let err = match import(&copy) {
                Ok(_) => panic!("{}: corrupting line {line} of {name} went unnoticed", rec.display()),
                Err(e) => e,
            };
            let shown = err.to_string();
            assert!(shown.contains(&format!("{name}:{line}:")), "{shown}");
            assert_eq!(err.line(), Some(line as u64));
            checked += 1;
        }
    }
    println!("{checked} corrupted files, each reported with file:line");
    assert!(checked >= 50, "only {checked} files checked");
}
