//! The frame budget's controller: how many triangles a frame may draw so that it takes the
//! target time.
//!
//! Fed after each frame with the time it took (GPU time where the adapter measures it, else the
//! frame's wall time) and the triangles it drew. A frame's time is a fixed part (filling pixels,
//! composing, the overlay) plus a part that grows with the triangles; the controller does not
//! need to know the split. It scales the budget by (target ÷ measured)^½ — a whole step if every
//! millisecond were the triangles', half of one in log terms, so that a large fixed part makes it
//! slower, never unstable. Within a dead band around the target it only trims, by a fifth of
//! that step, so that measurement noise does not swing the parts' levels every frame while a
//! steady offset inside the band is still worked off. The budget never grows beyond
//! twice what the last frame used (when the chooser stopped because nothing visible was left to
//! refine, more budget would only wind up) and stays within the scan's coarsest and finest
//! totals.
//!
//! Threading: plain data, owned by the render thread. Never panics; a measured time that is not
//! a positive finite number is ignored.

/// See the module docs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BudgetController {
    /// The frame time aimed at, seconds.
    pub target_s: f64,
    /// Within target × (1 ± dead_band) the budget is only trimmed ([`Self::trim`] of a step).
    pub dead_band: f64,
    /// The fraction of a step taken inside the dead band.
    pub trim: f64,
    /// Exponent of each step (0 < gain ≤ 1).
    pub gain: f64,
    /// Each step scales the budget by at most this factor (or its inverse).
    pub max_step: f64,
    budget: f64,
    min: f64,
    max: f64,
}

impl BudgetController {
    /// Aims at `target_s` per frame, for a scan drawing between `min_triangles` (every part at
    /// its coarsest) and `max_triangles` (full detail); starts at full detail.
    pub fn new(target_s: f64, min_triangles: u64, max_triangles: u64) -> Self {
        let min = min_triangles as f64;
        let max = (max_triangles as f64).max(min);
        Self {
            target_s,
            dead_band: 0.04,
            trim: 0.2,
            gain: 0.5,
            max_step: 2.0,
            budget: max,
            min,
            max,
        }
    }

    /// Starts from `triangles` (within the bounds) instead of full detail.
    pub fn starting_at(mut self, triangles: u64) -> Self {
        self.budget = (triangles as f64).clamp(self.min, self.max);
        self
    }

    /// Triangles the next frame may draw.
    pub fn budget(&self) -> u64 {
        self.budget as u64
    }

    /// After a frame that took `frame_s` drawing `triangles`: the next frame's budget.
    pub fn update(&mut self, frame_s: f64, triangles: u64) -> u64 {
        if !(frame_s.is_finite() && frame_s > 0.0 && self.target_s > 0.0) {
            return self.budget();
        }
        let ratio = self.target_s / frame_s;
        let gain = if (ratio - 1.0).abs() > self.dead_band {
            self.gain
        } else {
            self.gain * self.trim
        };
        self.budget *= ratio.powf(gain).clamp(1.0 / self.max_step, self.max_step);
        let used = (triangles as f64).max(self.min);
        self.budget = self.budget.min(2.0 * used).clamp(self.min, self.max);
        self.budget()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A frame of `fixed_s` plus `per_triangle_s` per triangle, with ±`noise` relative jitter.
    fn settle(fixed_s: f64, per_triangle_s: f64, noise: f64, target_s: f64) -> (Vec<f64>, BudgetController) {
        let mut c = BudgetController::new(target_s, 10_000, 4_000_000);
        let mut times = Vec::new();
        let mut seed = 12345u64;
        for _ in 0..120 {
            let tris = c.budget();
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            let jitter = ((seed >> 33) as f64 / (1u64 << 31) as f64 * 2.0 - 1.0) * noise;
            let t = (fixed_s + per_triangle_s * tris as f64) * (1.0 + jitter);
            times.push(t);
            c.update(t, tris);
        }
        (times, c)
    }

    #[test]
    fn settles_within_ten_percent_of_the_target() {
        // Triangle-bound, fill-bound and in between; 3 % measurement noise.
        for (fixed, per) in [(0.002, 2e-8), (0.02, 5e-9), (0.01, 1e-8)] {
            let target = 0.033;
            let (times, c) = settle(fixed, per, 0.03, target);
            for (k, t) in times.iter().enumerate().skip(30) {
                assert!(
                    (t / target - 1.0).abs() < 0.1,
                    "{fixed} + {per}/tri: frame {k} took {t}"
                );
            }
            let ideal = (target - fixed) / per;
            assert!(
                (c.budget() as f64 / ideal - 1.0).abs() < 0.15,
                "{} vs {ideal}",
                c.budget()
            );
        }
    }

    #[test]
    fn an_offset_inside_the_dead_band_is_worked_off() {
        // Without noise, the frames settle on the target itself, not anywhere within ±4 %.
        let (times, _) = settle(0.002, 2e-8, 0.0, 0.033);
        let last = times.last().copied().unwrap_or_default();
        assert!((last / 0.033 - 1.0).abs() < 0.01, "{last}");
    }

    #[test]
    fn an_unreachable_target_ends_at_a_bound_and_bad_times_are_ignored() {
        // Even the coarsest levels take longer than the target: the budget goes to the minimum.
        let (_, c) = settle(0.05, 1e-8, 0.0, 0.033);
        assert_eq!(c.budget(), 10_000);
        let mut c = BudgetController::new(0.033, 10, 1000);
        for bad in [f64::NAN, -1.0, 0.0, f64::INFINITY] {
            assert_eq!(c.update(bad, 1000), 1000);
        }
    }

    #[test]
    fn does_not_wind_up_when_frames_use_less_than_allowed() {
        let mut c = BudgetController::new(0.033, 100, 1_000_000);
        // Fast frames that use only 5000 triangles (nothing visible left to refine).
        for _ in 0..50 {
            c.update(0.005, 5000);
        }
        assert!(c.budget() <= 10_000, "{}", c.budget());
    }
}
