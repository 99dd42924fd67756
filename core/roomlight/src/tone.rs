//! From a camera's 8-bit output back to linear light: full-range BT.601 YCbCr → RGB (what
//! Android's `YUV_420_888` camera frames and iOS's `420f` buffers hold), and the inverse of the
//! sRGB transfer curve as the approximate inverse tone curve of a phone camera (its own S-curve
//! is not published; sRGB is what it is encoded for).
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

/// Full-range BT.601 YCbCr (JFIF) → RGB, each 8 bits.
pub fn rgb_from_ycbcr(y: u8, cb: u8, cr: u8) -> [u8; 3] {
    let (y, cb, cr) = (f32::from(y), f32::from(cb) - 128.0, f32::from(cr) - 128.0);
    let to_u8 = |v: f32| (v + 0.5).clamp(0.0, 255.0) as u8;
    [
        to_u8(y + 1.402 * cr),
        to_u8(y - 0.344_136 * cb - 0.714_136 * cr),
        to_u8(y + 1.772 * cb),
    ]
}

/// A 4:2:0 frame's planes as the platforms hand them over: the luma plane, and the two chroma
/// planes at half the size in each direction, each with its row stride and its pixel stride
/// (Android's `YUV_420_888` planes 1 and 2; iOS's bi-planar `420f` CbCr plane is both, offset by
/// one byte with a pixel stride of 2).
#[derive(Clone, Copy, Debug)]
pub struct Yuv420<'a> {
    pub width: u32,
    pub height: u32,
    pub y: &'a [u8],
    pub y_row_stride: usize,
    pub cb: &'a [u8],
    pub cr: &'a [u8],
    pub chroma_row_stride: usize,
    pub chroma_pixel_stride: usize,
}

#[derive(Debug, thiserror::Error, PartialEq, Eq)]
pub enum ToneError {
    #[error("a {width}×{height} frame's {plane} plane needs {needed} bytes, got {got}")]
    ShortPlane {
        plane: &'static str,
        width: u32,
        height: u32,
        needed: usize,
        got: usize,
    },
    #[error("a {width}×{height} frame with a {plane} row stride of {stride} bytes")]
    BadStride {
        plane: &'static str,
        width: u32,
        height: u32,
        stride: usize,
    },
}

impl Yuv420<'_> {
    /// RGBA (sRGB, alpha 255), `width × height × 4` bytes, rows packed.
    pub fn to_rgba8(&self) -> Result<Vec<u8>, ToneError> {
        let (w, h) = (self.width as usize, self.height as usize);
        let (cw, ch) = (w.div_ceil(2), h.div_ceil(2));
        let pixel = self.chroma_pixel_stride.max(1);
        let check = |plane, stride: usize, row_bytes: usize, rows: usize, data: &[u8]| {
            if rows == 0 {
                return Ok(());
            }
            if stride < row_bytes {
                return Err(ToneError::BadStride {
                    plane,
                    width: self.width,
                    height: self.height,
                    stride,
                });
            }
            let needed = stride * (rows - 1) + row_bytes;
            if data.len() < needed {
                return Err(ToneError::ShortPlane {
                    plane,
                    width: self.width,
                    height: self.height,
                    needed,
                    got: data.len(),
                });
            }
            Ok(())
        };
        check("Y", self.y_row_stride, w, h, self.y)?;
        let chroma_row = if cw == 0 { 0 } else { (cw - 1) * pixel + 1 };
        check("Cb", self.chroma_row_stride, chroma_row, ch, self.cb)?;
        check("Cr", self.chroma_row_stride, chroma_row, ch, self.cr)?;
        let mut out = Vec::with_capacity(w * h * 4);
        for y in 0..h {
            let c_row = (y / 2) * self.chroma_row_stride;
            for x in 0..w {
                let c = c_row + (x / 2) * pixel;
                let [r, g, b] = rgb_from_ycbcr(self.y[y * self.y_row_stride + x], self.cb[c], self.cr[c]);
                out.extend_from_slice(&[r, g, b, 255]);
            }
        }
        Ok(out)
    }
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

    #[test]
    fn ycbcr_primaries_and_grey() {
        assert_eq!(rgb_from_ycbcr(128, 128, 128), [128, 128, 128]);
        // JFIF's red, green and blue.
        assert_eq!(rgb_from_ycbcr(76, 85, 255), [254, 0, 0]);
        assert_eq!(rgb_from_ycbcr(150, 44, 21), [0, 255, 1]);
        assert_eq!(rgb_from_ycbcr(29, 255, 107), [0, 0, 254]);
    }

    #[test]
    fn planar_and_interleaved_chroma_give_the_same_picture() {
        // A 4 × 2 frame: two chroma samples (red-ish left, blue-ish right).
        let y = [76u8, 76, 29, 29, 76, 76, 29, 29];
        let (cb, cr) = ([85u8, 255], [255u8, 107]);
        let planar = Yuv420 {
            width: 4,
            height: 2,
            y: &y,
            y_row_stride: 4,
            cb: &cb,
            cr: &cr,
            chroma_row_stride: 2,
            chroma_pixel_stride: 1,
        };
        let interleaved_cbcr = [85u8, 255, 255, 107];
        let interleaved = Yuv420 {
            cb: &interleaved_cbcr,
            cr: &interleaved_cbcr[1..],
            chroma_row_stride: 4,
            chroma_pixel_stride: 2,
            ..planar
        };
        let a = planar.to_rgba8().expect("planar");
        assert_eq!(a, interleaved.to_rgba8().expect("interleaved"));
        assert_eq!(&a[..4], &[254, 0, 0, 255]);
        assert_eq!(&a[8..12], &[0, 0, 254, 255]);
        // Short planes and bad strides are errors, not panics.
        let short = Yuv420 { y: &y[..7], ..planar };
        assert!(matches!(
            short.to_rgba8(),
            Err(ToneError::ShortPlane { plane: "Y", .. })
        ));
        let narrow = Yuv420 {
            chroma_row_stride: 1,
            ..planar
        };
        assert!(matches!(
            narrow.to_rgba8(),
            Err(ToneError::BadStride { plane: "Cb", .. })
        ));
        let odd = Yuv420 {
            width: 3,
            height: 1,
            ..planar
        };
        assert_eq!(odd.to_rgba8().expect("odd size").len(), 12);
    }
}
