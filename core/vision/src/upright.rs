//! [`UprightImage`]: a camera frame read as if turned upright (in the device's natural portrait
//! orientation) without copying it, with bilinear reads, its colour where the frame has chroma,
//! and reduced copies for crops that shrink a lot ([`crate::reduced`]).
//!
//! Panics: none; a frame whose sizes do not fit its buffer is a [`FaceError::BadFrame`].

use crate::{CameraFrame, FaceError, Intrinsics, PixelFormat, reduced};
use glam::Vec2;

/// A frame turned upright, read through its rotation without copying.
pub struct UprightImage<'a> {
    frame: CameraFrame<'a>,
    /// Size of the upright image.
    pub width: u32,
    pub height: u32,
    pub intrinsics: Intrinsics,
    /// Buffer bytes from an upright pixel to its right-hand and to its lower neighbour.
    step_x: isize,
    step_y: isize,
    /// The image at half and a quarter of its resolution, each made when a crop first needs it.
    levels: [std::cell::OnceCell<reduced::Reduced>; REDUCED_LEVELS],
}

/// How many reduced levels a frame may get ([`reduced`]): a quarter of the resolution takes
/// BlazeFace's crop of a whole 640 × 480 frame (5 pixels an output pixel) to under two.
pub(crate) const REDUCED_LEVELS: usize = 2;

impl<'a> UprightImage<'a> {
    pub fn new(frame: CameraFrame<'a>) -> Result<Self, FaceError> {
        if !matches!(frame.rotation_cw_deg, 0 | 90 | 180 | 270) {
            return Err(FaceError::BadFrame(format!(
                "rotation must be 0, 90, 180 or 270 degrees, got {}",
                frame.rotation_cw_deg
            )));
        }
        let bpp = frame.format.bytes_per_pixel();
        let row = frame.width as usize * bpp;
        if frame.width == 0 || frame.height == 0 {
            return Err(FaceError::BadFrame("empty frame".into()));
        }
        if frame.row_stride < row {
            return Err(FaceError::BadFrame(format!(
                "row stride {} is shorter than a row ({row} bytes)",
                frame.row_stride
            )));
        }
        let needed = frame.row_stride * (frame.height as usize - 1) + row;
        if frame.data.len() < needed {
            return Err(FaceError::BadFrame(format!(
                "{}×{} needs {needed} bytes, got {}",
                frame.width,
                frame.height,
                frame.data.len()
            )));
        }
        let i = frame.intrinsics;
        if ![i.fx_px, i.fy_px, i.cx_px, i.cy_px].iter().all(|v| v.is_finite()) || i.fx_px <= 0.0 || i.fy_px <= 0.0 {
            return Err(FaceError::BadFrame(format!("invalid intrinsics {i:?}")));
        }
        let turns = frame.rotation_cw_deg / 90;
        let (width, height) = if turns % 2 == 1 {
            (frame.height, frame.width)
        } else {
            (frame.width, frame.height)
        };
        let (bpp, row) = (bpp as isize, frame.row_stride as isize);
        // Upright +x and +y in the buffer, through the inverse turn (see `buffer_xy`).
        let (step_x, step_y) = match frame.rotation_cw_deg {
            90 => (-row, bpp),
            180 => (-bpp, -row),
            270 => (row, -bpp),
            _ => (bpp, row),
        };
        Ok(Self {
            frame,
            width,
            height,
            intrinsics: i.turned_cw(frame.width, frame.height, turns),
            step_x,
            step_y,
            levels: Default::default(),
        })
    }

    /// 8-bit RGB of upright pixel `(x, y)`, which must be inside the image.
    fn rgb8(&self, x: u32, y: u32) -> [u8; 3] {
        self.rgb8_at(self.offset(x as i32, y as i32))
    }

    /// 8-bit RGB of the pixel at buffer offset `at`, which must be a pixel's offset.
    #[inline]
    fn rgb8_at(&self, at: usize) -> [u8; 3] {
        let d = self.frame.data;
        match self.frame.format {
            PixelFormat::Luma8 => [d[at]; 3],
            PixelFormat::Rgba8 => [d[at], d[at + 1], d[at + 2]],
        }
    }

    /// Reduced level `k` (1: half the resolution, up to [`REDUCED_LEVELS`]), made on first use.
    pub(crate) fn level(&self, k: usize) -> &reduced::Reduced {
        let k = k.clamp(1, REDUCED_LEVELS);
        self.levels[k - 1].get_or_init(|| {
            if k == 1 {
                reduced::Reduced::half_of(self.width, self.height, |y| {
                    // Upright row y starts at its buffer offset and steps `step_x` a pixel
                    // (both in the buffer: checked by `new`).
                    let (start, step) = (self.offset(0, y as i32) as isize, self.step_x);
                    move |x: u32| self.rgb8_at((start + x as isize * step) as usize)
                })
            } else {
                self.level(k - 1).half()
            }
        })
    }

    /// RGB in [0, 1] at integer upright coordinates (black outside).
    fn rgb(&self, x: i32, y: i32) -> [f32; 3] {
        if x < 0 || y < 0 || x >= self.width as i32 || y >= self.height as i32 {
            return [0.0; 3];
        }
        self.rgb8(x as u32, y as u32).map(|v| f32::from(v) / 255.0)
    }

    /// The buffer pixel of upright pixel `(x, y)`: the inverse of the clockwise turn.
    #[inline]
    fn buffer_xy(&self, x: i32, y: i32) -> (i32, i32) {
        let (w, h) = (self.frame.width as i32, self.frame.height as i32);
        match self.frame.rotation_cw_deg {
            90 => (y, h - 1 - x),
            180 => (w - 1 - x, h - 1 - y),
            270 => (w - 1 - y, x),
            _ => (x, y),
        }
    }

    /// The buffer's byte offset of upright pixel `(x, y)`, which must be inside the image.
    #[inline]
    fn offset(&self, x: i32, y: i32) -> usize {
        let (bx, by) = self.buffer_xy(x, y);
        by as usize * self.frame.row_stride + bx as usize * self.frame.format.bytes_per_pixel()
    }

    /// Whether crops read from this frame are grey: a luma frame's are (its chroma, if any, is
    /// read only where colour is asked for, [`Self::colour_at`]).
    pub fn samples_grey(&self) -> bool {
        self.frame.format == PixelFormat::Luma8
    }

    /// Whether colour can be read: an RGBA frame, or luma with its chroma planes.
    pub fn has_colour(&self) -> bool {
        self.frame.format == PixelFormat::Rgba8 || self.frame.chroma.is_some()
    }

    /// The sRGB colour of the upright pixel nearest `p`, when the frame has colour and `p` is
    /// inside it.
    pub fn colour_at(&self, p: Vec2) -> Option<[u8; 3]> {
        if !(p.x.is_finite() && p.y.is_finite()) || p.x < 0.0 || p.y < 0.0 {
            return None;
        }
        let (x, y) = (p.x as i32, p.y as i32);
        if x >= self.width as i32 || y >= self.height as i32 {
            return None;
        }
        let (bx, by) = self.buffer_xy(x, y);
        self.frame.rgb8_at(bx as u32, by as u32)
    }

    /// Bilinear RGB in [0, 1] at upright position `p` (pixel centres at half-integers).
    #[inline]
    pub(crate) fn bilinear(&self, p: Vec2) -> [f32; 3] {
        let (x, y) = (p.x - 0.5, p.y - 0.5);
        // floor without a libm call (the crops sample this hundreds of thousands of times).
        let floor = |v: f32| {
            let i = v as i32;
            if (i as f32) > v { i - 1 } else { i }
        };
        let (xi, yi) = (floor(x), floor(y));
        let (fx, fy) = (x - xi as f32, y - yi as f32);
        let weights = [
            (0, 0, (1.0 - fx) * (1.0 - fy)),
            (1, 0, fx * (1.0 - fy)),
            (0, 1, (1.0 - fx) * fy),
            (1, 1, fx * fy),
        ];
        let inside = xi >= 0 && yi >= 0 && xi < self.width as i32 - 1 && yi < self.height as i32 - 1;
        if !(inside && x.is_finite() && y.is_finite()) {
            // At the border (and for nonsense positions): black outside, as `rgb` reads it.
            let mut out = [0.0f32; 3];
            for (dx, dy, w) in weights {
                let c = self.rgb(xi.saturating_add(dx), yi.saturating_add(dy));
                for k in 0..3 {
                    out[k] += c[k] * w;
                }
            }
            return out;
        }
        // Inside: straight to the bytes (the neighbours a fixed step away), scaled to [0, 1] once.
        // In the image, so every offset is in the buffer (checked by `new`). One format test per
        // sample, not per neighbour: the crops sample hundreds of thousands of times a frame.
        let d = self.frame.data;
        let base = self.offset(xi, yi) as isize;
        let at = weights.map(|(dx, dy, _)| (base + dx as isize * self.step_x + dy as isize * self.step_y) as usize);
        let mut out = [0.0f32; 3];
        match self.frame.format {
            PixelFormat::Luma8 => {
                for (at, (_, _, w)) in at.into_iter().zip(weights) {
                    let v = f32::from(d[at]) * w;
                    out = [out[0] + v, out[1] + v, out[2] + v];
                }
            }
            PixelFormat::Rgba8 => {
                for (at, (_, _, w)) in at.into_iter().zip(weights) {
                    let Some(&[r, g, b]) = d.get(at..at + 3) else { continue };
                    out[0] += f32::from(r) * w;
                    out[1] += f32::from(g) * w;
                    out[2] += f32::from(b) * w;
                }
            }
        }
        out.map(|v| v * (1.0 / 255.0))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame(data: &[u8], w: u32, h: u32, rot: u32) -> CameraFrame<'_> {
        CameraFrame {
            width: w,
            height: h,
            row_stride: w as usize,
            format: PixelFormat::Luma8,
            data,
            rotation_cw_deg: rot,
            intrinsics: Intrinsics::from_horizontal_fov(w, h, 1.0),
            capture_t_ns: 0,
            chroma: None,
        }
    }

    #[test]
    fn upright_view_turns_pixels_and_intrinsics_together() {
        // 3×2 buffer, pixel values = index.
        let data: Vec<u8> = (0..6).collect();
        let mut f = frame(&data, 3, 2, 90);
        f.intrinsics = Intrinsics {
            fx_px: 10.0,
            fy_px: 20.0,
            cx_px: 1.0,
            cy_px: 0.5,
        };
        let up = UprightImage::new(f).unwrap();
        assert_eq!((up.width, up.height), (2, 3));
        // Turning clockwise puts the buffer's bottom-left pixel (index 3) at the top left.
        assert_eq!(up.rgb(0, 0)[0], 3.0 / 255.0);
        assert_eq!(up.rgb(1, 0)[0], 0.0);
        assert_eq!(up.rgb(0, 2)[0], 5.0 / 255.0);
        // The principal point is the same scene point: buffer (1, 0.5) → upright (2 − 0.5, 1).
        assert_eq!((up.intrinsics.cx_px, up.intrinsics.cy_px), (1.5, 1.0));
        assert_eq!((up.intrinsics.fx_px, up.intrinsics.fy_px), (20.0, 10.0));
        for rot in [180, 270] {
            let up = UprightImage::new(frame(&data, 3, 2, rot)).unwrap();
            let back = match rot {
                180 => up.rgb(2, 1),
                _ => up.rgb(0, 2),
            };
            assert_eq!(back[0], 0.0, "rotation {rot}: buffer (0,0) lands at the turned corner");
        }
    }

    #[test]
    fn bilinear_reads_the_same_pixels_in_every_turn_as_the_pixel_reader() {
        // A 7 × 5 luma buffer with padded rows, values from the position.
        let (w, h, stride) = (7u32, 5u32, 9usize);
        let data: Vec<u8> = (0..stride * h as usize).map(|i| ((i * 37) % 251) as u8).collect();
        for rot in [0, 90, 180, 270] {
            let mut f = frame(&data, w, h, rot);
            f.row_stride = stride;
            let up = UprightImage::new(f).unwrap();
            for (x, y) in [(1.3f32, 1.7f32), (2.5, 3.25), (0.6, 0.6), (4.9, 2.2)] {
                let p = Vec2::new(x, y);
                if p.x + 1.0 > up.width as f32 || p.y + 1.0 > up.height as f32 {
                    continue;
                }
                // The same weights over the four pixels, read one by one.
                let (fx, fy) = (p.x - 0.5, p.y - 0.5);
                let (x0, y0) = (fx.floor() as i32, fy.floor() as i32);
                let (ax, ay) = (fx - x0 as f32, fy - y0 as f32);
                let want = up.rgb(x0, y0)[0] * (1.0 - ax) * (1.0 - ay)
                    + up.rgb(x0 + 1, y0)[0] * ax * (1.0 - ay)
                    + up.rgb(x0, y0 + 1)[0] * (1.0 - ax) * ay
                    + up.rgb(x0 + 1, y0 + 1)[0] * ax * ay;
                let got = up.bilinear(p)[0];
                assert!((got - want).abs() < 1e-5, "rotation {rot} at {p}: {got} vs {want}");
            }
        }
    }

    #[test]
    fn the_half_level_averages_the_upright_pixels_in_every_turn_and_format() {
        // 7 × 5 pixels in a padded buffer, luma and RGBA, values from the byte's position.
        let (w, h) = (7u32, 5u32);
        for (format, bytes) in [(PixelFormat::Luma8, 1usize), (PixelFormat::Rgba8, 4)] {
            let stride = (w as usize + 2) * bytes;
            let data: Vec<u8> = (0..stride * h as usize).map(|i| ((i * 37) % 251) as u8).collect();
            for rot in [0, 90, 180, 270] {
                let mut f = frame(&data, w, h, rot);
                (f.row_stride, f.format) = (stride, format);
                let up = UprightImage::new(f).unwrap();
                // Each level pixel the rounded mean of its 2 × 2 block, read pixel by pixel.
                let level = up.level(1);
                assert_eq!((level.width, level.height), (up.width / 2, up.height / 2));
                for j in 0..level.height {
                    for i in 0..level.width {
                        let block = [(0, 0), (1, 0), (0, 1), (1, 1)].map(|(dx, dy)| up.rgb8(2 * i + dx, 2 * j + dy));
                        let want: [u8; 3] = std::array::from_fn(|k| {
                            ((block.iter().map(|c| u16::from(c[k])).sum::<u16>() + 2) / 4) as u8
                        });
                        let centre = Vec2::new(2.0 * i as f32 + 1.0, 2.0 * j as f32 + 1.0) * 0.5;
                        let got = level.bilinear(centre).map(|v| (v * 255.0).round() as u8);
                        assert_eq!(got, want, "{format:?} rotation {rot} at ({i}, {j})");
                    }
                }
            }
        }
    }

    #[test]
    fn bad_frames_are_errors_not_panics() {
        let data = vec![0u8; 10];
        assert!(UprightImage::new(frame(&data, 4, 4, 0)).is_err());
        assert!(UprightImage::new(frame(&data, 2, 2, 45)).is_err());
        assert!(UprightImage::new(frame(&data, 0, 2, 0)).is_err());
        let mut f = frame(&data, 2, 2, 0);
        f.intrinsics.fx_px = f32::NAN;
        assert!(UprightImage::new(f).is_err());
        f = frame(&data, 2, 2, 0);
        f.row_stride = 1;
        assert!(UprightImage::new(f).is_err());
    }
}
