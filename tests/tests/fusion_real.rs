//! The fused estimator on real recordings (`$PHANTOGRAM_DATA/imu`): fault injection, and the
//! world light's heading drift through the whole core. Without `PHANTOGRAM_DATA` these tests
//! print a notice and return; the synthetic fault test at the end always runs.

use phantogram::attitude::OrientationEstimator;
use phantogram::fusion::FusedOrientation;
use phantogram::glam::{Quat, Vec3};
use phantogram::light::heading_rad;
use phantogram::sensorlog::import::import;
use phantogram::sensors::{SensorEvent, SensorKind};
use phantogram::synthetic::{ImuSpec, tilt_sweep};
use phantogram::{Session, SessionConfig};
use phantogram_integration::data_subdir;

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
        if (faults[0].start_ns..faults[0].end_ns).contains(&e.t_ns) && k % 3 == 0 {
            e.value[(k % 3) as usize] = if k % 2 == 0 { f32::NAN } else { f32::INFINITY };
        }
        if (faults[1].start_ns..faults[1].end_ns).contains(&e.t_ns) {
            continue;
        }
        if e.kind == SensorKind::Accelerometer && (faults[2].start_ns..faults[2].end_ns).contains(&e.t_ns) && k % 4 == 0
        {
            let dir = Vec3::new((k as f32).sin(), (k as f32 * 1.7).cos(), 0.3).normalize();
            e = SensorEvent::accelerometer(e.t_ns, dir * 50.0 * 9.81);
        }
        out.push(e);
        if (faults[3].start_ns..faults[3].end_ns).contains(&e.t_ns) && k % 5 == 0 {
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

/// Heading drift of the world light: replay through the whole core, map the light's device-frame
/// direction into the motion-capture room with the ground truth, and fit its heading over time.
fn light_drift_deg_per_min(events: &[SensorEvent]) -> (f64, usize) {
    let mut session = Session::new(SessionConfig::default()).unwrap();
    // Ground truth with its time: only a current one may map the light into the room (motion
    // capture drops out, and a stale pose would misread a turning phone).
    let mut truth: Option<(i64, Quat)> = None;
    let (mut n, mut st, mut sh, mut stt, mut sth) = (0.0f64, 0.0, 0.0, 0.0, 0.0);
    let mut unwrap = None::<(f64, f64)>; // (last raw heading, accumulated offset)
    let t0 = events[0].t_ns;
    let mut next_frame = t0 + 5 * S; // after convergence
    for e in events {
        if e.t_ns >= next_frame {
            next_frame += S / 20;
            let view = session.frame().unwrap();
            let current = truth.filter(|(t, _)| e.t_ns - t <= S / 20).map(|(_, q)| q);
            if let (Some(q), true) = (current, view.light_anchored) {
                let world = q * view.toward_light_device;
                let raw = heading_rad(world).to_degrees() as f64;
                let h = match unwrap {
                    None => {
                        unwrap = Some((raw, 0.0));
                        raw
                    }
                    Some((last, mut off)) => {
                        if raw - last > 180.0 {
                            off -= 360.0;
                        } else if raw - last < -180.0 {
                            off += 360.0;
                        }
                        unwrap = Some((raw, off));
                        raw + off
                    }
                };
                let t = (e.t_ns - t0) as f64 * 1e-9 / 60.0;
                n += 1.0;
                st += t;
                sh += h;
                stt += t * t;
                sth += t * h;
            }
        }
        match e.kind {
            SensorKind::GroundTruth => truth = e.quat().map(|q| (e.t_ns, q)),
            SensorKind::RotationVector => {}
            _ => {
                let _ = session.push(*e);
            }
        }
    }
    let slope = (n * sth - st * sh) / (n * stt - st * st);
    (slope, n as usize)
}

/// Known limit, kept as a failing check: on two of the four undisturbed phone recordings the
/// light's heading trend exceeds 2°/min (measured +2.72 and −2.48°/min; −0.03 and −0.51 on the
/// others). The phone's magnetic heading there has pose- and place-dependent errors of ±5–10°
/// against the motion capture (Android's own estimate wanders more), and a longer heading time
/// constant lets the gyroscope drift instead (+7.4°/min on Guillaume_Texting at 60 s). Run with
/// `--ignored`.
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
        let (slope, frames) = light_drift_deg_per_min(&events);
        println!("{name}: light heading drift {slope:+.3}°/min over {frames} frames");
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
