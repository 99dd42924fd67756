//! Finding anaglyph glasses on a found face: which coloured filter covers which eye.
//!
//! A filter multiplies the light through it by its transmission, per colour channel; the skin
//! under a lens therefore looks like the skin beside it times the lens's transmission. So for
//! each eye the median linear colour of skin that a lens covers (below the eye and beside its
//! outer corner, in units of the eye distance, where any anaglyph lens reaches) is divided by the
//! median of the same side's cheek (below any lens), which cancels the skin's own colour and the
//! light's. What is left is the lens's transmission `T`, up to brightness: its log-chromaticity
//! `c = ln T − mean(ln T)` points towards the filter's colour and its length says how strongly it
//! tints (about 0 with no lens or clear glass; ≈ 2.5 for a saturated red or cyan lens; 0.44–0.6
//! for one that passes half of what it should stop). Glasses are reported when both eyes'
//! shifts are strong ([`MIN_STRENGTH`]) and point at the two filters of one kind of glasses.
//!
//! Needs colour (an RGBA frame, or luma with its chroma planes); a grey frame gives no answer.
//! Reads a few hundred pixels; no allocation beyond that, no panics.

use glam::{Vec2, Vec3};
use phantogram_geometry::srgb::{code_to_linear as linear, from_linear as linear_to_srgb, to_linear as srgb_to_linear};
pub use phantogram_sensing::glasses::{Filter, GlassesSeen};

use crate::{FaceFound, UprightImage};

/// The weakest colour shift (natural-log units, both eyes) taken for a lens: a lens that passes
/// half of the light it is meant to stop shifts by 0.44 (cyan) to 0.6 (red); bare faces on the
/// shared photographs shift by far less (printed by the glasses test).
pub const MIN_STRENGTH: f32 = 0.35;

/// How closely (cosine) an eye's shift must point at its filter's colour.
const MIN_COSINE: f32 = 0.8;

/// A filter's typical transmission (linear RGB): what its colour shift points at.
fn transmission(filter: Filter) -> [f32; 3] {
    match filter {
        Filter::Red => [0.9, 0.08, 0.08],
        Filter::Cyan => [0.08, 0.8, 0.9],
        Filter::Green => [0.08, 0.85, 0.1],
        Filter::Magenta => [0.85, 0.08, 0.85],
        Filter::Amber => [0.9, 0.6, 0.05],
        Filter::Blue => [0.05, 0.15, 0.9],
    }
}

/// `ln v − mean(ln v)`: colour without brightness.
fn log_chroma(v: [f32; 3]) -> Vec3 {
    let l = Vec3::from(v.map(|x| x.max(1e-4).ln()));
    l - Vec3::splat(l.element_sum() / 3.0)
}

fn cosine(a: Vec3, b: Vec3) -> f32 {
    a.dot(b) / (a.length() * b.length()).max(1e-6)
}

/// Median per channel of the linear colours at `points` (`None` when fewer than half are in the
/// image).
fn median_colour(image: &UprightImage, points: &[Vec2]) -> Option<[f32; 3]> {
    let mut channels: [Vec<f32>; 3] = Default::default();
    for p in points {
        if let Some(rgb) = image.colour_at(*p) {
            for k in 0..3 {
                channels[k].push(linear(rgb[k]));
            }
        }
    }
    if channels[0].len() * 2 < points.len() || channels[0].is_empty() {
        return None;
    }
    Some(channels.map(|mut c| {
        c.sort_by(f32::total_cmp);
        c[c.len() / 2]
    }))
}

/// What one eye's lens (if any) does to the skin under it: the median linear colour there over
/// the same side's cheek, per channel (≈ (1, 1, 1) × a brightness for no lens; the lens's
/// transmission for a lens). From the eye at `eye` with the face's unit axes `across` (towards
/// the outer corner of this eye) and `down`, `ipd` pixels.
fn eye_transmission(
    image: &UprightImage,
    eye: Vec2,
    across: Vec2,
    down: Vec2,
    ipd: f32,
) -> Option<([f32; 3], [f32; 3])> {
    let at = |a: f32, b: f32| eye + (across * a + down * b) * ipd;
    let grid = |a0: f32, a1: f32, b0: f32, b1: f32, n: usize| {
        let mut v = Vec::with_capacity(n * n);
        for i in 0..n {
            for j in 0..n {
                let (s, t) = (i as f32 / (n - 1) as f32, j as f32 / (n - 1) as f32);
                v.push(at(a0 + (a1 - a0) * s, b0 + (b1 - b0) * t));
            }
        }
        v
    };
    // Under the lens: below the lower lid, and beside the outer corner.
    let mut lens = grid(-0.14, 0.14, 0.09, 0.14, 6);
    lens.extend(grid(0.25, 0.30, -0.05, 0.05, 4));
    // The cheek below any lens, on the same side.
    let cheek = grid(-0.1, 0.1, 0.45, 0.55, 5);
    let (l, c) = (median_colour(image, &lens)?, median_colour(image, &cheek)?);
    // Too dark to tell colours apart (8-bit noise): no answer.
    if c.iter().all(|v| *v < 0.01) {
        return None;
    }
    Some(([0, 1, 2].map(|k| l[k].max(1e-4) / c[k].max(1e-4)), c))
}

/// The filter whose colour an eye's shift points at, and how closely.
fn nearest_filter(shift: Vec3) -> (Filter, f32) {
    Filter::ALL
        .into_iter()
        .map(|f| (f, cosine(shift, log_chroma(transmission(f)))))
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .unwrap_or((Filter::Red, 0.0))
}

/// What each eye's lens (if any) does (image-left eye at `left`, image-right at `right`; see
/// [`eye_transmission`]), and each side's cheek colour (linear), where colour allows.
fn transmissions_and_cheeks(image: &UprightImage, left: Vec2, right: Vec2) -> Option<[([f32; 3], [f32; 3]); 2]> {
    if !image.has_colour() {
        return None;
    }
    let ipd = left.distance(right);
    if !(ipd.is_finite() && ipd > 4.0) {
        return None;
    }
    let across = (right - left) / ipd;
    // Image y is down; the face's "down" is the eye line turned a quarter clockwise.
    let down = Vec2::new(-across.y, across.x);
    Some([
        eye_transmission(image, left, -across, down, ipd)?,
        eye_transmission(image, right, across, down, ipd)?,
    ])
}

/// What each eye's lens (if any) does to the skin under it (image-left eye at `left`,
/// image-right at `right`): linear RGB relative to the same side's cheek.
pub fn transmissions(image: &UprightImage, left: Vec2, right: Vec2) -> Option<[[f32; 3]; 2]> {
    transmissions_and_cheeks(image, left, right).map(|t| t.map(|(t, _)| t))
}

/// The colour shift (log-chromaticity of the transmission) of each eye of `face`.
pub fn eye_shifts(image: &UprightImage, face: &FaceFound) -> Option<[Vec3; 2]> {
    transmissions(image, face.left_eye_px, face.right_eye_px).map(|t| t.map(log_chroma))
}

/// The lens pair on a face, as seen in the image.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lenses {
    /// The filters over the image-left and the image-right eye.
    pub image_left: Filter,
    pub image_right: Filter,
    /// The weaker eye's colour shift, natural-log units.
    pub strength: f32,
    /// Each eye's measured transmission (image left, image right; linear RGB, relative to the
    /// cheek): what undoes the tint.
    pub transmission: [[f32; 3]; 2],
    /// Where they were measured: the eyes (image left, image right, pixels) and each side's
    /// cheek colour (linear).
    eyes_px: [Vec2; 2],
    cheek: [[f32; 3]; 2],
}

/// The glasses on the face whose eyes are at `left` and `right` (image left and right); `None`
/// without colour, without glasses, or when the two lenses are not the two filters of one kind
/// of glasses.
pub fn find_at(image: &UprightImage, left: Vec2, right: Vec2) -> Option<Lenses> {
    let measured = transmissions_and_cheeks(image, left, right)?;
    let transmission = measured.map(|(t, _)| t);
    let [a, b] = transmission.map(log_chroma);
    let strength = a.length().min(b.length());
    if strength < MIN_STRENGTH {
        return None;
    }
    let ((fa, ca), (fb, cb)) = (nearest_filter(a), nearest_filter(b));
    (fb == fa.partner() && ca >= MIN_COSINE && cb >= MIN_COSINE).then_some(Lenses {
        image_left: fa,
        image_right: fb,
        strength,
        transmission,
        eyes_px: [left, right],
        cheek: measured.map(|(_, c)| c),
    })
}

/// [`find_at`] for a found face.
pub fn find(image: &UprightImage, face: &FaceFound) -> Option<Lenses> {
    find_at(image, face.left_eye_px, face.right_eye_px)
}

impl Lenses {
    /// The glasses for the viewer's eyes: `image_left_is_viewers_left` says which image eye is the
    /// viewer's left (the tracker knows from the camera's pose).
    pub fn seen(&self, image_left_is_viewers_left: bool) -> GlassesSeen {
        let (left, right) = if image_left_is_viewers_left {
            (self.image_left, self.image_right)
        } else {
            (self.image_right, self.image_left)
        };
        GlassesSeen {
            left,
            right,
            strength: self.strength,
        }
    }
}

impl Lenses {
    /// `rgb` (sRGB-coded, [0, 1]) at image position `p` with a lens's tint undone when `p` is
    /// under a lens: near an eye (within 0.45 × 0.35 eye distances), and coloured as that lens
    /// colours skin (its colour relative to the cheek shifted the lens's way, at least half as
    /// far) — so the rim, the eye's own white and what lies beyond the lens stay as they are.
    pub fn untint_at(&self, p: Vec2, rgb: [f32; 3]) -> [f32; 3] {
        let [l, r] = self.eyes_px;
        let ipd = l.distance(r);
        if ipd.is_nan() || ipd <= 0.0 {
            return rgb;
        }
        let across = (r - l) / ipd;
        for i in 0..2 {
            let d = p - self.eyes_px[i];
            let (a, b) = (d.dot(across) / (0.45 * ipd), d.perp_dot(across) / (0.35 * ipd));
            if a * a + b * b > 1.0 {
                continue;
            }
            let lin = rgb.map(srgb_to_linear);
            let shift = log_chroma(self.transmission[i]);
            let here = log_chroma([0, 1, 2].map(|k| lin[k].max(1e-4) / self.cheek[i][k].max(1e-4)));
            if cosine(here, shift) >= 0.7 && here.length() >= 0.5 * shift.length() {
                return untint_colour(rgb, self.transmission[i]);
            }
            return rgb;
        }
        rgb
    }
}

/// One sRGB-coded colour ([0, 1]) seen through a lens of `transmission`, as it would be without:
/// each channel in linear light multiplied up to the lens's most transparent channel (gains
/// capped at 8, so a channel the lens all but stopped is not noise amplified without bound).
pub fn untint_colour(rgb: [f32; 3], transmission: [f32; 3]) -> [f32; 3] {
    const MAX_GAIN: f32 = 8.0;
    let top = transmission.iter().copied().fold(0.0f32, f32::max).max(1e-4);
    [0, 1, 2].map(|k| {
        let gain = (top / transmission[k].max(1e-4)).min(MAX_GAIN);
        linear_to_srgb(srgb_to_linear(rgb[k]) * gain)
    })
}

/// Undoes a lens's tint in a network's input crop (`n × n`, NCHW, values in [0, 1] sRGB-coded;
/// all of it under the lens), pixel by pixel as [`untint_colour`].
pub fn untint(tensor: &mut [f32], n: usize, transmission: [f32; 3]) {
    let (r, rest) = tensor.split_at_mut(n * n);
    let (g, b) = rest.split_at_mut(n * n);
    for ((r, g), b) in r.iter_mut().zip(g.iter_mut()).zip(b.iter_mut().take(n * n)) {
        [*r, *g, *b] = untint_colour([*r, *g, *b], transmission);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_filter_is_nearest_to_itself_and_partners_pair_up() {
        for f in Filter::ALL {
            let (g, c) = nearest_filter(log_chroma(transmission(f)));
            assert_eq!((g, c > 0.999), (f, true), "{f:?}");
            assert_eq!(f.partner().partner(), f);
            assert_ne!(f.is_left_by_convention(), f.partner().is_left_by_convention());
            // Half-transparent lenses still point at their filter, over the strength threshold.
            let half = transmission(f).map(|t| 0.5 + 0.5 * t);
            let (g, c) = nearest_filter(log_chroma(half));
            assert_eq!(g, f, "{f:?} at half strength");
            assert!(
                c >= MIN_COSINE && log_chroma(half).length() > MIN_STRENGTH,
                "{f:?}: {c}"
            );
        }
        // Grey has no colour shift.
        assert!(log_chroma([0.3, 0.3, 0.3]).length() < 1e-6);
    }
}
