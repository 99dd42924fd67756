//! Screening of inertial readings before they reach the inclination filter: readings beyond a
//! sensor's range, readings at its range (saturated, then reconstructed), and isolated spikes.
//!
//! Nothing is dropped for being large (the module docs of [`super`] say why and what it cost).
//! Each piece was checked on every recording of `$PHANTOGRAM_DATA/imu` (none of them fires there
//! except as stated) and on the recordings clipped artificially at ±2.5, ±3 and ±4 g.
//!
//! * **Out of range** ([`Range`]): a reading with an axis beyond the sensor's declared range
//!   ([`super::FusionParams::accel_range_m_s2`], [`super::FusionParams::gyro_range_rad_s`], ×1.05)
//!   cannot be a measurement. Where the platform declares none, the widest range of phone parts
//!   stands in (±16 g, ±4000 °/s).
//! * **Saturated** ([`Range`]): an axis at the range limit is a bound, not a measurement. Where
//!   the range is not declared, the ceiling is learnt: the largest axis magnitude read (at least
//!   the smallest range of any part) counts as the range once an axis has sat at it for
//!   consecutive readings, while another axis moved, on [`CEILING_REPEATS`] separate occasions
//!   (clipping pins an axis at one value, every time; real readings repeat to the last bit only
//!   by chance, at a flat peak, and BROAD's recordings repeat whole readings now and then).
//! * **Reconstructed** ([`Declipper`]): a run of clipped accelerometer readings is held until
//!   two readings follow it, and each clipped value is replaced by the cubic through the nearest
//!   reading on either side with the slopes there (kept beyond the limit: the truth lay beyond
//!   it). Keeping clipped values biases the average by what was cut off; on BROAD's fast
//!   translation clipped at ±3 g that was 0.97° RMSE against 0.46° unclipped, reconstructed
//!   0.52°. A quadratic through two readings on either side did as well on the recordings but
//!   not on a clipped jolt, whose far side already swings back.
//! * **Severe clipping** ([`Saturation`]): what the reconstruction put back is summed as a
//!   velocity in the almost-inertial frame over the episode. Should it be wrong entirely, a
//!   velocity `Δv` moves the filter's output by at most `Δv·0.645/τ` (the peak of its impulse
//!   response), so from [`severe_lost_velocity_m_s`] on (1° worth) the filter takes no readings
//!   for a while and starts a fresh average once the motion has calmed. Taps ring both ways and
//!   sum to little; shaking clipped on one side sums up. Holding for every clipped reading
//!   instead cost BROAD's tapping recording clipped at ±4 g 0.60° → 1.26°.
//! * **Gyroscope saturation**: the attitude the gyroscope carried through it is off by an
//!   unknown turn, so the filter holds and restarts the same way, and the heading re-averages.
//! * **Isolated spikes** ([`SpikeWindow`]): one accelerometer reading far from the straight line
//!   through the three readings on either side, which lie close to it themselves, is replaced by
//!   the line's value. With two neighbours a side, 112 readings of BROAD's tapping recording
//!   passed (the first swing of each tap's ringing looks isolated against two); with three, none
//!   of BROAD's readings and one of the phone recordings' pass.
//!
//! Plain data, no threads, no panics.

use std::collections::VecDeque;

use crate::clock::elapsed_s;
use glam::{DQuat, DVec3};

/// A learnt ceiling counts as the sensor's range once an axis was pinned at it this many times.
pub(super) const CEILING_REPEATS: u32 = 3;

/// A sensor's range per axis, declared or learnt (the accelerometer's in m/s², the gyroscope's
/// in rad/s).
#[derive(Clone, Debug)]
pub(super) struct Range {
    declared: f64,
    /// Where nothing is declared: readings beyond this (×1.05) are out of range.
    assumed_max: f32,
    /// No part has a smaller range: smaller readings are never taken for a ceiling.
    min_range: f32,
    last: [f32; 3],
    /// The largest axis magnitude read so far (of `min_range` or more).
    top_seen: f32,
    /// Separate occasions on which an axis sat at `top_seen` for consecutive readings while
    /// another axis moved.
    pinned_episodes: u32,
    pinned_now: bool,
}

/// What the range says of one reading.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum RangeVerdict {
    Measurement,
    /// `axes`: those at the range limit (their values are bounds, not measurements).
    Saturated {
        axes: [bool; 3],
    },
    OutOfRange,
}

impl RangeVerdict {
    /// The axes at the range limit (none for a measurement).
    pub(super) fn pinned_axes(self) -> [bool; 3] {
        match self {
            Self::Saturated { axes } => axes,
            _ => [false; 3],
        }
    }
}

/// Where the range is not declared: the widest range of phone accelerometers, ±16 g (the
/// common parts — Bosch BMI2xx, ST LSM6DS* — top out there; many phones set ±8 g).
pub(super) const ASSUMED_MAX_ACCEL_M_S2: f32 = 16.0 * 9.80665;

/// No accelerometer has a range below ±2 g.
pub(super) const MIN_ACCEL_RANGE_M_S2: f32 = 2.0 * 9.80665;

/// Where the range is not declared: the widest range of phone gyroscopes, ±4000 °/s (most set
/// ±2000 °/s).
pub(super) const ASSUMED_MAX_GYRO_RAD_S: f32 = 4000.0 * std::f32::consts::PI / 180.0;

/// No gyroscope has a range below ±125 °/s.
pub(super) const MIN_GYRO_RANGE_RAD_S: f32 = 125.0 * std::f32::consts::PI / 180.0;

impl Range {
    /// `declared`: the platform's figure, infinite when unknown.
    pub(super) fn new(declared: f64, assumed_max: f32, min_range: f32) -> Self {
        Self {
            declared,
            assumed_max,
            min_range,
            last: [0.0; 3],
            top_seen: 0.0,
            pinned_episodes: 0,
            pinned_now: false,
        }
    }

    /// `a` as the sensor gave it (f32: exact repeats are what clipping looks like).
    pub(super) fn judge(&mut self, a: [f32; 3]) -> RangeVerdict {
        let top = a.iter().fold(0.0f32, |m, v| m.max(v.abs()));
        if self.declared.is_finite() {
            let range = self.declared as f32;
            return if top > range * 1.05 {
                RangeVerdict::OutOfRange
            } else if top >= range * 0.999 {
                RangeVerdict::Saturated {
                    axes: a.map(|v| v.abs() >= range * 0.999),
                }
            } else {
                RangeVerdict::Measurement
            };
        }
        if top > self.assumed_max * 1.05 {
            return RangeVerdict::OutOfRange;
        }
        // Learn the ceiling (see the module docs). A whole reading repeated is a resent packet.
        let last = std::mem::replace(&mut self.last, a);
        if top >= self.min_range && top > self.top_seen {
            self.top_seen = top;
            self.pinned_episodes = 0;
            self.pinned_now = false;
            return RangeVerdict::Measurement;
        }
        let moved = a != last;
        let pinned = moved
            && self.top_seen >= self.min_range
            && a.iter().zip(last).any(|(v, l)| *v == l && v.abs() == self.top_seen);
        if pinned && !self.pinned_now {
            self.pinned_episodes = self.pinned_episodes.saturating_add(1);
        }
        self.pinned_now = pinned;
        if self.pinned_episodes >= CEILING_REPEATS && top == self.top_seen {
            RangeVerdict::Saturated {
                axes: a.map(|v| v.abs() == self.top_seen),
            }
        } else {
            RangeVerdict::Measurement
        }
    }
}

/// Longest run of clipped readings that is reconstructed, s; a longer one passes as it is and
/// counts as severe clipping.
pub(super) const MAX_DECLIP_RUN_S: f64 = 0.25;

/// The velocity put back by reconstruction from which an episode of clipping counts as severe,
/// m/s: as much as could move the inclination filter's output by 1° were it wrong entirely
/// (`Δv·0.645/τ` is the peak of the second-order Butterworth's response to a velocity step of
/// `Δv`, with `τ` = `tau_acc_s`). 0.80 m/s at VQF's 3 s.
pub(super) fn severe_lost_velocity_m_s(tau_acc_s: f64) -> f64 {
    let one_degree_m_s2 = 9.80665 * 1f64.to_radians();
    one_degree_m_s2 * tau_acc_s / (std::f64::consts::SQRT_2 * (-std::f64::consts::FRAC_PI_4).exp())
}

/// One accelerometer reading in the sensor frame, with what the filter needs to use it later.
#[derive(Clone, Copy, Debug)]
pub(super) struct Reading {
    pub t_ns: i64,
    pub dt_s: f64,
    pub raw: [f32; 3],
    /// The almost-inertial attitude at its time stamp.
    pub q_gyr: DQuat,
    /// Axes at the range limit (their value is a bound, not a measurement).
    pub pinned: [bool; 3],
}

/// Reconstructs clipped accelerometer readings (see the module docs).
#[derive(Clone, Debug, Default)]
pub(super) struct Declipper {
    /// The last two readings released.
    before: VecDeque<Reading>,
    run: Vec<Reading>,
    after: Vec<Reading>,
    /// What the reconstruction put back this episode, almost-inertial frame, m/s; infinite
    /// after a run too long to reconstruct.
    lost_velocity_m_s: DVec3,
}

impl Declipper {
    pub(super) fn clear(&mut self) {
        *self = Self::default();
    }

    /// Whether a run of clipped readings is waiting for its neighbours.
    pub(super) fn is_idle(&self) -> bool {
        self.run.is_empty()
    }

    pub(super) fn lost_velocity_m_s(&self) -> f64 {
        self.lost_velocity_m_s.length()
    }

    /// Starts a new episode's sum.
    pub(super) fn forget_lost_velocity(&mut self) {
        self.lost_velocity_m_s = DVec3::ZERO;
    }

    /// Takes a reading; appends to `out` the readings that are ready, in order.
    pub(super) fn push(&mut self, r: Reading, out: &mut Vec<Reading>) {
        let pinned = r.pinned.iter().any(|p| *p);
        if self.run.is_empty() {
            if pinned {
                self.run.push(r);
            } else {
                self.release(r, out);
            }
            return;
        }
        if pinned {
            // The run goes on: unclipped readings caught inside it belong to it.
            self.run.append(&mut self.after);
            self.run.push(r);
        } else {
            self.after.push(r);
        }
        let span_s = elapsed_s(self.run[0].t_ns, self.run[self.run.len() - 1].t_ns);
        if span_s > MAX_DECLIP_RUN_S {
            // Too long to bridge with a curve: let it through as it is.
            self.lost_velocity_m_s = DVec3::INFINITY;
            self.flush(out);
        } else if self.after.len() >= 2 {
            self.reconstruct();
            self.flush(out);
        }
    }

    fn flush(&mut self, out: &mut Vec<Reading>) {
        let run = std::mem::take(&mut self.run);
        let after = std::mem::take(&mut self.after);
        for r in run.into_iter().chain(after) {
            self.release(r, out);
        }
    }

    fn release(&mut self, r: Reading, out: &mut Vec<Reading>) {
        if self.before.len() == 2 {
            self.before.pop_front();
        }
        self.before.push_back(r);
        out.push(r);
    }

    fn reconstruct(&mut self) {
        // Without two readings before the run (just after a start) the run stays as it is.
        let (Some(b0), Some(b1)) = (self.before.front().copied(), self.before.back().copied()) else {
            return;
        };
        if self.before.len() < 2 {
            return;
        }
        let (a0, a1) = (self.after[0], self.after[1]);
        let t0 = b1.t_ns;
        let x = |r: &Reading| elapsed_s(t0, r.t_ns);
        let h = x(&a0);
        if h <= 0.0 {
            return;
        }
        for axis in 0..3 {
            if !self.run.iter().any(|r| r.pinned[axis]) {
                continue;
            }
            let v = |r: &Reading| f64::from(r.raw[axis]);
            let slope = |p: &Reading, q: &Reading| (v(q) - v(p)) / (x(q) - x(p)).max(1e-6);
            // Cubic Hermite from (0, y0, m0) to (h, y1, m1).
            let (y0, y1, m0, m1) = (v(&b1), v(&a0), slope(&b0, &b1), slope(&a0, &a1));
            for r in &mut self.run {
                if !r.pinned[axis] {
                    continue;
                }
                let u = x(r) / h;
                let (u2, u3) = (u * u, u * u * u);
                let guess = (2.0 * u3 - 3.0 * u2 + 1.0) * y0
                    + (u3 - 2.0 * u2 + u) * h * m0
                    + (-2.0 * u3 + 3.0 * u2) * y1
                    + (u3 - u2) * h * m1;
                let bound = f64::from(r.raw[axis]);
                let value = if bound > 0.0 {
                    guess.max(bound)
                } else {
                    guess.min(bound)
                };
                if !value.is_finite() {
                    continue;
                }
                r.raw[axis] = value as f32;
                let mut excess = DVec3::ZERO;
                excess[axis] = value - bound;
                self.lost_velocity_m_s += r.q_gyr * excess * r.dt_s;
            }
        }
    }
}

/// Readings on either side of the one judged for an isolated spike.
pub(super) const SPIKE_HALF_WINDOW: usize = 3;

/// An isolated spike lies this many times farther from its neighbours' line than they scatter
/// about it...
pub(super) const SPIKE_ISOLATION_RATIO: f64 = 6.0;

/// ... and at least this far, m/s² (1 g: a smaller one does the average no harm worth a guess).
pub(super) const SPIKE_MIN_M_S2: f64 = 9.80665;

/// One accelerometer reading on its way to the inclination filter, in the almost-inertial frame.
#[derive(Clone, Copy, Debug)]
pub(super) struct Pending {
    pub t_ns: i64,
    pub dt_s: f64,
    pub inertial: DVec3,
    /// The almost-inertial attitude at its time stamp.
    pub q_gyr: DQuat,
}

/// `2·SPIKE_HALF_WINDOW + 1` readings in a row (in the almost-inertial frame, where gravity
/// stands still): the middle one is an isolated spike when it lies far from the straight line
/// fitted through the readings on either side, which lie close to it themselves. It is then
/// replaced by the line's value, not dropped, so the average keeps its even weighting in time.
#[derive(Clone, Debug, Default)]
pub(super) struct SpikeWindow {
    window: VecDeque<Pending>,
}

impl SpikeWindow {
    pub(super) fn clear(&mut self) {
        self.window.clear();
    }

    /// Takes a reading; returns the one [`SPIKE_HALF_WINDOW`] places back once it is judged,
    /// `true` with it when it was an isolated spike and has been replaced. The first readings
    /// after a [`Self::clear`] come back at once, unjudged (too few neighbours before them); from
    /// then on each comes back that many readings late.
    pub(super) fn push(&mut self, p: Pending) -> Option<(Pending, bool)> {
        self.window.push_back(p);
        let n = self.window.len();
        if n <= SPIKE_HALF_WINDOW {
            return Some((p, false));
        }
        if n <= 2 * SPIKE_HALF_WINDOW {
            return None;
        }
        let judged = self.judge();
        self.window.pop_front();
        Some(judged)
    }

    fn judge(&mut self) -> (Pending, bool) {
        let h = SPIKE_HALF_WINDOW;
        let mid = self.window[h];
        let t0 = mid.t_ns;
        let neighbours = || {
            self.window
                .iter()
                .enumerate()
                .filter(move |(i, _)| *i != h)
                .map(move |(_, p)| (elapsed_s(t0, p.t_ns), p.inertial))
        };
        let n = (2 * h) as f64;
        let xm = neighbours().map(|p| p.0).sum::<f64>() / n;
        let ym = neighbours().map(|p| p.1).sum::<DVec3>() / n;
        let sxx: f64 = neighbours().map(|p| (p.0 - xm).powi(2)).sum();
        if sxx <= 0.0 {
            return (mid, false);
        }
        let slope = neighbours().map(|p| (p.1 - ym) * (p.0 - xm)).sum::<DVec3>() / sxx;
        let line = |x: f64| ym + slope * (x - xm);
        // Two parameters fitted: n − 2 degrees of freedom.
        let scatter = (neighbours().map(|p| (p.1 - line(p.0)).length_squared()).sum::<f64>() / (n - 2.0)).sqrt();
        let predicted = line(0.0);
        let jump = (mid.inertial - predicted).length();
        if jump < SPIKE_MIN_M_S2 || jump < SPIKE_ISOLATION_RATIO * scatter {
            return (mid, false);
        }
        let mut replaced = mid;
        replaced.inertial = predicted;
        self.window[h] = replaced;
        (replaced, true)
    }
}

/// Largest departure of the accelerometer's norm from gravity that counts as calm, m/s² (a fifth
/// of g: ordinary handling stays within it, shaking does not).
pub(super) const CALM_M_S2: f64 = 0.2 * 9.80665;

/// An episode of saturation: from the first saturated reading until the accelerometer's norm has
/// stayed within [`CALM_M_S2`] of gravity for the calm window. A severe one (see the module
/// docs) keeps readings out of the filter from the moment it is known to be severe, for at most
/// the hold time, and ends with a fresh average. Waiting for calm matters: a fresh average taken
/// while the hand still shakes would be worse than the filter it replaces.
#[derive(Clone, Debug, Default)]
pub(super) struct Saturation {
    in_episode: bool,
    severe: bool,
    /// The gyroscope clipped: the attitude it carried is off by an unknown turn.
    frame_doubtful: bool,
    calm_s: f64,
    /// Time since the episode began, s.
    since_s: f64,
}

impl Saturation {
    /// One accelerometer reading; `true` when the filter should start a fresh average now.
    pub(super) fn update(&mut self, saturated: bool, norm_m_s2: f64, dt_s: f64, calm_window_s: f64) -> bool {
        if saturated {
            self.in_episode = true;
            self.calm_s = 0.0;
            self.since_s += dt_s;
            return false;
        }
        if !self.in_episode {
            return false;
        }
        self.since_s += dt_s;
        if (norm_m_s2 - 9.80665).abs() < CALM_M_S2 {
            self.calm_s += dt_s;
        } else {
            self.calm_s = 0.0;
        }
        if self.calm_s < calm_window_s {
            return false;
        }
        let restart = self.severe || self.frame_doubtful;
        *self = Self::default();
        restart
    }

    /// The clipping of this episode turned out severe.
    pub(super) fn mark_severe(&mut self) {
        self.in_episode = true;
        self.severe = true;
    }

    /// A gyroscope reading at its range: severe at once, and the frame doubtful.
    pub(super) fn gyro_saturated(&mut self) {
        self.in_episode = true;
        self.severe = true;
        self.frame_doubtful = true;
        self.calm_s = 0.0;
    }

    pub(super) fn in_episode(&self) -> bool {
        self.in_episode
    }

    /// Whether the episode involves the gyroscope (read before the restart clears it).
    pub(super) fn frame_doubtful(&self) -> bool {
        self.frame_doubtful
    }

    /// Whether readings stay out of the filter now: in a severe episode, for at most `hold_s`
    /// from its start the gyroscope alone carries the attitude, as over a gap.
    pub(super) fn holding(&self, hold_s: f64) -> bool {
        self.severe && self.since_s <= hold_s
    }

    /// A restart for another reason cleared the filter too.
    pub(super) fn clear(&mut self) {
        *self = Self::default();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const G: f32 = 9.80665;

    #[test]
    fn a_declared_range_judges_each_reading() {
        let mut r = Range::new(8.0 * 9.80665, ASSUMED_MAX_ACCEL_M_S2, MIN_ACCEL_RANGE_M_S2);
        assert_eq!(r.judge([1.0, 2.0, G]), RangeVerdict::Measurement);
        assert_eq!(r.judge([7.9 * G, 0.0, 0.0]), RangeVerdict::Measurement);
        assert_eq!(
            r.judge([0.0, -8.0 * G, 1.0]),
            RangeVerdict::Saturated {
                axes: [false, true, false]
            }
        );
        assert_eq!(r.judge([0.0, 0.0, 9.0 * G]), RangeVerdict::OutOfRange);
    }

    #[test]
    fn the_ceiling_is_learnt_from_clipping_and_unlearnt_by_a_larger_reading() {
        let mut r = Range::new(f64::INFINITY, ASSUMED_MAX_ACCEL_M_S2, MIN_ACCEL_RANGE_M_S2);
        let clip = 8.0 * G;
        // Three clipping episodes: x pinned at the limit while y moves.
        let mut verdicts = Vec::new();
        for episode in 0..3 {
            for k in 0..4 {
                verdicts.push(r.judge([clip, k as f32 + episode as f32, G]));
            }
            for k in 0..4 {
                verdicts.push(r.judge([2.0 * G - k as f32, 1.0, G]));
            }
        }
        // From the third episode's second reading on, readings at the limit are saturated.
        assert!(
            verdicts[..17].iter().all(|v| *v == RangeVerdict::Measurement),
            "{verdicts:?}"
        );
        assert!(
            verdicts[17..20].iter().all(|v| *v
                == RangeVerdict::Saturated {
                    axes: [true, false, false]
                }),
            "{verdicts:?}"
        );
        assert_eq!(
            r.judge([-clip, 3.0, 2.0]),
            RangeVerdict::Saturated {
                axes: [true, false, false]
            }
        );
        assert_eq!(r.judge([0.5 * clip, 3.0, 2.0]), RangeVerdict::Measurement);
        // A larger reading shows the ceiling was no limit.
        assert_eq!(r.judge([clip * 1.2, 0.0, 0.0]), RangeVerdict::Measurement);
        assert_eq!(r.judge([clip, 5.0, 0.0]), RangeVerdict::Measurement);
        // Beyond the widest phone range: out of range.
        assert_eq!(r.judge([0.0, 20.0 * G, 0.0]), RangeVerdict::OutOfRange);
    }

    #[test]
    fn flat_peaks_and_repeated_packets_are_not_clipping() {
        let mut r = Range::new(f64::INFINITY, ASSUMED_MAX_ACCEL_M_S2, MIN_ACCEL_RANGE_M_S2);
        // A whole reading repeated (a resent packet), many times: no clipping.
        for _ in 0..10 {
            assert_eq!(r.judge([3.0 * G, 1.0, 2.0]), RangeVerdict::Measurement);
            assert_eq!(r.judge([3.0 * G, 1.0, 2.0]), RangeVerdict::Measurement);
            assert_eq!(r.judge([0.0, 1.0, G]), RangeVerdict::Measurement);
        }
        // Flat peaks at ever different values: never the same ceiling three times.
        let mut r = Range::new(f64::INFINITY, ASSUMED_MAX_ACCEL_M_S2, MIN_ACCEL_RANGE_M_S2);
        for k in 0..20 {
            let peak = (3.0 + 0.01 * k as f32) * G;
            assert_eq!(r.judge([peak, 1.0, 2.0]), RangeVerdict::Measurement);
            assert_eq!(r.judge([peak, 1.5, 2.0]), RangeVerdict::Measurement);
            assert_eq!(r.judge([0.0, 1.0, G]), RangeVerdict::Measurement);
        }
    }

    #[test]
    fn a_severe_episode_holds_the_filter_until_the_motion_calms() {
        let mut s = Saturation::default();
        let dt = 0.01;
        assert!(!s.update(false, 30.0, dt, 0.5) && !s.in_episode());
        assert!(!s.update(true, 80.0, dt, 0.5));
        assert!(s.in_episode() && !s.holding(3.0), "mild until shown severe");
        s.mark_severe();
        assert!(s.holding(3.0));
        // Still shaking: no restart, however long.
        for _ in 0..100 {
            assert!(!s.update(false, 40.0, dt, 0.5));
        }
        // Held at most 3 s (1.01 s so far), then readings flow again even without calm.
        assert!(s.holding(3.0) && !s.holding(1.0));
        // Calm for the window: one restart, and the episode ends.
        let restarts = (0..60).filter(|_| s.update(false, 9.9, dt, 0.5)).count();
        assert_eq!(restarts, 1);
        assert!(!s.holding(3.0) && !s.in_episode());
        // A mild episode ends without a restart.
        assert!(!s.update(true, 80.0, dt, 0.5));
        assert_eq!((0..60).filter(|_| s.update(false, 9.9, dt, 0.5)).count(), 0);
        assert!(!s.in_episode());
    }

    #[test]
    fn the_severity_threshold_is_a_degree_of_filter_output() {
        // 1° of g times τ over the Butterworth's peak response 0.645.
        let v = severe_lost_velocity_m_s(3.0);
        assert!((v - 0.796).abs() < 0.002, "{v}");
    }

    fn reading(t_ms: i64, x: f32, ceiling: f32) -> Reading {
        Reading {
            t_ns: t_ms * 1_000_000,
            dt_s: 0.005,
            raw: [x.clamp(-ceiling, ceiling), 0.0, 9.80665],
            q_gyr: DQuat::IDENTITY,
            pinned: [x.abs() >= ceiling, false, false],
        }
    }

    #[test]
    fn clipped_runs_are_reconstructed_from_their_neighbours() {
        // A 5 Hz, 12 g sine sampled at 200 Hz and clipped at 8 g.
        let ceiling = 8.0 * G;
        let truth = |t_ms: i64| 12.0 * G * (std::f32::consts::TAU * 5.0 * t_ms as f32 * 1e-3).sin();
        let mut d = Declipper::default();
        let mut out = Vec::new();
        for k in 0..40 {
            d.push(reading(5 * k, truth(5 * k), ceiling), &mut out);
        }
        assert_eq!(out.len(), 40, "every reading comes out, in order");
        assert!(out.windows(2).all(|w| w[0].t_ns < w[1].t_ns));
        let clipped: Vec<_> = (0..40).filter(|k| truth(5 * k).abs() >= ceiling).collect();
        assert!(clipped.len() >= 10);
        let (mut err_kept, mut err_rebuilt) = (0.0f32, 0.0f32);
        for &k in &clipped {
            let t = truth(5 * k);
            err_kept += (t - t.clamp(-ceiling, ceiling)).abs();
            err_rebuilt += (t - out[k as usize].raw[0]).abs();
            // Never inside the limit: the truth lay beyond it.
            assert!(out[k as usize].raw[0].abs() >= ceiling);
        }
        assert!(
            err_rebuilt < 0.35 * err_kept,
            "{err_rebuilt} vs {err_kept} kept clipped"
        );
        // What was put back is summed as velocity: over a whole period both sides cancel.
        let one_side: f64 = clipped
            .iter()
            .filter(|&&k| truth(5 * k) > 0.0)
            .map(|&k| f64::from(out[k as usize].raw[0] - ceiling) * 0.005)
            .sum();
        assert!(one_side > 0.1, "{one_side}");
        assert!(
            d.lost_velocity_m_s() < 0.5 * one_side,
            "{} vs {one_side}",
            d.lost_velocity_m_s()
        );
    }

    #[test]
    fn a_run_too_long_to_bridge_passes_as_it_is_and_counts_as_severe() {
        let ceiling = 8.0 * G;
        let mut d = Declipper::default();
        let mut out = Vec::new();
        for k in 0..10 {
            d.push(reading(5 * k, 0.0, ceiling), &mut out);
        }
        for k in 10..80 {
            d.push(reading(5 * k, 9.0 * G, ceiling), &mut out);
        }
        assert!(out.len() > 60 && out.iter().all(|r| r.raw[0] <= ceiling));
        assert!(d.lost_velocity_m_s().is_infinite());
        d.forget_lost_velocity();
        assert_eq!(d.lost_velocity_m_s(), 0.0);
    }
}
