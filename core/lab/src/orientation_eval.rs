//! Scoring orientation estimators against recorded ground truth, with the BROAD benchmark's
//! definitions (Laidig et al. 2021; `broad_utils.py`):
//!
//! * error quaternion in the earth frame `q_e = q_est ⊗ q_gt⁻¹`;
//! * total error `2·acos(|w|)`, heading error `2·atan(|z / w|)`, inclination error
//!   `2·acos(√(w² + z²))`;
//! * RMSE over the rows marked as movement (BROAD) or over all ground-truth rows (phone
//!   recordings, whose motion capture has no such mark).
//!
//! Phone recordings' ground truth has the motion-capture room's heading, not north. The
//! inclination error does not depend on the reference's heading and is scored as is; heading and
//! total errors are scored after removing the constant turn between the room and the estimator's
//! north, fitted per trial and estimator as the circular mean of the signed heading errors over
//! the main rows (the same turn then applies to the convergence rows). So on phone trials the
//! heading figure measures how steady an estimator's heading is, not where its north lies. The first
//! [`CONVERGENCE_S`] seconds of each trial are scored separately, as convergence, and left out of
//! the main figures.
//!
//! Estimators see the events in time order; at each ground-truth time stamp the estimate is read
//! (no prediction). Another program's estimates (VQF's, for the benchmark) are scored the same way
//! by replaying its track as an estimator ([`RecordedTrack`]).

use phantogram_sensing::clock::elapsed_s;
use std::path::Path;
use std::time::Instant;

use glam::DQuat;

use crate::sensorlog::LogError;
use crate::sensorlog::import::{self, SourceFormat};
use phantogram_sensing::attitude::{LowPassAttitude, OrientationEstimator};
use phantogram_sensing::fusion::FusedOrientation;
use phantogram_sensing::lowpass::time_constant_from_paper_coefficient;
use phantogram_sensing::sensors::{SensorEvent, SensorKind};

/// Seconds at the start of a trial reported separately as convergence.
pub const CONVERGENCE_S: f64 = 5.0;

/// What the ground truth of a trial supports.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TruthFrame {
    /// Earth frame with north: inclination, heading and total errors.
    EastNorthUp,
    /// Heading of an arbitrary room: inclination only.
    ArbitraryHeading,
}

/// A recording with ground truth.
#[derive(Clone, Debug)]
pub struct Trial {
    pub name: String,
    pub events: Vec<SensorEvent>,
    pub truth_frame: TruthFrame,
    /// Movement phases (BROAD): `(t_ns, moving)` at each row; `None` scores every row.
    pub movement: Option<Vec<(i64, bool)>>,
}

/// A recording's trial name: its file name without `.csv.gz` / `.csv` (BROAD), or its folder's
/// name (phone recordings). Tables, reference tracks (`DIR/<name>.csv`) and the benchmark's logs
/// are keyed by it.
pub fn trial_name(path: &Path) -> String {
    path.file_name()
        .map(|n| {
            n.to_string_lossy()
                .trim_end_matches(".csv.gz")
                .trim_end_matches(".csv")
                .to_owned()
        })
        .unwrap_or_else(|| path.display().to_string())
}

/// BROAD's inclination error of an estimate, rad: `2·acos(√(w² + z²))` of the earth-frame error
/// quaternion `est ⊗ truth⁻¹` (independent of either side's heading).
pub fn inclination_error_rad(est: DQuat, truth: DQuat) -> f64 {
    let e = (est * truth.inverse()).normalize();
    2.0 * (e.w * e.w + e.z * e.z).sqrt().clamp(0.0, 1.0).acos()
}

impl Trial {
    pub fn load(path: &Path) -> Result<Self, LogError> {
        let format = import::detect(path)?;
        let log = import::import(path)?;
        let name = trial_name(path);
        let (truth_frame, movement) = match format {
            SourceFormat::Broad => (TruthFrame::EastNorthUp, Some(import::read_broad_movement(path)?)),
            _ => (TruthFrame::ArbitraryHeading, None),
        };
        if !log.events.iter().any(|e| e.kind == SensorKind::GroundTruth) {
            return Err(LogError::format(path, "no ground-truth orientation in this recording"));
        }
        Ok(Self {
            name,
            events: log.events,
            truth_frame,
            movement,
        })
    }

    /// Median accelerometer rate, Hz (for converting the paper's per-sample coefficient).
    pub fn accel_rate_hz(&self) -> f64 {
        let mut dts: Vec<i64> = self
            .events
            .iter()
            .filter(|e| e.kind == SensorKind::Accelerometer)
            .map(|e| e.t_ns)
            .collect::<Vec<_>>()
            .windows(2)
            .map(|w| w[1] - w[0])
            .filter(|d| *d > 0)
            .collect();
        if dts.is_empty() {
            return 100.0;
        }
        dts.sort_unstable();
        1e9 / dts[dts.len() / 2] as f64
    }

    pub fn has(&self, kind: SensorKind) -> bool {
        self.events.iter().any(|e| e.kind == kind)
    }
}

/// RMSEs in degrees over a set of rows.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Rmse {
    pub rows: usize,
    pub inclination_deg: f64,
    /// `None` where the estimate has no heading. On room-frame truth, after removing the constant
    /// turn between the room and the estimator's north (see the module docs).
    pub heading_deg: Option<f64>,
    pub total_deg: Option<f64>,
}

#[derive(Default)]
struct Accumulator {
    n: usize,
    incl: f64,
    /// Earth-frame error quaternions of the rows whose estimate had a heading of its own; only
    /// they score heading and total. Kept whole: room-frame truth needs its turn removed first.
    heading_errors: Vec<DQuat>,
}

impl Accumulator {
    /// One row; `has_heading` is false for an estimate made from "up" alone (any heading).
    fn add(&mut self, est: DQuat, truth: DQuat, has_heading: bool) {
        let incl = inclination_error_rad(est, truth);
        self.n += 1;
        self.incl += incl * incl;
        if has_heading {
            self.heading_errors.push((est * truth.inverse()).normalize());
        }
    }

    /// The constant turn about the vertical between the estimator's frame and the truth's, rad:
    /// the circular mean of the signed heading errors (`2·atan2(z, w)`, the heading part of
    /// BROAD's decomposition). `None` without rows that have a heading.
    fn heading_offset_rad(&self) -> Option<f64> {
        if self.heading_errors.is_empty() {
            return None;
        }
        let (sin, cos) = self.heading_errors.iter().fold((0.0, 0.0), |(s, c), e| {
            let h = 2.0 * e.z.atan2(e.w);
            (s + h.sin(), c + h.cos())
        });
        Some(sin.atan2(cos))
    }

    /// RMSEs; heading and total only with `heading_offset_rad`, removed from every error first
    /// (0 for truth with north).
    fn finish(&self, heading_offset_rad: Option<f64>) -> Rmse {
        let r = |s: f64, n: usize| {
            if n == 0 {
                f64::NAN
            } else {
                (s / n as f64).sqrt().to_degrees()
            }
        };
        let heading = heading_offset_rad
            .filter(|_| !self.heading_errors.is_empty())
            .map(|offset| {
                let unturn = DQuat::from_rotation_z(-offset);
                let (head, total) = self.heading_errors.iter().fold((0.0, 0.0), |(h, t), e| {
                    let e = unturn * *e;
                    let head = 2.0 * (e.z / e.w).abs().atan();
                    let total = 2.0 * e.w.abs().clamp(0.0, 1.0).acos();
                    (h + head * head, t + total * total)
                });
                let n = self.heading_errors.len();
                (r(head, n), r(total, n))
            });
        Rmse {
            rows: self.n,
            inclination_deg: r(self.incl, self.n),
            heading_deg: heading.map(|h| h.0),
            total_deg: heading.map(|h| h.1),
        }
    }
}

/// One estimator's score on one trial.
#[derive(Clone, Debug, PartialEq)]
pub struct Score {
    pub estimator: String,
    /// Rows after the convergence period (and in movement phases, where marked).
    pub main: Rmse,
    /// Rows in the first [`CONVERGENCE_S`] seconds.
    pub convergence: Rmse,
    /// Wall time per sensor event (accelerometer, gyroscope or magnetometer), nanoseconds.
    pub ns_per_event: f64,
    /// Ground-truth rows where the estimator had no estimate yet.
    pub rows_without_estimate: usize,
}

/// Runs `estimator` over the trial and scores it. An estimator that knows "up" but has no
/// heading (the low-pass without a magnetometer) is still scored for inclination, from "up"
/// alone; its heading and total errors are then not reported.
pub fn score(trial: &Trial, name: &str, estimator: &mut dyn OrientationEstimator) -> Score {
    let t0 = trial.events.first().map_or(0, |e| e.t_ns);
    let mut movement = trial.movement.as_deref().map(|m| m.iter().peekable());
    let mut main = Accumulator::default();
    let mut conv = Accumulator::default();
    let mut missing = 0;
    let mut sensor_events = 0usize;
    let mut busy = std::time::Duration::ZERO;
    let mut pending: Vec<SensorEvent> = Vec::with_capacity(8);
    let mut flush = |estimator: &mut dyn OrientationEstimator, pending: &mut Vec<SensorEvent>| {
        let start = Instant::now();
        for e in pending.iter() {
            estimator.push(e);
        }
        busy += start.elapsed();
        sensor_events += pending.len();
        pending.clear();
    };
    for e in &trial.events {
        if e.kind != SensorKind::GroundTruth {
            // Batch events between ground-truth rows so the timer brackets real work.
            pending.push(*e);
            continue;
        }
        flush(estimator, &mut pending);
        let Some(truth) = e.quat() else { continue };
        let moving = match &mut movement {
            Some(iter) => {
                while iter.peek().is_some_and(|(t, _)| *t < e.t_ns) {
                    iter.next();
                }
                iter.peek().is_some_and(|(t, m)| *t == e.t_ns && *m)
            }
            None => true,
        };
        let (est, has_heading) = match estimator.device_to_world() {
            Some(q) => (q, true),
            // Any heading will do: the inclination error does not depend on it.
            None => match estimator
                .up_device()
                .and_then(phantogram_sensing::attitude::device_to_world_from_up)
            {
                Some(q) => (q, false),
                None => {
                    missing += 1;
                    continue;
                }
            },
        };
        let (est, truth) = (est.as_dquat(), truth.as_dquat());
        let in_convergence = elapsed_s(t0, e.t_ns) < CONVERGENCE_S;
        // The inclination error does not depend on the reference's heading (a rotation about the
        // vertical on either side leaves the tilt angle unchanged), so room-frame truth scores it
        // the same way; heading and total are scored there after removing the room's turn.
        if in_convergence {
            conv.add(est, truth, has_heading);
        } else if moving {
            main.add(est, truth, has_heading);
        }
    }
    flush(estimator, &mut pending);
    let heading_offset_rad = match trial.truth_frame {
        TruthFrame::EastNorthUp => Some(0.0),
        TruthFrame::ArbitraryHeading => main.heading_offset_rad(),
    };
    Score {
        estimator: name.to_owned(),
        main: main.finish(heading_offset_rad),
        convergence: conv.finish(heading_offset_rad),
        ns_per_event: busy.as_nanos() as f64 / sensor_events.max(1) as f64,
        rows_without_estimate: missing,
    }
}

/// The platform's own rotation vector as an "estimator", for comparison.
#[derive(Clone, Debug, Default)]
pub struct PlatformRotationVector {
    latest: Option<glam::Quat>,
}

impl OrientationEstimator for PlatformRotationVector {
    fn push(&mut self, event: &SensorEvent) {
        if event.kind == SensorKind::RotationVector
            && let Some(q) = event.quat()
        {
            self.latest = Some(q);
        }
    }

    fn up_device(&self) -> Option<glam::Vec3> {
        self.latest.map(|q| q.inverse() * glam::Vec3::Z)
    }

    fn device_to_world(&self) -> Option<glam::Quat> {
        self.latest
    }

    fn reset(&mut self) {
        self.latest = None;
    }
}

/// The paper's coefficient.
pub const PAPER_C: f32 = 0.1;

/// The paper's low-pass coefficients tried when searching for the best `c` of a trial (the
/// paper's own among them).
pub const LOW_PASS_C_GRID: [f32; 10] = [0.002, 0.005, 0.01, 0.02, 0.03, 0.05, 0.1, 0.2, 0.3, 0.5];

/// Which estimators [`score_selected`] runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Selection {
    /// The paper's low-pass at c = 0.1 and at its best c.
    pub low_pass: bool,
    pub fused: bool,
    /// The platform's rotation vector, where the recording has one.
    pub platform: bool,
}

impl Selection {
    pub const ALL: Self = Self {
        low_pass: true,
        fused: true,
        platform: true,
    };
}

/// All scores for one trial: low-pass at c = 0.1, low-pass at its best c (lowest main
/// inclination RMSE over [`LOW_PASS_C_GRID`]), the fused estimator, and the platform rotation
/// vector where the recording has one.
pub fn score_all(trial: &Trial) -> Vec<Score> {
    score_selected(trial, Selection::ALL)
}

/// The scores of [`score_all`] that `which` selects, in the same order.
pub fn score_selected(trial: &Trial, which: Selection) -> Vec<Score> {
    let mut out = Vec::new();
    if which.low_pass {
        let rate = trial.accel_rate_hz() as f32;
        let low_pass = |c: f32| {
            let tau = time_constant_from_paper_coefficient(c, rate).unwrap_or(0.0);
            let mut est = LowPassAttitude::new(tau, tau);
            score(trial, &format!("low-pass c={c}"), &mut est)
        };
        // Each coefficient of the grid once; the paper's c = 0.1 is one of them.
        let grid: Vec<Score> = LOW_PASS_C_GRID.iter().map(|&c| low_pass(c)).collect();
        let paper = grid
            .iter()
            .zip(LOW_PASS_C_GRID)
            .find(|(_, c)| *c == PAPER_C)
            .map(|(s, _)| s.clone())
            .expect("the grid holds the paper's coefficient");
        out.push(paper);
        if let Some(mut best) = grid
            .into_iter()
            .min_by(|a, b| a.main.inclination_deg.total_cmp(&b.main.inclination_deg))
        {
            best.estimator = format!("{} (best)", best.estimator);
            out.push(best);
        }
    }
    if which.fused {
        out.push(score(trial, "fused", &mut FusedOrientation::default()));
    }
    if which.platform && trial.has(SensorKind::RotationVector) {
        out.push(score(
            trial,
            "platform rotation vector",
            &mut PlatformRotationVector::default(),
        ));
    }
    out
}

/// Another program's orientation track for a trial (VQF's, say: `benchmarks/vqf/`), replayed as
/// an estimator so that it is scored by exactly the same rows and definitions as ours. The file
/// is CSV with the header `t_ns,w,x,y,z`: device → world quaternions in the trial's time base,
/// each row the estimate after the input samples up to its time stamp. Rows whose quaternion is
/// not finite or not of unit length (±1 %) are refused, as are time stamps that go backwards.
#[derive(Clone, Debug, Default)]
pub struct RecordedTrack {
    rows: Vec<(i64, glam::Quat)>,
    next: usize,
    latest: Option<glam::Quat>,
}

/// A [`RecordedTrack`] file that cannot be used.
#[derive(Debug, thiserror::Error)]
pub enum TrackError {
    #[error("{}: {error}", path.display())]
    Io {
        path: std::path::PathBuf,
        error: std::io::Error,
    },
    #[error("{}: larger than {max_bytes} bytes: not an orientation track", path.display())]
    TooLarge { path: std::path::PathBuf, max_bytes: u64 },
    #[error("{}:{line}: {message}", path.display())]
    Parse {
        path: std::path::PathBuf,
        line: usize,
        message: &'static str,
    },
}

/// Largest track file read, bytes: seven hours of rows at 200 Hz. A larger file (or a device
/// that never ends, such as `/dev/zero`) is refused rather than read into memory.
pub const MAX_TRACK_BYTES: u64 = 256 << 20;

impl RecordedTrack {
    /// Reads a track file (see the type's docs).
    pub fn load(path: &Path) -> Result<Self, TrackError> {
        Self::load_at_most(path, MAX_TRACK_BYTES)
    }

    fn load_at_most(path: &Path, max_bytes: u64) -> Result<Self, TrackError> {
        use std::io::Read;
        let io = |error| TrackError::Io {
            path: path.to_path_buf(),
            error,
        };
        let mut bytes = Vec::new();
        // Regular files only: a pipe would block.
        phantogram_files::open_regular_file(path)
            .map_err(io)?
            .take(max_bytes + 1)
            .read_to_end(&mut bytes)
            .map_err(io)?;
        if bytes.len() as u64 > max_bytes {
            return Err(TrackError::TooLarge {
                path: path.to_path_buf(),
                max_bytes,
            });
        }
        let text = String::from_utf8(bytes).map_err(|_| TrackError::Parse {
            path: path.to_path_buf(),
            line: 1,
            message: "not UTF-8 text",
        })?;
        let parse_err = |line: usize, message| TrackError::Parse {
            path: path.to_path_buf(),
            line,
            message,
        };
        let mut lines = text.lines().enumerate();
        match lines.next() {
            Some((_, header)) if header.trim() == "t_ns,w,x,y,z" => {}
            _ => return Err(parse_err(1, "expected the header t_ns,w,x,y,z")),
        }
        let mut rows: Vec<(i64, glam::Quat)> = Vec::new();
        for (i, line) in lines {
            if line.trim().is_empty() {
                continue;
            }
            let mut fields = line.split(',').map(str::trim);
            let t_ns = fields
                .next()
                .and_then(|f| f.parse::<i64>().ok())
                .ok_or_else(|| parse_err(i + 1, "expected an integer time stamp in ns"))?;
            let v: Vec<f32> = fields
                .map(|f| f.parse::<f32>())
                .collect::<Result<_, _>>()
                .map_err(|_| parse_err(i + 1, "expected four numbers w,x,y,z"))?;
            let [w, x, y, z] = v[..] else {
                return Err(parse_err(i + 1, "expected four numbers w,x,y,z"));
            };
            let q = glam::Quat::from_xyzw(x, y, z, w);
            if !q.is_finite() || (q.length() - 1.0).abs() > 0.01 {
                return Err(parse_err(i + 1, "not a unit quaternion"));
            }
            if rows.last().is_some_and(|(t, _)| t_ns < *t) {
                return Err(parse_err(i + 1, "time stamp goes backwards"));
            }
            rows.push((t_ns, q.normalize()));
        }
        Ok(Self {
            rows,
            next: 0,
            latest: None,
        })
    }
}

impl OrientationEstimator for RecordedTrack {
    fn push(&mut self, event: &SensorEvent) {
        while let Some((t, q)) = self.rows.get(self.next) {
            if *t > event.t_ns {
                break;
            }
            self.latest = Some(*q);
            self.next += 1;
        }
    }

    fn up_device(&self) -> Option<glam::Vec3> {
        self.latest.map(|q| q.inverse() * glam::Vec3::Z)
    }

    fn device_to_world(&self) -> Option<glam::Quat> {
        self.latest
    }

    fn reset(&mut self) {
        self.next = 0;
        self.latest = None;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use phantogram_sensing::synthetic::{ImuSpec, tilt_sweep};

    #[test]
    fn error_definitions_match_broad() {
        // A pure heading error of 10° and a pure tilt error of 4°.
        let truth = DQuat::from_rotation_x(0.3);
        let mut acc = Accumulator::default();
        acc.add(DQuat::from_rotation_z(10f64.to_radians()) * truth, truth, true);
        let r = acc.finish(Some(0.0));
        assert!((r.heading_deg.unwrap() - 10.0).abs() < 1e-9 && r.inclination_deg < 1e-6);
        let mut acc = Accumulator::default();
        acc.add(DQuat::from_rotation_y(4f64.to_radians()) * truth, truth, true);
        let r = acc.finish(Some(0.0));
        assert!((r.inclination_deg - 4.0).abs() < 1e-9 && r.heading_deg.unwrap() < 1e-6);
        assert!((r.total_deg.unwrap() - 4.0).abs() < 1e-9);
        // The inclination error ignores any heading offset of the reference (room-frame truth).
        let est = DQuat::from_rotation_y(0.05) * truth;
        let offset_truth = DQuat::from_rotation_z(1.0) * truth;
        let mut acc = Accumulator::default();
        acc.add(est, offset_truth, true);
        let r = acc.finish(acc.heading_offset_rad());
        assert!((r.inclination_deg - 0.05f64.to_degrees()).abs() < 1e-6);
        assert!(r.heading_deg.unwrap() < 1e-6, "{r:?}");
    }

    #[test]
    fn room_frame_heading_is_scored_about_its_mean_turn() {
        // The room is turned 178° from north; the estimate's heading errs by ±6° about that, so
        // its turn wraps past 180° (an arithmetic mean would say 4°): RMSE 6°. Headless rows
        // count for inclination only.
        let mut acc = Accumulator::default();
        for (k, tilt) in [0.1, -0.3, 0.7, 1.2].into_iter().enumerate() {
            let truth = DQuat::from_rotation_x(tilt) * DQuat::from_rotation_z(0.2 * k as f64);
            let err = if k % 2 == 0 { 6f64 } else { -6.0 };
            let est = DQuat::from_rotation_z((178.0 + err).to_radians()) * truth;
            acc.add(est, truth, true);
            acc.add(truth, truth, false);
        }
        let offset = acc.heading_offset_rad().unwrap().to_degrees();
        assert!((offset - 178.0).abs() < 1e-9, "{offset}");
        let r = acc.finish(Some(offset.to_radians()));
        assert!((r.heading_deg.unwrap() - 6.0).abs() < 1e-9, "{r:?}");
        assert!((r.total_deg.unwrap() - 6.0).abs() < 1e-9, "{r:?}");
        assert_eq!(r.rows, 8);
        assert_eq!(Accumulator::default().finish(Some(0.0)).heading_deg, None);
    }

    #[test]
    fn a_recorded_track_is_scored_like_an_estimator() {
        let scratch = phantogram_testkit::Scratch::new("recorded-track");
        let events = tilt_sweep(&ImuSpec::default());
        let trial = Trial {
            name: "synthetic".into(),
            events: events.clone(),
            truth_frame: TruthFrame::EastNorthUp,
            movement: None,
        };
        // The truth itself, turned 2° about x, as another program's track.
        let tilt = glam::Quat::from_rotation_x(2f32.to_radians());
        let mut text = String::from("t_ns,w,x,y,z\n");
        for e in events.iter().filter(|e| e.kind == SensorKind::GroundTruth) {
            let q = tilt * e.quat().unwrap();
            text += &format!("{},{},{},{},{}\n", e.t_ns, q.w, q.x, q.y, q.z);
        }
        let path = scratch.join("synthetic.csv");
        std::fs::write(&path, text).unwrap();
        let mut track = RecordedTrack::load(&path).unwrap();
        let s = score(&trial, "track", &mut track);
        assert!((s.main.inclination_deg - 2.0).abs() < 0.01, "{s:?}");
        assert!(s.main.heading_deg.unwrap() < 0.01, "{s:?}");

        for (bad, why) in [
            ("t,w,x,y,z\n", "expected the header"),
            ("t_ns,w,x,y,z\n10,1,0,0\n", "four numbers"),
            ("t_ns,w,x,y,z\n10,2,0,0,0\n", "unit quaternion"),
            ("t_ns,w,x,y,z\n10,1,0,0,0\n5,1,0,0,0\n", "backwards"),
            ("t_ns,w,x,y,z\nten,1,0,0,0\n", "integer time stamp"),
        ] {
            std::fs::write(&path, bad).unwrap();
            let err = RecordedTrack::load(&path).unwrap_err().to_string();
            assert!(err.contains(why) && err.contains("synthetic.csv"), "{err}");
        }
        assert!(RecordedTrack::load(&scratch.join("missing.csv")).is_err());
        std::fs::write(&path, "t_ns,w,x,y,z\n10,1,0,0,0\n").unwrap();
        assert!(RecordedTrack::load_at_most(&path, 100).is_ok());
        let err = RecordedTrack::load_at_most(&path, 10).unwrap_err().to_string();
        assert!(err.contains("larger than 10 bytes"), "{err}");
        std::fs::write(&path, b"t_ns,w,x,y,z\n\xff\n").unwrap();
        assert!(RecordedTrack::load(&path).unwrap_err().to_string().contains("UTF-8"));
    }

    #[test]
    fn scores_a_synthetic_trial() {
        let trial = Trial {
            name: "synthetic".into(),
            events: tilt_sweep(&ImuSpec::default()),
            truth_frame: TruthFrame::EastNorthUp,
            movement: None,
        };
        let scores = score_all(&trial);
        let fused = scores.iter().find(|s| s.estimator == "fused").unwrap();
        let paper = &scores[0];
        assert!(fused.main.rows > 600);
        assert!(fused.main.inclination_deg < 0.5, "{fused:?}");
        assert!(fused.main.heading_deg.unwrap() < 1.0, "{fused:?}");
        // The low-pass lags while the phone turns: clearly worse.
        assert!(
            paper.main.inclination_deg > 2.0 * fused.main.inclination_deg,
            "{paper:?}"
        );

        // Without a magnetometer the low-pass has no orientation, only "up": it is still scored
        // for inclination (as before, from the accelerometer alone), with no heading.
        let no_field = Trial {
            events: trial
                .events
                .iter()
                .filter(|e| e.kind != SensorKind::Magnetometer)
                .copied()
                .collect(),
            ..trial
        };
        let scores = score_all(&no_field);
        let headless = &scores[0];
        assert_eq!(headless.main.rows, paper.main.rows, "{headless:?}");
        assert!(
            (headless.main.inclination_deg - paper.main.inclination_deg).abs() < 1e-3,
            "{headless:?} vs {paper:?}"
        );
        assert_eq!((headless.main.heading_deg, headless.main.total_deg), (None, None));
        // The best-c search compares real numbers, and the fused estimator runs in 6-D.
        assert!(scores[1].main.inclination_deg <= headless.main.inclination_deg);
        let fused_6d = scores.iter().find(|s| s.estimator == "fused").unwrap();
        assert!(fused_6d.main.inclination_deg < 0.5, "{fused_6d:?}");
    }
}
