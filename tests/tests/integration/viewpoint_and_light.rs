//! The gravity viewpoint and the world-fixed light through the whole session (inbox → estimator →
//! viewpoint → light), on synthetic sensor streams whose truth is known exactly.

use phantogram::glam::{Quat, Vec3};
use phantogram::light::heading_rad;
use phantogram::sensors::{SensorEvent, SensorKind};
use phantogram::synthetic::{ImuSpec, simulate};
use phantogram::{FrameView, Session, SessionConfig};

fn run(events: &[SensorEvent], frame_every_ns: i64) -> Vec<(i64, FrameView)> {
    let mut session = Session::new(SessionConfig::default()).unwrap();
    let mut frames = Vec::new();
    let mut next = events[0].t_ns;
    for e in events {
        while next < e.t_ns {
            frames.push((next, session.frame().unwrap()));
            next += frame_every_ns;
        }
        session.push(*e).unwrap();
    }
    frames.push((next, session.frame().unwrap()));
    frames
}

fn spec(rate_hz: f64, noisy: bool) -> ImuSpec {
    let d = ImuSpec::default();
    ImuSpec {
        accel_hz: rate_hz,
        gyro_hz: 0.0,
        mag_hz: rate_hz / 2.0,
        truth_hz: 0.0,
        accel_noise_m_s2: if noisy { d.accel_noise_m_s2 } else { 0.0 },
        mag_noise_ut: if noisy { d.mag_noise_ut } else { 0.0 },
        ..d
    }
}

/// Flat up to 1 s, then tilted by `theta` about the device's x axis (top edge raised). The step
/// starts just after an instant every rate samples, so each rate sees the same held signal (a step
/// *at* a sample instant is ambiguous: each rate would attribute a different interval to it).
fn step_tilt(theta_rad: f32) -> impl Fn(f64) -> Quat {
    move |t| {
        if t <= 1.0 {
            Quat::IDENTITY
        } else {
            Quat::from_rotation_x(theta_rad)
        }
    }
}

#[test]
fn static_tilt_eye_matches_gravity_at_every_rate() {
    for theta_deg in [10.0f32, 30.0, 60.0] {
        let pose = step_tilt(theta_deg.to_radians());
        let true_up = pose(2.0).inverse() * Vec3::Z;
        for rate in [50.0, 100.0, 200.0] {
            let frames = run(&simulate(&spec(rate, true), 3.0, 0, &pose), 20_000_000);
            // Settled: 1 s after the step (≈ 10 time constants).
            for (t, f) in frames.iter().filter(|(t, _)| *t >= 2_000_000_000) {
                let err = f.eyes.cyclopean_m.angle_between(true_up).to_degrees();
                assert!(err < 0.5, "θ {theta_deg}° at {rate} Hz, t {t} ns: {err}°");
            }
        }
        // Identical response at every rate: noise-free streams, frames at shared times.
        let curves: Vec<Vec<Vec3>> = [50.0, 100.0, 200.0]
            .iter()
            .map(|&rate| {
                run(&simulate(&spec(rate, false), 3.0, 0, &pose), 20_000_000)
                    .into_iter()
                    .map(|(_, f)| f.eyes.cyclopean_m)
                    .collect()
            })
            .collect();
        let mut worst = 0.0f32;
        for other in &curves[1..] {
            assert_eq!(other.len(), curves[0].len());
            for (a, b) in curves[0].iter().zip(other) {
                worst = worst.max(a.angle_between(*b).to_degrees());
            }
        }
        // The step itself moves the eye by θ; the rates agree to a tiny fraction of that.
        assert!(worst < 0.02, "θ {theta_deg}°: rates differ by up to {worst}°");
    }
}

/// The light's direction in the device frame at the last frame of each phase.
fn light_after_each_phase(pose: impl Fn(f64) -> Quat, phase_ends_s: &[f64]) -> Vec<(Vec3, Quat)> {
    let end = *phase_ends_s.last().unwrap();
    let events = simulate(&ImuSpec::default(), end, 0, &pose);
    let frames = run(&events, 10_000_000);
    phase_ends_s
        .iter()
        .map(|&t_end| {
            let t_ns = (t_end * 1e9) as i64 - 20_000_000;
            let (_, f) = frames.iter().rev().find(|(t, _)| *t <= t_ns).unwrap();
            assert!(f.light_anchored);
            (f.toward_light_device, pose(t_ns as f64 * 1e-9))
        })
        .collect()
}

fn ramp(t: f64, start: f64, end: f64) -> f32 {
    (((t - start) / (end - start)).clamp(0.0, 1.0)) as f32
}

#[test]
fn turning_about_the_vertical_turns_the_light_the_other_way() {
    // Flat, then a 90° turn about the vertical over one second, then still.
    let pose = |t: f64| Quat::from_rotation_z(std::f32::consts::FRAC_PI_2 * ramp(t, 1.0, 2.0));
    let phases = light_after_each_phase(pose, &[1.0, 3.5]);
    let (before, _) = phases[0];
    let (after, _) = phases[1];
    let expected = Quat::from_rotation_z(-std::f32::consts::FRAC_PI_2) * before;
    let err = after.angle_between(expected).to_degrees();
    assert!(err < 1.0, "light after the turn is {err}° off");
    // And it really moved: by 90° in azimuth about the device z (the vertical here).
    let az = |v: Vec3| v.y.atan2(v.x).to_degrees();
    let turned = (az(after) - az(before) + 540.0) % 360.0 - 180.0;
    assert!((turned + 90.0).abs() < 1.0, "turned {turned}°");
}

#[test]
fn pitching_leaves_the_lights_heading_unchanged() {
    // Flat, then pitched 30° (top edge raised) over one second, then still; the field dips 60°,
    // so a heading that is not tilt-compensated would swing by tens of degrees.
    let pose = |t: f64| Quat::from_rotation_x(30f32.to_radians() * ramp(t, 1.0, 2.0));
    let phases = light_after_each_phase(pose, &[1.0, 3.5]);
    let world = |(l, q): (Vec3, Quat)| q * l;
    let before = world(phases[0]);
    let after = world(phases[1]);
    let d_heading = (heading_rad(after) - heading_rad(before)).to_degrees();
    assert!(d_heading.abs() < 1.0, "heading moved {d_heading}°");
    assert!(
        before.angle_between(after).to_degrees() < 1.0,
        "light moved in the room"
    );
    // In the device frame it did move: by the 30° pitch.
    let moved = phases[0].0.angle_between(phases[1].0).to_degrees();
    assert!(moved > 20.0, "device-frame light moved only {moved}°");
}

#[test]
fn recalibration_reties_the_light_to_the_current_pose() {
    let pose = |t: f64| Quat::from_rotation_z(1.5 * ramp(t, 0.5, 1.0));
    let events = simulate(&ImuSpec::default(), 2.0, 0, pose);
    let mut session = Session::new(SessionConfig::default()).unwrap();
    for chunk in events.chunks(4) {
        for e in chunk {
            session.push(*e).unwrap();
        }
        session.frame().unwrap();
    }
    let before = session.frame().unwrap().toward_light_device;
    session.recalibrate_light().unwrap();
    let after = session.frame().unwrap().toward_light_device;
    let default = SessionConfig::default().light_toward_device.normalize();
    assert!(after.angle_between(default).to_degrees() < 0.5);
    assert!(before.angle_between(default).to_degrees() > 30.0);
    assert!(events.iter().any(|e| e.kind == SensorKind::Magnetometer));
}
