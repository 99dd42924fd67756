//! Time stamp arithmetic that cannot overflow.
//!
//! Time stamps are `i64` nanoseconds of the sensor clock (any epoch). Stamps from outside (logs,
//! shells, FFI) may be anything an `i64` holds, and `a - b` of two of them may not fit an `i64`:
//! in a release build it wraps, and a gap of centuries reads as a step backwards (a replay of a
//! three-line log then ran "forever"). So every difference of two stamps goes through here:
//! [`elapsed_ns`] saturates (a huge gap stays huge, with its sign), [`elapsed_s`] is exact before
//! its conversion to seconds, and [`advance_ns`] stops at the end of the accepted range.
//!
//! Accepted stamps lie within ±[`MAX_ABS_T_NS`], chosen so that the difference of any two of them
//! still fits an `i64`; the functions here are correct for every `i64` all the same.

/// Largest time stamp magnitude accepted anywhere, ns: 2⁶² − 1 ns, about 146 years, so that the
/// difference of any two accepted stamps fits in an `i64` (2⁶³ − 2 at most). Phone clocks count
/// from boot, exports from 1970 (1.8·10¹⁸ ns in 2026); a larger stamp is damage.
pub const MAX_ABS_T_NS: i64 = (1 << 62) - 1;

/// Whether `t_ns` is within ±[`MAX_ABS_T_NS`]: true of every time stamp the core accepts
/// (sensor events, camera captures, display times).
pub fn time_in_range(t_ns: i64) -> bool {
    t_ns.unsigned_abs() <= MAX_ABS_T_NS as u64
}

/// `to_ns − from_ns`, saturated at `i64::MIN`/`i64::MAX` where it does not fit, so that
/// comparisons against a threshold keep their meaning.
pub fn elapsed_ns(from_ns: i64, to_ns: i64) -> i64 {
    to_ns.saturating_sub(from_ns)
}

/// `to_ns − from_ns` in seconds, computed exactly (in `i128`) before the conversion.
pub fn elapsed_s(from_ns: i64, to_ns: i64) -> f64 {
    (i128::from(to_ns) - i128::from(from_ns)) as f64 * 1e-9
}

/// `t_ns + by_ns`, or `None` when the sum leaves ±[`MAX_ABS_T_NS`] (or an `i64`).
pub fn advance_ns(t_ns: i64, by_ns: i64) -> Option<i64> {
    t_ns.checked_add(by_ns).filter(|&t| time_in_range(t))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn differences_of_extreme_stamps_neither_wrap_nor_panic() {
        // The damaged log's two stamps: their difference is 2⁶³, one past i64::MAX.
        let (a, b) = (-(1i64 << 62), 1i64 << 62);
        assert_eq!(elapsed_ns(a, b), i64::MAX);
        assert_eq!(elapsed_ns(b, a), -(1i64 << 62) * 2);
        assert_eq!(elapsed_ns(i64::MAX, i64::MIN), i64::MIN);
        assert!((elapsed_s(a, b) - 2f64.powi(63) * 1e-9).abs() < 1.0);
        assert!(elapsed_s(i64::MIN, i64::MAX) > 1.8e10);
        assert_eq!(elapsed_s(1_000_000_000, 3_500_000_000), 2.5);
        // Any two accepted stamps have a difference that fits.
        assert_eq!(
            elapsed_ns(-MAX_ABS_T_NS, MAX_ABS_T_NS),
            (i128::from(MAX_ABS_T_NS) * 2) as i64
        );
        assert!(!time_in_range(1 << 62) && !time_in_range(-(1 << 62)) && time_in_range(MAX_ABS_T_NS));
    }

    #[test]
    fn advancing_stops_at_the_end_of_the_range() {
        assert_eq!(advance_ns(5, 10), Some(15));
        assert_eq!(advance_ns(MAX_ABS_T_NS - 1, 1), Some(MAX_ABS_T_NS));
        assert_eq!(advance_ns(MAX_ABS_T_NS, 1), None);
        assert_eq!(advance_ns(i64::MAX, 1), None);
    }
}
