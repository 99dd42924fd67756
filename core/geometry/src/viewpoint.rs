//! The viewpoint from gravity, the paper's method: the viewer's cyclopean eye is assumed to lie
//! along "up" at the viewing distance, `eye = d · normalize(aₜ)` in the device frame, where `aₜ` is
//! the low-passed accelerometer (`phantogram_sensing::attitude::LowPassAttitude`).
//!
//! **Sign**: the paper writes `v = −d·aₜ` because iOS reports −1 g on z for a phone lying face up;
//! Android (and this crate's device frame) reads +9.81 m/s² on z in that pose, so the eye lies along
//! `+aₜ`: straight above the glass.
//!
//! **Flat angle**: nobody holds a phone flat. A flat-angle calibration stores the rotation that
//! takes the "up" measured in a chosen holding pose to the screen normal, so that this pose counts
//! as "straight on"; every later "up" is rotated by it. [`Viewpoint::calibrate_flat_angle`] sets it
//! from the current pose in one call.
//!
//! **Front hemisphere**: the viewer is always in front of the glass. When "up" points behind it
//! (the phone held above the head, screen down) the eye is kept at least
//! [`Viewpoint::MIN_ELEVATION_RAD`] above the glass plane, in the same azimuth.

use glam::{Quat, Vec3};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Viewpoint {
    /// Rotates measured "up" (device frame) into the direction of the eye (device frame).
    flat_reference: Quat,
}

impl Default for Viewpoint {
    fn default() -> Self {
        Self {
            flat_reference: Quat::IDENTITY,
        }
    }
}

impl Viewpoint {
    /// Lowest elevation of the eye above the glass plane: 10°.
    pub const MIN_ELEVATION_RAD: f32 = 10.0 * std::f32::consts::PI / 180.0;

    /// Makes the pose in which "up" reads `up_device` count as straight on. Returns `false` and
    /// changes nothing if `up_device` is degenerate.
    pub fn calibrate_flat_angle(&mut self, up_device: Vec3) -> bool {
        match up_device.try_normalize() {
            Some(up) => {
                self.flat_reference = Quat::from_rotation_arc(up, Vec3::Z);
                true
            }
            None => false,
        }
    }

    /// Back to the paper's default: lying flat is straight on.
    pub fn reset_flat_angle(&mut self) {
        self.flat_reference = Quat::IDENTITY;
    }

    pub fn flat_reference(&self) -> Quat {
        self.flat_reference
    }

    /// The unit "up" (device frame) of the pose calibrated as straight on, as
    /// [`Self::calibrate_flat_angle`] took it (for saving); `None` while lying flat is straight on.
    pub fn flat_up_device(&self) -> Option<Vec3> {
        (self.flat_reference != Quat::IDENTITY).then(|| self.flat_reference.inverse() * Vec3::Z)
    }

    /// Unit direction from the screen centre to the cyclopean eye, device frame. With no usable
    /// "up" yet, the viewer is assumed straight on.
    pub fn eye_direction(&self, up_device: Option<Vec3>) -> Vec3 {
        let Some(up) = up_device.and_then(Vec3::try_normalize) else {
            return Vec3::Z;
        };
        keep_in_front(self.flat_reference * up)
    }

    /// The cyclopean eye position in metres, device frame.
    pub fn cyclopean_eye_m(&self, up_device: Option<Vec3>, viewing_distance_m: f32) -> Vec3 {
        self.eye_direction(up_device) * viewing_distance_m
    }
}

fn keep_in_front(dir: Vec3) -> Vec3 {
    let min_z = Viewpoint::MIN_ELEVATION_RAD.sin();
    if dir.z >= min_z {
        return dir;
    }
    match glam::Vec2::new(dir.x, dir.y).try_normalize() {
        Some(xy) => {
            let c = Viewpoint::MIN_ELEVATION_RAD.cos();
            Vec3::new(xy.x * c, xy.y * c, min_z)
        }
        None => Vec3::Z,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn deg(a: Vec3, b: Vec3) -> f32 {
        a.angle_between(b).to_degrees()
    }

    #[test]
    fn flat_phone_puts_the_eye_straight_above() {
        let v = Viewpoint::default();
        // Android reads +9.81 on z lying face up: the eye is at +z, not -z (the paper's iOS sign).
        let eye = v.cyclopean_eye_m(Some(Vec3::new(0.0, 0.0, 9.81)), 0.3);
        assert!(eye.distance(Vec3::new(0.0, 0.0, 0.3)) < 1e-6);
        assert_eq!(v.eye_direction(None), Vec3::Z);
    }

    #[test]
    fn flat_angle_calibration_makes_the_holding_pose_straight_on() {
        let mut v = Viewpoint::default();
        // Held at 40° from horizontal, top edge raised: up has components along +y and +z.
        let tilt = 40f32.to_radians();
        let up40 = Vec3::new(0.0, tilt.sin(), tilt.cos());
        assert!((deg(v.eye_direction(Some(up40)), Vec3::Z) - 40.0).abs() < 1e-3);
        assert!(v.calibrate_flat_angle(up40 * 9.81));
        assert!(deg(v.eye_direction(Some(up40)), Vec3::Z) < 1e-3);
        // Tilting 10° further about the same axis moves the eye 10° off the normal.
        let t50 = 50f32.to_radians();
        let up50 = Vec3::new(0.0, t50.sin(), t50.cos());
        assert!((deg(v.eye_direction(Some(up50)), Vec3::Z) - 10.0).abs() < 1e-3);
        assert!(!v.calibrate_flat_angle(Vec3::ZERO));
        // What a calibration file keeps gives the same viewpoint back.
        let saved = v.flat_up_device().unwrap();
        assert!(saved.distance(up40) < 1e-6, "{saved}");
        let mut restored = Viewpoint::default();
        assert!(restored.calibrate_flat_angle(saved));
        assert!(deg(restored.eye_direction(Some(up50)), v.eye_direction(Some(up50))) < 1e-3);
        v.reset_flat_angle();
        assert_eq!(v.flat_reference(), Quat::IDENTITY);
        assert_eq!(v.flat_up_device(), None);
    }

    #[test]
    fn eye_never_goes_behind_the_glass() {
        let v = Viewpoint::default();
        for up in [Vec3::new(1.0, 0.0, -0.5), Vec3::new(0.0, -1.0, -3.0), -Vec3::Z] {
            let d = v.eye_direction(Some(up));
            assert!(d.z >= Viewpoint::MIN_ELEVATION_RAD.sin() - 1e-6, "{up} -> {d}");
            assert!((d.length() - 1.0).abs() < 1e-5);
        }
    }
}
