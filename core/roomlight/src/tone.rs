//! From a camera's 8-bit output back to linear light: the inverse of the sRGB transfer curve as
//! the approximate inverse tone curve of a phone camera (its own S-curve is not published; sRGB
//! is what it is encoded for). YCbCr → RGB is the camera frame's own business
//! (`phantogram_sensing::camera::yuv`).
//!
//! Pure functions and one table built on first use; no panics on any input.

use std::sync::LazyLock;

/// Linear value in [0, 1] of each 8-bit sRGB code (the curve: `phantogram_geometry::srgb`).
static SRGB_TO_LINEAR: LazyLock<[f32; 256]> =
    LazyLock::new(|| std::array::from_fn(|i| phantogram_geometry::srgb::code_to_linear(i as u8)));

/// The linear value of an 8-bit sRGB code (a table: the room map reads millions).
pub fn linear_from_srgb8(code: u8) -> f32 {
    SRGB_TO_LINEAR[usize::from(code)]
}

/// The 8-bit sRGB code of a linear value (clipped to [0, 1], as a camera clips).
pub fn srgb8_from_linear(v: f32) -> u8 {
    phantogram_geometry::srgb::linear_to_code(v)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_srgb_curve_round_trips_and_has_its_known_points() {
        for code in 0..=255u8 {
            assert_eq!(srgb8_from_linear(linear_from_srgb8(code)), code);
        }
        // Middle grey (18 %) is code 118 in sRGB; clipping above 1, zero for NaN.
        assert_eq!(srgb8_from_linear(0.18), 118);
        assert_eq!(srgb8_from_linear(7.0), 255);
        assert_eq!(srgb8_from_linear(f32::NAN), 0);
        assert!((linear_from_srgb8(255) - 1.0).abs() < 1e-6);
    }
}
