//! A synthetic phone camera that looks into an equirectangular HDR environment, for replaying the
//! live room light on the desktop (`phantogram render --environment-from-camera LOG`, the tests):
//! given the device's orientation it renders the frame the phone's camera would deliver — the
//! buffer turned as the platform delivers it, exposed by its [`Metering`], clipped and encoded as
//! 8-bit sRGB — and reports the exposure it chose, as Camera2 and AVFoundation report theirs.
//! [`as_yuv420`] encodes such a frame as the phones deliver it (4:2:0 YCbCr, padded rows).
//!
//! Pure function of its inputs (no clock, no randomness). **Panics**: none.

use glam::{Quat, Vec3};
use phantogram_assets::ibl::Environment;
use phantogram_geometry::srgb::luminance;
use phantogram_roomlight::tone::srgb8_from_linear;
use phantogram_roomlight::world_from_buffer_camera;
use phantogram_sensing::camera::{CameraPose, ChromaPlanes, Exposure, Intrinsics, OwnedFrame, PixelFormat};

/// How a frame's exposure is chosen.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Metering {
    /// The frame's mean luminance at middle grey (18 %): what auto-exposure does for the face
    /// tracker and the viewer.
    Average,
    /// The frame's brightest pixel just below clipping (at 90 %), the exposure no shorter than
    /// `min_ratio` × the average metering's: the short frame of an exposure bracket, which the
    /// room light takes between the others so that lamps and windows are not clipped.
    Highlights { min_ratio: f32 },
}

/// The camera: its buffer, optics and placement on the device.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SyntheticCamera {
    /// The buffer as delivered (before `rotation_cw_deg` turns it upright).
    pub width: u32,
    pub height: u32,
    pub intrinsics: Intrinsics,
    pub rotation_cw_deg: u32,
    pub pose: CameraPose,
    /// The linear value the auto-exposure puts the frame's mean luminance at (18 % grey).
    pub middle_grey: f32,
}

impl SyntheticCamera {
    /// A phone's front camera as Android delivers it in portrait: a 320 × 240 landscape buffer
    /// turned 270° clockwise to upright, 70° across its long side.
    pub fn phone_front() -> Self {
        Self::phone_320x240(70.0, 270, CameraPose::front(Vec3::new(0.0, 0.07, 0.0)))
    }

    /// A phone's main rear camera as Android delivers it in portrait: a 320 × 240 landscape
    /// buffer turned 90° clockwise to upright (the rear sensor is mounted the other way round from
    /// the front one), 67° across its long side (a 26 mm-equivalent lens on a 4:3 sensor).
    pub fn phone_rear() -> Self {
        Self::phone_320x240(67.0, 90, CameraPose::rear(Vec3::new(0.0, 0.06, 0.0)))
    }

    fn phone_320x240(hfov_deg: f32, rotation_cw_deg: u32, pose: CameraPose) -> Self {
        let (width, height) = (320, 240);
        Self {
            width,
            height,
            intrinsics: Intrinsics::from_horizontal_fov(width, height, hfov_deg.to_radians()),
            rotation_cw_deg,
            pose,
            middle_grey: 0.18,
        }
    }

    /// World from the buffer's camera frame (x along rows, y down, z along the optical axis).
    pub fn world_from_camera(&self, world_from_device: Quat) -> Quat {
        world_from_buffer_camera(world_from_device, &self.pose, self.rotation_cw_deg)
    }

    /// The frame seen with the device at `world_from_device`, and its exposure (radiance ×
    /// exposure = the linear value before clipping).
    pub fn capture(
        &self,
        env: &Environment,
        world_from_device: Quat,
        metering: Metering,
        capture_t_ns: i64,
    ) -> (OwnedFrame, f32) {
        let q = self.world_from_camera(world_from_device);
        let k = self.intrinsics;
        let (w, h) = (self.width as usize, self.height as usize);
        let radiance: Vec<[f32; 3]> = (0..h)
            .flat_map(|y| (0..w).map(move |x| (x, y)))
            .map(|(x, y)| {
                let ray = Vec3::new(
                    (x as f32 + 0.5 - k.cx_px) / k.fx_px,
                    (y as f32 + 0.5 - k.cy_px) / k.fy_px,
                    1.0,
                );
                env.sample(q * ray)
            })
            .collect();
        let mean = radiance.iter().copied().map(luminance).sum::<f32>() / radiance.len().max(1) as f32;
        let average = if mean > 1e-9 { self.middle_grey / mean } else { 1.0 };
        let exposure = match metering {
            Metering::Average => average,
            Metering::Highlights { min_ratio } => {
                let peak = radiance.iter().flat_map(|c| c.iter().copied()).fold(0.0f32, f32::max);
                if peak > 1e-9 {
                    (0.9 / peak).clamp(average * min_ratio.min(1.0), average)
                } else {
                    average
                }
            }
        };
        let data = radiance
            .iter()
            .flat_map(|c| {
                let [r, g, b] = c.map(|v| srgb8_from_linear(v * exposure));
                [r, g, b, 255]
            })
            .collect();
        let frame = OwnedFrame {
            width: self.width,
            height: self.height,
            row_stride: w * 4,
            format: PixelFormat::Rgba8,
            data,
            rotation_cw_deg: self.rotation_cw_deg,
            intrinsics: k,
            capture_t_ns,
            chroma: None,
            // Radiance × `exposure` is the linear value: a camera at ISO 100 exposing that long.
            exposure: Exposure::new(exposure, 100.0),
        };
        (frame, exposure)
    }
}

/// `frame` (RGBA) as a phone's camera delivers it: full-range BT.601 4:2:0, the luma plane with
/// rows padded to a multiple of 64 bytes and one interleaved CbCr plane (iOS's `420f`; Android's
/// `YUV_420_888` on most devices), each chroma sample the mean of its 2 × 2 pixels. Other frames
/// come back as they are.
pub fn as_yuv420(frame: &OwnedFrame) -> OwnedFrame {
    if frame.format != PixelFormat::Rgba8 {
        return frame.clone();
    }
    let (w, h) = (frame.width as usize, frame.height as usize);
    let luma_stride = w.div_ceil(64) * 64;
    let (cw, ch) = (w.div_ceil(2), h.div_ceil(2));
    let chroma_stride = (cw * 2).div_ceil(64) * 64;
    let rgb = |x: usize, y: usize| {
        let i = y * frame.row_stride + x * 4;
        [0, 1, 2].map(|c| f32::from(frame.data[i + c]))
    };
    let mut luma = vec![0u8; luma_stride * h];
    let mut cbcr = vec![128u8; chroma_stride * ch];
    let code = |v: f32| (v + 0.5).clamp(0.0, 255.0) as u8;
    for y in 0..h {
        for x in 0..w {
            let [r, g, b] = rgb(x, y);
            luma[y * luma_stride + x] = code(0.299 * r + 0.587 * g + 0.114 * b);
        }
    }
    for cy in 0..ch {
        for cx in 0..cw {
            let (mut sum, mut n) = ([0.0f32; 3], 0.0);
            for (x, y) in [(0, 0), (1, 0), (0, 1), (1, 1)].map(|(dx, dy)| (2 * cx + dx, 2 * cy + dy)) {
                if x < w && y < h {
                    let c = rgb(x, y);
                    (0..3).for_each(|i| sum[i] += c[i]);
                    n += 1.0;
                }
            }
            let [r, g, b] = sum.map(|v| v / n);
            let i = cy * chroma_stride + cx * 2;
            cbcr[i] = code(128.0 - 0.168_736 * r - 0.331_264 * g + 0.5 * b);
            cbcr[i + 1] = code(128.0 + 0.5 * r - 0.418_688 * g - 0.081_312 * b);
        }
    }
    let chroma = ChromaPlanes::interleaved(&cbcr, chroma_stride);
    match OwnedFrame::yuv420(
        frame.width,
        frame.height,
        luma_stride,
        &luma,
        chroma,
        frame.rotation_cw_deg,
        frame.intrinsics,
        frame.capture_t_ns,
    ) {
        Ok(yuv) => yuv.with_exposure(frame.exposure),
        // The planes were sized for the frame above; a refusal would be a bug here, shown as
        // the frame unchanged rather than a panic.
        Err(_) => frame.clone(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_camera_sees_what_is_in_front_of_the_screen_exposed_to_middle_grey() {
        // North bright, the rest dark. A phone upright (screen facing south, the viewer to its
        // south): its front camera looks south, at the dark; turned about, north, at the bright.
        let mut env = Environment {
            width: 64,
            height: 32,
            texels: vec![[0.1; 3]; 64 * 32],
        };
        for y in 0..32 {
            for x in 0..64 {
                if env.direction(x, y).y > 0.5 {
                    env.texels[y * 64 + x] = [8.0; 3];
                }
            }
        }
        let cam = SyntheticCamera::phone_front();
        // Device upright: y up (world z), screen normal z towards world south (−y).
        let upright = Quat::from_rotation_x(std::f32::consts::FRAC_PI_2);
        assert!((upright * Vec3::Z).distance(-Vec3::Y) < 1e-5);
        let (south, e_south) = cam.capture(&env, upright, Metering::Average, 0);
        let turned = Quat::from_rotation_z(std::f32::consts::PI) * upright;
        let (north, e_north) = cam.capture(&env, turned, Metering::Average, 0);
        // Each is exposed so that its mean sits at middle grey: the dark view longer.
        assert!((e_south / e_north - 80.0).abs() < 8.0, "{e_south} {e_north}");
        assert_eq!((south.width, south.height, south.data.len()), (320, 240, 320 * 240 * 4));
        let centre = |f: &OwnedFrame| f.data[(120 * 320 + 160) * 4];
        assert_eq!(centre(&south), 118);
        assert_eq!(centre(&north), 118);
        // A lamp of 500 in a dim room, straight ahead: metered for the highlights, its peak sits
        // just below clipping; a floor on the exposure is kept; never longer than the average's.
        let mut lamp = env.clone();
        lamp.texels.fill([0.1; 3]);
        for (x, y) in [(15, 15), (16, 15), (15, 16), (16, 16)] {
            lamp.texels[y * 64 + x] = [500.0; 3];
        }
        let (_, e_average) = cam.capture(&lamp, turned, Metering::Average, 0);
        let (short, e_short) = cam.capture(&lamp, turned, Metering::Highlights { min_ratio: 1e-4 }, 0);
        assert!((e_short * 500.0 - 0.9).abs() < 1e-3, "{e_short}");
        let peak = short.data.chunks_exact(4).flat_map(|p| &p[..3]).copied().max();
        assert_eq!(peak, Some(srgb8_from_linear(0.9)));
        let (_, e_floor) = cam.capture(&lamp, turned, Metering::Highlights { min_ratio: 0.5 }, 0);
        assert!((e_floor / e_average - 0.5).abs() < 1e-4);
        let (_, e_dark) = cam.capture(&env, upright, Metering::Highlights { min_ratio: 1e-4 }, 0);
        assert_eq!(e_dark, e_south);
    }

    #[test]
    fn a_yuv_frame_decodes_close_to_its_rgb() {
        let cam = SyntheticCamera::phone_front();
        let env = Environment::studio();
        let (rgb, exposure) = cam.capture(&env, Quat::from_rotation_x(0.3), Metering::Average, 5);
        let yuv = as_yuv420(&rgb);
        assert_eq!(
            (yuv.format, yuv.exposure),
            (PixelFormat::Luma8, Exposure::new(exposure, 100.0))
        );
        assert!(yuv.row_stride.is_multiple_of(64) && yuv.row_stride >= yuv.width as usize);
        let back = yuv.into_colour();
        assert_eq!(back.format, PixelFormat::Rgba8);
        // Luma is exact to rounding; chroma is shared by 2 × 2 pixels, so edges differ more.
        let diffs: Vec<u8> = rgb.data.iter().zip(&back.data).map(|(a, b)| a.abs_diff(*b)).collect();
        let mean = diffs.iter().map(|&d| f64::from(d)).sum::<f64>() / diffs.len() as f64;
        assert!(mean < 1.5, "mean difference {mean:.2} codes");
    }
}
