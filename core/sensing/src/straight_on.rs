//! The straight-on pose, re-adapted slowly to how the viewer settles: after "Start" (or a
//! double tap) fixes the pose held then as straight on, a visitor shifts — sits down, leans
//! back — and would otherwise see the artifact from an angle for as long as they hold the new
//! pose. Without a face to track, the straight-on "up" follows the held "up" through a low-pass
//! of long time constant, so that:
//!
//! * a pose held for a minute or more becomes straight on (63 % of the way in
//!   [`StraightOnParams::time_constant_s`], 30 s; 95 % in 90 s);
//! * a tilt to look around the artifact — seconds long — still reads as a tilt: 2 s at 25°
//!   moves the reference by 25° × 2 / 30 ≈ 1.7°, which flows back when the tilt ends;
//! * it stands still while the phone moves (the held "up" turning faster than
//!   [`StraightOnParams::max_steady_rate_rad_s`]), while a face is tracked (the camera gives the
//!   eyes themselves), and for poses further than [`StraightOnParams::max_offset_rad`] from it
//!   (the phone laid on a table or handed over is not a new way of looking);
//! * it does nothing before a pose was taken: lying flat stays straight on, as in the paper.
//!
//! Plain data on the render thread; no panics.

use glam::{Quat, Vec3};

/// How the straight-on pose follows the held one (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StraightOnParams {
    pub time_constant_s: f32,
    /// Faster turning of the held "up" than this is motion, not a pose.
    pub max_steady_rate_rad_s: f32,
    /// Further from the straight-on "up" than this is not a viewing pose.
    pub max_offset_rad: f32,
}

impl Default for StraightOnParams {
    fn default() -> Self {
        Self {
            time_constant_s: 30.0,
            max_steady_rate_rad_s: 0.35,
            max_offset_rad: 40f32.to_radians(),
        }
    }
}

/// The low-pass state: the previous held "up" and its time.
#[derive(Clone, Debug, Default)]
pub struct StraightOnAdapter {
    params: StraightOnParams,
    last: Option<(i64, Vec3)>,
}

impl StraightOnAdapter {
    pub fn new(params: StraightOnParams) -> Self {
        Self { params, last: None }
    }

    /// One step at sensor time `t_ns`: `straight_up` is the current straight-on "up" (device
    /// frame), `held_up` the measured one, `face_tracked` whether the camera gives the eyes.
    /// Returns the new straight-on "up" (unchanged when it must stand still).
    pub fn step(&mut self, t_ns: i64, straight_up: Vec3, held_up: Vec3, face_tracked: bool) -> Vec3 {
        let Some(held) = held_up.try_normalize() else {
            return straight_up;
        };
        let previous = self.last.replace((t_ns, held));
        let Some((t0, up0)) = previous else {
            return straight_up;
        };
        let dt_s = crate::clock::elapsed_s(t0, t_ns) as f32;
        // Out of order, repeated, or a long gap (the app was paused): no step.
        if !(dt_s > 0.0 && dt_s < 1.0) || face_tracked {
            return straight_up;
        }
        let rate = up0.angle_between(held) / dt_s;
        let Some(straight) = straight_up.try_normalize() else {
            return straight_up;
        };
        if rate > self.params.max_steady_rate_rad_s || straight.angle_between(held) > self.params.max_offset_rad {
            return straight_up;
        }
        let alpha = 1.0 - (-dt_s / self.params.time_constant_s).exp();
        let toward = Quat::from_rotation_arc(straight, held);
        Quat::IDENTITY.slerp(toward, alpha) * straight
    }

    /// Forgets the previous sample (after the pose was set anew).
    pub fn reset(&mut self) {
        self.last = None;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// "Up" of a phone held `deg` from flat, top edge raised.
    fn held(deg: f32) -> Vec3 {
        let a = deg.to_radians();
        Vec3::new(0.0, a.sin(), a.cos())
    }

    fn deg_between(a: Vec3, b: Vec3) -> f32 {
        a.angle_between(b).to_degrees()
    }

    /// Runs `seconds` of a held pose (`up_at(t_s)`) at 100 Hz, returning the straight-on "up" at
    /// the end.
    fn run(
        a: &mut StraightOnAdapter,
        mut straight: Vec3,
        t0_s: f32,
        seconds: f32,
        up_at: impl Fn(f32) -> Vec3,
        face: bool,
    ) -> Vec3 {
        let steps = (seconds * 100.0) as i64;
        for k in 0..steps {
            let t_s = t0_s + k as f32 * 0.01;
            straight = a.step((f64::from(t_s) * 1e9) as i64, straight, up_at(t_s), face);
        }
        straight
    }

    #[test]
    fn a_new_pose_held_for_a_minute_and_a_half_becomes_straight_on() {
        let mut a = StraightOnAdapter::default();
        let straight = run(&mut a, held(35.0), 0.0, 90.0, |_| held(55.0), false);
        assert!(
            deg_between(straight, held(55.0)) < 20.0 * 0.06,
            "{}",
            deg_between(straight, held(55.0))
        );
        // After one time constant, about 63 % of the way.
        let mut b = StraightOnAdapter::default();
        let straight = run(&mut b, held(35.0), 0.0, 30.0, |_| held(55.0), false);
        let moved = deg_between(straight, held(35.0));
        assert!((moved - 20.0 * 0.632).abs() < 0.5, "{moved}");
    }

    #[test]
    fn a_tilt_of_a_few_seconds_still_reads_as_a_tilt_and_flows_back() {
        let mut a = StraightOnAdapter::default();
        // Held at 35°, then tilted to 60° over half a second, held 2 s, back over half a second.
        let up_at = |t: f32| {
            let deg = if t < 1.0 {
                35.0
            } else if t < 1.5 {
                35.0 + 25.0 * (t - 1.0) / 0.5
            } else if t < 3.5 {
                60.0
            } else if t < 4.0 {
                60.0 - 25.0 * (t - 3.5) / 0.5
            } else {
                35.0
            };
            held(deg)
        };
        let during = run(&mut a, held(35.0), 0.0, 3.5, up_at, false);
        // The tilt moved the reference by under two degrees: the view still turned by ~23°.
        assert!(
            deg_between(during, held(35.0)) < 2.0,
            "{}",
            deg_between(during, held(35.0))
        );
        let after = run(&mut a, during, 3.5, 60.0, up_at, false);
        assert!(
            deg_between(after, held(35.0)) < 0.3,
            "{}",
            deg_between(after, held(35.0))
        );
    }

    #[test]
    fn it_stands_still_while_moving_while_a_face_is_tracked_and_far_from_the_pose() {
        // Waved back and forth at 1 Hz through ±20°: turning at up to 2.2 rad/s.
        let mut a = StraightOnAdapter::default();
        let waved = run(
            &mut a,
            held(35.0),
            0.0,
            30.0,
            |t| held(35.0 + 20.0 * (std::f32::consts::TAU * t).sin()),
            false,
        );
        assert!(
            deg_between(waved, held(35.0)) < 2.0,
            "{}",
            deg_between(waved, held(35.0))
        );
        let mut b = StraightOnAdapter::default();
        let tracked = run(&mut b, held(35.0), 0.0, 60.0, |_| held(55.0), true);
        assert_eq!(tracked, held(35.0));
        // Laid flat on a table from a 60° pose: 60° away, not a way of looking.
        let mut c = StraightOnAdapter::default();
        let laid = run(&mut c, held(60.0), 0.0, 60.0, |_| held(0.0), false);
        assert!(deg_between(laid, held(60.0)) < 1e-3);
    }

    #[test]
    fn gaps_and_nonsense_leave_it_as_it_was() {
        let mut a = StraightOnAdapter::default();
        let s = held(35.0);
        assert_eq!(a.step(0, s, held(50.0), false), s, "a first sample has no rate");
        assert_eq!(a.step(5_000_000_000, s, held(50.0), false), s, "a 5 s gap");
        assert_eq!(a.step(4_000_000_000, s, held(50.0), false), s, "backwards");
        assert_eq!(a.step(4_010_000_000, s, Vec3::ZERO, false), s);
        assert_eq!(a.step(4_020_000_000, Vec3::ZERO, held(50.0), false), Vec3::ZERO);
    }
}
