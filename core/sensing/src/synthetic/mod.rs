//! Synthetic, deterministic sensor streams with exact ground truth, for tests, benchmarks and the
//! default replay (`assets/logs/tilt-sweep.pglog`, made by `cargo xtask assets`).
//!
//! **These are not recordings.** The phone is rotated about the centre of its screen (so the
//! accelerometer sees gravity alone), the field is a fixed Earth-like vector, and the noise is
//! white Gaussian from a seeded generator. Real behaviour is tested on the recordings in
//! `../shared/data/imu`. [`vigorous`] shakes any orientation track (recorded motion-capture truth
//! included) with the hand motion the recordings lack.

pub mod vigorous;

use glam::{EulerRot, Quat, Vec3};

use crate::sensors::{SensorEvent, SensorKind};

/// Standard gravity, m/s².
pub const GRAVITY_M_S2: f32 = 9.80665;

/// An Earth-like field for the default synthetic world: 48 µT inclined 60° downwards, pointing
/// north (magnetic north = true north here).
pub fn default_field_world_ut() -> Vec3 {
    let incl = 60f32.to_radians();
    Vec3::new(0.0, incl.cos(), -incl.sin()) * 48.0
}

/// SplitMix64 with a Box–Muller normal: tiny, seeded, and identical on every platform.
#[derive(Clone, Debug)]
pub struct Noise {
    state: u64,
}

impl Noise {
    pub fn new(seed: u64) -> Self {
        Self { state: seed }
    }

    pub fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `[0, 1)`.
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    pub fn normal(&mut self) -> f32 {
        let u1 = self.uniform().max(f64::MIN_POSITIVE);
        let u2 = self.uniform();
        ((-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()) as f32
    }

    pub fn vec3(&mut self, sigma: f32) -> Vec3 {
        Vec3::new(self.normal(), self.normal(), self.normal()) * sigma
    }
}

/// Rates and noise of a simulated phone IMU.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImuSpec {
    pub accel_hz: f64,
    pub gyro_hz: f64,
    pub mag_hz: f64,
    pub truth_hz: f64,
    pub accel_noise_m_s2: f32,
    pub gyro_noise_rad_s: f32,
    pub mag_noise_ut: f32,
    pub field_world_ut: Vec3,
    pub seed: u64,
}

impl Default for ImuSpec {
    /// A phone at Android's game rate: 100 Hz inertial, 50 Hz magnetometer, with typical
    /// consumer-MEMS noise densities.
    fn default() -> Self {
        Self {
            accel_hz: 100.0,
            gyro_hz: 100.0,
            mag_hz: 50.0,
            truth_hz: 100.0,
            accel_noise_m_s2: 0.02,
            gyro_noise_rad_s: 0.002,
            mag_noise_ut: 0.3,
            field_world_ut: default_field_world_ut(),
            seed: 0x5EED,
        }
    }
}

/// Samples `pose(t_s)` (device → world) with the sensors of `spec` from 0 to `duration_s`,
/// time-ordered, starting at `t0_ns`. Includes ground-truth events.
pub fn simulate(spec: &ImuSpec, duration_s: f64, t0_ns: i64, pose: impl Fn(f64) -> Quat) -> Vec<SensorEvent> {
    let mut noise = Noise::new(spec.seed);
    let mut events = Vec::new();
    let up_world = Vec3::Z * GRAVITY_M_S2;
    let streams = [
        (SensorKind::Accelerometer, spec.accel_hz),
        (SensorKind::Gyroscope, spec.gyro_hz),
        (SensorKind::Magnetometer, spec.mag_hz),
        (SensorKind::GroundTruth, spec.truth_hz),
    ];
    for (kind, rate) in streams {
        if !rate.is_finite() || rate <= 0.0 {
            continue;
        }
        let n = (duration_s * rate).floor() as i64;
        for k in 0..=n {
            let t_s = k as f64 / rate;
            let t_ns = t0_ns + (t_s * 1e9).round() as i64;
            let q = pose(t_s);
            let event = match kind {
                SensorKind::Accelerometer => {
                    SensorEvent::accelerometer(t_ns, q.inverse() * up_world + noise.vec3(spec.accel_noise_m_s2))
                }
                SensorKind::Gyroscope => {
                    // Body rate from a central difference of the pose.
                    let h = 1e-4;
                    let dq = pose(t_s - h).inverse() * pose(t_s + h);
                    let (axis, angle) = dq.to_axis_angle();
                    let w = axis * (angle / (2.0 * h) as f32);
                    SensorEvent::gyroscope(t_ns, w + noise.vec3(spec.gyro_noise_rad_s))
                }
                SensorKind::Magnetometer => {
                    SensorEvent::magnetometer(t_ns, q.inverse() * spec.field_world_ut + noise.vec3(spec.mag_noise_ut))
                }
                _ => SensorEvent::orientation(SensorKind::GroundTruth, t_ns, q),
            };
            events.push(event);
        }
    }
    events.sort_by_key(|e| e.t_ns);
    events
}

/// The pose of the default tilt sweep at `t_s`: held still for 1 s at 35° from horizontal, facing
/// a viewer to the south; then 10 s of smooth roll (±30°), pitch (±15°) and yaw (±10°) sweeps,
/// easing in and out; then still again.
pub fn tilt_sweep_pose(t_s: f64) -> Quat {
    let hold = Quat::from_rotation_x(35f32.to_radians());
    let active = (t_s - 1.0).clamp(0.0, 10.0);
    // Smooth envelope: 0 at both ends, 1 in the middle, continuous slope.
    let envelope = (std::f64::consts::PI * active / 10.0).sin().powi(2);
    let wave = |amp_deg: f64, period_s: f64| {
        (envelope * amp_deg * (std::f64::consts::TAU * active / period_s).sin()).to_radians() as f32
    };
    let (roll, pitch, yaw) = (wave(30.0, 4.0), wave(15.0, 3.0), wave(10.0, 7.0));
    Quat::from_rotation_z(yaw) * hold * Quat::from_euler(EulerRot::XYZ, pitch, roll, 0.0)
}

/// Duration of [`tilt_sweep_pose`]'s script.
pub const TILT_SWEEP_DURATION_S: f64 = 12.0;

/// The default synthetic tilt log's events (see [`tilt_sweep_pose`]).
pub fn tilt_sweep(spec: &ImuSpec) -> Vec<SensorEvent> {
    simulate(spec, TILT_SWEEP_DURATION_S, 0, tilt_sweep_pose)
}

/// Meta lines for logs written from [`tilt_sweep`].
pub fn tilt_sweep_meta() -> Vec<(String, String)> {
    vec![
        (
            "source".into(),
            "synthetic tilt sweep (phantogram::synthetic::tilt_sweep)".into(),
        ),
        (
            "note".into(),
            "SYNTHETIC, not a recording: rotation about the screen centre, Gaussian noise, ground truth exact".into(),
        ),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn noise_is_seeded_and_roughly_normal() {
        let mut a = Noise::new(1);
        let mut b = Noise::new(1);
        let xs: Vec<f32> = (0..20_000).map(|_| a.normal()).collect();
        assert!(xs.iter().zip((0..).map(|_| b.normal())).all(|(x, y)| *x == y));
        let mean = xs.iter().sum::<f32>() / xs.len() as f32;
        let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<f32>() / xs.len() as f32;
        assert!(mean.abs() < 0.03 && (var - 1.0).abs() < 0.05, "{mean} {var}");
    }

    #[test]
    fn gyroscope_integrates_to_the_pose() {
        let spec = ImuSpec {
            gyro_noise_rad_s: 0.0,
            gyro_hz: 1000.0,
            ..ImuSpec::default()
        };
        let events = tilt_sweep(&spec);
        let mut q = tilt_sweep_pose(0.0);
        let mut last_t: Option<i64> = None;
        for e in events.iter().filter(|e| e.kind == SensorKind::Gyroscope) {
            if let Some(t) = last_t {
                let dt = (e.t_ns - t) as f32 * 1e-9;
                q = (q * Quat::from_scaled_axis(e.vec3() * dt)).normalize();
            }
            last_t = Some(e.t_ns);
        }
        let end = tilt_sweep_pose(last_t.unwrap() as f64 * 1e-9);
        assert!(q.angle_between(end).to_degrees() < 0.5);
    }

    #[test]
    fn accelerometer_reads_up_with_gravity_sign() {
        let spec = ImuSpec {
            accel_noise_m_s2: 0.0,
            ..ImuSpec::default()
        };
        let events = simulate(&spec, 0.0, 0, |_| Quat::IDENTITY);
        let acc = events.iter().find(|e| e.kind == SensorKind::Accelerometer).unwrap();
        assert!((acc.vec3() - Vec3::Z * GRAVITY_M_S2).length() < 1e-6);
    }
}
