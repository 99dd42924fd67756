//! The sRGB transfer curve (IEC 61966-2-1), the one place it is written: camera codes back to
//! linear light (the room light, the glasses check, drawn test glasses) and linear light to codes;
//! and the luminance of a colour in sRGB's primaries ([`luminance`]).
//!
//! Values in [0, 1]; inputs outside are clamped and NaN counts as 0. Pure functions, no panics;
//! the table-backed ones build their tables on first use (thread-safe, once per process).

use std::sync::LazyLock;

/// The linear value of an sRGB-coded value.
pub fn to_linear(c: f32) -> f32 {
    let c = if c.is_nan() { 0.0 } else { c.clamp(0.0, 1.0) };
    if c <= 0.040_45 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// The sRGB-coded value of a linear value.
pub fn from_linear(v: f32) -> f32 {
    let v = if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) };
    if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

/// The linear value of an 8-bit sRGB code (from a table of all 256, made on first use).
pub fn code_to_linear(code: u8) -> f32 {
    static TABLE: LazyLock<[f32; 256]> = LazyLock::new(|| std::array::from_fn(|i| to_linear(i as f32 / 255.0)));
    TABLE[code as usize]
}

/// Entries of the tables behind [`to_linear_fast`] and [`from_linear_fast`], over [0, 1].
const FAST_STEPS: usize = 4096;

/// [`to_linear`] and [`from_linear`] at `i / FAST_STEPS`.
static FAST: LazyLock<(Vec<f32>, Vec<f32>)> = LazyLock::new(|| {
    let at = |i: usize| i as f32 / FAST_STEPS as f32;
    (
        (0..=FAST_STEPS).map(|i| to_linear(at(i))).collect(),
        (0..=FAST_STEPS).map(|i| from_linear(at(i))).collect(),
    )
});

/// `table` (FAST_STEPS + 1 samples over [0, 1]) read linearly between samples at `x`, clamped to
/// [0, 1] (NaN as 0).
fn read(table: &[f32], x: f32) -> f32 {
    let x = if x.is_nan() { 0.0 } else { x.clamp(0.0, 1.0) } * FAST_STEPS as f32;
    let i = (x as usize).min(FAST_STEPS - 1);
    let f = x - i as f32;
    table[i] + (table[i + 1] - table[i]) * f
}

/// [`to_linear`] from a table, within 2·10⁻⁶ of it: for per-pixel work on whole crops, where the
/// power function is most of the cost.
pub fn to_linear_fast(c: f32) -> f32 {
    read(&FAST.0, c)
}

/// [`from_linear`] from a table, within 2·10⁻⁵ of it (under a twentieth of an 8-bit step).
pub fn from_linear_fast(v: f32) -> f32 {
    read(&FAST.1, v)
}

/// Relative luminance of a linear-light colour in sRGB's (Rec. 709) primaries: the one weighting
/// of red, green and blue used wherever the project asks how bright a colour is.
pub fn luminance(linear: [f32; 3]) -> f32 {
    0.2126 * linear[0] + 0.7152 * linear[1] + 0.0722 * linear[2]
}

/// The nearest 8-bit sRGB code of a linear value.
pub fn linear_to_code(v: f32) -> u8 {
    (from_linear(v) * 255.0 + 0.5) as u8
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn codes_round_trip_and_the_known_points_hold() {
        for code in 0..=255u8 {
            assert_eq!(linear_to_code(code_to_linear(code)), code);
        }
        // Middle grey (18 %) is code 118; clipped above 1 and below 0; NaN is black.
        assert_eq!(linear_to_code(0.18), 118);
        assert_eq!(linear_to_code(7.0), 255);
        assert_eq!(linear_to_code(-1.0), 0);
        assert_eq!(linear_to_code(f32::NAN), 0);
        assert!((to_linear(1.0) - 1.0).abs() < 1e-6 && (from_linear(to_linear(0.5)) - 0.5).abs() < 1e-6);
    }

    #[test]
    fn the_fast_curves_stay_within_their_stated_errors() {
        let (mut worst_to, mut worst_from) = (0.0f32, 0.0f32);
        for i in 0..=100_000 {
            let x = i as f32 / 100_000.0;
            worst_to = worst_to.max((to_linear_fast(x) - to_linear(x)).abs());
            worst_from = worst_from.max((from_linear_fast(x) - from_linear(x)).abs());
        }
        assert!(worst_to < 2e-6 && worst_from < 2e-5, "{worst_to} {worst_from}");
        // Clamped and NaN as the exact ones.
        for x in [-1.0, 2.0, f32::NAN] {
            assert_eq!(to_linear_fast(x), to_linear(x));
            assert_eq!(from_linear_fast(x), from_linear(x));
        }
    }
}
