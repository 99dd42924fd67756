//! The room map: camera frames, each with the camera's orientation in the world, accumulated into
//! an equirectangular map of radiance in the world frame (the [`Environment`] convention: x east,
//! y north, z up; column 0 east, row 0 the zenith).
//!
//! For each frame ([`RoomCapture::add`]):
//! 1. the 8-bit sRGB pixels are linearised ([`crate::tone`]) and box-filtered down to about the
//!    map's angular resolution, so that a texel averages the pixels it covers instead of picking
//!    one;
//! 2. the frame's exposure normalises them to relative radiance: `radiance = linear / exposure`,
//!    with `exposure` as the platform reports it (exposure time × sensor gain), or, when it does
//!    not, estimated from where the frame overlaps what the map has already seen (the median
//!    ratio over well-exposed texels) — so a camera's auto-exposure does not paint the room in
//!    bands;
//! 3. every map texel the camera sees is blended in with a weight that favours well-exposed
//!    values (Debevec & Malik's hat over the code) — judged by the best exposed of the pixels
//!    the sample draws on, as the brightest carries most of its value, so a lamp beside dark
//!    walls in a short exposure keeps its trust; near-black samples, and any that draw on a
//!    clipped pixel (a lower bound), count a thousandth: kept only where nothing better was
//!    seen — and fades towards the frame's edges (no seams). The weights of a texel are capped at
//!    [`CaptureParams::memory_frames`], so the map follows a room whose light changes.
//!
//! [`RoomCapture::environment`] fills what was never seen ([`crate::fill`]): a small gap from the
//! nearest light seen (pull-push), a large unseen region — a floor never looked at — from the
//! band of elevation seen nearest to it on its side of the horizon, averaged over every azimuth.
//!
//! **Threading**: plain data; `add` runs on the caller's thread (a 256 × 128 map takes well under
//! a millisecond per frame in release builds). **Panics**: none on any input; malformed frames are
//! errors.

use glam::{Quat, Vec3};
use phantogram_assets::ibl::Environment;
use phantogram_sensing::camera::{CameraFrame, CameraPose, PixelFormat};

use crate::fill::fill_unseen;
use crate::tone::linear_from_srgb8;

/// How the room map is kept.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CaptureParams {
    /// Width of the equirectangular map, texels (height is half). 256 (1.4° a texel) is plenty
    /// for the diffuse light and the rough end of the specular levels.
    pub width_px: usize,
    /// How many well-exposed observations of a texel the map remembers: more averages noise
    /// away, fewer follows a changing room sooner.
    pub memory_frames: f32,
}

impl Default for CaptureParams {
    fn default() -> Self {
        Self {
            width_px: 256,
            memory_frames: 8.0,
        }
    }
}

/// One frame for the map: the image as delivered, where its camera looked, and its exposure.
#[derive(Clone, Copy, Debug)]
pub struct CaptureFrame<'a> {
    /// `Rgba8` (sRGB) or `Luma8` (grey light); YUV frames are converted first (`OwnedFrame::into_colour`).
    pub image: CameraFrame<'a>,
    /// World from the camera of the buffer as delivered (x along its rows, y down its columns,
    /// z along the optical axis); see [`world_from_buffer_camera`].
    pub world_from_camera: Quat,
    /// Exposure time × sensor gain (any fixed unit), when the platform reports it.
    pub exposure: Option<f32>,
}

/// World from the delivered buffer's camera frame: the device's orientation, the camera's pose
/// on the device (of the upright image) and the turn that makes the buffer upright.
pub fn world_from_buffer_camera(world_from_device: Quat, pose: &CameraPose, rotation_cw_deg: u32) -> Quat {
    // Turning the image clockwise by 90° takes a buffer ray (a, b, 1) to (−b, a, 1): a turn of
    // +90° about the optical axis.
    let upright_from_buffer = Quat::from_rotation_z((rotation_cw_deg % 360) as f32 * std::f32::consts::PI / 180.0);
    world_from_device * pose.device_from_camera * upright_from_buffer
}

/// What one frame did to the map.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AddReport {
    /// Map texels the frame saw.
    pub texels: usize,
    /// The exposure used: the reported one, or the estimate.
    pub exposure: f32,
    /// Whether `exposure` was estimated from the overlap with the map.
    pub exposure_estimated: bool,
}

#[derive(Debug, thiserror::Error, PartialEq)]
pub enum CaptureError {
    #[error("a {width}×{height} camera frame with {len} bytes and a row stride of {row_stride}: too few")]
    ShortFrame {
        width: u32,
        height: u32,
        len: usize,
        row_stride: usize,
    },
    #[error("a camera frame without pixels ({width}×{height})")]
    Empty { width: u32, height: u32 },
    #[error("camera intrinsics or orientation that are not finite and positive")]
    BadGeometry,
    #[error("an exposure of {0}: must be finite and positive")]
    BadExposure(f32),
}

/// Code values whose pixels are trusted fully: away from black noise and from clipping.
fn exposure_weight(max_code: f32) -> f32 {
    // A smooth hat over [0, 255] (Debevec & Malik's idea): 1 in the middle, 0 at both ends.
    let t = 2.0 * max_code / 255.0 - 1.0;
    (1.0 - t.powi(8)).max(1e-3)
}

/// A frame box-filtered to about the map's resolution, as linear RGB, with the brightest code of
/// each block.
struct Linearised {
    width: usize,
    height: usize,
    /// Buffer pixels per pixel here.
    factor: f32,
    rgb: Vec<[f32; 3]>,
    /// The brightest code of each block's pixels.
    code: Vec<u8>,
}

/// The code at and above which a pixel is taken as clipped.
const CLIPPED_CODE: u8 = 254;

impl Linearised {
    fn new(frame: &CameraFrame<'_>, factor: usize) -> Result<Self, CaptureError> {
        let (w, h) = (frame.width as usize, frame.height as usize);
        if w == 0 || h == 0 {
            return Err(CaptureError::Empty {
                width: frame.width,
                height: frame.height,
            });
        }
        let bpp = frame.format.bytes_per_pixel();
        let short = CaptureError::ShortFrame {
            width: frame.width,
            height: frame.height,
            len: frame.data.len(),
            row_stride: frame.row_stride,
        };
        if frame.row_stride < w * bpp || frame.data.len() < frame.row_stride * (h - 1) + w * bpp {
            return Err(short);
        }
        let factor = factor.clamp(1, w.min(h));
        let (lw, lh) = (w / factor, h / factor);
        let mut rgb = vec![[0.0f32; 3]; lw * lh];
        let mut codes = vec![0u8; lw * lh];
        let norm = 1.0 / (factor * factor) as f32;
        for ly in 0..lh {
            for lx in 0..lw {
                let (mut acc, mut max_code) = ([0.0f32; 3], 0u8);
                for y in ly * factor..(ly + 1) * factor {
                    let row = &frame.data[y * frame.row_stride..];
                    for x in lx * factor..(lx + 1) * factor {
                        let p = &row[x * bpp..x * bpp + bpp];
                        let code = match frame.format {
                            PixelFormat::Rgba8 => [p[0], p[1], p[2]],
                            PixelFormat::Luma8 => [p[0]; 3],
                        };
                        for c in 0..3 {
                            acc[c] += linear_from_srgb8(code[c]);
                        }
                        max_code = max_code.max(code[0]).max(code[1]).max(code[2]);
                    }
                }
                rgb[ly * lw + lx] = acc.map(|v| v * norm);
                codes[ly * lw + lx] = max_code;
            }
        }
        Ok(Self {
            width: lw,
            height: lh,
            factor: factor as f32,
            rgb,
            code: codes,
        })
    }

    /// Bilinear value at buffer pixel coordinates and how far it is trusted (`None` outside): as
    /// far as the best exposed of the blocks it draws on — the brightest carries most of the
    /// value, so a lamp beside dark walls in a short exposure keeps its trust — and hardly at
    /// all when any of them holds a clipped pixel (the value is then a lower bound).
    fn sample(&self, u_px: f32, v_px: f32) -> Option<([f32; 3], f32)> {
        let (u, v) = (u_px / self.factor - 0.5, v_px / self.factor - 0.5);
        if !(u >= 0.0 && v >= 0.0 && u <= (self.width - 1) as f32 && v <= (self.height - 1) as f32) {
            return None;
        }
        let (x0, y0) = (u as usize, v as usize);
        let (x1, y1) = ((x0 + 1).min(self.width - 1), (y0 + 1).min(self.height - 1));
        let (fx, fy) = (u - x0 as f32, v - y0 as f32);
        let mut rgb = [0.0f32; 3];
        let mut brightest = 0u8;
        for (x, y, w) in [
            (x0, y0, (1.0 - fx) * (1.0 - fy)),
            (x1, y0, fx * (1.0 - fy)),
            (x0, y1, (1.0 - fx) * fy),
            (x1, y1, fx * fy),
        ] {
            let i = y * self.width + x;
            for (acc, v) in rgb.iter_mut().zip(self.rgb[i]) {
                *acc += v * w;
            }
            if w > 0.0 {
                brightest = brightest.max(self.code[i]);
            }
        }
        let weight = if brightest >= CLIPPED_CODE {
            1e-3
        } else {
            exposure_weight(f32::from(brightest))
        };
        Some((rgb, weight))
    }
}

/// The room map (see the module docs).
#[derive(Clone, Debug)]
pub struct RoomCapture {
    params: CaptureParams,
    width: usize,
    height: usize,
    /// World direction of each texel's centre.
    directions: Vec<Vec3>,
    /// Solid angle of each row's texels, steradians.
    row_solid_angle: Vec<f32>,
    /// Weighted sums of radiance, and the weights.
    sum: Vec<[f32; 3]>,
    weight: Vec<f32>,
    frames: u64,
}

impl RoomCapture {
    pub fn new(params: CaptureParams) -> Self {
        let width = params.width_px.clamp(8, 4096) & !1;
        let height = width / 2;
        let grid = Environment {
            width,
            height,
            texels: Vec::new(),
        };
        let directions = (0..height)
            .flat_map(|y| (0..width).map(move |x| (x, y)))
            .map(|(x, y)| grid.direction(x, y))
            .collect();
        let (d_phi, d_theta) = (
            std::f32::consts::TAU / width as f32,
            std::f32::consts::PI / height as f32,
        );
        let row_solid_angle = (0..height)
            .map(|y| ((y as f32 + 0.5) * d_theta).sin() * d_theta * d_phi)
            .collect();
        Self {
            params,
            width,
            height,
            directions,
            row_solid_angle,
            sum: vec![[0.0; 3]; width * height],
            weight: vec![0.0; width * height],
            frames: 0,
        }
    }

    /// Frames added so far.
    pub fn frames(&self) -> u64 {
        self.frames
    }

    /// Blends one frame into the map (see the module docs).
    pub fn add(&mut self, frame: &CaptureFrame<'_>) -> Result<AddReport, CaptureError> {
        let k = frame.image.intrinsics;
        let finite = [k.fx_px, k.fy_px, k.cx_px, k.cy_px].iter().all(|v| v.is_finite());
        let q = frame.world_from_camera;
        if !finite || k.fx_px <= 0.0 || k.fy_px <= 0.0 || !q.is_finite() || q.length_squared() < 0.5 {
            return Err(CaptureError::BadGeometry);
        }
        if let Some(e) = frame.exposure
            && !(e.is_finite() && e > 0.0)
        {
            return Err(CaptureError::BadExposure(e));
        }
        // Box-filter to about one map texel per pixel: a texel spans 2π/width radians.
        let texel_rad = std::f32::consts::TAU / self.width as f32;
        let factor = (texel_rad * k.fx_px.min(k.fy_px)).floor().max(1.0) as usize;
        let image = Linearised::new(&frame.image, factor)?;
        let camera_from_world = q.normalize().inverse();
        let (w_px, h_px) = (frame.image.width as f32, frame.image.height as f32);

        // What the camera sees: (texel, linear value, weight).
        let mut seen = Vec::new();
        for (i, d) in self.directions.iter().enumerate() {
            let c = camera_from_world * *d;
            if c.z <= 1e-3 {
                continue;
            }
            let (u, v) = (k.fx_px * c.x / c.z + k.cx_px, k.fy_px * c.y / c.z + k.cy_px);
            let Some((rgb, w)) = image.sample(u, v) else { continue };
            // Fade over the outer tenth of the frame, so that frames blend without seams.
            let edge = (u.min(w_px - u) / w_px).min(v.min(h_px - v) / h_px);
            let fade = (edge / 0.1).clamp(0.0, 1.0);
            seen.push((i, rgb, w * fade.max(1e-3)));
        }

        let (exposure, estimated) = match frame.exposure {
            Some(e) => (e, false),
            None => (self.estimate_exposure(&seen), true),
        };
        let cap = self.params.memory_frames.max(1.0);
        for &(i, rgb, w) in &seen {
            for (sum, v) in self.sum[i].iter_mut().zip(rgb) {
                *sum += w * v / exposure;
            }
            self.weight[i] += w;
            if self.weight[i] > cap {
                let s = cap / self.weight[i];
                self.sum[i] = self.sum[i].map(|v| v * s);
                self.weight[i] = cap;
            }
        }
        self.frames += 1;
        Ok(AddReport {
            texels: seen.len(),
            exposure,
            exposure_estimated: estimated,
        })
    }

    /// The exposure that makes a frame agree with the map where both are well exposed: the
    /// median of `linear / radiance`; 1 where there is no such overlap (the first frame sets the
    /// scale).
    fn estimate_exposure(&self, seen: &[(usize, [f32; 3], f32)]) -> f32 {
        let mut ratios: Vec<f32> = seen
            .iter()
            .filter(|(i, _, w)| *w > 0.5 && self.weight[*i] > 0.5)
            .filter_map(|&(i, rgb, _)| {
                let map = self.sum[i].iter().sum::<f32>() / self.weight[i];
                let frame = rgb.iter().sum::<f32>();
                (map > 1e-6 && frame > 1e-4).then(|| frame / map)
            })
            .collect();
        if ratios.len() < 16 {
            return 1.0;
        }
        let mid = ratios.len() / 2;
        *ratios.select_nth_unstable_by(mid, f32::total_cmp).1
    }

    /// The share of the sphere seen so far (by solid angle), 0 to 1.
    pub fn coverage(&self) -> f32 {
        let seen: f32 = (0..self.height)
            .map(|y| {
                let row = &self.weight[y * self.width..(y + 1) * self.width];
                row.iter().filter(|w| **w > 0.0).count() as f32 * self.row_solid_angle[y]
            })
            .sum();
        seen / (4.0 * std::f32::consts::PI)
    }

    /// The map's width, texels.
    pub fn width(&self) -> usize {
        self.width
    }

    /// The map's height, texels (half its width).
    pub fn height(&self) -> usize {
        self.height
    }

    /// Whether texel `(x, y)` has been seen.
    pub fn seen(&self, x: usize, y: usize) -> bool {
        self.weight.get(y * self.width + x).is_some_and(|w| *w > 0.0)
    }

    /// The map as an environment (relative radiance, world frame), what was never seen filled
    /// (`fill_unseen`: nearby gaps from their surroundings, the floor from the band seen nearest
    /// to it or as lit by the room). All zero before any frame.
    pub fn environment(&self) -> Environment {
        // Each texel's radiance and its weight (solid angle where seen, else 0).
        let (mut rgb, mut weight) = (Vec::with_capacity(self.sum.len()), Vec::with_capacity(self.sum.len()));
        for (i, (s, w)) in self.sum.iter().zip(&self.weight).enumerate() {
            if *w > 0.0 {
                rgb.push(s.map(|v| v / w));
                weight.push(self.row_solid_angle[i / self.width]);
            } else {
                rgb.push([0.0; 3]);
                weight.push(0.0);
            }
        }
        fill_unseen(self.width, self.height, rgb, weight)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fill::UNSEEN_FLOOR_REFLECTANCE;
    use phantogram_sensing::camera::Intrinsics;

    fn grey_frame(width: u32, height: u32, code: u8) -> Vec<u8> {
        vec![code; (width * height * 4) as usize]
    }

    fn frame(data: &[u8], width: u32, height: u32, world_from_camera: Quat, exposure: Option<f32>) -> CaptureFrame<'_> {
        CaptureFrame {
            image: CameraFrame {
                width,
                height,
                row_stride: width as usize * 4,
                format: PixelFormat::Rgba8,
                data,
                rotation_cw_deg: 0,
                intrinsics: Intrinsics::from_horizontal_fov(width, height, 1.2),
                capture_t_ns: 0,
                chroma: None,
            },
            world_from_camera,
            exposure,
        }
    }

    /// A camera looking along world `dir` (its image's up towards the zenith where possible).
    fn looking(dir: Vec3) -> Quat {
        let z = dir.normalize();
        let x = z.cross(Vec3::Z).try_normalize().unwrap_or(Vec3::X);
        let y = z.cross(x);
        Quat::from_mat3(&glam::Mat3::from_cols(x, y, z))
    }

    #[test]
    fn a_frame_lands_where_its_camera_looks() {
        let mut cap = RoomCapture::new(CaptureParams::default());
        let data = grey_frame(64, 48, 118);
        let report = cap
            .add(&frame(&data, 64, 48, looking(Vec3::Y), Some(1.0)))
            .expect("frame");
        assert!(report.texels > 100);
        let env = cap.environment();
        // North (a quarter turn from east, on the horizon) was seen; south only filled in.
        let (north, south) = ((cap.width / 4, cap.height / 2), (3 * cap.width / 4, cap.height / 2));
        assert!(cap.seen(north.0, north.1) && !cap.seen(south.0, south.1));
        let t = env.texels[north.1 * cap.width + north.0];
        assert!((t[0] - 0.18).abs() < 0.005, "{t:?}");
        // The filled-in rest is what was seen (here all of one radiance).
        let filled = env.texels[south.1 * cap.width + south.0];
        assert!((filled[0] - t[0]).abs() < 1e-5, "{filled:?} vs {t:?}");
        // A 69° field of view sees about 10 % of the sphere.
        assert!((0.05..0.15).contains(&cap.coverage()), "{}", cap.coverage());
    }

    #[test]
    fn a_lower_hemisphere_never_seen_is_a_floor_lit_by_the_upper_one() {
        // A grey ceiling seen straight up, then a bright window on the horizon's upper edge.
        let mut cap = RoomCapture::new(CaptureParams::default());
        let ceiling = grey_frame(64, 48, 118); // 0.18 linear
        cap.add(&frame(&ceiling, 64, 48, looking(Vec3::Z), Some(1.0)))
            .expect("ceiling");
        let env = cap.environment();
        let at = |x: usize, y: usize| env.texels[y * cap.width + x][0];
        let (x, nadir, below) = (cap.width / 3, cap.height - 1, cap.height / 2 + 4);
        assert!(!cap.seen(x, nadir) && !cap.seen(x, below));
        // Everything above is 0.18 (seen or filled from the band), so the floor is 0.2 × 0.18.
        let floor = UNSEEN_FLOOR_REFLECTANCE * 0.18;
        for y in [nadir, below] {
            assert!(
                (at(x, y) - floor).abs() < 0.002,
                "row {y}: {} against {floor}",
                at(x, y)
            );
        }
        // A window 35° up (its frame's lower edge 8° above the horizon), brighter than the
        // ceiling: the floor is brighter with its light, and far darker than the window.
        let window = grey_frame(64, 48, 255);
        cap.add(&frame(&window, 64, 48, looking(Vec3::new(1.0, 0.0, 0.7)), Some(1.0)))
            .expect("window");
        assert!((cap.height / 2..cap.height).all(|y| (0..cap.width).all(|x| !cap.seen(x, y))));
        let env = cap.environment();
        let lit = env.texels[nadir * cap.width + x][0];
        assert!(lit > 1.05 * floor && lit < 0.5, "{lit} against {floor}");
        // Once the floor is seen, it is what was seen.
        let dark = grey_frame(64, 48, 30);
        cap.add(&frame(&dark, 64, 48, looking(Vec3::NEG_Z), Some(1.0)))
            .expect("floor");
        let env = cap.environment();
        let seen_floor = env.texels[nadir * cap.width + x][0];
        assert!(
            (seen_floor - crate::tone::linear_from_srgb8(30)).abs() < 0.003,
            "{seen_floor}"
        );
    }

    #[test]
    fn exposure_is_reported_or_estimated_from_the_overlap() {
        let mut cap = RoomCapture::new(CaptureParams::default());
        let bright = grey_frame(64, 48, 118); // 0.18 linear
        cap.add(&frame(&bright, 64, 48, looking(Vec3::Y), Some(2.0)))
            .expect("first");
        // The same wall at a quarter of the exposure, unreported: estimated, and the map agrees.
        let dark = grey_frame(64, 48, srgb(0.045));
        let tilted = looking(Vec3::new(0.3, 1.0, 0.1));
        let r = cap.add(&frame(&dark, 64, 48, tilted, None)).expect("second");
        assert!(r.exposure_estimated);
        assert!((r.exposure - 0.5).abs() < 0.02, "{r:?}");
        let env = cap.environment();
        let t = env.texels[(cap.height / 2) * cap.width + cap.width / 4];
        assert!((t[0] - 0.09).abs() < 0.004, "{t:?}");
    }

    fn srgb(v: f32) -> u8 {
        crate::tone::srgb8_from_linear(v)
    }

    #[test]
    fn clipped_pixels_yield_to_well_exposed_ones_and_the_map_follows_a_changing_room() {
        let mut cap = RoomCapture::new(CaptureParams::default());
        let clipped = grey_frame(64, 48, 255);
        let q = looking(Vec3::Y);
        cap.add(&frame(&clipped, 64, 48, q, Some(1.0))).expect("clipped");
        // The same place at a shorter exposure shows the true radiance (4.0): it wins.
        let good = grey_frame(64, 48, srgb(0.5));
        cap.add(&frame(&good, 64, 48, q, Some(0.125))).expect("good");
        let i = (cap.height / 2) * cap.width + cap.width / 4;
        assert!((cap.environment().texels[i][0] - 4.0).abs() < 0.05);
        // The light changes to half: after a few frames the map shows it.
        let half = grey_frame(64, 48, srgb(0.25));
        for _ in 0..40 {
            cap.add(&frame(&half, 64, 48, q, Some(0.125))).expect("half");
        }
        assert!((cap.environment().texels[i][0] - 2.0).abs() < 0.05);
    }

    #[test]
    fn malformed_frames_are_errors() {
        let mut cap = RoomCapture::new(CaptureParams::default());
        let data = grey_frame(64, 48, 100);
        let mut f = frame(&data[..100], 64, 48, Quat::IDENTITY, None);
        assert!(matches!(cap.add(&f), Err(CaptureError::ShortFrame { .. })));
        f.image.data = &data;
        f.image.intrinsics.fx_px = f32::NAN;
        assert_eq!(cap.add(&f), Err(CaptureError::BadGeometry));
        f.image.intrinsics.fx_px = 50.0;
        f.world_from_camera = Quat::from_xyzw(0.0, 0.0, 0.0, 0.0);
        assert_eq!(cap.add(&f), Err(CaptureError::BadGeometry));
        f.world_from_camera = Quat::IDENTITY;
        f.exposure = Some(-1.0);
        assert_eq!(cap.add(&f), Err(CaptureError::BadExposure(-1.0)));
        f.exposure = None;
        f.image.width = 0;
        assert!(matches!(cap.add(&f), Err(CaptureError::Empty { .. })));
        assert_eq!(cap.frames(), 0);
    }

    #[test]
    fn a_turned_buffer_looks_where_the_upright_image_does() {
        // A front camera, buffer delivered turned (as Android's front cameras are): a pixel's
        // ray through the buffer's intrinsics and `world_from_buffer_camera` is the ray through
        // the upright intrinsics and the upright camera.
        let (w, h) = (64u32, 48u32);
        let k = phantogram_sensing::camera::Intrinsics::new(50.0, 52.0, 30.0, 25.0);
        let pose = CameraPose::front(Vec3::ZERO);
        let world_from_device = Quat::from_rotation_x(0.4) * Quat::from_rotation_z(0.3);
        for turns in 0..4u32 {
            let q = world_from_buffer_camera(world_from_device, &pose, 90 * turns);
            let upright_k = k.turned_cw(w, h, turns);
            let (x, y) = (10.0f32, 40.0f32);
            let ray_buffer = q * Vec3::new((x - k.cx_px) / k.fx_px, (y - k.cy_px) / k.fy_px, 1.0);
            // The same pixel in the upright image (turned clockwise `turns` times).
            let (mut ux, mut uy, mut bw, mut bh) = (x, y, w as f32, h as f32);
            for _ in 0..turns {
                (ux, uy) = (bh - uy, ux);
                (bw, bh) = (bh, bw);
            }
            let _ = bw;
            let ray_upright = world_from_device
                * pose.device_from_camera
                * Vec3::new(
                    (ux - upright_k.cx_px) / upright_k.fx_px,
                    (uy - upright_k.cy_px) / upright_k.fy_px,
                    1.0,
                );
            assert!(
                ray_buffer.normalize().distance(ray_upright.normalize()) < 1e-4,
                "{turns}: {ray_buffer} vs {ray_upright}"
            );
        }
    }
}
