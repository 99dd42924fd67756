//! "Reduce motion": the view turned by touch instead of by tilting the phone.
//!
//! For a visitor who cannot or would rather not tilt the phone (or who gets queasy when the
//! picture moves with the hand), the viewpoint stops following gravity and the camera: the eye
//! stays straight on, in the pose calibrated as such, and a one-finger drag turns the artifact.
//! The light stays where it was in the device frame when the mode was turned on, so that nothing
//! in the picture moves unless touched.
//!
//! Turning is stored as two angles of the eye about the straight-on direction (device frame):
//! `yaw` about the screen's up axis, `pitch` about its right axis, each within
//! [`TurnByTouch::MAX_TURN_RAD`] so that the eye stays well in front of the glass (the tilt
//! model's own limit is 10° above it). A drag to the right turns the artifact to the right (the
//! eye moves to the left around it); a drag down tilts its top towards the viewer.
//!
//! Plain data; no threads, no panics (non-finite turns are ignored).

use glam::{Quat, Vec3};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TurnByTouch {
    yaw_rad: f32,
    pitch_rad: f32,
    /// Device → world when the mode was turned on: the light and environment stay as they were.
    frozen_device_to_world: Option<Quat>,
    /// The viewing distance then (the camera may have measured it): kept, as the rest.
    distance_m: f32,
}

impl TurnByTouch {
    /// The largest turn from straight on, each way: 50°, so the eye stays 40° or more above the
    /// glass.
    pub const MAX_TURN_RAD: f32 = 50.0 * std::f32::consts::PI / 180.0;

    /// Turned on with the device → world orientation (if known) and the viewing distance of
    /// that moment.
    pub fn new(device_to_world: Option<Quat>, distance_m: f32) -> Self {
        Self {
            yaw_rad: 0.0,
            pitch_rad: 0.0,
            frozen_device_to_world: device_to_world,
            distance_m,
        }
    }

    /// Turns the artifact by `right_rad` (a drag to the right) and `down_rad` (a drag down).
    pub fn turn(&mut self, right_rad: f32, down_rad: f32) {
        if !(right_rad.is_finite() && down_rad.is_finite()) {
            return;
        }
        let max = Self::MAX_TURN_RAD;
        self.yaw_rad = (self.yaw_rad + right_rad).clamp(-max, max);
        self.pitch_rad = (self.pitch_rad + down_rad).clamp(-max, max);
    }

    /// The turn so far: (right, down), radians.
    pub fn angles_rad(&self) -> (f32, f32) {
        (self.yaw_rad, self.pitch_rad)
    }

    /// Unit direction from the screen centre to the eye, device frame: straight on (`+z`),
    /// turned about the displayed image's `up` and `right` axes (device frame: they follow the
    /// display rotation, so a drag right is a turn right however the phone is held). Turning
    /// the artifact right moves the eye left (−right); tilting its top towards the viewer moves
    /// the eye towards the image's lower edge (−up).
    pub fn eye_direction(&self, right: Vec3, up: Vec3) -> Vec3 {
        Quat::from_axis_angle(up, -self.yaw_rad) * Quat::from_axis_angle(right, self.pitch_rad) * Vec3::Z
    }

    pub fn device_to_world(&self) -> Option<Quat> {
        self.frozen_device_to_world
    }

    /// A newly calibrated viewing distance (a validated eye model's).
    pub fn set_distance_m(&mut self, distance_m: f32) {
        if distance_m.is_finite() && distance_m > 0.0 {
            self.distance_m = distance_m;
        }
    }

    /// The cyclopean eye, metres, device frame (axes as [`Self::eye_direction`]).
    pub fn eye_m(&self, right: Vec3, up: Vec3) -> Vec3 {
        self.eye_direction(right, up) * self.distance_m
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn drags_turn_the_eye_around_the_artifact_within_limits() {
        let mut t = TurnByTouch::new(None, 0.3);
        let (x, y) = (Vec3::X, Vec3::Y);
        assert_eq!(t.eye_direction(x, y), Vec3::Z, "straight on until touched");
        t.turn(0.3, 0.0);
        let d = t.eye_direction(x, y);
        assert!(d.x < -0.25 && d.y.abs() < 1e-6, "a drag right moves the eye left: {d}");
        t.turn(-0.3, 0.3);
        let d = t.eye_direction(x, y);
        assert!(
            d.y < -0.25 && d.x.abs() < 1e-6,
            "a drag down moves the eye towards the lower edge: {d}"
        );
        t.turn(10.0, 10.0);
        assert_eq!(t.angles_rad(), (TurnByTouch::MAX_TURN_RAD, TurnByTouch::MAX_TURN_RAD));
        let d = t.eye_direction(x, y);
        assert!(
            (d.length() - 1.0).abs() < 1e-5 && d.z > 0.3,
            "still in front of the glass: {d}"
        );
        // Landscape (the image's right is the device's +y): a drag right moves the eye to −y.
        let mut l = TurnByTouch::new(None, 0.3);
        l.turn(0.3, 0.0);
        let d = l.eye_direction(Vec3::Y, -Vec3::X);
        assert!(d.y < -0.25 && d.x.abs() < 1e-6, "{d}");
        t.turn(f32::NAN, 0.0);
        assert_eq!(t.angles_rad(), (TurnByTouch::MAX_TURN_RAD, TurnByTouch::MAX_TURN_RAD));
    }
}
