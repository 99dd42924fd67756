//! Following an eye between iris-network runs by aligning its image patch (no network).
//!
//! The networks are nearly all of a tracked frame's cost (`benchmarks/face.md`: FaceMesh and two
//! irises 10–18 ms here, depending on the machine and its load), yet from one frame to the next at 30 frames/s an eye mostly just moves
//! across the image with the head. So when the iris network has placed an eye, the grey patch
//! around it becomes a
//! template ([`EyePatch::take`]: about 1.6 × 1 eye widths, 24 × 16 samples), and on the next
//! frames the same patch is found again ([`EyePatch::find`]) by Lucas–Kanade alignment in its
//! inverse-compositional form (Baker & Matthews 2004): translation only, on zero-mean,
//! unit-variance samples so that the camera's exposure and white balance may change (gain and
//! bias). The template's gradients and the 2 × 2 Gauss–Newton matrix are computed once; each
//! iteration samples the frame once at 384 points.
//!
//! The result is the iris centre carried by the patch's motion: how far the patch moved, not
//! where the iris is in it — a gaze shift inside the eye is not seen until the network runs
//! again (a few frames later: `NETWORK_EVERY` in the tracker).
//!
//! Noise lowers the correlation (about σ²/(σ² + n²) for a patch of contrast σ and noise n), so
//! in dim light more matches are refused and the networks run more often: slower, never a
//! worse eye.
//!
//! A match is refused (`None`, and the tracker runs the network instead) when the alignment
//! does not settle within [`MAX_ITERATIONS`], when it moves further than the patch's own half
//! height (the linearisation no longer holds), when the template has no texture to align (a
//! flat patch: its standard deviation under 1/255), or when the aligned samples correlate with
//! the template by less than [`MIN_CORRELATION`] (a blink, a hand, another face, a large turn of
//! the head).
//!
//! Coordinates: upright image pixels, centres at half-integers (as `UprightImage::bilinear`).
//!
//! **Threading**: an [`EyePatch`] is plain data (`Send`, `Sync`); the tracker keeps one per eye.
//!
//! **Panics**: none; NaN positions or sizes give `None`.

use glam::Vec2;

use crate::upright::REDUCED_LEVELS;
use crate::{UprightImage, reduced};

/// Template samples across and down the eye.
const COLUMNS: usize = 24;
const ROWS: usize = 16;
/// Patch size in eye widths (corner to corner): the eye with its corners, lids and a little of
/// the brow and cheek, which give the alignment texture in both directions.
const WIDTH_IN_EYES: f32 = 1.6;
const HEIGHT_IN_EYES: f32 = 1.0;
/// Gauss–Newton iterations at most; a match that has not settled by then is refused.
pub const MAX_ITERATIONS: usize = 12;
/// Settled: the last update moved the patch by less than this, in template samples.
const SETTLED_SAMPLES: f32 = 0.01;
/// The lowest correlation (zero-mean, normalised) of an accepted match. Sensor noise and a few
/// per cent of scale between frames leave it above 0.95 (unit tests), the hand-held test's
/// frames (moving, rolling, nearing) at 0.998 or more; a closed eye or a different patch falls
/// under.
pub const MIN_CORRELATION: f32 = 0.9;

/// An eye's grey patch from the frame where the iris network last placed it, centred on the
/// iris.
#[derive(Clone, Debug)]
pub struct EyePatch {
    /// Upright pixels between neighbouring samples.
    step: f32,
    /// Zero-mean, unit-variance samples, row by row.
    values: Vec<f32>,
    /// Their gradients per template sample (not per pixel), and the inverse of the Gauss–Newton
    /// matrix built from them.
    gradients: Vec<Vec2>,
    inverse_hessian: [[f32; 2]; 2],
}

/// The grey level at upright positions sampled `step` pixels apart: from the reduced level where
/// that step is at most two pixels (so the samples do not alias), else the image.
fn grey_sampler<'i>(image: &'i UprightImage, step: f32) -> impl Fn(Vec2) -> f32 + 'i {
    let (level, _) = reduced::level_for(step, REDUCED_LEVELS);
    let reduced = (level > 0).then(|| (image.level(level), 1.0 / (1u32 << level) as f32));
    move |p: Vec2| {
        let c = match reduced {
            Some((r, scale)) => r.bilinear(p * scale),
            None => image.bilinear(p),
        };
        (c[0] + c[1] + c[2]) * (1.0 / 3.0)
    }
}

/// The template grid's offset from its centre, upright pixels, for sample `(i, j)`.
fn grid(i: usize, j: usize, step: f32) -> Vec2 {
    Vec2::new(
        i as f32 - 0.5 * (COLUMNS - 1) as f32,
        j as f32 - 0.5 * (ROWS - 1) as f32,
    ) * step
}

/// Mean and standard deviation of `v`.
fn mean_std(v: &[f32]) -> (f32, f32) {
    let n = v.len() as f32;
    let mean = v.iter().sum::<f32>() / n;
    let var = v.iter().map(|x| (x - mean) * (x - mean)).sum::<f32>() / n;
    (mean, var.max(0.0).sqrt())
}

impl EyePatch {
    /// The patch around the iris at `centre` of an eye `eye_width_px` wide (corner to corner),
    /// or `None` if it has no texture to align or the figures are not finite and positive.
    pub fn take(image: &UprightImage, centre: Vec2, eye_width_px: f32) -> Option<Self> {
        if !(centre.is_finite() && eye_width_px.is_finite() && eye_width_px > 0.0) {
            return None;
        }
        let step = (WIDTH_IN_EYES * eye_width_px / COLUMNS as f32).min(HEIGHT_IN_EYES * eye_width_px / ROWS as f32);
        if step < 0.25 {
            return None;
        }
        let grey = grey_sampler(image, step);
        let mut values = Vec::with_capacity(COLUMNS * ROWS);
        let mut gradients = Vec::with_capacity(COLUMNS * ROWS);
        let (dx, dy) = (Vec2::new(step, 0.0), Vec2::new(0.0, step));
        for j in 0..ROWS {
            for i in 0..COLUMNS {
                let p = centre + grid(i, j, step);
                values.push(grey(p));
                // Central differences one sample apart: the gradient per template sample.
                gradients.push(Vec2::new(grey(p + dx) - grey(p - dx), grey(p + dy) - grey(p - dy)) * 0.5);
            }
        }
        let (mean, std) = mean_std(&values);
        if std.is_nan() || std < 1.0 / 255.0 {
            return None;
        }
        let scale = 1.0 / std;
        values.iter_mut().for_each(|v| *v = (*v - mean) * scale);
        gradients.iter_mut().for_each(|g| *g *= scale);
        let (mut a, mut b, mut c) = (0.0f32, 0.0f32, 0.0f32);
        for g in &gradients {
            a += g.x * g.x;
            b += g.x * g.y;
            c += g.y * g.y;
        }
        let det = a * c - b * b;
        // An edge that is straight along one direction cannot be aligned along it.
        if det.is_nan() || det <= 1e-6 * (a + c) * (a + c) {
            return None;
        }
        Some(Self {
            step,
            values,
            gradients,
            inverse_hessian: [[c / det, -b / det], [-b / det, a / det]],
        })
    }

    /// Where this patch's centre is in `image`, searched from `guess`: the aligned centre and
    /// the correlation there, or `None` when refused (see the module docs).
    pub fn find(&self, image: &UprightImage, guess: Vec2) -> Option<(Vec2, f32)> {
        if !guess.is_finite() {
            return None;
        }
        let grey = grey_sampler(image, self.step);
        let mut at = guess;
        let mut sampled = vec![0.0f32; self.values.len()];
        for _ in 0..MAX_ITERATIONS {
            for j in 0..ROWS {
                for i in 0..COLUMNS {
                    sampled[j * COLUMNS + i] = grey(at + grid(i, j, self.step));
                }
            }
            let (mean, std) = mean_std(&sampled);
            if std.is_nan() || std < 1.0 / 255.0 {
                return None;
            }
            let scale = 1.0 / std;
            let (mut b, mut correlation) = (Vec2::ZERO, 0.0f32);
            for ((s, t), g) in sampled.iter().zip(&self.values).zip(&self.gradients) {
                let s = (s - mean) * scale;
                b += *g * (s - t);
                correlation += s * t;
            }
            correlation /= self.values.len() as f32;
            let h = self.inverse_hessian;
            // Inverse compositional: the template's own step solves for the update, which is
            // then undone on the frame's side (the frame's patch moves the other way).
            let delta = Vec2::new(h[0][0] * b.x + h[0][1] * b.y, h[1][0] * b.x + h[1][1] * b.y);
            at -= delta * self.step;
            if !at.is_finite() || at.distance(guess) > 0.5 * ROWS as f32 * self.step {
                return None;
            }
            if delta.length() < SETTLED_SAMPLES {
                return (correlation >= MIN_CORRELATION).then_some((at, correlation));
            }
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use phantogram_sensing::camera::{CameraFrame, Intrinsics, PixelFormat};

    /// A smooth, textured grey scene (an "eye": a dark disc in a lighter almond, with a few
    /// blobs around), sampled at `(x, y)` after moving it by `shift`, scaling it by `scale`
    /// about (80, 60) and applying `gain` and `bias`.
    fn scene(w: u32, h: u32, shift: Vec2, scale: f32, gain: f32, bias: f32) -> Vec<u8> {
        let mut out = Vec::with_capacity((w * h) as usize);
        for y in 0..h {
            for x in 0..w {
                let p = (Vec2::new(x as f32 + 0.5, y as f32 + 0.5) - shift - Vec2::new(80.0, 60.0)) / scale;
                let almond = (-(p.x * p.x / 600.0 + p.y * p.y / 120.0)).exp();
                let iris = (-(p - Vec2::new(3.0, 0.0)).length_squared() / 40.0).exp();
                let blobs = (0.07 * p.x).sin() * (0.11 * p.y + 0.5).cos();
                let v = 120.0 + 60.0 * almond - 90.0 * iris + 20.0 * blobs;
                out.push((gain * v + bias).clamp(0.0, 255.0).round() as u8);
            }
        }
        out
    }

    fn image(data: &[u8], w: u32, h: u32) -> UprightImage<'_> {
        UprightImage::new(CameraFrame {
            width: w,
            height: h,
            row_stride: w as usize,
            format: PixelFormat::Luma8,
            data,
            rotation_cw_deg: 0,
            intrinsics: Intrinsics::from_horizontal_fov(w, h, 1.0),
            capture_t_ns: 0,
            chroma: None,
        })
        .unwrap()
    }

    const EYE: Vec2 = Vec2::new(80.0, 60.0);

    #[test]
    fn a_moved_eye_is_found_to_a_five_hundredth_of_its_width_through_exposure_changes() {
        let (w, h) = (200, 130);
        let key = scene(w, h, Vec2::ZERO, 1.0, 1.0, 0.0);
        for eye_width in [20.0f32, 36.0, 70.0] {
            let patch = EyePatch::take(&image(&key, w, h), EYE, eye_width).expect("textured");
            for (shift, gain, bias) in [
                (Vec2::new(1.3, -0.7), 1.0, 0.0),
                (Vec2::new(-3.6, 2.2), 1.25, -20.0),
                (Vec2::new(4.5, 0.4), 0.8, 15.0),
            ] {
                let frame = scene(w, h, shift, 1.0, gain, bias);
                // Searched from where the eye was: the alignment itself covers the move.
                let (found, correlation) = patch
                    .find(&image(&frame, w, h), EYE)
                    .unwrap_or_else(|| panic!("eye {eye_width} px, moved {shift}: refused"));
                let error = found.distance(EYE + shift);
                // Measured: 0.003–0.08 px, growing with the sample step (eye width / 16).
                assert!(
                    error < 0.002 * eye_width,
                    "eye {eye_width} px, moved {shift}: off by {error} px"
                );
                assert!(correlation > 0.99, "{correlation}");
            }
        }
    }

    #[test]
    fn sensor_noise_leaves_the_match_accepted_and_placed() {
        let (w, h) = (200, 130);
        let key = scene(w, h, Vec2::ZERO, 1.0, 1.0, 0.0);
        let patch = EyePatch::take(&image(&key, w, h), EYE, 36.0).unwrap();
        // Noise of about 3.5 grey levels (a uniform ±6), as a phone's front camera indoors.
        let mut state = 7u32;
        let frame: Vec<u8> = scene(w, h, Vec2::new(2.4, -1.1), 1.0, 1.0, 0.0)
            .into_iter()
            .map(|v| {
                state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
                let n = (state >> 24) as f32 / 255.0 * 12.0 - 6.0;
                (f32::from(v) + n).clamp(0.0, 255.0).round() as u8
            })
            .collect();
        let (found, correlation) = patch.find(&image(&frame, w, h), EYE).expect("found");
        assert!(found.distance(EYE + Vec2::new(2.4, -1.1)) < 0.01 * 36.0, "{found}");
        assert!(correlation > 0.95, "{correlation}");
    }

    #[test]
    fn a_few_per_cent_of_scale_still_matches_and_places_the_centre() {
        let (w, h) = (200, 130);
        let key = scene(w, h, Vec2::ZERO, 1.0, 1.0, 0.0);
        let patch = EyePatch::take(&image(&key, w, h), EYE, 36.0).unwrap();
        // The face 4 % nearer and moved: the scaling is about the eye, so its centre is exact.
        let frame = scene(w, h, Vec2::new(2.0, 1.0), 1.04, 1.0, 0.0);
        let (found, correlation) = patch.find(&image(&frame, w, h), EYE).expect("found");
        assert!(found.distance(EYE + Vec2::new(2.0, 1.0)) < 0.3, "{found}");
        assert!(correlation > 0.95, "{correlation}");
    }

    #[test]
    fn a_different_patch_a_flat_one_or_nonsense_is_refused() {
        let (w, h) = (200, 130);
        let key = scene(w, h, Vec2::ZERO, 1.0, 1.0, 0.0);
        let patch = EyePatch::take(&image(&key, w, h), EYE, 36.0).unwrap();
        // The eye closed: the iris and almond gone, the blobs left.
        let mut closed = key.clone();
        for (k, v) in closed.iter_mut().enumerate() {
            let p = Vec2::new((k % w as usize) as f32 + 0.5, (k / w as usize) as f32 + 0.5) - EYE;
            if p.x.abs() < 25.0 && p.y.abs() < 10.0 {
                *v = 130;
            }
        }
        assert!(patch.find(&image(&closed, w, h), EYE).is_none());
        // Moved further than the alignment reaches.
        let far = scene(w, h, Vec2::new(30.0, 0.0), 1.0, 1.0, 0.0);
        assert!(patch.find(&image(&far, w, h), EYE).is_none());
        let flat = vec![90u8; (w * h) as usize];
        assert!(patch.find(&image(&flat, w, h), EYE).is_none());
        assert!(EyePatch::take(&image(&flat, w, h), EYE, 36.0).is_none());
        assert!(patch.find(&image(&key, w, h), Vec2::new(f32::NAN, 1.0)).is_none());
        assert!(EyePatch::take(&image(&key, w, h), EYE, f32::NAN).is_none());
        assert!(EyePatch::take(&image(&key, w, h), EYE, 0.0).is_none());
    }
}
