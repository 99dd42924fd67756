//! The gravity the diorama's bodies feel, in the device frame.
//!
//! The tray moves with the phone, so the bodies are simulated in the device frame, where two
//! things pull on them:
//!
//! * the room's real gravity, `g_device = R⁻¹ · (0, 0, −9.81)` with `R` the fused device → world
//!   orientation: tilt the phone to the left in the room and "down" in the device frame points
//!   to its left edge, so the bodies slide there;
//! * the hand's own acceleration, as a box in the hand makes its contents lag behind: in the
//!   device's accelerating frame a free body accelerates by `−a`, where `a = s + g_device` is the
//!   device's linear acceleration from the accelerometer's specific force `s`. This nudge is
//!   low-passed (time constant [`ShakeParams::time_constant_s`], so sensor noise does not
//!   jitter resting bodies) and bounded to [`ShakeParams::max_m_s2`] (half a g by default:
//!   enough to slosh the tray when shaken, never enough to throw a body against the lid from a
//!   knock). The rotation's own fictitious forces are left out: at a hand's turning rates they
//!   are far below the contacts' friction.
//!
//! Plain data; non-finite readings are ignored. **Panics**: none.

use glam::{Quat, Vec3};

/// Standard gravity, m/s².
pub const G_M_S2: f32 = 9.806_65;

/// How the hand's acceleration nudges the bodies.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShakeParams {
    /// Low-pass time constant, seconds.
    pub time_constant_s: f32,
    /// The largest nudge, m/s².
    pub max_m_s2: f32,
}

impl Default for ShakeParams {
    fn default() -> Self {
        Self {
            time_constant_s: 0.05,
            max_m_s2: 0.5 * G_M_S2,
        }
    }
}

/// The room's gravity in the device frame, from the device → world orientation.
pub fn gravity_device(device_to_world: Quat) -> Vec3 {
    device_to_world.inverse() * Vec3::new(0.0, 0.0, -G_M_S2)
}

/// The bodies' gravity: the room's plus the hand's bounded nudge (see the module docs).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ApparentGravity {
    params: ShakeParams,
    nudge: Vec3,
    last_t_ns: Option<i64>,
}

impl ApparentGravity {
    pub fn new(params: ShakeParams) -> Self {
        Self {
            params,
            nudge: Vec3::ZERO,
            last_t_ns: None,
        }
    }

    /// Takes an accelerometer reading (specific force, device frame, m/s²) at `t_ns` with the
    /// orientation of that moment.
    pub fn observe(&mut self, t_ns: i64, specific_force: Vec3, device_to_world: Quat) {
        if !specific_force.is_finite() || !device_to_world.is_finite() {
            return;
        }
        let dt_s = match self.last_t_ns {
            Some(last) if t_ns > last => (t_ns.saturating_sub(last)) as f32 * 1e-9,
            Some(_) => return, // out of order: skipped
            None => 0.0,
        };
        self.last_t_ns = Some(t_ns);
        let hand = specific_force + gravity_device(device_to_world);
        let target = -hand.clamp_length_max(self.params.max_m_s2);
        let k = if self.params.time_constant_s > 0.0 {
            1.0 - (-dt_s / self.params.time_constant_s).exp()
        } else {
            1.0
        };
        self.nudge = (self.nudge + (target - self.nudge) * k).clamp_length_max(self.params.max_m_s2);
    }

    /// The hand's nudge alone, device frame.
    pub fn nudge(&self) -> Vec3 {
        self.nudge
    }

    /// The gravity the bodies feel now, device frame.
    pub fn device(&self, device_to_world: Quat) -> Vec3 {
        gravity_device(device_to_world) + self.nudge
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_phone_tilted_left_pulls_towards_its_left_edge() {
        // Lying flat: straight into the glass.
        let flat = gravity_device(Quat::IDENTITY);
        assert!(flat.distance(Vec3::new(0.0, 0.0, -G_M_S2)) < 1e-5);
        // Rolled 30° so that its left edge is lower in the room (device +y towards world +y;
        // the left edge, −x, goes down): gravity gains a −x component.
        let rolled = Quat::from_rotation_y(-30f32.to_radians());
        let g = gravity_device(rolled);
        assert!(g.x < -4.0 && (g.length() - G_M_S2).abs() < 1e-4, "{g}");
    }

    #[test]
    fn the_hands_nudge_is_low_passed_and_bounded() {
        let mut a = ApparentGravity::new(ShakeParams::default());
        let q = Quat::IDENTITY;
        // At rest the accelerometer reads +g up: no nudge.
        for k in 0..100 {
            a.observe(k * 5_000_000, Vec3::new(0.0, 0.0, G_M_S2), q);
        }
        assert!(a.nudge().length() < 1e-4);
        // The hand jerks to the right at 3 g: the bodies lag to the left, by at most half a g.
        for k in 100..200 {
            a.observe(k * 5_000_000, Vec3::new(3.0 * G_M_S2, 0.0, G_M_S2), q);
        }
        let n = a.nudge();
        assert!(n.x < -0.49 * G_M_S2 && n.length() <= 0.5 * G_M_S2 + 1e-4, "{n}");
        assert!((a.device(q) - (gravity_device(q) + n)).length() < 1e-6);
        // One reading of the jerk alone (5 ms) moves it by a tenth of its way, not at once.
        let mut b = ApparentGravity::new(ShakeParams::default());
        b.observe(0, Vec3::new(0.0, 0.0, G_M_S2), q);
        b.observe(5_000_000, Vec3::new(3.0 * G_M_S2, 0.0, G_M_S2), q);
        assert!(b.nudge().length() < 0.11 * 0.5 * G_M_S2, "{}", b.nudge());
        // Nonsense is ignored.
        b.observe(6_000_000, Vec3::NAN, q);
        b.observe(1_000_000, Vec3::ZERO, q);
        assert!(b.nudge().is_finite());
    }
}
