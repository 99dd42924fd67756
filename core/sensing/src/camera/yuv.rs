//! 4:2:0 YCbCr camera frames → RGB: full-range BT.601 (JFIF), which is what Android's
//! `YUV_420_888` camera frames and iOS's `420f` (`kCVPixelFormatType_420YpCbCr8BiPlanarFullRange`)
//! buffers hold. The bridges keep the planes as delivered ([`super::ChromaPlanes`] beside the luma
//! plane) so the face networks keep their luma input; whoever wants colour converts here.
//!
//! Pure functions; plane sizes and strides are checked, so no input panics.

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
pub enum YuvError {
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
    /// Whether the planes hold a whole frame: each at least its rows' bytes, strides no shorter
    /// than a row.
    pub fn check(&self) -> Result<(), YuvError> {
        let (w, h) = (self.width as usize, self.height as usize);
        let (cw, ch) = (w.div_ceil(2), h.div_ceil(2));
        let pixel = self.chroma_pixel_stride.max(1);
        let check = |plane, stride: usize, row_bytes: usize, rows: usize, data: &[u8]| {
            if rows == 0 {
                return Ok(());
            }
            if stride < row_bytes {
                return Err(YuvError::BadStride {
                    plane,
                    width: self.width,
                    height: self.height,
                    stride,
                });
            }
            // Saturating: strides come from the platforms (and FFI callers) unchecked.
            let needed = stride.saturating_mul(rows - 1).saturating_add(row_bytes);
            if data.len() < needed {
                return Err(YuvError::ShortPlane {
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
        let chroma_row = if cw == 0 {
            0
        } else {
            (cw - 1).saturating_mul(pixel).saturating_add(1)
        };
        check("Cb", self.chroma_row_stride, chroma_row, ch, self.cb)?;
        check("Cr", self.chroma_row_stride, chroma_row, ch, self.cr)
    }

    /// RGBA (sRGB, alpha 255), `width × height × 4` bytes, rows packed.
    pub fn to_rgba8(&self) -> Result<Vec<u8>, YuvError> {
        self.check()?;
        let (w, h) = (self.width as usize, self.height as usize);
        let pixel = self.chroma_pixel_stride.max(1);
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
        assert!(matches!(short.to_rgba8(), Err(YuvError::ShortPlane { plane: "Y", .. })));
        let narrow = Yuv420 {
            chroma_row_stride: 1,
            ..planar
        };
        assert!(matches!(
            narrow.to_rgba8(),
            Err(YuvError::BadStride { plane: "Cb", .. })
        ));
        let odd = Yuv420 {
            width: 3,
            height: 1,
            ..planar
        };
        assert_eq!(odd.to_rgba8().expect("odd size").len(), 12);
    }

    #[test]
    fn a_yuv_frame_keeps_its_luma_and_gives_its_colour() {
        use crate::camera::{ChromaPlanes, Exposure, Intrinsics, OwnedFrame, PixelFormat};
        let k = Intrinsics::new(4.0, 4.0, 2.0, 1.0);
        // Rows padded to 6 bytes (luma) and 4 (interleaved chroma), as platforms pad them.
        let y = [76u8, 76, 29, 29, 0, 0, 76, 76, 29, 29, 0, 0];
        let cbcr = [85u8, 255, 255, 107];
        let frame = OwnedFrame::yuv420(4, 2, 6, &y, ChromaPlanes::interleaved(&cbcr, 4), 90, k, 7)
            .expect("a whole frame")
            .with_exposure(Exposure::new(0.01, 200.0));
        assert_eq!(frame.format, PixelFormat::Luma8);
        assert_eq!(frame.data, y);
        let rgba = frame.clone().into_colour();
        assert_eq!(
            (rgba.format, rgba.row_stride, rgba.rotation_cw_deg),
            (PixelFormat::Rgba8, 16, 90)
        );
        assert_eq!(&rgba.data[..4], &[254, 0, 0, 255]);
        assert_eq!(&rgba.data[28..32], &[0, 0, 254, 255]);
        assert_eq!(rgba.exposure.map(Exposure::relative), Some(0.02));
        // The same picture from separate planes.
        let separate = OwnedFrame::yuv420(
            4,
            2,
            6,
            &y,
            ChromaPlanes::separate(&[85, 255], &[255, 107], 2, 1),
            90,
            k,
            7,
        )
        .expect("a whole frame");
        assert_eq!(separate.into_colour().data, rgba.data);
        // Too short a chroma plane is refused up front; luma alone has no colour.
        assert!(matches!(
            OwnedFrame::yuv420(4, 4, 6, &[0; 24], ChromaPlanes::interleaved(&cbcr, 4), 0, k, 0),
            Err(YuvError::ShortPlane { plane: "Cb", .. })
        ));
        // A stride that would overflow the size sum is refused, not wrapped.
        assert!(matches!(
            OwnedFrame::yuv420(4, 4, 6, &[0; 24], ChromaPlanes::interleaved(&cbcr, usize::MAX), 0, k, 0),
            Err(YuvError::ShortPlane { .. })
        ));
        let grey = OwnedFrame::luma8(4, 2, 6, &y, 0, k, 0).into_colour();
        assert_eq!((grey.format, grey.data), (PixelFormat::Luma8, y.to_vec()));
        // Exposures the platforms cannot give are none.
        assert_eq!(Exposure::new(0.0, 100.0), None);
        assert_eq!(Exposure::new(0.01, f32::NAN), None);
    }
}
