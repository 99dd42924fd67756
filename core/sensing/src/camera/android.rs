//! Intrinsics from what Android's Camera2 reports (`CameraCharacteristics`), for an output image
//! of a given size. The Kotlin shell reads the characteristics and forwards them as they are;
//! the maths is here, tested on the desktop.
//!
//! **Coordinates** (Camera2's): the pixel array is the whole sensor; the active array
//! (`SENSOR_INFO_ACTIVE_ARRAY_SIZE`) and the pre-correction active array
//! (`SENSOR_INFO_PRE_CORRECTION_ACTIVE_ARRAY_SIZE`) are rectangles in pixel-array coordinates.
//! `LENS_INTRINSIC_CALIBRATION` (`[fx, fy, cx, cy, s]`) is given in the pre-correction array's
//! coordinates; output streams show the active array.
//!
//! **Output images**: with the default crop region (the whole active array) the camera fills an
//! output stream with the largest region of the active array, centred, that has the stream's
//! aspect ratio, scaled to the stream's size: a 16:9 stream of a 4:3 sensor drops rows at the top
//! and bottom, a 4:3 stream of a 16:9 sensor columns at the sides. (The shell this replaced
//! assumed the width always matched, which put the principal point off by the dropped columns'
//! half in the second case.) Coordinates are continuous, pixel `i` covering `[i, i + 1)`, so a
//! scale maps them exactly.

use super::Intrinsics;

/// A rectangle of sensor pixels (`android.graphics.Rect`: left, top inclusive; right, bottom
/// exclusive).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PixelRect {
    pub left: i32,
    pub top: i32,
    pub right: i32,
    pub bottom: i32,
}

impl PixelRect {
    fn size(&self) -> Option<(f64, f64)> {
        let w = i64::from(self.right) - i64::from(self.left);
        let h = i64::from(self.bottom) - i64::from(self.top);
        (w > 0 && h > 0).then_some((w as f64, h as f64))
    }
}

/// The characteristics of one camera that its intrinsics follow from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera2Characteristics {
    /// `SENSOR_INFO_ACTIVE_ARRAY_SIZE`.
    pub active_array: PixelRect,
    /// `SENSOR_INFO_PRE_CORRECTION_ACTIVE_ARRAY_SIZE` (API 23), if reported; else the active array.
    pub pre_correction_active_array: Option<PixelRect>,
    /// `SENSOR_INFO_PIXEL_ARRAY_SIZE`, if reported: the pixels that `physical_size_mm` spans.
    pub pixel_array_px: Option<[u32; 2]>,
    /// `SENSOR_INFO_PHYSICAL_SIZE`, millimetres.
    pub physical_size_mm: Option<[f32; 2]>,
    /// `LENS_INFO_AVAILABLE_FOCAL_LENGTHS[0]`, millimetres (front cameras have one).
    pub focal_length_mm: Option<f32>,
    /// `LENS_INTRINSIC_CALIBRATION`'s `[fx, fy, cx, cy]` (API 28, where the device publishes it).
    pub lens_intrinsic_calibration: Option<[f32; 4]>,
}

/// Why no intrinsics could be derived.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum CameraInfoError {
    #[error("the active array {0:?} is empty")]
    EmptyActiveArray(PixelRect),
    #[error("the output image must be at least 1×1 pixel, got {width_px}×{height_px}")]
    EmptyImage { width_px: u32, height_px: u32 },
    #[error("the camera reports neither an intrinsic calibration nor a focal length with a physical sensor size")]
    NoFocalLength,
    #[error("implausible camera characteristics: {0}")]
    Implausible(&'static str),
}

impl Camera2Characteristics {
    /// The intrinsics in active-array pixels: the published calibration, moved from the
    /// pre-correction array's origin to the active array's; else the focal length over the pixel
    /// pitch (physical size over the pixel array, or over the active array when the pixel array
    /// is not reported: a few pixels wider at most, < 1 %), principal point at the centre.
    pub fn active_array_intrinsics(&self) -> Result<Intrinsics, CameraInfoError> {
        let (aw, ah) = self
            .active_array
            .size()
            .ok_or(CameraInfoError::EmptyActiveArray(self.active_array))?;
        if let Some([fx, fy, cx, cy]) = self.lens_intrinsic_calibration.filter(|k| k[0] > 0.0) {
            if ![fx, fy, cx, cy].iter().all(|v| v.is_finite()) || fy <= 0.0 {
                return Err(CameraInfoError::Implausible(
                    "non-finite or negative intrinsic calibration",
                ));
            }
            let pre = self
                .pre_correction_active_array
                .filter(|r| r.size().is_some())
                .unwrap_or(self.active_array);
            let dx = f64::from(pre.left) - f64::from(self.active_array.left);
            let dy = f64::from(pre.top) - f64::from(self.active_array.top);
            return Ok(Intrinsics {
                fx_px: fx,
                fy_px: fy,
                cx_px: (f64::from(cx) + dx) as f32,
                cy_px: (f64::from(cy) + dy) as f32,
            });
        }
        let focal_mm = self.focal_length_mm.filter(|f| f.is_finite() && *f > 0.0);
        let physical = self
            .physical_size_mm
            .filter(|[w, h]| w.is_finite() && h.is_finite() && *w > 0.0 && *h > 0.0);
        let (Some(focal_mm), Some([pw_mm, ph_mm])) = (focal_mm, physical) else {
            return Err(CameraInfoError::NoFocalLength);
        };
        let (nw, nh) = match self.pixel_array_px {
            Some([w, h]) if w > 0 && h > 0 => (f64::from(w), f64::from(h)),
            _ => (aw, ah),
        };
        let fx = f64::from(focal_mm) / (f64::from(pw_mm) / nw);
        let fy = f64::from(focal_mm) / (f64::from(ph_mm) / nh);
        Ok(Intrinsics {
            fx_px: fx as f32,
            fy_px: fy as f32,
            cx_px: (aw * 0.5) as f32,
            cy_px: (ah * 0.5) as f32,
        })
    }

    /// The intrinsics of an output image of `width_px × height_px` as delivered (before any
    /// rotation to upright): the centred region of the active array with the image's aspect
    /// ratio, scaled to the image (module docs).
    pub fn image_intrinsics(&self, width_px: u32, height_px: u32) -> Result<Intrinsics, CameraInfoError> {
        if width_px == 0 || height_px == 0 {
            return Err(CameraInfoError::EmptyImage { width_px, height_px });
        }
        let k = self.active_array_intrinsics()?;
        let (aw, ah) = self
            .active_array
            .size()
            .ok_or(CameraInfoError::EmptyActiveArray(self.active_array))?;
        let (w, h) = (f64::from(width_px), f64::from(height_px));
        // The largest centred region with the image's aspect ratio.
        let (crop_w, crop_h) = if aw * h > ah * w {
            (ah * w / h, ah)
        } else {
            (aw, aw * h / w)
        };
        let (x0, y0) = ((aw - crop_w) * 0.5, (ah - crop_h) * 0.5);
        let s = w / crop_w;
        Ok(Intrinsics {
            fx_px: (f64::from(k.fx_px) * s) as f32,
            fy_px: (f64::from(k.fy_px) * s) as f32,
            cx_px: ((f64::from(k.cx_px) - x0) * s) as f32,
            cy_px: ((f64::from(k.cy_px) - y0) * s) as f32,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 4:3 sensor of 4032 × 3024 active pixels inside a 4056 × 3040 pixel array, 4.2 mm lens,
    /// 1.0 µm pixels — numbers in the range of today's front cameras.
    fn sensor() -> Camera2Characteristics {
        Camera2Characteristics {
            active_array: PixelRect {
                left: 12,
                top: 8,
                right: 12 + 4032,
                bottom: 8 + 3024,
            },
            pre_correction_active_array: None,
            pixel_array_px: Some([4056, 3040]),
            physical_size_mm: Some([4.056, 3.040]),
            focal_length_mm: Some(4.2),
            lens_intrinsic_calibration: None,
        }
    }

    /// Projects a point (camera frame, z forward) through active-array intrinsics, then through
    /// the camera's crop and scale to the output image: the ground truth the derived image
    /// intrinsics must reproduce.
    fn truth_pixel(k: Intrinsics, crop: (f64, f64, f64), p: [f64; 3]) -> (f64, f64) {
        let (x0, y0, s) = crop;
        let u = f64::from(k.fx_px) * p[0] / p[2] + f64::from(k.cx_px);
        let v = f64::from(k.fy_px) * p[1] / p[2] + f64::from(k.cy_px);
        ((u - x0) * s, (v - y0) * s)
    }

    fn pixel(k: Intrinsics, p: [f64; 3]) -> (f64, f64) {
        (
            f64::from(k.fx_px) * p[0] / p[2] + f64::from(k.cx_px),
            f64::from(k.fy_px) * p[1] / p[2] + f64::from(k.cy_px),
        )
    }

    fn close(a: (f64, f64), b: (f64, f64)) -> bool {
        (a.0 - b.0).abs() < 1e-2 && (a.1 - b.1).abs() < 1e-2
    }

    #[test]
    fn focal_length_over_the_pixel_pitch() {
        let k = sensor().active_array_intrinsics().unwrap();
        // 4.2 mm over 1 µm pixels.
        assert!(
            (k.fx_px - 4200.0).abs() < 0.5 && (k.fy_px - 4200.0).abs() < 0.5,
            "{k:?}"
        );
        assert_eq!((k.cx_px, k.cy_px), (2016.0, 1512.0));
        // Without the pixel array, the active array's width stands in (0.6 % here).
        let k2 = Camera2Characteristics {
            pixel_array_px: None,
            ..sensor()
        }
        .active_array_intrinsics()
        .unwrap();
        assert!((k2.fx_px / k.fx_px - 4032.0 / 4056.0).abs() < 1e-4);
    }

    #[test]
    fn output_images_are_the_centred_crop_of_their_aspect_scaled() {
        let c = sensor();
        let k = c.active_array_intrinsics().unwrap();
        let points = [[0.0, 0.0, 0.5], [0.1, -0.05, 0.4], [-0.2, 0.15, 0.6]];
        // (image size, crop origin in the active array, scale) worked out by hand.
        let cases = [
            // Same aspect: the whole array, scaled by 1/6.3.
            ((640, 480), (0.0, 0.0, 640.0 / 4032.0)),
            // 16:9 of a 4:3 array: full width, 2268 rows from row 378.
            ((1280, 720), (0.0, 378.0, 1280.0 / 4032.0)),
            // Square: full height, 3024 columns from column 504.
            ((480, 480), (504.0, 0.0, 480.0 / 3024.0)),
        ];
        for ((w, h), crop) in cases {
            let ki = c.image_intrinsics(w, h).unwrap();
            for p in points {
                let want = truth_pixel(k, crop, p);
                let got = pixel(ki, p);
                assert!(close(got, want), "{w}×{h}: {got:?} vs {want:?}");
            }
        }
    }

    /// A 4:3 stream of a 16:9 sensor is cropped at the sides: the old Kotlin code matched the
    /// width and cropped rows that do not exist, which moved the principal point.
    #[test]
    fn a_narrower_stream_of_a_wide_sensor_drops_columns() {
        let c = Camera2Characteristics {
            active_array: PixelRect {
                left: 0,
                top: 0,
                right: 3840,
                bottom: 2160,
            },
            pixel_array_px: Some([3840, 2160]),
            physical_size_mm: Some([3.84, 2.16]),
            ..sensor()
        };
        let k = c.image_intrinsics(640, 480).unwrap();
        // Crop 2880 × 2160 from column 480, scale 640 / 2880.
        let s = 640.0 / 2880.0;
        assert!(
            (k.cx_px - 320.0).abs() < 1e-3 && (k.cy_px - 240.0).abs() < 1e-3,
            "{k:?}"
        );
        assert!((f64::from(k.fx_px) - 4200.0 * s).abs() < 1e-2, "{k:?}");
    }

    #[test]
    fn the_published_calibration_wins_and_moves_to_the_active_array() {
        let c = Camera2Characteristics {
            lens_intrinsic_calibration: Some([4150.0, 4160.0, 2030.0, 1500.0]),
            // The pre-correction array starts 4 columns and 2 rows before the active one.
            pre_correction_active_array: Some(PixelRect {
                left: 8,
                top: 6,
                right: 8 + 4040,
                bottom: 6 + 3028,
            }),
            ..sensor()
        };
        let k = c.active_array_intrinsics().unwrap();
        assert_eq!((k.fx_px, k.fy_px, k.cx_px, k.cy_px), (4150.0, 4160.0, 2026.0, 1498.0));
        let half = c.image_intrinsics(2016, 1512).unwrap();
        assert_eq!(
            (half.fx_px, half.fy_px, half.cx_px, half.cy_px),
            (2075.0, 2080.0, 1013.0, 749.0)
        );
    }

    #[test]
    fn unusable_characteristics_are_errors() {
        let c = sensor();
        assert!(matches!(
            c.image_intrinsics(0, 480),
            Err(CameraInfoError::EmptyImage { .. })
        ));
        let empty = PixelRect {
            left: 5,
            top: 0,
            right: 5,
            bottom: 10,
        };
        assert!(matches!(
            Camera2Characteristics {
                active_array: empty,
                ..c
            }
            .image_intrinsics(640, 480),
            Err(CameraInfoError::EmptyActiveArray(_))
        ));
        for (focal, physical) in [
            (None, Some([4.0, 3.0])),
            (Some(4.2), None),
            (Some(f32::NAN), Some([4.0, 3.0])),
        ] {
            let c = Camera2Characteristics {
                focal_length_mm: focal,
                physical_size_mm: physical,
                ..sensor()
            };
            assert_eq!(c.image_intrinsics(640, 480), Err(CameraInfoError::NoFocalLength));
        }
        let bad = Camera2Characteristics {
            lens_intrinsic_calibration: Some([4000.0, f32::INFINITY, 2000.0, 1500.0]),
            ..sensor()
        };
        assert!(matches!(
            bad.image_intrinsics(640, 480),
            Err(CameraInfoError::Implausible(_))
        ));
        // A zero fx means "not calibrated" on some devices: the focal length is used instead.
        let zero = Camera2Characteristics {
            lens_intrinsic_calibration: Some([0.0, 0.0, 0.0, 0.0]),
            ..sensor()
        };
        assert_eq!(zero.active_array_intrinsics(), sensor().active_array_intrinsics());
    }
}
