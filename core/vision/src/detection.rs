//! BlazeFace's output: its anchors, decoding the raw regressors and scores into face boxes and
//! keypoints, MediaPipe's weighted non-maximum suppression, and FaceMesh's crop from a detection.

use crate::roi::Roi;
use crate::sigmoid;
use glam::Vec2;

/// One face-detector hit: box and the six keypoints, pixels.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Detection {
    pub(crate) min: Vec2,
    pub(crate) max: Vec2,
    /// Eyes (image left, image right), nose tip, mouth, ears.
    pub(crate) keypoints: [Vec2; 6],
    pub(crate) score: f32,
}

const DETECTOR_MIN_SCORE: f32 = 0.5;
const DETECTOR_NMS_IOU: f32 = 0.3;
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
pub(crate) fn decode_detections(regressors: &[f32], scores: &[f32], roi: &Roi) -> Vec<Detection> {
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
pub(crate) fn merge_detections(mut hits: Vec<Detection>) -> Vec<Detection> {
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

/// MediaPipe's face-landmark crop from a detection: the box's longer side × 1.5, turned so the
/// eyes are level.
pub(crate) fn roi_from_detection(d: &Detection) -> Roi {
    let extent = d.max - d.min;
    let (l, r) = (d.keypoints[0], d.keypoints[1]);
    let (from, to) = if l.x <= r.x { (l, r) } else { (r, l) };
    Roi {
        centre: (d.min + d.max) * 0.5,
        size: extent.x.max(extent.y) * 1.5,
        angle: (to.y - from.y).atan2(to.x - from.x),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
}
