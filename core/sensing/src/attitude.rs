//! Device attitude: where "up" is in the device frame, and the full device → world orientation.
//!
//! [`OrientationEstimator`] is the seam between the sensors and everything that needs the phone's
//! pose (viewpoint, world-fixed light). [`LowPassAttitude`] is the paper's method: the
//! accelerometer, low-passed, is taken as the "up" direction; the magnetometer, low-passed too,
//! gives the heading. The orientation from the two vectors is tilt-compensated by construction
//! (east = field × up, north = up × east, as Android's `SensorManager.getRotationMatrix`), so
//! pitching the phone does not swing the heading however steep the field's inclination.
//!
//! Limits of this estimator, by design (it is the published baseline): it lags by its time
//! constant, and it cannot tell gravity from the hand's own acceleration.

use glam::{Mat3, Quat, Vec3};

use crate::lowpass::VectorLowPass;
use crate::sensors::{SensorEvent, SensorKind};

/// Anything that turns sensor events into an attitude. Implementations ignore event kinds they
/// do not use, and must stay finite whatever they are fed.
pub trait OrientationEstimator: Send {
    /// Feeds one event; events arrive in time order per sensor.
    fn push(&mut self, event: &SensorEvent);
    /// Unit vector pointing away from the Earth (opposite to gravity), in the device frame.
    fn up_device(&self) -> Option<Vec3>;
    /// Device → world (east, north, up) rotation, once both gravity and a usable magnetic field
    /// are known.
    fn device_to_world(&self) -> Option<Quat>;
    /// Device → world predicted forward to `t_ns` (a frame's display time). Estimators that
    /// cannot predict return the current estimate.
    fn predict_device_to_world(&self, t_ns: i64) -> Option<Quat> {
        let _ = t_ns;
        self.device_to_world()
    }
    /// Clears all state (e.g. after the sensors restart).
    fn reset(&mut self);
    /// The sensors' ranges as the platform declares them; estimators that do not use them
    /// ignore them.
    fn set_sensor_ranges(&mut self, ranges: crate::sensors::SensorRanges) {
        let _ = ranges;
    }
}

/// The orientation with rows east, north, up expressed in the device frame, from the "up"
/// direction and the magnetic field (both device frame). `None` if either is degenerate or the
/// two are parallel.
pub fn device_to_world_from_up_and_field(up: Vec3, field: Vec3) -> Option<Quat> {
    let up = up.try_normalize()?;
    let east = field.cross(up).try_normalize()?;
    let north = up.cross(east);
    // Rows E, N, U map a device vector v to (E·v, N·v, U·v) in the world.
    let m = Mat3::from_cols(east, north, up).transpose();
    let q = Quat::from_mat3(&m).normalize();
    q.is_finite().then_some(q)
}

/// A device → world rotation with an arbitrary but consistent heading, from "up" alone: used
/// where no magnetometer is available, so that tilt is still tracked.
pub fn device_to_world_from_up(up: Vec3) -> Option<Quat> {
    let up = up.try_normalize()?;
    Some(Quat::from_rotation_arc(up, Vec3::Z))
}

/// The paper's estimator: low-passed accelerometer for "up", low-passed magnetometer for heading.
#[derive(Clone, Debug)]
pub struct LowPassAttitude {
    accel: VectorLowPass,
    field: VectorLowPass,
}

impl LowPassAttitude {
    /// The default time constant, the paper's `c = 0.1` at 100 Hz expressed in seconds.
    pub const DEFAULT_TAU_S: f32 = 0.095;

    pub fn new(accel_tau_s: f32, field_tau_s: f32) -> Self {
        Self {
            accel: VectorLowPass::new(accel_tau_s),
            field: VectorLowPass::new(field_tau_s),
        }
    }

    pub fn accel_time_constant_s(&self) -> f32 {
        self.accel.time_constant_s()
    }

    /// The low-passed magnetic field in the device frame, µT.
    pub fn field_device(&self) -> Option<Vec3> {
        self.field.value()
    }
}

impl Default for LowPassAttitude {
    fn default() -> Self {
        Self::new(Self::DEFAULT_TAU_S, Self::DEFAULT_TAU_S)
    }
}

impl OrientationEstimator for LowPassAttitude {
    fn push(&mut self, event: &SensorEvent) {
        if !event.time_in_range() {
            return; // its interval to the previous sample could overflow
        }
        match event.kind {
            SensorKind::Accelerometer => {
                self.accel.update(event.t_ns, event.vec3());
            }
            SensorKind::Magnetometer => {
                self.field.update(event.t_ns, event.vec3());
            }
            _ => {}
        }
    }

    fn up_device(&self) -> Option<Vec3> {
        self.accel.value()?.try_normalize()
    }

    fn device_to_world(&self) -> Option<Quat> {
        device_to_world_from_up_and_field(self.up_device()?, self.field.value()?)
    }

    fn reset(&mut self) {
        self.accel.reset();
        self.field.reset();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Earth's field with a steep (60°) inclination, pointing north and down, µT.
    fn field_world() -> Vec3 {
        let incl = 60f32.to_radians();
        Vec3::new(0.0, incl.cos(), -incl.sin()) * 48.0
    }

    #[test]
    fn recovers_any_orientation_from_exact_vectors() {
        for (yaw, pitch, roll) in [(0.0, 0.0, 0.0), (1.0, 0.3, -0.2), (-2.5, -1.2, 0.7), (3.0, 1.5, 2.0)] {
            let truth = Quat::from_euler(glam::EulerRot::ZXY, yaw, pitch, roll);
            let up = truth.inverse() * Vec3::Z;
            let field = truth.inverse() * field_world();
            let est = device_to_world_from_up_and_field(up, field).unwrap();
            assert!(est.angle_between(truth) < 1e-3, "{yaw} {pitch} {roll}");
        }
    }

    #[test]
    fn degenerate_inputs_give_none() {
        assert!(device_to_world_from_up_and_field(Vec3::ZERO, Vec3::Y).is_none());
        assert!(device_to_world_from_up_and_field(Vec3::Z, Vec3::Z * 3.0).is_none());
        assert!(device_to_world_from_up_and_field(Vec3::Z, Vec3::NAN).is_none());
        assert!(device_to_world_from_up(Vec3::ZERO).is_none());
    }

    #[test]
    fn low_pass_estimator_reads_up_from_the_accelerometer() {
        let mut a = LowPassAttitude::default();
        assert!(a.up_device().is_none());
        a.push(&SensorEvent::accelerometer(0, Vec3::new(0.0, 9.81, 0.0)));
        assert_eq!(a.up_device(), Some(Vec3::Y));
        assert!(a.device_to_world().is_none(), "no field yet");
        a.push(&SensorEvent::magnetometer(0, Vec3::new(0.0, 0.0, -30.0)));
        // Standing upright with a horizontal field out of the phone's back: the back (-z) faces
        // north, so the device → world map sends -z to north.
        let q = a.device_to_world().unwrap();
        assert!((q * -Vec3::Z).distance(Vec3::Y) < 1e-5);
    }
}
