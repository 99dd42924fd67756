//! From a camera's 8-bit output back to linear light: the inverse of the sRGB transfer curve as
//! the approximate inverse tone curve of a phone camera (its own S-curve is not published; sRGB
//! is what it is encoded for). YCbCr → RGB is the camera frame's own business
//! (`phantogram_sensing::camera::yuv`).
//!
//! Pure functions and one table built on first use; no panics on any input.

use std::sync::LazyLock;

/// Linear value in [0, 1] of each 8-bit sRGB code.
static SRGB_TO_LINEAR: LazyLock<[f32; 256]> = LazyLock::new(|| {
    std::array::from_fn(|i| {
        let c = i as f32 / 255.0;
        if c <= 0.040_45 {
            c / 12.92
        } else {
            ((c + 0.055) / 1.055).powf(2.4)
        }
    })
});

/// The linear value of an 8-bit sRGB code.
pub fn linear_from_srgb8(code: u8) -> f32 {
    SRGB_TO_LINEAR[usize::from(code)]
}

/// The 8-bit sRGB code of a linear value (clipped to [0, 1], as a camera clips).
pub fn srgb8_from_linear(v: f32) -> u8 {
    let v = if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) };
    let c = if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    };
    (c * 255.0 + 0.5).clamp(0.0, 255.0) as u8
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
