//! The sRGB transfer curve (IEC 61966-2-1), the one place it is written: camera codes back to
//! linear light (the room light, the glasses check, drawn test glasses) and linear light to codes.
//!
//! Values in [0, 1]; inputs outside are clamped and NaN counts as 0. Pure functions, no panics.

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

/// The linear value of an 8-bit sRGB code.
pub fn code_to_linear(code: u8) -> f32 {
    to_linear(f32::from(code) / 255.0)
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
}
