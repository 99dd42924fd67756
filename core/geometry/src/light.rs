//! A directional light that stays fixed in the room.
//!
//! At start (the first time an orientation is known) or on re-calibration, the light's default
//! direction — given in the device frame, i.e. as the user sees it on the screen at that moment —
//! is tied to the world through the current device → world orientation (gravity and magnetic
//! field). Afterwards its device-frame direction is the world direction rotated back by the
//! current orientation: turning the phone by 90° about the vertical turns the light by 90° the
//! other way on screen, while pitching the phone leaves the light's heading in the room unchanged
//! (the orientation's heading is tilt-compensated, see `phantogram_sensing::attitude`).
//!
//! Directions are unit vectors pointing *towards* the light.

use glam::{Quat, Vec3};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WorldLight {
    default_toward_light_device: Vec3,
    toward_light_world: Option<Vec3>,
}

impl Default for WorldLight {
    fn default() -> Self {
        Self::new(Self::DEFAULT_TOWARD_LIGHT_DEVICE)
    }
}

impl WorldLight {
    /// Over the viewer's left shoulder: up-left and in front of the glass, the classic key light.
    /// (Not normalised; [`Self::new`] normalises.)
    pub const DEFAULT_TOWARD_LIGHT_DEVICE: Vec3 = Vec3::new(-0.4, 0.5, 0.77);

    /// `toward_light_device`: where the light should appear at anchoring time, device frame.
    /// A degenerate vector falls back to straight above the glass.
    pub fn new(toward_light_device: Vec3) -> Self {
        Self {
            default_toward_light_device: toward_light_device.try_normalize().unwrap_or(Vec3::Z),
            toward_light_world: None,
        }
    }

    pub fn is_anchored(&self) -> bool {
        self.toward_light_world.is_some()
    }

    /// Ties the default direction to the world at the current orientation.
    pub fn anchor(&mut self, device_to_world: Quat) {
        self.toward_light_world = Some((device_to_world * self.default_toward_light_device).normalize());
    }

    /// Forgets the anchor; the next [`Self::anchor`] ties the light anew.
    pub fn release(&mut self) {
        self.toward_light_world = None;
    }

    /// Direction towards the light in the world frame, once anchored.
    pub fn toward_light_world(&self) -> Option<Vec3> {
        self.toward_light_world
    }

    /// Direction towards the light in the device frame for the current orientation; the default
    /// direction while not anchored.
    pub fn toward_light_device(&self, device_to_world: Option<Quat>) -> Vec3 {
        match (self.toward_light_world, device_to_world) {
            (Some(w), Some(q)) => (q.inverse() * w).normalize(),
            _ => self.default_toward_light_device,
        }
    }
}

/// Heading of a world direction: radians clockwise from north towards east, in `(−π, π]`.
pub fn heading_rad(world_dir: Vec3) -> f32 {
    world_dir.x.atan2(world_dir.y)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unanchored_light_shows_its_default() {
        let l = WorldLight::new(Vec3::new(0.0, 0.0, 2.0));
        assert_eq!(l.toward_light_device(Some(Quat::from_rotation_x(1.0))), Vec3::Z);
        assert_eq!(WorldLight::new(Vec3::ZERO).toward_light_device(None), Vec3::Z);
    }

    #[test]
    fn anchored_light_counter_rotates_with_the_device() {
        let mut l = WorldLight::default();
        l.anchor(Quat::IDENTITY);
        let before = l.toward_light_device(Some(Quat::IDENTITY));
        let turned = Quat::from_rotation_z(std::f32::consts::FRAC_PI_2);
        let after = l.toward_light_device(Some(turned));
        let expected = Quat::from_rotation_z(-std::f32::consts::FRAC_PI_2) * before;
        assert!(after.distance(expected) < 1e-6);
        l.release();
        assert!(!l.is_anchored());
    }
}
