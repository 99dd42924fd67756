//! Front-space containment for a single object: whatever stands out in front of the glass must stay
//! inside the pyramid from each eye to the screen rectangle, or the screen's edge cuts it and the
//! illusion breaks. (Behind the glass, the screen edge reads as a window frame and hides it
//! naturally.)
//!
//! Geometry, for an axis-aligned box in the device frame and the pyramid of one eye `E`
//! (`E.z > 0`): a point `(x, y, z)` with `0 ≤ z < E.z` is inside iff the ray from `E` through it
//! crosses the glass inside the rectangle. For a column `(x, y)` whose foot lies in the rectangle,
//! the heights inside form an interval `[0, z_max(x, y)]` (the pyramid is convex and contains the
//! foot), so the box's front part is inside both pyramids iff the four top corners are below
//! `z_max` of their columns for both eyes, and the box's footprint lies within the rectangle. The
//! needed push-back (a move along −z) is therefore exact: `max(0, top − min z_max)`; a footprint
//! wider than the screen can only go entirely behind the glass.
//!
//! [`ContainmentSmoother`] turns the exact requirement into a push-back that never pops: it rises
//! at most [`ContainmentSmoother::max_step_m`] per frame (the requirement moves smoothly, since the
//! eye does), keeps a small margin, and relaxes with a time constant once the requirement drops.

use glam::{Vec2, Vec3};

use crate::screen::Screen;

/// Axis-aligned box in the device frame, metres.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    pub min: Vec3,
    pub max: Vec3,
}

impl Aabb {
    pub fn new(a: Vec3, b: Vec3) -> Self {
        Self {
            min: a.min(b),
            max: a.max(b),
        }
    }

    pub fn translated(&self, by: Vec3) -> Self {
        Self {
            min: self.min + by,
            max: self.max + by,
        }
    }

    /// Scaled about `pivot`.
    pub fn scaled_about(&self, pivot: Vec3, s: f32) -> Self {
        Self::new(pivot + (self.min - pivot) * s, pivot + (self.max - pivot) * s)
    }

    /// The `(n+1)³` points of a regular lattice spanning the box, corners included (`n ≥ 1`).
    pub fn lattice(&self, n: u32) -> impl Iterator<Item = Vec3> + '_ {
        let n = n.max(1);
        let step = (self.max - self.min) / n as f32;
        (0..=n).flat_map(move |i| {
            (0..=n).flat_map(move |j| (0..=n).map(move |k| self.min + step * Vec3::new(i as f32, j as f32, k as f32)))
        })
    }

    pub fn corners(&self) -> [Vec3; 8] {
        let (a, b) = (self.min, self.max);
        [
            Vec3::new(a.x, a.y, a.z),
            Vec3::new(b.x, a.y, a.z),
            Vec3::new(a.x, b.y, a.z),
            Vec3::new(b.x, b.y, a.z),
            Vec3::new(a.x, a.y, b.z),
            Vec3::new(b.x, a.y, b.z),
            Vec3::new(a.x, b.y, b.z),
            Vec3::new(b.x, b.y, b.z),
        ]
    }
}

/// Highest point of the column above glass point `(x, y)` that eye `eye_m` still sees through the
/// screen rectangle of half extents `half`; `None` if the column's foot is outside the rectangle
/// or the eye is not in front of the glass.
fn column_height_limit(eye_m: Vec3, xy: Vec2, half: Vec2) -> Option<f32> {
    if eye_m.z.is_nan() || eye_m.z <= 0.0 || xy.x.abs() > half.x || xy.y.abs() > half.y {
        return None;
    }
    // The ray from the eye through (x, y, z) meets the glass at E + (p − E)·s with
    // s = E.z / (E.z − z) ≥ 1; in-plane it moves away from E's foot as s grows. Find the largest
    // s that keeps it inside along each axis.
    let e = Vec2::new(eye_m.x, eye_m.y);
    let mut s_max = f32::INFINITY;
    for axis in 0..2 {
        let dir = xy[axis] - e[axis];
        let limit = if dir > 0.0 {
            (half[axis] - e[axis]) / dir
        } else if dir < 0.0 {
            (-half[axis] - e[axis]) / dir
        } else {
            f32::INFINITY
        };
        s_max = s_max.min(limit);
    }
    // s_max ≥ 1 because the foot is inside; z = E.z·(1 − 1/s).
    Some(eye_m.z * (1.0 - 1.0 / s_max.max(1.0)))
}

/// How far the box must move back (along −z, metres, ≥ 0) for its part in front of the glass to be
/// inside every eye's pyramid.
pub fn required_push_back_m(bounds: &Aabb, eyes_m: &[Vec3], screen: &Screen) -> f32 {
    let top = bounds.max.z;
    if top <= 0.0 {
        return 0.0;
    }
    let half = screen.half_extent_device_m();
    let mut lowest_limit = f32::INFINITY;
    for corner in &bounds.corners()[4..] {
        for &eye in eyes_m {
            match column_height_limit(eye, Vec2::new(corner.x, corner.y), half) {
                Some(z) => lowest_limit = lowest_limit.min(z),
                // Footprint outside the glass: only entirely behind it is safe.
                None => return top,
            }
        }
    }
    (top - lowest_limit).max(0.0)
}

/// Largest uniform scale in `(0, 1]` about `pivot` (a point on the glass inside the screen, e.g.
/// under the object's centre) at which the box needs no push-back. Bisection to 1e-4.
pub fn required_scale(bounds: &Aabb, pivot: Vec3, eyes_m: &[Vec3], screen: &Screen) -> f32 {
    let fits = |s: f32| required_push_back_m(&bounds.scaled_about(pivot, s), eyes_m, screen) <= 0.0;
    if fits(1.0) {
        return 1.0;
    }
    let (mut lo, mut hi) = (0.0f32, 1.0f32);
    while hi - lo > 1e-4 {
        let mid = 0.5 * (lo + hi);
        if fits(mid) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    lo
}

/// Rate-limited, hysteretic push-back.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContainmentSmoother {
    /// Largest change of the push-back in one update (one frame), metres.
    pub max_step_m: f32,
    /// Extra push-back kept while any is needed, metres: headroom for the rate limit.
    pub margin_m: f32,
    /// Time constant with which the push-back relaxes once less is needed, seconds.
    pub release_tau_s: f32,
    current_m: f32,
}

impl Default for ContainmentSmoother {
    /// 3 mm per frame (18 cm/s at 60 Hz), 2 mm margin, 0.5 s release.
    fn default() -> Self {
        Self::new(0.003, 0.002, 0.5)
    }
}

impl ContainmentSmoother {
    pub fn new(max_step_m: f32, margin_m: f32, release_tau_s: f32) -> Self {
        Self {
            max_step_m: max_step_m.max(0.0),
            margin_m: margin_m.max(0.0),
            release_tau_s: release_tau_s.max(0.0),
            current_m: 0.0,
        }
    }

    pub fn push_back_m(&self) -> f32 {
        self.current_m
    }

    /// Advances by one frame towards the push-back `bounds` needs for `eyes` (the frame's stereo
    /// pair) on `screen`, and returns it.
    pub fn follow(&mut self, bounds: &Aabb, eyes: &[Vec3], screen: &Screen, dt_s: f32) -> f32 {
        self.update(required_push_back_m(bounds, eyes, screen), dt_s)
    }

    /// Advances by one frame of `dt_s` seconds towards `required_m` and returns the push-back.
    pub fn update(&mut self, required_m: f32, dt_s: f32) -> f32 {
        if !required_m.is_finite() {
            return self.current_m;
        }
        let required_m = required_m.max(0.0);
        let target = if required_m > 0.0 {
            required_m + self.margin_m
        } else {
            0.0
        };
        let next = if target >= self.current_m {
            target.min(self.current_m + self.max_step_m)
        } else {
            let keep = if self.release_tau_s > 0.0 && dt_s > 0.0 {
                (-dt_s / self.release_tau_s).exp()
            } else {
                0.0
            };
            let relaxed = target + (self.current_m - target) * keep;
            // Hold at least what is required right now (plus margin), and never drop by more than
            // one step.
            relaxed.max(target).max(self.current_m - self.max_step_m)
        };
        self.current_m = next;
        next
    }

    pub fn reset(&mut self) {
        self.current_m = 0.0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn screen() -> Screen {
        Screen::default()
    }

    /// Independent check: every sampled point of the box's front part, pushed back, sees the glass
    /// inside the rectangle from every eye.
    fn inside_all(bounds: &Aabb, eyes: &[Vec3], s: &Screen) -> bool {
        let half = s.half_extent_device_m();
        bounds.lattice(6).filter(|p| p.z > 0.0).all(|p| {
            eyes.iter().all(|&e| {
                let hit = e + (p - e) * (e.z / (e.z - p.z));
                p.z < e.z && hit.x.abs() <= half.x + 1e-6 && hit.y.abs() <= half.y + 1e-6
            })
        })
    }

    #[test]
    fn lattice_spans_the_box() {
        let b = Aabb::new(Vec3::ZERO, Vec3::new(1.0, 2.0, 3.0));
        let pts: Vec<_> = b.lattice(2).collect();
        assert_eq!(pts.len(), 27);
        assert!(pts.contains(&Vec3::ZERO) && pts.contains(&Vec3::new(1.0, 2.0, 3.0)));
        assert!(pts.contains(&Vec3::new(0.5, 1.0, 1.5)));
    }

    #[test]
    fn push_back_is_exact() {
        let s = screen();
        let eyes = [Vec3::new(-0.03, 0.05, 0.28), Vec3::new(0.033, 0.05, 0.28)];
        let b = Aabb::new(Vec3::new(-0.025, -0.03, -0.04), Vec3::new(0.025, 0.04, 0.06));
        let d = required_push_back_m(&b, &eyes, &s);
        assert!(d > 0.0);
        assert!(inside_all(&b.translated(Vec3::Z * -d), &eyes, &s));
        // A millimetre less and it sticks out.
        assert!(!inside_all(&b.translated(Vec3::Z * -(d - 1e-3)), &eyes, &s));
    }

    #[test]
    fn footprint_wider_than_the_screen_goes_behind_the_glass() {
        let s = screen();
        let eyes = [Vec3::new(0.0, 0.0, 0.3)];
        let b = Aabb::new(Vec3::new(-0.05, -0.01, -0.02), Vec3::new(0.05, 0.01, 0.01));
        assert_eq!(required_push_back_m(&b, &eyes, &s), 0.01);
    }

    #[test]
    fn nothing_in_front_needs_nothing() {
        let b = Aabb::new(Vec3::new(-0.5, -0.5, -0.2), Vec3::new(0.5, 0.5, 0.0));
        assert_eq!(required_push_back_m(&b, &[Vec3::new(0.1, 0.0, 0.2)], &screen()), 0.0);
    }

    #[test]
    fn scale_makes_it_fit() {
        let s = screen();
        let eyes = [Vec3::new(0.1, 0.1, 0.25)];
        let b = Aabb::new(Vec3::new(-0.03, -0.03, -0.03), Vec3::new(0.03, 0.03, 0.05));
        let pivot = Vec3::ZERO;
        let k = required_scale(&b, pivot, &eyes, &s);
        assert!(k > 0.0 && k < 1.0);
        assert!(inside_all(&b.scaled_about(pivot, k), &eyes, &s));
        assert!(!inside_all(&b.scaled_about(pivot, (k + 0.01).min(1.0)), &eyes, &s));
    }

    #[test]
    fn smoother_is_rate_limited_and_relaxes() {
        let mut sm = ContainmentSmoother::new(0.002, 0.001, 0.2);
        let mut last = 0.0;
        for _ in 0..20 {
            let v = sm.update(0.02, 1.0 / 60.0);
            assert!(v - last <= 0.002 + 1e-7);
            last = v;
        }
        assert!((last - 0.021).abs() < 1e-6);
        for _ in 0..200 {
            let v = sm.update(0.0, 1.0 / 60.0);
            assert!(last - v <= 0.002 + 1e-7 && v <= last);
            last = v;
        }
        assert!(last < 1e-4);
        assert_eq!(sm.update(f32::NAN, 0.016), last, "bad input holds");
    }
}
