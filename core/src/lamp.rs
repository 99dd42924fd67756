//! A lamp the visitor places: a point or spot light over the diorama, in place of the room's
//! directional light — a raking light low over a tablet to read its inscription, a torch held by
//! the phone. A finger on the glass moves it (the engine's drags, while a lamp is on): the lamp
//! goes above the touched point at its height, its cone aimed at the artifact.
//!
//! **Frames**: positions in the device frame (metres; the diorama's mesh coordinates: x right,
//! y up the screen, z out of the glass, origin at the screen's centre). A [`LampAnchor::Room`]
//! lamp keeps its place in the room as the phone turns (it turns about the diorama's centre,
//! as the room's light does); a [`LampAnchor::Torch`] lamp stays where it is on the phone.
//!
//! Plain data; no panics (non-finite input leaves the lamp where it was).

use glam::{Quat, Vec3};

use crate::render::Lamp;

/// How a lamp keeps its place.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LampAnchor {
    /// Fixed in the room: turning the phone moves it across the diorama.
    Room,
    /// Held by the phone like a torch.
    Torch,
}

/// What kind of lamp, and how bright.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LampSetting {
    pub anchor: LampAnchor,
    /// Half-angle of its cone (a spot light), radians; `None`: a bare bulb shining every way.
    pub cone_half_angle_rad: Option<f32>,
    /// Radiant intensity, linear RGB per steradian.
    pub intensity_rgb: Vec3,
    /// Height above the glass, metres: low for a raking light.
    pub height_m: f32,
}

impl LampSetting {
    /// A raking spot light, fixed in the room: 2 cm above the glass, its light grazing the
    /// diorama from the side, bright enough at 6 cm to match the room's light head-on.
    pub fn raking() -> Self {
        Self {
            anchor: LampAnchor::Room,
            cone_half_angle_rad: Some(1.0),
            intensity_rgb: Vec3::new(3.2, 3.0, 2.7) * 0.06 * 0.06 * 2.0,
            height_m: 0.02,
        }
    }

    /// A torch held by the phone above its top edge, shining down into the diorama.
    pub fn torch() -> Self {
        Self {
            anchor: LampAnchor::Torch,
            cone_half_angle_rad: Some(0.5),
            intensity_rgb: Vec3::new(3.2, 3.1, 3.0) * 0.12 * 0.12,
            height_m: 0.08,
        }
    }
}

/// A lamp placed in the diorama.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlacedLamp {
    pub setting: LampSetting,
    /// Where it was placed, device frame, and the device → world orientation then (`None`: not
    /// known yet; it is taken at the first frame with one).
    position_m: Vec3,
    placed_at: Option<Quat>,
}

impl PlacedLamp {
    /// A lamp above the point `(x_m, y_m)` of the glass (device frame) at the setting's height.
    pub fn new(setting: LampSetting, x_m: f32, y_m: f32) -> Self {
        let height = if setting.height_m.is_finite() {
            setting.height_m.max(0.001)
        } else {
            0.05
        };
        Self {
            setting,
            position_m: Vec3::new(x_m, y_m, height),
            placed_at: None,
        }
        .finite_or(Vec3::new(0.0, 0.0, height))
    }

    fn finite_or(mut self, fallback: Vec3) -> Self {
        if !self.position_m.is_finite() {
            self.position_m = fallback;
        }
        self
    }

    /// Moves the lamp above the point `(x_m, y_m)` of the glass, now (`device_to_world`: the
    /// device's orientation at this moment, for a room-fixed lamp).
    pub fn move_to(&mut self, x_m: f32, y_m: f32, device_to_world: Option<Quat>) {
        if !(x_m.is_finite() && y_m.is_finite()) {
            return;
        }
        self.position_m = Vec3::new(x_m, y_m, self.position_m.z);
        self.placed_at = device_to_world;
    }

    /// Where it is now, device frame, with the device at `device_to_world`.
    pub fn position_m(&mut self, device_to_world: Option<Quat>) -> Vec3 {
        match (self.setting.anchor, self.placed_at, device_to_world) {
            (LampAnchor::Room, Some(then), Some(now)) => now.inverse() * (then * self.position_m),
            (LampAnchor::Room, None, Some(now)) => {
                // The first orientation known: the lamp is fixed in the room from here.
                self.placed_at = Some(now);
                self.position_m
            }
            _ => self.position_m,
        }
    }

    /// The renderer's lamp this frame, aimed at `target` (the artifact's centre).
    pub fn lamp(&mut self, device_to_world: Option<Quat>, target: Vec3) -> Lamp {
        let position_m = self.position_m(device_to_world);
        Lamp {
            position_m,
            axis: (target - position_m).normalize_or(-Vec3::Z),
            cone_half_angle_rad: self.setting.cone_half_angle_rad,
            intensity_rgb: self.setting.intensity_rgb,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_room_lamp_stays_in_the_room_and_a_torch_on_the_phone() {
        let mut room = PlacedLamp::new(LampSetting::raking(), -0.05, 0.0);
        let mut torch = PlacedLamp::new(LampSetting::torch(), 0.0, 0.07);
        let flat = Quat::IDENTITY;
        assert_eq!(room.position_m(Some(flat)), Vec3::new(-0.05, 0.0, 0.02));
        // The phone turns a quarter about its normal: the room's lamp turns the other way in the
        // device frame, the torch stays.
        let turned = Quat::from_rotation_z(std::f32::consts::FRAC_PI_2);
        let p = room.position_m(Some(turned));
        assert!(p.distance(Vec3::new(0.0, 0.05, 0.02)) < 1e-6, "{p}");
        assert_eq!(torch.position_m(Some(turned)), Vec3::new(0.0, 0.07, 0.08));
        // Moved by a finger while turned: placed there now, and it stays there in the room.
        room.move_to(0.01, -0.02, Some(turned));
        assert!(room.position_m(Some(turned)).distance(Vec3::new(0.01, -0.02, 0.02)) < 1e-6);
        // The renderer's lamp aims at the target.
        let lamp = torch.lamp(Some(turned), Vec3::ZERO);
        assert!(lamp.axis.distance(-Vec3::new(0.0, 0.07, 0.08).normalize()) < 1e-6);
        assert_eq!(lamp.cone_half_angle_rad, Some(0.5));
        // Nonsense leaves it where it was.
        torch.move_to(f32::NAN, 0.0, None);
        assert_eq!(torch.position_m(None), Vec3::new(0.0, 0.07, 0.08));
        let placed = PlacedLamp::new(LampSetting::torch(), f32::INFINITY, 0.0);
        assert!(placed.position_m.is_finite());
    }
}
