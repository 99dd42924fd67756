//! The three MediaPipe networks (BlazeFace, FaceMesh, Iris) loaded into tract and run on crops
//! of an [`UprightImage`]: loading and optimising them, the crops each network reads, decoding
//! their outputs into image positions, and finding every face of a still image. Stateless: the
//! tracker ([`crate::tracker`]) decides which of them run on a frame.
//!
//! Panics: none on frames or model output (wrong shapes are [`FaceError::Inference`], NaN output
//! is "not found").

use crate::detection::{Detection, decode_detections, merge_detections, roi_from_detection};
use crate::roi::Roi;
use crate::{FACE_FLAG_MIN, MIN_FACE_CONFIDENCE};
use crate::{FaceError, FaceFound, Mesh, UprightImage, eye_corners, glasses, max_pool, prelu, rim, sigmoid};
use glam::Vec2;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use tract_onnx::prelude::*;

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

impl FaceModels {
    /// Every face the detector finds in the whole image (letterboxed into its square input),
    /// best first.
    pub(crate) fn detect(&self, image: &UprightImage) -> Result<Vec<Detection>, FaceError> {
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
    /// `lenses` (glasses seen where the eyes were expected), their tint is undone in the crop and
    /// their dark rims are filled ([`rim`]).
    fn mesh(
        &self,
        image: &UprightImage,
        roi: &Roi,
        lenses: Option<&glasses::Lenses>,
    ) -> Result<Option<(Vec<Vec2>, f32)>, FaceError> {
        let crop = match lenses {
            Some(l) => {
                let rims = l.rims(image, &l.outlines(image));
                roi.tensor_with(image, 192, (0.0, 1.0), false, |p, c| {
                    rim::without_rims(image, &rims, p, c).unwrap_or_else(|| l.untint_at(image, p, c))
                })
            }
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
    /// lens (`lens`: the glasses, which of their lenses, 0 for the image-left one, and the
    /// glasses' dark rims), the crop's tint is undone and the rims filled first.
    fn iris(
        &self,
        image: &UprightImage,
        from: Vec2,
        to: Vec2,
        flip: bool,
        lens: Option<(&glasses::Lenses, usize, &[Option<rim::Rim>; 2])>,
    ) -> Result<Option<(Vec2, f32)>, FaceError> {
        let roi = Roi::around([from, to].into_iter(), from, to, 2.3);
        if roi.size.is_nan() || roi.size <= 1.0 {
            return Ok(None);
        }
        let crop = match lens {
            Some((l, i, rims)) => roi.tensor_with(image, 64, (0.0, 1.0), flip, |p, c| {
                rim::without_rims(image, rims, p, c).unwrap_or_else(|| l.untint_all_at(image, i, p, c))
            }),
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
    /// tint undone and the rims filled under `lenses`; `None` unless both are found.
    fn irises(
        &self,
        image: &UprightImage,
        [la, lb, ra, rb]: [Vec2; 4],
        lenses: Option<(&glasses::Lenses, &[Option<rim::Rim>; 2])>,
    ) -> Result<Option<[(Vec2, f32); 2]>, FaceError> {
        let left = self.iris(image, la, lb, false, lenses.map(|(l, r)| (l, 0, r)))?;
        let right = self.iris(image, ra, rb, true, lenses.map(|(l, r)| (l, 1, r)))?;
        Ok(left.zip(right).map(|(l, r)| [l, r]))
    }

    /// Landmarks + irises for the face in `roi`, whose eyes are expected near `eyes_hint` (image
    /// left, image right: a detection's keypoints, or the last frame's eyes) when known.
    pub(crate) fn face_in(
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

    /// FaceMesh for the face in `roi` (its crop's tint undone and rims filled where glasses are
    /// seen around `eyes_hint`): the landmarks and the face flag, or `None` if not a face.
    pub(crate) fn mesh_in(
        &self,
        image: &UprightImage,
        roi: &Roi,
        eyes_hint: Option<[Vec2; 2]>,
    ) -> Result<Option<Mesh>, FaceError> {
        let hinted = eyes_hint.and_then(|[l, r]| glasses::find_at(image, l, r));
        self.mesh_with(image, roi, hinted)
    }

    /// FaceMesh in `roi`, through `lenses` when glasses were seen: the landmarks and the face
    /// flag, or `None` if not a face.
    fn mesh_with(
        &self,
        image: &UprightImage,
        roi: &Roi,
        lenses: Option<glasses::Lenses>,
    ) -> Result<Option<Mesh>, FaceError> {
        Ok(self.mesh(image, roi, lenses.as_ref())?.map(|(landmarks, flag)| Mesh {
            landmarks,
            flag,
            detector_score: None,
            through_glasses: lenses.is_some(),
        }))
    }

    /// The irises in the crops that `mesh`'s eye corners place in `image` (glasses looked for
    /// there first): the face, or `None` unless both are found.
    pub(crate) fn eyes_in(&self, image: &UprightImage, mesh: Mesh) -> Result<Option<FaceFound>, FaceError> {
        let Some([la, lb, ra, rb]) = eye_corners(&mesh.landmarks) else {
            return Ok(None);
        };
        // Glasses, looked for around the eyes' corners' midpoints (the irises are not known yet).
        let lenses = glasses::find_at(image, (la + lb) * 0.5, (ra + rb) * 0.5);
        // The lenses' outlines: their dark rims for the iris crops, their centres for the fusion.
        let outlines = lenses.as_ref().map(|l| l.outlines(image));
        let rims = match (&lenses, &outlines) {
            (Some(l), Some(o)) => l.rims(image, o),
            _ => [None, None],
        };
        let Some([(left_eye_px, dl), (right_eye_px, dr)]) =
            self.irises(image, [la, lb, ra, rb], lenses.as_ref().map(|l| (l, &rims)))?
        else {
            return Ok(None);
        };
        // With glasses on, each lens is a second, independent fix of its eye.
        let [left_eye_px, right_eye_px] = match outlines {
            Some(o) => glasses::with_lens_centres([left_eye_px, right_eye_px], o.map(|o| o.map(|o| o.centre))),
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
    /// ([`Mesh::confidence`]). Glasses are looked for at the detector's eyes and, where they are
    /// not seen there, anywhere in its box ([`glasses::find_in_box`]): tinted eyes can turn all of
    /// the detector's keypoints, and then its eyes miss the lenses. Glasses found that way also
    /// turn FaceMesh's crop: the lenses' line is the face's, the keypoints' was not.
    pub(crate) fn mesh_from_detection(&self, image: &UprightImage, d: &Detection) -> Result<Option<Mesh>, FaceError> {
        let [a, b] = [d.keypoints[0], d.keypoints[1]];
        let [l, r] = if a.x <= b.x { [a, b] } else { [b, a] };
        let mut roi = roi_from_detection(d);
        let lenses = match glasses::find_at(image, l, r) {
            Some(lenses) => Some(lenses),
            None => glasses::find_in_box(image, d.min, d.max).inspect(|lenses| {
                let [l, r] = lenses.eyes_px();
                roi.angle = (r.y - l.y).atan2(r.x - l.x);
            }),
        };
        Ok(self.mesh_with(image, &roi, lenses)?.map(|m| Mesh {
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

#[cfg(test)]
mod tests {
    use super::*;

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
}
