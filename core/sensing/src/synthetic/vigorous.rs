//! Vigorous hand motion imposed on a known orientation track: the stress set of the orientation
//! estimators (issue 15).
//!
//! **Synthetic, not a recording.** Any orientation track (a motion-capture recording's, or a
//! function) is taken as the slow part of the motion; on top of it, during *bouts*, the hand
//! shakes the device: translation made of a few sinusoids at 3–8 Hz along random directions,
//! scaled so that its acceleration peaks at the bout's figure (10–16 g), a rotational shake of
//! the same kind peaking near the bout's rate (up to 700 °/s), and short jolts (a push and the
//! matching stop, 30 ms each, as when the hand strikes). Translation starts and ends at rest, so
//! velocity and position are bounded, as in a real hand.
//!
//! The sensors read the specific force `Rᵀ·(p̈ + g·ẑ)` and the body rate, with white noise, a
//! constant bias and the range limits of real parts: each accelerometer axis clips at
//! [`VigorousSpec::accel_range_m_s2`] (±8 g and ±16 g are common), each gyroscope axis at
//! [`VigorousSpec::gyro_range_rad_s`] (±2000 °/s). Like real parts, each gyroscope sample is the
//! mean rate over the interval it ends (the exact rotation between the two sample times), each
//! accelerometer sample the instantaneous specific force. Everything is seeded: the same spec
//! gives the same events on every platform.
//!
//! Frames as in the crate docs: device frame = Android's sensor frame, world = east-north-up.

use glam::{DQuat, DVec3, Quat};

use super::{GRAVITY_M_S2, Noise, default_field_world_ut};
use crate::sensors::SensorEvent;

/// One stretch of shaking.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bout {
    pub start_s: f64,
    pub duration_s: f64,
    /// Largest hand acceleration (gravity not included) during the bout, m/s².
    pub peak_accel_m_s2: f64,
    /// Largest rate of the rotational shake, rad/s (before the slow track's own rate is added).
    pub peak_rate_rad_s: f64,
    /// Jolts (push and stop) spread over the bout.
    pub jolts: u32,
}

impl Bout {
    pub fn end_s(&self) -> f64 {
        self.start_s + self.duration_s
    }
}

/// The sensors and the bouts.
#[derive(Clone, Debug, PartialEq)]
pub struct VigorousSpec {
    /// Accelerometer and gyroscope rate, Hz.
    pub imu_hz: f64,
    /// Magnetometer rate, Hz (0: none).
    pub mag_hz: f64,
    /// Ground-truth rate, Hz.
    pub truth_hz: f64,
    /// Each accelerometer axis reads at most this much, m/s².
    pub accel_range_m_s2: f64,
    /// Each gyroscope axis reads at most this much, rad/s.
    pub gyro_range_rad_s: f64,
    pub accel_noise_m_s2: f64,
    pub gyro_noise_rad_s: f64,
    pub mag_noise_ut: f64,
    /// Constant gyroscope bias, device frame, rad/s.
    pub gyro_bias_rad_s: DVec3,
    /// Constant accelerometer bias, device frame, m/s².
    pub accel_bias_m_s2: DVec3,
    pub field_world_ut: DVec3,
    pub bouts: Vec<Bout>,
    pub seed: u64,
}

impl VigorousSpec {
    /// A phone-like IMU (200 Hz, ±`range_g` g accelerometer, ±2000 °/s gyroscope, 50 Hz
    /// magnetometer, consumer noise and a small gyroscope bias) shaken in bouts of 4 s every
    /// 12 s from 20 s on (the estimators have learnt the gyroscope bias by then), peaks rising
    /// from 10 to 16 g and rates from 400 to 700 °/s, up to `duration_s`, with at least 4 s of
    /// calm after the last bout.
    pub fn phone(range_g: f64, duration_s: f64, seed: u64) -> Self {
        let mut bouts = Vec::new();
        let mut start = 20.0;
        let mut k = 0u32;
        while start + 4.0 + 4.0 <= duration_s {
            let f = (k % 4) as f64 / 3.0; // 0, 1/3, 2/3, 1, 0, ...
            bouts.push(Bout {
                start_s: start,
                duration_s: 4.0,
                peak_accel_m_s2: (10.0 + 6.0 * f) * GRAVITY_M_S2 as f64,
                peak_rate_rad_s: (400.0 + 300.0 * f).to_radians(),
                jolts: 2 + k % 3,
            });
            start += 12.0;
            k += 1;
        }
        Self {
            imu_hz: 200.0,
            mag_hz: 50.0,
            truth_hz: 100.0,
            accel_range_m_s2: range_g * GRAVITY_M_S2 as f64,
            gyro_range_rad_s: 2000f64.to_radians(),
            accel_noise_m_s2: 0.02,
            gyro_noise_rad_s: 0.002,
            mag_noise_ut: 0.3,
            gyro_bias_rad_s: DVec3::new(0.3, -0.2, 0.25) * 1f64.to_radians(),
            accel_bias_m_s2: DVec3::new(0.03, -0.05, 0.04),
            field_world_ut: default_field_world_ut().as_dvec3(),
            bouts,
            seed,
        }
    }
}

/// A sum of sinusoids along fixed directions, under a smooth envelope that is zero with zero
/// slope at both ends of its bout.
#[derive(Clone, Debug)]
struct Wave {
    start_s: f64,
    duration_s: f64,
    /// (amplitude vector, angular frequency rad/s, phase)
    parts: Vec<(DVec3, f64, f64)>,
    scale: f64,
}

impl Wave {
    fn random(noise: &mut Noise, bout: &Bout) -> Self {
        let parts = (0..3)
            .map(|_| {
                let dir = DVec3::new(noise.uniform() - 0.5, noise.uniform() - 0.5, noise.uniform() - 0.5)
                    .try_normalize()
                    .unwrap_or(DVec3::X);
                let f_hz = 3.0 + 5.0 * noise.uniform();
                let amp = 0.5 + noise.uniform();
                (
                    dir * amp,
                    std::f64::consts::TAU * f_hz,
                    std::f64::consts::TAU * noise.uniform(),
                )
            })
            .collect();
        Self {
            start_s: bout.start_s,
            duration_s: bout.duration_s,
            parts,
            scale: 1.0,
        }
    }

    /// Envelope: a 0.5 s raised-cosine ramp at each end.
    fn envelope(&self, t_s: f64) -> f64 {
        let u = t_s - self.start_s;
        if u <= 0.0 || u >= self.duration_s {
            return 0.0;
        }
        let ramp = 0.5f64.min(self.duration_s / 2.0);
        let x = (u.min(self.duration_s - u) / ramp).min(1.0);
        0.5 - 0.5 * (std::f64::consts::PI * x).cos()
    }

    fn value(&self, t_s: f64) -> DVec3 {
        let e = self.envelope(t_s);
        if e == 0.0 {
            return DVec3::ZERO;
        }
        let sum: DVec3 = self.parts.iter().map(|(a, w, ph)| *a * (w * t_s + ph).sin()).sum();
        sum * e * self.scale
    }

    /// Second derivative by central differences (the wave is smooth; h is far below its periods).
    fn second_derivative(&self, t_s: f64) -> DVec3 {
        let h = 1e-4;
        (self.value(t_s + h) - 2.0 * self.value(t_s) + self.value(t_s - h)) / (h * h)
    }

    fn derivative(&self, t_s: f64) -> DVec3 {
        let h = 1e-5;
        (self.value(t_s + h) - self.value(t_s - h)) / (2.0 * h)
    }

    /// Scales the wave so that `of(t)` peaks at `peak` over the bout (sampled at 2 kHz).
    fn scale_peak(&mut self, peak: f64, of: impl Fn(&Self, f64) -> f64) {
        let n = (self.duration_s * 2000.0) as usize;
        let max = (0..=n)
            .map(|k| of(self, self.start_s + k as f64 / 2000.0))
            .fold(0.0, f64::max);
        if max > 0.0 {
            self.scale = peak / max;
        }
    }
}

/// A jolt: a half-sine push of `accel` for `half_s`, then the matching stop, so the velocity
/// returns to what it was.
#[derive(Clone, Copy, Debug)]
struct Jolt {
    start_s: f64,
    half_s: f64,
    accel: DVec3,
}

impl Jolt {
    fn acceleration(&self, t_s: f64) -> DVec3 {
        let u = t_s - self.start_s;
        if u <= 0.0 || u >= 2.0 * self.half_s {
            return DVec3::ZERO;
        }
        self.accel * (std::f64::consts::PI * u / self.half_s).sin()
    }
}

/// The imposed motion: translation (as acceleration) and rotational shake.
struct Shake {
    translation: Vec<Wave>,
    rotation: Vec<Wave>,
    jolts: Vec<Jolt>,
}

impl Shake {
    fn new(spec: &VigorousSpec, noise: &mut Noise) -> Self {
        let mut translation = Vec::new();
        let mut rotation = Vec::new();
        let mut jolts = Vec::new();
        for bout in &spec.bouts {
            let mut t = Wave::random(noise, bout);
            t.scale_peak(bout.peak_accel_m_s2, |w, t| w.second_derivative(t).length());
            translation.push(t);
            let mut r = Wave::random(noise, bout);
            r.scale_peak(bout.peak_rate_rad_s, |w, t| w.derivative(t).length());
            rotation.push(r);
            for j in 0..bout.jolts {
                let dir = DVec3::new(noise.uniform() - 0.5, noise.uniform() - 0.5, noise.uniform() - 0.5)
                    .try_normalize()
                    .unwrap_or(DVec3::Y);
                let at = bout.start_s + bout.duration_s * (j as f64 + 0.5) / bout.jolts as f64;
                jolts.push(Jolt {
                    start_s: at,
                    half_s: 0.03,
                    accel: dir * bout.peak_accel_m_s2,
                });
            }
        }
        Self {
            translation,
            rotation,
            jolts,
        }
    }

    /// Hand acceleration in the world frame, m/s².
    fn accel_world(&self, t_s: f64) -> DVec3 {
        let waves: DVec3 = self.translation.iter().map(|w| w.second_derivative(t_s)).sum();
        let jolts: DVec3 = self.jolts.iter().map(|j| j.acceleration(t_s)).sum();
        waves + jolts
    }

    /// The rotational shake, applied in the device frame after the slow track.
    fn rotation(&self, t_s: f64) -> DQuat {
        let v: DVec3 = self.rotation.iter().map(|w| w.value(t_s)).sum();
        DQuat::from_scaled_axis(v)
    }
}

/// The device → world orientation at each time: the slow track times the shake.
struct VigorousMotion<F: Fn(f64) -> DQuat> {
    slow: F,
    shake: Shake,
}

impl<F: Fn(f64) -> DQuat> VigorousMotion<F> {
    fn orientation(&self, t_s: f64) -> DQuat {
        ((self.slow)(t_s) * self.shake.rotation(t_s)).normalize()
    }

    /// Hand acceleration (gravity not included), world frame, m/s².
    fn accel_world(&self, t_s: f64) -> DVec3 {
        self.shake.accel_world(t_s)
    }
}

/// Samples the sensors of `spec` over `[0, duration_s]` for the slow orientation track `slow`
/// (device → world at a time in seconds) shaken as `spec` says; time-ordered events from
/// `t0_ns`, ground truth included.
pub fn simulate_vigorous(
    spec: &VigorousSpec,
    duration_s: f64,
    t0_ns: i64,
    slow: impl Fn(f64) -> DQuat,
) -> Vec<SensorEvent> {
    let mut noise = Noise::new(spec.seed);
    let motion = VigorousMotion {
        shake: Shake::new(spec, &mut noise),
        slow,
    };
    let g_world = DVec3::Z * GRAVITY_M_S2 as f64;
    let clip = |v: DVec3, range: f64| v.clamp(DVec3::splat(-range), DVec3::splat(range));
    let noise3 = |noise: &mut Noise, sigma: f64| noise.vec3(1.0).as_dvec3() * sigma;
    let mut events = Vec::new();
    let t_ns = |t_s: f64| t0_ns + (t_s * 1e9).round() as i64;
    if spec.imu_hz > 0.0 {
        let n = (duration_s * spec.imu_hz).floor() as i64;
        for k in 0..=n {
            let t = k as f64 / spec.imu_hz;
            let q = motion.orientation(t);
            let f = q.inverse() * (motion.accel_world(t) + g_world);
            let a = clip(
                f + spec.accel_bias_m_s2 + noise3(&mut noise, spec.accel_noise_m_s2),
                spec.accel_range_m_s2,
            );
            events.push(SensorEvent::accelerometer(t_ns(t), a.as_vec3()));
            // Mean body rate over the interval this sample ends.
            let dt = 1.0 / spec.imu_hz;
            let step = (motion.orientation(t - dt).inverse() * q).normalize();
            // q and −q are one rotation: take the short way round.
            let step = if step.w < 0.0 { -step } else { step };
            let w = step.to_scaled_axis() / dt;
            let w = clip(
                w + spec.gyro_bias_rad_s + noise3(&mut noise, spec.gyro_noise_rad_s),
                spec.gyro_range_rad_s,
            );
            events.push(SensorEvent::gyroscope(t_ns(t), w.as_vec3()));
        }
    }
    if spec.mag_hz > 0.0 {
        let n = (duration_s * spec.mag_hz).floor() as i64;
        for k in 0..=n {
            let t = k as f64 / spec.mag_hz;
            let m = motion.orientation(t).inverse() * spec.field_world_ut + noise3(&mut noise, spec.mag_noise_ut);
            events.push(SensorEvent::magnetometer(t_ns(t), m.as_vec3()));
        }
    }
    if spec.truth_hz > 0.0 {
        let n = (duration_s * spec.truth_hz).floor() as i64;
        for k in 0..=n {
            let t = k as f64 / spec.truth_hz;
            let q: Quat = motion.orientation(t).as_quat();
            events.push(SensorEvent::orientation(
                crate::sensors::SensorKind::GroundTruth,
                t_ns(t),
                q,
            ));
        }
    }
    // Stable: at equal time stamps the inertial samples come before the truth.
    events.sort_by_key(|e| e.t_ns);
    events
}

/// The orientation track of recorded ground truth, as a function of seconds from `t0_ns`:
/// spherical interpolation between the samples (held at the ends). Rows must be time-ordered
/// and finite (drop lost-tracking rows first).
pub fn track_from_samples(samples: Vec<(i64, DQuat)>, t0_ns: i64) -> impl Fn(f64) -> DQuat {
    move |t_s: f64| {
        let t = t0_ns as f64 + t_s * 1e9;
        let i = samples.partition_point(|(ts, _)| (*ts as f64) <= t);
        match (i.checked_sub(1).and_then(|j| samples.get(j)), samples.get(i)) {
            (Some((ta, qa)), Some((tb, qb))) => {
                let u = ((t - *ta as f64) / (*tb - *ta).max(1) as f64).clamp(0.0, 1.0);
                // Same hemisphere, so the slerp takes the short way.
                let qb = if qa.dot(*qb) < 0.0 { -*qb } else { *qb };
                qa.slerp(qb, u).normalize()
            }
            (Some((_, q)), None) | (None, Some((_, q))) => *q,
            (None, None) => DQuat::IDENTITY,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sensors::SensorKind;

    #[test]
    fn bouts_reach_their_peaks_and_the_sensors_clip() {
        let spec = VigorousSpec::phone(8.0, 72.0, 7);
        assert_eq!(spec.bouts.len(), 4);
        let events = simulate_vigorous(&spec, 72.0, 0, |_| DQuat::from_rotation_x(0.6));
        let acc: Vec<_> = events.iter().filter(|e| e.kind == SensorKind::Accelerometer).collect();
        let gyr: Vec<_> = events.iter().filter(|e| e.kind == SensorKind::Gyroscope).collect();
        let range = spec.accel_range_m_s2 as f32;
        // Some axis readings sit at the range limit, none beyond it.
        let clipped = acc
            .iter()
            .filter(|e| e.vec3().abs().max_element() >= range * 0.9999)
            .count();
        assert!(clipped > 20, "{clipped} clipped readings");
        assert!(acc.iter().all(|e| e.vec3().abs().max_element() <= range * 1.0001));
        // Hand acceleration peaks at the bout's figure; rates near 700 °/s in the last bout.
        let g = GRAVITY_M_S2;
        let big = acc.iter().filter(|e| e.vec3().length() > 8.0 * g).count();
        assert!(big > 100, "{big} readings above 8 g");
        let fastest = gyr
            .iter()
            .map(|e| e.vec3().length())
            .fold(0.0f32, f32::max)
            .to_degrees();
        assert!((500.0..2000.0).contains(&fastest), "{fastest}°/s");
        // At rest between bouts the accelerometer reads gravity (plus bias and noise).
        let calm = acc.iter().find(|e| e.t_ns == 18_000_000_000).unwrap();
        assert!((calm.vec3().length() - g).abs() < 0.2, "{:?}", calm.vec3());
    }

    #[test]
    fn gyroscope_integrates_to_the_truth_through_the_shaking() {
        let spec = VigorousSpec {
            gyro_noise_rad_s: 0.0,
            gyro_bias_rad_s: DVec3::ZERO,
            gyro_range_rad_s: 1e3,
            ..VigorousSpec::phone(16.0, 24.0, 3)
        };
        let slow = |t: f64| DQuat::from_rotation_z(0.3 * t) * DQuat::from_rotation_x(0.8);
        let events = simulate_vigorous(&spec, 24.0, 0, slow);
        let mut q: Option<DQuat> = None;
        let mut last: Option<i64> = None;
        let mut worst = 0.0f64;
        for e in &events {
            match e.kind {
                SensorKind::Gyroscope => {
                    if let (Some(t), Some(q)) = (last, q.as_mut()) {
                        *q = (*q * DQuat::from_scaled_axis(e.vec3().as_dvec3() * ((e.t_ns - t) as f64 * 1e-9)))
                            .normalize();
                    }
                    last = Some(e.t_ns);
                }
                SensorKind::GroundTruth => {
                    let truth = e.quat().unwrap().as_dquat();
                    match q {
                        None => q = Some(truth),
                        Some(q) => worst = worst.max(q.angle_between(truth).to_degrees()),
                    }
                }
                _ => {}
            }
        }
        assert!(worst < 0.05, "gyroscope integration strays {worst}° from the truth");
    }
}
