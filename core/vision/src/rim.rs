//! A dark rim around an anaglyph lens (a plastic frame, a black cardboard edge), and its removal
//! from the crops the networks read.
//!
//! A thin dark line just outside each lens lies inside both FaceMesh's crop and the iris crops
//! (a lens 0.6–0.8 eye distances wide puts its rim 0.18–0.4 eye distances from the eye, the iris
//! crop reaches 0.52): the networks take it for a lid or a brow and move the eye, mostly up or
//! down. On the glasses test's thin dark rims without a reflection the eyes moved by 8.0 % of
//! the eye distance at the 90th percentile, against 2.2 % for rimless lenses; on the hand-held
//! test's faces (eyes 90 px apart, thin dark rims) by 3.3 %. So where a lens has one, the crops
//! read the cheek's colour instead of the rim's pixels: 5.7 % and 1.0 % then
//! (`benchmarks/face.md`, 2026-12-04, third session). On small faces a rim a pixel or less wide
//! is mostly blended into the skin and is not found.
//!
//! How a rim is found ([`Rim::around`]): from the lens outline's centre ([`LensOutline`]: the hull
//! of the cells seen through the lens), 64 rays cross the outline; along each, the first rim pixel
//! (darker than a third of the cheek's luminance) must come within 4 % of the eye distance beyond
//! the outline (the hull of cell centres lies up to a cell inside the real edge), and the dark run
//! must end within 12 %. With such a run on half the rays the lens has a rim, reaching the
//! median run's end (three rays in five at first; the start, end and share swept afterwards:
//! only the share mattered, and half was at least as good as three in five on every set of the
//! glasses test, `benchmarks/face.md`, fifth session). A brow or the dark background beside a
//! rimless lens crosses fewer rays; a
//! light (white cardboard) rim is not dark and is left alone (it did not move the eyes: 3.0 % at
//! the 90th percentile).
//!
//! Pure functions of the image; no panics (rays that leave the image are not counted).

use crate::UprightImage;
use crate::glasses::{LensOutline, Lenses};
use glam::Vec2;
use phantogram_geometry::srgb::{code_to_linear, from_linear_fast, luminance, to_linear_fast};

/// Rays from the outline's centre.
const RAYS: usize = 64;
/// Angular bins of the outline's radius, for a quick lookup per crop pixel.
const BINS: usize = 256;
/// A rim pixel is darker than this share of the cheek's luminance (linear light).
const DARK_SHARE: f32 = 1.0 / 3.0;
/// The dark run starts within this far beyond the outline, and ends within this far (shares of
/// the eye distance).
const START_WITHIN_IPD: f32 = 0.04;
const END_WITHIN_IPD: f32 = 0.12;
/// Share of the rays that must cross a dark run for the lens to have a rim: a majority.
const MIN_RAY_SHARE: f32 = 0.5;

/// A dark rim found around one lens.
#[derive(Clone, Debug, PartialEq)]
pub struct Rim {
    centre: Vec2,
    /// The outline's distance from `centre` by direction (`BINS` bins from the image's +x towards
    /// +y), pixels, and its least and greatest.
    radius_px: Vec<f32>,
    radius_range_px: (f32, f32),
    /// How far beyond the outline the rim reaches, pixels.
    pub reach_px: f32,
    dark_luminance: f32,
    /// The cheek's colour (sRGB-coded, [0, 1]) and its luminance coded as grey, for colour and
    /// grey (luma) crops.
    fill: [f32; 3],
    fill_grey: f32,
}

impl Rim {
    /// The dark rim around lens `i` (0: image left) of `lenses`, whose outline is `outline`;
    /// `None` without one.
    pub fn around(image: &UprightImage, lenses: &Lenses, i: usize, outline: &LensOutline) -> Option<Self> {
        let ipd_px = lenses.eye_distance_px();
        let cheek = lenses.cheek(i)?;
        if outline.hull_px.len() < 3 || !(ipd_px.is_finite() && ipd_px > 4.0) || !cheek.iter().all(|c| c.is_finite()) {
            return None;
        }
        let dark = DARK_SHARE * luminance(cheek);
        let is_rim = |rgb: [u8; 3]| luminance(rgb.map(code_to_linear)) < dark;
        let centre = outline.centre;
        let radius_px: Vec<f32> = (0..BINS)
            .map(|b| hull_radius(&outline.hull_px, centre, direction(b as f32 / BINS as f32)))
            .collect::<Option<_>>()?;
        let mut ends = Vec::with_capacity(RAYS);
        for k in 0..RAYS {
            let d = direction(k as f32 / RAYS as f32);
            let r = radius_px[k * BINS / RAYS];
            let mut t = r - 1.0;
            let mut start = None;
            while t < r + END_WITHIN_IPD * ipd_px {
                let Some(rgb) = image.colour_at(centre + d * t) else {
                    break;
                };
                match (is_rim(rgb), start) {
                    (true, None) if t > r + START_WITHIN_IPD * ipd_px => break,
                    (true, None) => start = Some(t),
                    (false, Some(_)) => {
                        ends.push(t - r);
                        break;
                    }
                    _ => {}
                }
                t += 0.5;
            }
        }
        if (ends.len() as f32) < MIN_RAY_SHARE * RAYS as f32 {
            return None;
        }
        ends.sort_by(f32::total_cmp);
        let fill = cheek.map(from_linear_fast);
        let range = radius_px
            .iter()
            .fold((f32::INFINITY, 0.0f32), |(lo, hi), &r| (lo.min(r), hi.max(r)));
        Some(Self {
            centre,
            radius_px,
            radius_range_px: range,
            reach_px: ends[ends.len() / 2] + 1.0,
            dark_luminance: dark,
            fill,
            fill_grey: from_linear_fast(luminance(cheek)),
        })
    }

    /// `sample` (sRGB-coded, [0, 1]; `grey`: read from luma) at image position `p`, as the
    /// cheek's colour where it is this rim: dark, and between the outline and the rim's reach.
    /// `None` elsewhere. A lens darker than the rim's threshold (a blue one over skin) has the
    /// sliver between its outline and its edge filled too, with about what undoing its tint would
    /// give there.
    pub fn filled(&self, p: Vec2, sample: [f32; 3], grey: bool) -> Option<[f32; 3]> {
        let v = p - self.centre;
        let len = v.length();
        let (lo, hi) = self.radius_range_px;
        if !(len > lo - 1.0 && len <= hi + self.reach_px) {
            return None;
        }
        if luminance(sample.map(to_linear_fast)) >= self.dark_luminance {
            return None;
        }
        let turn = v.y.atan2(v.x) / std::f32::consts::TAU;
        let bin = ((turn.rem_euclid(1.0) * BINS as f32) as usize).min(BINS - 1);
        let beyond = len - self.radius_px[bin];
        (beyond > -1.0 && beyond <= self.reach_px).then_some(if grey { [self.fill_grey; 3] } else { self.fill })
    }
}

/// `sample` at `p` of `image` as either lens's rim filled ([`Rim::filled`]); `None` where it is
/// neither rim.
pub fn without_rims(image: &UprightImage, rims: &[Option<Rim>; 2], p: Vec2, sample: [f32; 3]) -> Option<[f32; 3]> {
    let grey = image.samples_grey();
    rims.iter().flatten().find_map(|r| r.filled(p, sample, grey))
}

/// The unit direction a `turn` (fraction of a full turn) from the image's +x towards +y.
fn direction(turn: f32) -> Vec2 {
    let (s, c) = (turn * std::f32::consts::TAU).sin_cos();
    Vec2::new(c, s)
}

/// How far from `centre` (inside it) the convex polygon `hull` lies along the unit direction `d`.
fn hull_radius(hull: &[Vec2], centre: Vec2, d: Vec2) -> Option<f32> {
    let n = hull.len();
    (0..n)
        .filter_map(|k| {
            let (a, e) = (hull[k], hull[(k + 1) % n] - hull[k]);
            let den = d.perp_dot(e);
            if den.abs() < 1e-9 {
                return None;
            }
            let (t, s) = ((a - centre).perp_dot(e) / den, (a - centre).perp_dot(d) / den);
            (t > 0.0 && (-1e-4..=1.0 + 1e-4).contains(&s)).then_some(t)
        })
        .min_by(f32::total_cmp)
}
