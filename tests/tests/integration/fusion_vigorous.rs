//! The fused estimator through vigorous hand motion (issue 15): hand shaking with 10–16 g peaks,
//! jolts and up to 700 °/s of rotational shake, imposed on known orientation tracks and read by
//! accelerometers that clip at ±8 g or ±16 g ([`phantogram::synthetic::vigorous`]).
//!
//! Goals: after each bout of shaking the inclination is back within 1° of the truth within 2 s,
//! and stays there; over the whole run the inclination RMSE stays small. The synthetic slow
//! track always runs; the motion-capture tracks of `$PHANTOGRAM_DATA/imu` (BROAD and phone
//! trials, fast rotation included) run where the data is.
//!
//! The estimator before issue 15 (readings above 8 g dropped) failed every one of these: on the
//! synthetic track at ±8 g 13.5° RMSE, 27.8° at worst, and no bout followed by 6 s within 1°.

use phantogram::attitude::OrientationEstimator;
use phantogram::fusion::{FusedOrientation, FusionParams};
use phantogram::glam::{DQuat, DVec3};
use phantogram::sensors::{SensorEvent, SensorKind};
use phantogram::synthetic::vigorous::{VigorousSpec, simulate_vigorous, track_from_samples};
use phantogram_integration::data_subdir;
use phantogram_lab::orientation_eval::inclination_error_rad;
use phantogram_lab::sensorlog::import::import;

const DURATION_S: f64 = 72.0;

/// What one run measured.
#[derive(Debug)]
struct Outcome {
    /// Inclination RMSE after the first 5 s, degrees.
    rmse_deg: f64,
    /// Worst inclination error during the bouts, degrees.
    worst_in_bouts_deg: f64,
    /// Per bout: seconds after its end until the error stays below 1° (until the next bout or
    /// 6 s later); `None` if it never does.
    recovery_s: Vec<Option<f64>>,
}

fn run(spec: &VigorousSpec, params: FusionParams, slow: impl Fn(f64) -> DQuat) -> Outcome {
    let events = simulate_vigorous(spec, DURATION_S, 0, slow);
    let mut f = FusedOrientation::new(params);
    let mut errors: Vec<(f64, f64)> = Vec::new();
    for e in &events {
        if e.kind == SensorKind::GroundTruth {
            if let (Some(est), Some(truth)) = (f.device_to_world(), e.quat()) {
                errors.push((
                    e.t_ns as f64 * 1e-9,
                    inclination_error_rad(est.as_dquat(), truth.as_dquat()).to_degrees(),
                ));
            }
        } else {
            f.push(e);
        }
    }
    let main: Vec<f64> = errors.iter().filter(|(t, _)| *t >= 5.0).map(|e| e.1).collect();
    let rmse_deg = (main.iter().map(|e| e * e).sum::<f64>() / main.len().max(1) as f64).sqrt();
    let in_bout = |t: f64| spec.bouts.iter().any(|b| t >= b.start_s && t <= b.end_s());
    let worst_in_bouts_deg = errors
        .iter()
        .filter(|(t, _)| in_bout(*t))
        .map(|e| e.1)
        .fold(0.0, f64::max);
    let recovery_s = spec
        .bouts
        .iter()
        .enumerate()
        .map(|(i, b)| {
            let until = spec
                .bouts
                .get(i + 1)
                .map_or(b.end_s() + 6.0, |n| n.start_s)
                .min(DURATION_S);
            // The last time within the window that the error was 1° or more.
            let last_bad = errors
                .iter()
                .filter(|(t, e)| *t >= b.end_s() && *t <= until && *e >= 1.0)
                .map(|(t, _)| *t)
                .fold(None, |m: Option<f64>, t| Some(m.map_or(t, |m| m.max(t))));
            match last_bad {
                None => Some(0.0),
                Some(t) if t < until - 0.5 => Some(t - b.end_s()),
                Some(_) => None,
            }
        })
        .collect();
    Outcome {
        rmse_deg,
        worst_in_bouts_deg,
        recovery_s,
    }
}

fn check(label: &str, outcome: &Outcome, max_rmse_deg: f64) {
    println!(
        "{label}: inclination RMSE {:.2}°, worst during bouts {:.1}°, back within 1° after {:?} s",
        outcome.rmse_deg,
        outcome.worst_in_bouts_deg,
        outcome
            .recovery_s
            .iter()
            .map(|r| r.map(|s| (s * 100.0).round() / 100.0))
            .collect::<Vec<_>>()
    );
    for (i, r) in outcome.recovery_s.iter().enumerate() {
        assert!(
            r.is_some_and(|s| s <= 2.0),
            "{label}: after bout {i} the inclination took {r:?} s to come back within 1°"
        );
    }
    assert!(
        outcome.rmse_deg <= max_rmse_deg,
        "{label}: inclination RMSE {:.2}° > {max_rmse_deg}°",
        outcome.rmse_deg
    );
}

/// A hand-held phone's slow motion: tilting about 40° from the vertical, turning and nodding.
fn synthetic_slow(t: f64) -> DQuat {
    DQuat::from_rotation_z(1.0 * (0.2 * t).sin())
        * DQuat::from_rotation_x(0.7 + 0.3 * (0.37 * t).sin())
        * DQuat::from_rotation_y(0.25 * (0.23 * t).sin())
}

#[test]
fn vigorous_shaking_on_a_synthetic_track() {
    for range_g in [8.0, 16.0] {
        for seed in [1, 2] {
            let spec = VigorousSpec::phone(range_g, DURATION_S, seed);
            let label = format!("synthetic track, ±{range_g} g, seed {seed}");
            check(&label, &run(&spec, FusionParams::default(), synthetic_slow), 1.0);
        }
    }
}

/// Where the platform declares the accelerometer's range, saturation is known from the first
/// clipped reading instead of being learnt.
#[test]
fn vigorous_shaking_with_a_declared_range() {
    let spec = VigorousSpec::phone(8.0, DURATION_S, 3);
    let params = FusionParams {
        accel_range_m_s2: spec.accel_range_m_s2,
        ..FusionParams::default()
    };
    check(
        "synthetic track, declared ±8 g",
        &run(&spec, params, synthetic_slow),
        1.0,
    );
}

/// Spun faster than the gyroscope reads (bouts peaking at 2600 °/s, ±2000 °/s part): the
/// attitude the gyroscope carries through the clipped readings is off, and the estimate must
/// still come back within 1° within 2 s of each bout's end.
#[test]
fn spinning_past_the_gyroscope_range() {
    let mut spec = VigorousSpec::phone(16.0, DURATION_S, 4);
    for b in &mut spec.bouts {
        b.peak_rate_rad_s = 2600f64.to_radians();
    }
    let events = simulate_vigorous(&spec, DURATION_S, 0, synthetic_slow);
    let range = spec.gyro_range_rad_s as f32;
    let clipped = events
        .iter()
        .filter(|e| e.kind == SensorKind::Gyroscope && e.vec3().abs().max_element() >= range * 0.9999)
        .count();
    assert!(clipped > 50, "only {clipped} clipped gyroscope readings");
    // While the gyroscope clips the attitude is lost (up to ~20° during the bouts: no sensor
    // says how far it turned), so the RMSE bound is loose; the recovery is what is tested
    // (3.3 s, and once not within the 8 s to the next bout, when clipped rates are integrated as
    // they come and nothing restarts; 0.45 s at most now).
    check(
        "synthetic track, 2600 °/s",
        &run(&spec, FusionParams::default(), synthetic_slow),
        4.0,
    );
}

/// The ground-truth track of a recording, from its first finite row on.
fn recorded_track(events: &[SensorEvent]) -> impl Fn(f64) -> DQuat + use<> {
    let samples: Vec<(i64, DQuat)> = events
        .iter()
        .filter(|e| e.kind == SensorKind::GroundTruth)
        .filter_map(|e| e.quat().filter(|q| q.is_finite()).map(|q| (e.t_ns, q.as_dquat())))
        .collect();
    let t0 = samples.first().map_or(0, |s| s.0);
    track_from_samples(samples, t0)
}

#[test]
fn vigorous_shaking_on_motion_capture_tracks() {
    let Some(dir) = data_subdir("imu") else { return };
    let trials = [
        "broad/02_undisturbed_slow_rotation_B.csv.gz",
        "broad/10_undisturbed_slow_translation_A.csv.gz",
        "broad/07_undisturbed_fast_rotation_B.csv.gz",
        "broad-extra/21_undisturbed_fast_combined.csv.gz",
        "broad-extra/26_disturbed_phone_vibration_A.csv.gz",
        "phone/Thibaud_Nexus5_NoDist_AR",
        "phone/Guillaume_Nexus5_NoDist_Texting",
    ];
    for (i, name) in trials.iter().enumerate() {
        let events = import(&dir.join(name)).unwrap_or_else(|e| panic!("{e}")).events;
        for range_g in [8.0, 16.0] {
            let spec = VigorousSpec {
                gyro_bias_rad_s: DVec3::new(0.2, 0.3, -0.25) * 1f64.to_radians(),
                ..VigorousSpec::phone(range_g, DURATION_S, 10 + i as u64)
            };
            let label = format!("{name}, ±{range_g} g");
            check(
                &label,
                &run(&spec, FusionParams::default(), recorded_track(&events)),
                1.0,
            );
        }
    }
}
