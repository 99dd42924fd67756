//! The fused estimator on real recordings (`$PHANTOGRAM_DATA/imu`): fault injection, the
//! accuracy goals of issue #4, and the world light's heading drift through the whole core. Without `PHANTOGRAM_DATA` these tests
//! print a notice and return; the synthetic fault test at the end always runs.

use phantogram::attitude::OrientationEstimator;
use phantogram::fusion::FusedOrientation;
use phantogram::glam::{Quat, Vec3};
use phantogram::light::heading_rad;
use phantogram::sensors::{SensorEvent, SensorKind};
use phantogram::synthetic::{ImuSpec, tilt_sweep};
use phantogram::{Session, SessionConfig};
use phantogram_integration::data_subdir;
use phantogram_lab::sensorlog::import::import;

fn trial(group: &str, name: &str) -> Option<Vec<SensorEvent>> {
    let dir = data_subdir("imu")?;
    Some(
        import(&dir.join(group).join(name))
            .unwrap_or_else(|e| panic!("{e}"))
            .events,
    )
}

fn phone_trial(name: &str) -> Option<Vec<SensorEvent>> {
    trial("phone", name)
}

fn broad_trial(name: &str) -> Option<Vec<SensorEvent>> {
    trial("broad", name)
}

const S: i64 = 1_000_000_000;

/// One injected fault: what it does and the interval it affects.
struct Fault {
    name: &'static str,
    start_ns: i64,
    end_ns: i64,
}

/// The trial's sensor events with four faults injected, 15 s apart starting `first_s` into the
/// trial: NaN/Inf values, a 1 s dropout of every sensor, 50 g accelerometer spikes, and a stretch
/// of time stamps going backwards.
fn inject_faults(clean: &[SensorEvent], first_s: i64) -> (Vec<SensorEvent>, Vec<Fault>) {
    let t0 = clean[0].t_ns;
    let at = |k: i64| t0 + (first_s + 15 * k) * S;
    let faults = vec![
        Fault {
            name: "NaN/Inf samples",
            start_ns: at(0),
            end_ns: at(0) + S / 2,
        },
        Fault {
            name: "1 s dropout",
            start_ns: at(1),
            end_ns: at(1) + S,
        },
        Fault {
            name: "50 g spikes",
            start_ns: at(2),
            end_ns: at(2) + S / 2,
        },
        Fault {
            name: "time stamps going backwards",
            start_ns: at(3),
            end_ns: at(3) + S / 2,
        },
    ];
    let mut out = Vec::with_capacity(clean.len());
    let mut k = 0u64;
    for e in clean.iter().filter(|e| !e.kind.is_orientation()) {
        let mut e = *e;
        k += 1;
        if (faults[0].start_ns..faults[0].end_ns).contains(&e.t_ns) && k.is_multiple_of(3) {
            e.value[(k % 3) as usize] = if k.is_multiple_of(2) { f32::NAN } else { f32::INFINITY };
        }
        if (faults[1].start_ns..faults[1].end_ns).contains(&e.t_ns) {
            continue;
        }
        if e.kind == SensorKind::Accelerometer
            && (faults[2].start_ns..faults[2].end_ns).contains(&e.t_ns)
            && k.is_multiple_of(4)
        {
            let dir = Vec3::new((k as f32).sin(), (k as f32 * 1.7).cos(), 0.3).normalize();
            e = SensorEvent::accelerometer(e.t_ns, dir * 50.0 * 9.81);
        }
        out.push(e);
        if (faults[3].start_ns..faults[3].end_ns).contains(&e.t_ns) && k.is_multiple_of(5) {
            // A stale copy from 0.3 s earlier, with a garbage value.
            let mut stale = e;
            stale.t_ns -= 3 * S / 10;
            stale.value = [stale.value[1], -stale.value[0], stale.value[2] * 0.5, 0.0];
            out.push(stale);
        }
    }
    (out, faults)
}

/// Runs the estimator over `events`, recording `(t, orientation)` after each event; asserts that
/// no orientation is ever non-finite.
fn trace(events: &[SensorEvent]) -> Vec<(i64, Quat)> {
    let mut f = FusedOrientation::default();
    let mut out = Vec::with_capacity(events.len());
    for e in events {
        f.push(e);
        if let Some(q) = f.device_to_world() {
            assert!(q.is_finite(), "non-finite orientation at {} ns after {e:?}", e.t_ns);
            out.push((e.t_ns, q));
        }
        if let Some(up) = f.up_device() {
            assert!(up.is_finite());
        }
    }
    out
}

/// The estimate at `t_ns` (the last one recorded at or before it).
fn at(trace: &[(i64, Quat)], t_ns: i64) -> Option<Quat> {
    let i = trace.partition_point(|(t, _)| *t <= t_ns);
    (i > 0).then(|| trace[i - 1].1)
}

/// Worst difference from the undisturbed run 2–12 s after each fault, in degrees.
fn recovery(clean: &[SensorEvent], first_s: i64, label: &str) -> Vec<(&'static str, f32)> {
    let reference = trace(
        &clean
            .iter()
            .copied()
            .filter(|e| !e.kind.is_orientation())
            .collect::<Vec<_>>(),
    );
    let (faulty, faults) = inject_faults(clean, first_s);
    let disturbed = trace(&faulty);
    let mut results = Vec::new();
    for f in &faults {
        // From 2 s after the fault until just before the next one, within 2°.
        let mut worst = 0.0f32;
        let mut t = f.end_ns + 2 * S;
        while t < f.end_ns + 12 * S {
            if let (Some(a), Some(b)) = (at(&reference, t), at(&disturbed, t)) {
                worst = worst.max(a.angle_between(b).to_degrees());
            }
            t += S / 20;
        }
        println!(
            "{label}: {}: worst difference 2–12 s after the fault: {worst:.3}°",
            f.name
        );
        results.push((f.name, worst));
    }
    results
}

fn assert_recovers(results: &[(&str, f32)], label: &str) {
    for (name, worst) in results {
        assert!(*worst < 2.0, "{label}: after {name}: {worst}° from the undisturbed run");
    }
}

#[test]
fn faults_on_a_real_phone_trial_recover_within_two_seconds() {
    let Some(events) = phone_trial("Thibaud_Nexus5_NoDist_AR") else {
        return;
    };
    assert_recovers(
        &recovery(&events, 20, "Thibaud_Nexus5_NoDist_AR"),
        "Thibaud_Nexus5_NoDist_AR",
    );
}

#[test]
fn faults_on_a_slow_broad_trial_recover_within_two_seconds() {
    let Some(events) = broad_trial("02_undisturbed_slow_rotation_B.csv.gz") else {
        return;
    };
    assert_recovers(
        &recovery(&events, 40, "02_undisturbed_slow_rotation_B"),
        "02_undisturbed_slow_rotation_B",
    );
}

#[test]
fn faults_during_fast_rotation_all_but_the_dropout_recover() {
    let Some(events) = broad_trial("07_undisturbed_fast_rotation_B.csv.gz") else {
        return;
    };
    let results = recovery(&events, 40, "07_undisturbed_fast_rotation_B");
    let others: Vec<_> = results.iter().copied().filter(|(n, _)| *n != "1 s dropout").collect();
    assert_eq!(others.len(), 3);
    assert_recovers(&others, "07_undisturbed_fast_rotation_B");
}

/// Losing every sensor for 1 s during BROAD's fast rotation leaves a rotation no sensor
/// observed; the bridged heading is kept as a prior in the fresh magnetometer average (measured
/// 1.55° from the undisturbed run 2–12 s later; 3.3° when the heading was averaged from scratch).
#[test]
fn dropout_during_fast_rotation_recovers_within_two_seconds() {
    let Some(events) = broad_trial("07_undisturbed_fast_rotation_B.csv.gz") else {
        return;
    };
    assert_recovers(
        &recovery(&events, 40, "07_undisturbed_fast_rotation_B"),
        "07_undisturbed_fast_rotation_B",
    );
}

#[test]
fn faults_on_the_synthetic_sweep_recover() {
    // Always runs: the same faults on the synthetic sweep (3 s apart is too tight for four faults
    // in 12 s, so this checks the first fault only, fully, and no NaN ever).
    let events = tilt_sweep(&ImuSpec::default());
    let (faulty, _) = inject_faults(&events, 2);
    let disturbed = trace(&faulty);
    let reference = trace(
        &events
            .iter()
            .copied()
            .filter(|e| !e.kind.is_orientation())
            .collect::<Vec<_>>(),
    );
    let t = events[0].t_ns + 5 * S; // 2.5 s after the NaN burst ended
    let d = at(&reference, t)
        .unwrap()
        .angle_between(at(&disturbed, t).unwrap())
        .to_degrees();
    assert!(d < 2.0, "{d}°");
}

/// The fixed rotation from the phone's sensor frame to the motion-capture marker body (the data's
/// README: the marker body is not exactly aligned with the IMU), as `marker_from_imu * v_imu`.
///
/// Estimated from rates alone, so it can neither hide nor cause a heading drift: between two
/// motion-capture poses at most 1/30 s apart the marker turns at the gyroscope's mean rate over
/// that interval, rotated by the mounting. Least squares over the intervals where the phone turns
/// faster than 0.5 rad/s (slower ones carry little direction and more noise), by Gauss–Newton on a
/// rotation vector from the identity. Returns the rotation and how many intervals it used.
fn marker_from_imu(events: &[SensorEvent]) -> (Quat, usize) {
    let gyro: Vec<(i64, Vec3)> = events
        .iter()
        .filter(|e| e.kind == SensorKind::Gyroscope && e.value.iter().all(|v| v.is_finite()))
        .map(|e| (e.t_ns, e.vec3()))
        .collect();
    let truth: Vec<(i64, Quat)> = events
        .iter()
        .filter(|e| e.kind == SensorKind::GroundTruth)
        .filter_map(|e| e.quat().map(|q| (e.t_ns, q)))
        .collect();
    let mut pairs = Vec::new(); // (marker-frame rate, IMU-frame rate), rad/s
    for w in truth.windows(2) {
        let ((t0, q0), (t1, q1)) = (w[0], w[1]);
        let dt = (t1 - t0) as f32 * 1e-9;
        if !(1e-3..=1.0 / 30.0).contains(&dt) {
            continue;
        }
        let from = gyro.partition_point(|(t, _)| *t < t0);
        let to = gyro.partition_point(|(t, _)| *t <= t1);
        if to <= from {
            continue;
        }
        let imu = gyro[from..to].iter().map(|(_, w)| *w).sum::<Vec3>() / (to - from) as f32;
        let (axis, angle) = (q0.inverse() * q1).normalize().to_axis_angle();
        let angle = if angle > std::f32::consts::PI {
            angle - std::f32::consts::TAU
        } else {
            angle
        };
        let marker = axis * angle / dt;
        if imu.length() > 0.5 && marker.is_finite() {
            pairs.push((marker, imu));
        }
    }
    let mut r = Quat::IDENTITY;
    for _ in 0..8 {
        let (mut normal, mut rhs) = (phantogram::glam::Mat3::ZERO, Vec3::ZERO);
        for (a, b) in &pairs {
            let c = r * *b;
            normal += phantogram::glam::Mat3::from_diagonal(Vec3::splat(c.length_squared()))
                - phantogram::glam::Mat3::from_cols(c * c.x, c * c.y, c * c.z);
            rhs += c.cross(*a - c);
        }
        let step = normal.inverse() * rhs;
        if !step.is_finite() {
            break;
        }
        r = (Quat::from_scaled_axis(step) * r).normalize();
    }
    (r, pairs.len())
}

/// [`marker_from_imu`] over a whole trial, with how far apart the estimates from its two halves
/// are: texting turns the phone mostly about one axis, which leaves the rotation about it loose.
struct Mounting {
    /// `marker_from_imu`'s rotation.
    rotation: Quat,
    intervals: usize,
    halves_apart_deg: f32,
}

impl Mounting {
    fn of(events: &[SensorEvent]) -> Self {
        let (rotation, intervals) = marker_from_imu(events);
        let half = events.len() / 2;
        let halves_apart_deg = marker_from_imu(&events[..half])
            .0
            .angle_between(marker_from_imu(&events[half..]).0)
            .to_degrees();
        Self {
            rotation,
            intervals,
            halves_apart_deg,
        }
    }

    /// Used only where the halves agree within 2°.
    fn determined(&self) -> bool {
        self.halves_apart_deg < 2.0
    }

    fn angle_deg(&self) -> f32 {
        self.rotation.angle_between(Quat::IDENTITY).to_degrees()
    }
}

/// The events with every ground-truth attitude `q` replaced by `q · by`.
fn truth_turned(events: &[SensorEvent], by: Quat) -> Vec<SensorEvent> {
    events
        .iter()
        .map(|e| match e.quat() {
            Some(q) if e.kind == SensorKind::GroundTruth => {
                SensorEvent::orientation(SensorKind::GroundTruth, e.t_ns, q * by)
            }
            _ => *e,
        })
        .collect()
}

/// Least-squares trend of an angle over time, unwrapping it across ±180°.
#[derive(Default)]
struct HeadingTrend {
    n: f64,
    st: f64,
    sh: f64,
    stt: f64,
    sth: f64,
    /// Last raw heading and the offset accumulated by unwrapping, degrees.
    unwrap: Option<(f64, f64)>,
}

impl HeadingTrend {
    fn add(&mut self, t_min: f64, raw_deg: f64) {
        let off = match self.unwrap {
            None => 0.0,
            Some((last, off)) if raw_deg - last > 180.0 => off - 360.0,
            Some((last, off)) if raw_deg - last < -180.0 => off + 360.0,
            Some((_, off)) => off,
        };
        self.unwrap = Some((raw_deg, off));
        let h = raw_deg + off;
        self.n += 1.0;
        self.st += t_min;
        self.sh += h;
        self.stt += t_min * t_min;
        self.sth += t_min * h;
    }

    /// Degrees per minute.
    fn slope(&self) -> f64 {
        (self.n * self.sth - self.st * self.sh) / (self.n * self.stt - self.st * self.st)
    }
}

/// Heading drift of the world light: replay through the whole core, map the light's device-frame
/// direction into the motion-capture room with the ground truth, and fit its heading over time.
fn light_drift_deg_per_min(events: &[SensorEvent]) -> (f64, usize) {
    let drift = light_drift_with_mounting(events, Quat::IDENTITY);
    (drift.ours_deg_per_min, drift.frames)
}

/// What [`light_drift_with_mounting`] measures.
struct LightDrift {
    ours_deg_per_min: f64,
    frames: usize,
    /// The same for a light fixed in the world of Android's own rotation vector, if recorded.
    android_deg_per_min: Option<f64>,
}

/// [`light_drift_deg_per_min`] with the ground truth corrected by the IMU's mounting in the
/// marker body ([`marker_from_imu`]), and the same trend for Android's rotation vector.
fn light_drift_with_mounting(events: &[SensorEvent], marker_from_imu: Quat) -> LightDrift {
    let mut session = Session::new(SessionConfig::default()).unwrap();
    // Ground truth with its time: only a current one may map the light into the room (motion
    // capture drops out, and a stale pose would misread a turning phone). Likewise Android's.
    let mut truth: Option<(i64, Quat)> = None;
    let mut android: Option<(i64, Quat)> = None;
    let (mut ours, mut theirs) = (HeadingTrend::default(), HeadingTrend::default());
    let t0 = events[0].t_ns;
    let mut next_frame = t0 + 5 * S; // after convergence
    let fresh = |sample: Option<(i64, Quat)>, t_ns: i64| sample.filter(|(t, _)| t_ns - t <= S / 20).map(|(_, q)| q);
    for e in events {
        if e.t_ns >= next_frame {
            next_frame += S / 20;
            let view = session.frame().unwrap();
            let t_min = (e.t_ns - t0) as f64 * 1e-9 / 60.0;
            if let Some(q) = fresh(truth, e.t_ns) {
                let room_from_imu = q * marker_from_imu;
                if view.light_anchored {
                    let world = room_from_imu * view.toward_light_device;
                    ours.add(t_min, heading_rad(world).to_degrees() as f64);
                }
                if let Some(a) = fresh(android, e.t_ns) {
                    // A light fixed at Android's east, seen through the phone into the room.
                    let world = room_from_imu * (a.inverse() * Vec3::new(0.8, 0.0, 0.6));
                    theirs.add(t_min, heading_rad(world).to_degrees() as f64);
                }
            }
        }
        match e.kind {
            SensorKind::GroundTruth => truth = e.quat().map(|q| (e.t_ns, q)),
            SensorKind::RotationVector => android = e.quat().map(|q| (e.t_ns, q)),
            _ => {
                let _ = session.push(*e);
            }
        }
    }
    LightDrift {
        ours_deg_per_min: ours.slope(),
        frames: ours.n as usize,
        android_deg_per_min: (theirs.n > 1000.0).then(|| theirs.slope()),
    }
}

/// Known limit, kept as a failing check: on two of the four undisturbed phone recordings the
/// light's heading trend exceeds 2°/min. Measured with the ground truth corrected for the IMU's
/// mounting in the marker body where it is determined ([`marker_from_imu`]): +2.22 (Guillaume
/// AR) and −2.38°/min (Thibaud Texting, mounting not determined); −0.16 (Guillaume Texting)
/// and −1.27 (Thibaud AR) on the others (before the gyroscope bias was estimated in motion:
/// +2.04, −2.48, −0.03 and −0.75). Android's own rotation vector, measured the same way, in the
/// order Guillaume AR, Guillaume Texting, Thibaud AR, Thibaud Texting: +16.5, −1.69, −1.19 and
/// −1.59°/min.
/// The phone's magnetic heading there has pose- and place-dependent errors of ±5–10° against
/// the motion capture. The following were measured before in-motion bias estimation: a longer
/// heading time constant lets the gyroscope drift instead (+4.5°/min
/// on Guillaume Texting at 40 s), and learning gyroscope bias about the vertical from the
/// magnetometer's steady corrections (an integral term, 40–80 s) learns the field's errors as
/// bias and makes it worse (−3.1 to −4.9°/min there). Even an oracle magnetometer calibration,
/// fitted per trial against the motion capture and removed from the recording before the replay,
/// does not bring all four under 2°/min (Guillaume AR, Guillaume Texting, Thibaud AR, Thibaud
/// Texting): a hard-iron offset alone gives +3.19, +0.42, +2.47 and −1.43°/min; hard and soft
/// iron (offset and 3×3 matrix; heading scatter against the truth 9.5 → 4.0° on Guillaume AR)
/// −1.15, +0.96, +2.03 and −1.25°/min. Run with `--ignored`.
#[test]
#[ignore = "known limit: 2 of 4 phone recordings exceed 2°/min (magnetometer heading errors)"]
fn world_light_heading_drifts_less_than_two_degrees_per_minute() {
    let mut results = Vec::new();
    for name in [
        "Guillaume_Nexus5_NoDist_AR",
        "Guillaume_Nexus5_NoDist_Texting",
        "Thibaud_Nexus5_NoDist_AR",
        "Thibaud_Nexus5_NoDist_Texting",
    ] {
        let Some(events) = phone_trial(name) else { return };
        let (unaligned, _) = light_drift_deg_per_min(&events);
        let mounting = Mounting::of(&events);
        let aligned = light_drift_with_mounting(
            &events,
            if mounting.determined() {
                mounting.rotation
            } else {
                Quat::IDENTITY
            },
        );
        let (slope, frames) = (aligned.ours_deg_per_min, aligned.frames);
        println!(
            "{name}: light heading drift {slope:+.3}°/min over {frames} frames (IMU {:.2}° off the marker from {} intervals, halves {:.1}° apart: {}; {unaligned:+.3}°/min taking the marker for the IMU); Android's rotation vector: {:+.3?}°/min",
            mounting.angle_deg(),
            mounting.intervals,
            mounting.halves_apart_deg,
            if mounting.determined() { "used" } else { "not used" },
            aligned.android_deg_per_min,
        );
        results.push((name, slope, frames));
    }
    for (name, slope, frames) in results {
        assert!(frames > 1000, "{name}: {frames} frames with ground truth");
        assert!(slope.abs() < 2.0, "{name}: light heading drifts {slope}°/min");
    }
}

/// The mechanism behind a world-fixed light, always run: with a gyroscope bias of 0.3°/s about
/// the vertical (18°/min if uncorrected) and a clean field, the light's heading in the world stays
/// put over two minutes of motion.
#[test]
fn magnetometer_keeps_the_light_from_drifting_with_gyro_bias() {
    let spec = ImuSpec::default();
    let pose = |t: f64| {
        let t = t as f32;
        Quat::from_rotation_z(0.6 * (0.21 * t).sin()) * Quat::from_rotation_x(0.6 + 0.3 * (0.37 * t).sin())
    };
    let bias = Vec3::new(0.0, 0.0, 0.3f32.to_radians());
    let events: Vec<_> = phantogram::synthetic::simulate(&spec, 120.0, 0, pose)
        .into_iter()
        .map(|e| {
            if e.kind == SensorKind::Gyroscope {
                SensorEvent::gyroscope(e.t_ns, e.vec3() + bias)
            } else {
                e
            }
        })
        .collect();
    let (slope, frames) = light_drift_deg_per_min(&events);
    println!("synthetic, 0.3°/s gyro bias: light heading drift {slope:+.3}°/min over {frames} frames");
    assert!(frames > 2000);
    assert!(slope.abs() < 2.0, "{slope}°/min");
}

/// Every estimator shows a floor of about 2° of inclination error on the phone recordings (the
/// data's README), which hides much of the difference between estimators (fused 1.63° against
/// Android's 1.69° on Thibaud Texting, `benchmarks/orientation.md`). The floor is the marker
/// body's mounting on the phone:
/// with the ground truth turned by the mounting estimated from rates alone ([`marker_from_imu`],
/// which no estimator's output enters), both estimators' inclination RMSE falls on every trial
/// whose mounting is determined, and there the fused estimator is the better of the two.
/// Prints raw and aligned figures for all six trials.
#[test]
fn phone_inclination_floor_is_the_marker_mounting() {
    use phantogram_lab::orientation_eval::{PlatformRotationVector, Trial, TruthFrame, score};
    let mut determined = 0;
    for name in [
        "Guillaume_Nexus5_Dist_Texting",
        "Guillaume_Nexus5_NoDist_AR",
        "Guillaume_Nexus5_NoDist_Texting",
        "Thibaud_Nexus5_Dist_AR",
        "Thibaud_Nexus5_NoDist_AR",
        "Thibaud_Nexus5_NoDist_Texting",
    ] {
        let Some(events) = phone_trial(name) else { return };
        let mounting = Mounting::of(&events);
        let turned = truth_turned(&events, mounting.rotation);
        // Inclination RMSE after the first 5 s, as `phantogram eval orientation` scores it:
        // (fused, rotation vector).
        let rmse = |events: Vec<SensorEvent>| {
            let trial = Trial {
                name: name.to_owned(),
                events,
                truth_frame: TruthFrame::ArbitraryHeading,
                movement: None,
            };
            (
                score(&trial, "fused", &mut FusedOrientation::default())
                    .main
                    .inclination_deg,
                score(&trial, "rotation vector", &mut PlatformRotationVector::default())
                    .main
                    .inclination_deg,
            )
        };
        let (raw, aligned) = (rmse(events), rmse(turned));
        println!(
            "{name}: inclination RMSE fused {:.2}° / rotation vector {:.2}° against the marker; {:.2}° / {:.2}° against the IMU (mounting {:.2}°, halves {:.1}° apart: {})",
            raw.0,
            raw.1,
            aligned.0,
            aligned.1,
            mounting.angle_deg(),
            mounting.halves_apart_deg,
            if mounting.determined() { "determined" } else { "loose" },
        );
        if mounting.determined() {
            determined += 1;
            assert!(aligned.0 < raw.0 && aligned.1 < raw.1, "{name}: {raw:?} → {aligned:?}");
            assert!(
                aligned.0 <= aligned.1,
                "{name}: fused {} > rotation vector {}",
                aligned.0,
                aligned.1
            );
        }
    }
    assert!(determined >= 3, "only {determined} trials with a determined mounting");
}

/// The mounting estimate recovers a known rotation between the IMU and the "marker": the
/// synthetic sweep's ground truth turned by 4° about a skew axis.
#[test]
fn marker_mounting_is_recovered_from_rates() {
    let mounting = Quat::from_axis_angle(Vec3::new(1.0, -2.0, 0.5).normalize(), 4f32.to_radians());
    let events = truth_turned(&tilt_sweep(&ImuSpec::default()), mounting.inverse());
    let (estimate, used) = marker_from_imu(&events);
    let error = estimate.angle_between(mounting).to_degrees();
    println!("mounting recovered within {error:.3}° from {used} intervals");
    assert!(used > 100, "{used} intervals");
    assert!(error < 0.2, "{error}°");
}

/// Issue #4's accuracy goal on the phones: on every provided recording the fused estimator's
/// inclination RMSE (after the first 5 s, as `phantogram eval orientation` scores it) is no worse
/// than that of Android's own rotation vector recorded beside it. Before the gyroscope bias was
/// estimated in motion it was worse on two of them (2.38 vs 2.25°, 1.80 vs 1.69°).
/// And its heading, scored about the room's constant turn from north, is steadier than Android's
/// on each, the magnetically disturbed recordings included (what a world-fixed light needs).
#[test]
fn phone_fused_no_worse_than_androids_rotation_vector() {
    use phantogram_lab::orientation_eval::{PlatformRotationVector, Trial, score};
    let Some(dir) = data_subdir("imu") else { return };
    let mut scored = 0;
    for entry in std::fs::read_dir(dir.join("phone")).unwrap() {
        let path = entry.unwrap().path();
        if !path.is_dir() {
            continue;
        }
        let trial = Trial::load(&path).unwrap_or_else(|e| panic!("{e}"));
        let ours = score(&trial, "fused", &mut FusedOrientation::default()).main;
        let android = score(&trial, "rotation vector", &mut PlatformRotationVector::default()).main;
        let heading = |r: &phantogram_lab::orientation_eval::Rmse| r.heading_deg.expect("both have a heading");
        println!(
            "{}: inclination RMSE fused {:.2}° / rotation vector {:.2}°, heading {:.2}° / {:.2}°, over {} rows",
            trial.name,
            ours.inclination_deg,
            android.inclination_deg,
            heading(&ours),
            heading(&android),
            ours.rows
        );
        assert!(ours.rows > 1000 && android.rows > 1000, "{}: too few rows", trial.name);
        assert!(
            ours.inclination_deg <= android.inclination_deg,
            "{}: fused {:.3}° > rotation vector {:.3}°",
            trial.name,
            ours.inclination_deg,
            android.inclination_deg
        );
        assert!(
            heading(&ours) < heading(&android),
            "{}: heading fused {:.3}° ≥ rotation vector {:.3}°",
            trial.name,
            heading(&ours),
            heading(&android)
        );
        scored += 1;
    }
    assert!(scored >= 6, "only {scored} phone recordings");
}

/// Issue #4's accuracy goal on BROAD: mean inclination RMSE ≤ 0.7° and heading RMSE ≤ 2.0° over
/// the provided trials (VQF reaches 0.70° / 1.92° over all 39).
#[test]
fn broad_means_meet_the_goal() {
    use phantogram_lab::orientation_eval::{Trial, score};
    let Some(dir) = data_subdir("imu") else { return };
    let (mut incl, mut head, mut n) = (0.0, 0.0, 0);
    let mut paths: Vec<_> = std::fs::read_dir(dir.join("broad"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.to_string_lossy().ends_with(".csv.gz"))
        .collect();
    paths.sort();
    for path in paths {
        let trial = Trial::load(&path).unwrap_or_else(|e| panic!("{e}"));
        let main = score(&trial, "fused", &mut FusedOrientation::default()).main;
        let heading = main.heading_deg.expect("BROAD has a heading");
        println!("{}: {:.2}° / {heading:.2}°", trial.name, main.inclination_deg);
        incl += main.inclination_deg;
        head += heading;
        n += 1;
    }
    assert!(n >= 14, "only {n} BROAD trials");
    let (incl, head) = (incl / n as f64, head / n as f64);
    println!("BROAD means over {n} trials: inclination {incl:.2}°, heading {head:.2}°");
    assert!(incl <= 0.7 && head <= 2.0, "{incl}° / {head}°");
}

/// Issue 15's goal on the six BROAD trials of `imu/broad-extra`: inclination RMSE within 0.2° of
/// VQF's on each, and the mean heading RMSE below VQF's. VQF's figures are the data's own
/// (its README: VQF 2.1.2 from PyPI, default parameters, 9-D, scored with BROAD's metrics;
/// `cargo xtask bench orientation` reproduces them to the hundredth with our scoring).
#[test]
fn broad_extra_level_with_vqf() {
    use phantogram_lab::orientation_eval::{Trial, score};
    let Some(dir) = data_subdir("imu") else { return };
    // (trial, VQF inclination, VQF heading), degrees.
    let vqf = [
        ("06_undisturbed_fast_rotation_A", 0.80, 3.95),
        ("08_undisturbed_fast_rotation_with_breaks_A", 1.76, 2.84),
        ("21_undisturbed_fast_combined", 1.72, 3.70),
        ("26_disturbed_phone_vibration_A", 0.56, 1.66),
        ("28_disturbed_stationary_magnet_A", 1.21, 3.86),
        ("29_disturbed_stationary_magnet_B", 1.06, 2.13),
    ];
    let (mut ours_head, mut vqf_head) = (0.0, 0.0);
    for (name, vqf_incl, vqf_heading) in vqf {
        let path = dir.join("broad-extra").join(format!("{name}.csv.gz"));
        let trial = Trial::load(&path).unwrap_or_else(|e| panic!("{e}"));
        let main = score(&trial, "fused", &mut FusedOrientation::default()).main;
        let heading = main.heading_deg.expect("BROAD has a heading");
        println!(
            "{name}: inclination {:.2}° (VQF {vqf_incl:.2}°), heading {heading:.2}° (VQF {vqf_heading:.2}°)",
            main.inclination_deg
        );
        assert!(
            main.inclination_deg <= vqf_incl + 0.2,
            "{name}: inclination {:.3}° vs VQF {vqf_incl}°",
            main.inclination_deg
        );
        ours_head += heading;
        vqf_head += vqf_heading;
    }
    let n = vqf.len() as f64;
    println!("mean heading {:.2}° (VQF {:.2}°)", ours_head / n, vqf_head / n);
    assert!(
        ours_head < vqf_head,
        "mean heading {:.3}° ≥ VQF's {:.3}°",
        ours_head / n,
        vqf_head / n
    );
}

/// Real motion read by an accelerometer with a smaller range: BROAD's fast translation (peaks of
/// 5.5 g) and tapping (16 g) clipped at ±3 g and ±4 g, as a ±3 g or ±4 g part would have read
/// them, range not declared. The clipped readings are learnt as saturated and reconstructed, so
/// the inclination stays near the unclipped run's. Kept as clipped they cost the fast
/// translation 0.46° → 0.97° at ±3 g; holding the filter at every clipped reading cost the
/// tapping 0.60° → 1.26° at ±4 g.
#[test]
fn clipped_recordings_stay_near_the_unclipped() {
    use phantogram_lab::orientation_eval::{Trial, score};
    let Some(dir) = data_subdir("imu") else { return };
    for (name, clip_g, margin_deg) in [
        ("15_undisturbed_fast_translation_A", 3.0f32, 0.15),
        ("24_disturbed_tapping_A", 4.0, 0.05),
        ("24_disturbed_tapping_A", 3.0, 0.05),
    ] {
        let mut trial =
            Trial::load(&dir.join("broad").join(format!("{name}.csv.gz"))).unwrap_or_else(|e| panic!("{e}"));
        let clean = score(&trial, "fused", &mut FusedOrientation::default())
            .main
            .inclination_deg;
        let limit = clip_g * 9.80665;
        let mut clipped_readings = 0;
        for e in &mut trial.events {
            if e.kind == SensorKind::Accelerometer && e.vec3().abs().max_element() > limit {
                clipped_readings += 1;
                for v in &mut e.value[..3] {
                    *v = v.clamp(-limit, limit);
                }
            }
        }
        let mut fused = FusedOrientation::default();
        let clipped = score(&trial, "fused", &mut fused).main.inclination_deg;
        println!(
            "{name} clipped at ±{clip_g} g ({clipped_readings} readings): {clipped:.2}° against {clean:.2}° unclipped; {:?}",
            fused.stats()
        );
        assert!(
            clipped_readings > 20,
            "{name}: only {clipped_readings} readings clipped"
        );
        assert!(fused.stats().accel_saturated > 0, "{name}: no saturation learnt");
        assert!(
            clipped <= clean + margin_deg,
            "{name} at ±{clip_g} g: {clipped:.3}° against {clean:.3}° unclipped"
        );
    }
}
