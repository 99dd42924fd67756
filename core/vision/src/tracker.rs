//! [`FaceTracker`]: detect, then track — which networks run on each camera frame, and how the
//! eyes are followed between them by their image patches ([`crate::eye_patch`]).
//!
//! Threading: a tracker is `Send`, one per camera, driven from one thread ([`crate::FaceWorker`]).
//! Panics: none on frames or model output.

use crate::MIN_FACE_CONFIDENCE;
use crate::networks::FaceModels;
use crate::roi::Roi;
use crate::{
    CameraFrame, CameraPose, FaceError, FaceFound, FaceObservation, Mesh, UprightImage, eye_corners, eye_patch,
};
use glam::{Vec2, Vec3};
use std::sync::Arc;

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
}
