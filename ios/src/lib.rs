//! The iOS side of the phantogram core: the C ABI the Swift shell calls ([`ffi`], header
//! `include/phantogram.h`), the `UIView` surface ([`platform_ios`]), and the conversion from
//! Core Motion's conventions to the core's sensor events (below).
//!
//! Built as a static library (`cargo xtask ios` packs it into an XCFramework on macOS). The
//! desktop tests link the same static library into a C program (`tests/c/replay.c`).
//!
//! Core Motion's device axes are the core's (x right, y up, z out of the screen), but its
//! accelerometer reports in g with the opposite sign (a phone lying face up reads −1 g on z, where
//! the core, like Android, reads +9.81 m/s²). Gyroscope (rad/s) and calibrated magnetic field (µT)
//! pass through. Time stamps are seconds since boot (`CMLogItem.timestamp`).

use phantogram::glam::{Quat, Vec3};

pub mod ffi;
pub mod platform_ios;

mod platform {
    pub use super::platform_ios::view_window;
}
use phantogram::sensors::SensorEvent;

/// Standard gravity used by Core Motion's g unit, m/s².
pub const STANDARD_GRAVITY_M_S2: f64 = 9.80665;

/// Seconds (Core Motion time stamp) to the core's integer nanoseconds; `None` if not finite or
/// beyond the core's ±[`phantogram::sensors::MAX_ABS_T_NS`].
pub fn timestamp_ns(seconds: f64) -> Option<i64> {
    let ns = seconds * 1e9;
    (ns.is_finite() && ns.abs() <= phantogram::sensors::MAX_ABS_T_NS as f64).then(|| ns.round() as i64)
}

/// `CMAccelerometerData.acceleration` (g, iOS sign) → core accelerometer event (m/s², up positive).
pub fn accelerometer_event(timestamp_s: f64, acceleration_g: [f64; 3]) -> Option<SensorEvent> {
    let a = acceleration_g.map(|g| (-g * STANDARD_GRAVITY_M_S2) as f32);
    Some(SensorEvent::accelerometer(
        timestamp_ns(timestamp_s)?,
        Vec3::from_array(a),
    ))
}

/// `CMGyroData.rotationRate` (rad/s) → core gyroscope event.
pub fn gyroscope_event(timestamp_s: f64, rate_rad_s: [f64; 3]) -> Option<SensorEvent> {
    Some(SensorEvent::gyroscope(
        timestamp_ns(timestamp_s)?,
        Vec3::from_array(rate_rad_s.map(|v| v as f32)),
    ))
}

/// `CMMagnetometerData.magneticField` (µT) → core magnetometer event.
pub fn magnetometer_event(timestamp_s: f64, field_ut: [f64; 3]) -> Option<SensorEvent> {
    Some(SensorEvent::magnetometer(
        timestamp_ns(timestamp_s)?,
        Vec3::from_array(field_ut.map(|v| v as f32)),
    ))
}

/// `CMDeviceMotion.attitude.quaternion` (w, x, y, z) in the `xMagneticNorthZVertical` reference
/// frame (x magnetic north, z up, y west) → a core rotation-vector event (device → ENU world):
/// a quarter turn about z takes north to the world's y and west to −x. The quaternion is taken
/// to rotate device vectors into the reference frame; this reading of Apple's documentation has
/// not been checked on a device (it only feeds the comparison, never the estimators).
pub fn attitude_event(timestamp_s: f64, wxyz: [f64; 4]) -> Option<SensorEvent> {
    let q = Quat::from_xyzw(wxyz[1] as f32, wxyz[2] as f32, wxyz[3] as f32, wxyz[0] as f32);
    if !q.is_finite() || q.length_squared() < 0.5 {
        return None;
    }
    let enu_from_reference = Quat::from_rotation_z(std::f32::consts::FRAC_PI_2);
    Some(SensorEvent::orientation(
        phantogram::sensors::SensorKind::RotationVector,
        timestamp_ns(timestamp_s)?,
        (enu_from_reference * q.normalize()).normalize(),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn face_up_reads_up_in_the_core_convention() {
        let e = accelerometer_event(1.5, [0.0, 0.0, -1.0]).unwrap();
        assert_eq!(e.t_ns, 1_500_000_000);
        assert!((e.vec3() - Vec3::new(0.0, 0.0, 9.80665)).length() < 1e-5);
        assert!(gyroscope_event(f64::NAN, [0.0; 3]).is_none());
        assert_eq!(
            magnetometer_event(0.0, [1.0, 2.0, 3.0]).unwrap().vec3(),
            Vec3::new(1.0, 2.0, 3.0)
        );
    }
}
