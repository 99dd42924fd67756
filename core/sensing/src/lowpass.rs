//! First-order low-pass filter on 3-vectors, parameterised by a time constant in seconds so that it
//! behaves the same whatever the sample rate.
//!
//! The paper writes the filter per sample as `aₜ = c·a + (1−c)·aₜ₋₁` with a fixed `c`, which makes
//! its lag depend on the sensor rate. Here each update uses `c = 1 − exp(−Δt/τ)` from the actual
//! time since the previous sample: for a held (piecewise constant) input this is the exact
//! discretisation of the continuous filter `τ·ẏ = a − y`, so two streams of the same signal at 50,
//! 100 or 200 Hz give the same output at the times they share, and jittered or missing samples are
//! handled without special cases (a long gap simply lets the filter jump to the new value).
//!
//! Invariants: the state is finite whenever it is `Some`; non-finite inputs and time stamps that do
//! not advance are ignored (the caller counts them, see [`crate::sensors`]).

use glam::Vec3;

/// Time constant equivalent to the paper's per-sample coefficient `c` at `rate_hz`:
/// `τ = −1 / (f · ln(1 − c))`. For small `c` this is close to the lag `(1 − c)/(c·f)` (0.095 s
/// against 0.090 s for c = 0.1 at 100 Hz).
pub fn time_constant_from_paper_coefficient(c: f32, rate_hz: f32) -> Option<f32> {
    if !(c > 0.0 && c <= 1.0 && rate_hz.is_finite() && rate_hz > 0.0) {
        return None;
    }
    if c == 1.0 {
        return Some(0.0);
    }
    Some(-1.0 / (rate_hz * (1.0 - c).ln()))
}

#[derive(Clone, Debug, PartialEq)]
pub struct VectorLowPass {
    tau_s: f32,
    state: Option<Vec3>,
    last_t_ns: Option<i64>,
}

impl VectorLowPass {
    /// `tau_s` ≤ 0 (or not finite) means no smoothing: the output follows the input.
    pub fn new(tau_s: f32) -> Self {
        Self {
            tau_s: if tau_s.is_finite() && tau_s > 0.0 { tau_s } else { 0.0 },
            state: None,
            last_t_ns: None,
        }
    }

    pub fn time_constant_s(&self) -> f32 {
        self.tau_s
    }

    /// Feeds one sample. Returns `false` (and changes nothing) for a non-finite sample or a time
    /// stamp that is not after the previous one.
    pub fn update(&mut self, t_ns: i64, x: Vec3) -> bool {
        if !x.is_finite() {
            return false;
        }
        match (self.state, self.last_t_ns) {
            (Some(y), Some(last)) => {
                if t_ns <= last {
                    return false;
                }
                let dt_s = crate::clock::elapsed_s(last, t_ns);
                let c = if self.tau_s == 0.0 {
                    1.0
                } else {
                    // exp_m1 keeps precision for Δt ≪ τ.
                    -(-dt_s / self.tau_s as f64).exp_m1() as f32
                };
                self.state = Some(y + (x - y) * c);
            }
            _ => self.state = Some(x),
        }
        self.last_t_ns = Some(t_ns);
        true
    }

    pub fn value(&self) -> Option<Vec3> {
        self.state
    }

    pub fn last_t_ns(&self) -> Option<i64> {
        self.last_t_ns
    }

    pub fn reset(&mut self) {
        self.state = None;
        self.last_t_ns = None;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn step_response_is_independent_of_rate() {
        let tau = 0.09;
        let mut outputs = Vec::new();
        for rate in [50i64, 100, 200] {
            let mut f = VectorLowPass::new(tau);
            let period_ns = 1_000_000_000 / rate;
            f.update(0, Vec3::ZERO);
            let mut at_shared = Vec::new();
            for k in 1..=rate {
                let t = k * period_ns;
                f.update(t, Vec3::X);
                if t % 20_000_000 == 0 {
                    at_shared.push(f.value().unwrap().x);
                }
            }
            outputs.push(at_shared);
        }
        for (a, b) in outputs[0].iter().zip(&outputs[2]) {
            assert!((a - b).abs() < 1e-5, "{a} vs {b}");
        }
        for (a, b) in outputs[1].iter().zip(&outputs[2]) {
            assert!((a - b).abs() < 1e-5, "{a} vs {b}");
        }
        // And it is the continuous response 1 − e^(−t/τ): after 20 ms, 1 − e^(−0.2/0.9).
        let expected = 1.0 - (-0.02f32 / tau).exp();
        assert!((outputs[2][0] - expected).abs() < 1e-5);
    }

    #[test]
    fn paper_coefficient_reproduces_the_papers_filter_at_its_rate() {
        let c = 0.1;
        let tau = time_constant_from_paper_coefficient(c, 100.0).unwrap();
        assert!((tau - 0.0949).abs() < 1e-3);
        let mut f = VectorLowPass::new(tau);
        let mut paper = 0.0f32;
        f.update(0, Vec3::ZERO);
        for k in 1..50 {
            let x = (k as f32 * 0.37).sin();
            paper = c * x + (1.0 - c) * paper;
            f.update(k * 10_000_000, Vec3::splat(x));
            assert!((f.value().unwrap().x - paper).abs() < 1e-5);
        }
        assert_eq!(time_constant_from_paper_coefficient(0.0, 100.0), None);
        assert_eq!(time_constant_from_paper_coefficient(1.0, 100.0), Some(0.0));
    }

    #[test]
    fn ignores_bad_samples_and_stale_time_stamps() {
        let mut f = VectorLowPass::new(0.1);
        assert!(f.update(10, Vec3::ONE));
        assert!(!f.update(20, Vec3::new(f32::NAN, 0.0, 0.0)));
        assert!(!f.update(10, Vec3::ZERO));
        assert!(!f.update(5, Vec3::ZERO));
        assert_eq!(f.value(), Some(Vec3::ONE));
        // A long gap lets the filter adopt the new value.
        assert!(f.update(10 + 60_000_000_000, Vec3::ZERO));
        assert!(f.value().unwrap().length() < 1e-6);
    }
}
