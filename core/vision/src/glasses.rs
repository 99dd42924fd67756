//! Finding anaglyph glasses on a found face: which coloured filter covers which eye.
//!
//! A filter multiplies the light through it by its transmission, per colour channel; the skin
//! under a lens therefore looks like the skin beside it times the lens's transmission. So for
//! each eye the median linear colour of skin that a lens covers (below and above the eye and
//! beside both its corners, within a quarter of the eye distance, where any anaglyph lens reaches
//! even when it sits off the eye) is divided by the
//! median of the same side's cheek (below any lens), which cancels the skin's own colour and the
//! light's. What is left is the lens's transmission `T`, up to brightness: its log-chromaticity
//! `c = ln T − mean(ln T)` points towards the filter's colour and its length says how strongly it
//! tints (about 0 with no lens or clear glass; ≈ 2.5 for a saturated red or cyan lens; 0.44–0.6
//! for one that passes half of what it should stop). Glasses are reported when both eyes'
//! shifts are strong ([`MIN_STRENGTH`]) and point at the two filters of one kind of glasses
//! (named as a pair, so that a clearly named lens settles a partner that lies between two filters).
//!
//! Where a face's eye estimate is too far off for that (the detector's keypoints on tinted eyes
//! can all be turned together), [`find_in_box`] looks for the lens pair by colour in the
//! detector's box and hands its centres to the same test.
//!
//! Each lens is then also a fiducial: [`Lenses::centres`] finds the middle of the pixels its
//! tint colours, and [`with_lens_centres`] fuses it with the iris network's eye, weighted by how
//! sure each is (the lens counts for more on small or blurred faces).
//!
//! Needs colour (an RGBA frame, or luma with its chroma planes); a grey frame gives no answer.
//! Naming the filters reads a few hundred pixels; finding the lens centres 2 × 3000 (about a
//! third of a millisecond here; per-pixel logarithms and sRGB curves come from tables). No
//! panics.

use glam::{Vec2, Vec3};
use phantogram_geometry::srgb::{code_to_linear as linear, from_linear_fast, to_linear_fast};
pub use phantogram_sensing::glasses::{Filter, GlassesSeen};
use std::sync::LazyLock;

use crate::rim::Rim;
use crate::{FaceFound, UprightImage};

mod search;
pub use search::find_in_box;

/// The weakest colour shift (natural-log units, both eyes) taken for a lens: a lens that passes
/// half of the light it is meant to stop shifts by 0.44 (cyan) to 0.6 (red); bare faces on the
/// shared photographs shift by far less (printed by the glasses test).
pub const MIN_STRENGTH: f32 = 0.35;

/// How closely (cosine) an eye's shift must point at its filter's colour.
const MIN_COSINE: f32 = 0.8;

/// A filter's typical transmission (linear RGB): what its colour shift points at.
pub(crate) fn transmission(filter: Filter) -> [f32; 3] {
    match filter {
        Filter::Red => [0.9, 0.08, 0.08],
        Filter::Cyan => [0.08, 0.8, 0.9],
        Filter::Green => [0.08, 0.85, 0.1],
        Filter::Magenta => [0.85, 0.08, 0.85],
        Filter::Amber => [0.9, 0.6, 0.05],
        Filter::Blue => [0.05, 0.15, 0.9],
    }
}

/// The natural log of an 8-bit sRGB code's linear value, floored at 10⁻⁴ as [`log_chroma`]
/// floors (from a table of all 256).
fn ln_linear(code: u8) -> f32 {
    static TABLE: LazyLock<[f32; 256]> = LazyLock::new(|| std::array::from_fn(|i| linear(i as u8).max(1e-4).ln()));
    TABLE[code as usize]
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
    // Under the lens: below the lower lid, above the upper one, and beside both corners.
    let mut lens = grid(-0.14, 0.14, 0.09, 0.13, 6);
    lens.extend(grid(-0.14, 0.14, -0.13, -0.09, 6));
    lens.extend(grid(0.2, 0.24, -0.04, 0.04, 4));
    lens.extend(grid(-0.24, -0.2, -0.04, 0.04, 4));
    // The cheek below any lens, on the same side.
    let cheek = grid(-0.1, 0.1, 0.45, 0.55, 5);
    let (l, c) = (median_colour(image, &lens)?, median_colour(image, &cheek)?);
    // Too dark to tell colours apart (8-bit noise): no answer.
    if c.iter().all(|v| *v < 0.01) {
        return None;
    }
    Some(([0, 1, 2].map(|k| l[k].max(1e-4) / c[k].max(1e-4)), c))
}

/// How closely (cosine) a colour shift points at `filter`'s colour.
fn filter_cosine(shift: Vec3, filter: Filter) -> f32 {
    cosine(shift, log_chroma(transmission(filter)))
}

/// The filter whose colour an eye's shift points at, and how closely.
fn nearest_filter(shift: Vec3) -> (Filter, f32) {
    Filter::ALL
        .into_iter()
        .map(|f| (f, filter_cosine(shift, f)))
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .unwrap_or((Filter::Red, 0.0))
}

/// The kind of glasses (and which way round) that a pair of eye shifts points at: the filter
/// pair whose weaker cosine, each eye against its filter, is the highest, and that cosine.
///
/// Named as a pair, not eye by eye: a lens's measured shift can lie between two filters (a
/// magenta lens over lids less blue than the cheek it is measured against reads nearer red than
/// magenta), and then the other lens, named clearly, says which of the two it is. The cosine
/// each eye must reach ([`MIN_COSINE`]) is the same either way.
fn nearest_pair(a: Vec3, b: Vec3) -> (Filter, Filter, f32) {
    Filter::ALL
        .into_iter()
        .map(|f| {
            let p = f.partner();
            (f, p, filter_cosine(a, f).min(filter_cosine(b, p)))
        })
        .max_by(|x, y| x.2.total_cmp(&y.2))
        .unwrap_or((Filter::Red, Filter::Cyan, 0.0))
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
    /// Where they were measured: the eyes (image left, image right, pixels); each side's
    /// cheek colour (natural log of linear RGB) and each lens's colour shift
    /// ([`log_chroma`] of its transmission), kept for the per-pixel tests.
    eyes_px: [Vec2; 2],
    ln_cheek: [Vec3; 2],
    shift: [Vec3; 2],
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
    let (fa, fb, cosine) = nearest_pair(a, b);
    (cosine >= MIN_COSINE).then_some(Lenses {
        image_left: fa,
        image_right: fb,
        strength,
        transmission,
        eyes_px: [left, right],
        ln_cheek: measured.map(|(_, c)| Vec3::from(c.map(|v| v.max(1e-4).ln()))),
        shift: [a, b],
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
    /// Whether the colour `rgb` (8-bit sRGB codes) near eye `i` (0: image left) is seen through
    /// that eye's lens: in linear light, its colour relative to that side's cheek is shifted the
    /// lens's way (cosine 0.7 or more) and at least half as far as the lens shifts skin. So a rim
    /// and what lies beyond the lens are not taken for it.
    ///
    /// Codes, so that the logarithms come from a table: it runs on every pixel of the crops' eye
    /// regions. Cosine and lengths compared squared (no roots).
    fn through_lens(&self, i: usize, rgb: [u8; 3]) -> bool {
        let l = Vec3::from(rgb.map(ln_linear)) - self.ln_cheek[i];
        let here = l - Vec3::splat(l.element_sum() / 3.0);
        let shift = self.shift[i];
        let (dot, here2, shift2) = (here.dot(shift), here.length_squared(), shift.length_squared());
        dot > 0.0 && dot * dot >= 0.49 * here2 * shift2 && here2 >= 0.25 * shift2
    }

    /// A crop's sample `sample` (sRGB-coded, [0, 1]) at image position `p` with a lens's tint
    /// undone when `p` is under a lens: near an eye (within 0.45 × 0.35 eye distances), and
    /// coloured as that lens colours skin (its colour relative to the cheek shifted the lens's
    /// way, at least half as far: `through_lens`). How: `untinted_sample`. A grey sample (a
    /// YUV frame's crops are read from luma) is judged by the colour of the frame's pixel there.
    pub fn untint_at(&self, image: &UprightImage, p: Vec2, sample: [f32; 3]) -> [f32; 3] {
        let [l, r] = self.eyes_px;
        let ipd = l.distance(r);
        if ipd.is_nan() || ipd <= 0.0 {
            return sample;
        }
        let across = (r - l) / ipd;
        for i in 0..2 {
            let d = p - self.eyes_px[i];
            let (a, b) = (d.dot(across) / (0.45 * ipd), d.perp_dot(across) / (0.35 * ipd));
            if a * a + b * b > 1.0 {
                continue;
            }
            let t = self.transmission[i];
            if image.samples_grey() {
                return match image.colour_at(p) {
                    Some(rgb) if self.through_lens(i, rgb) => brightened(sample, rgb, t),
                    _ => sample,
                };
            }
            let code = sample.map(|c| (c.clamp(0.0, 1.0) * 255.0 + 0.5) as u8);
            return if self.through_lens(i, code) {
                untint_colour(sample, t)
            } else {
                sample
            };
        }
        sample
    }

    /// A crop's sample at `p` with the tint of lens `i` (0: image left) undone, whatever colour
    /// it has: for the iris network's crop, which lies all under the lens.
    pub fn untint_all_at(&self, image: &UprightImage, i: usize, p: Vec2, sample: [f32; 3]) -> [f32; 3] {
        match self.transmission.get(i) {
            Some(t) => untinted_sample(image, p, sample, *t),
            None => sample,
        }
    }
}

/// A crop's sample (sRGB-coded, [0, 1]) at image position `p` seen through a lens of
/// `transmission`, as it would be without: a colour sample by [`untint_colour`]; a grey one (a
/// YUV frame's crop, read from luma so that the networks get what they get without glasses)
/// scaled by how much brighter undoing the tint makes the colour of the frame's pixel at `p`
/// (Rec. 601 luma of the sRGB codes, as the frame's luma is made), since per-channel gains on
/// grey would paint it with the lens's opposite colour.
fn untinted_sample(image: &UprightImage, p: Vec2, sample: [f32; 3], transmission: [f32; 3]) -> [f32; 3] {
    if !image.samples_grey() {
        return untint_colour(sample, transmission);
    }
    match image.colour_at(p) {
        Some(rgb) => brightened(sample, rgb, transmission),
        None => sample,
    }
}

/// A grey crop sample scaled as undoing the tint of `transmission` brightens `rgb`, the frame's
/// colour (8-bit sRGB codes) where it was taken ([`untinted_sample`]).
fn brightened(sample: [f32; 3], rgb: [u8; 3], transmission: [f32; 3]) -> [f32; 3] {
    let luma = |c: [f32; 3]| 0.299 * c[0] + 0.587 * c[1] + 0.114 * c[2];
    let seen = rgb.map(|c| f32::from(c) / 255.0);
    let (before, after) = (luma(seen), luma(untint_colour(seen, transmission)));
    // Black under the lens: nothing to scale.
    if before < 1.0 / 255.0 {
        return sample;
    }
    sample.map(|v| (v * after / before).min(1.0))
}

impl Lenses {
    /// Where each lens (image left, image right) is centred in the image, from the pixels its
    /// tint colours. Around each eye (half the eye distance each way along the eye line, 0.42
    /// across it: one lens and its rim, not the other's) a grid of 60 × 50 cells is read; a cell
    /// is the lens's when it is seen through it (`through_lens`) and is not too dark to
    /// have a colour. The lens is the largest connected group of such cells (so hair or
    /// a background of the lens's colour elsewhere in the window does not count), and its centre
    /// the centroid of that group's convex hull: holes inside the outline (the dark iris, a
    /// reflection, a shadowed lid) and notches in it do not move it, where they would move the
    /// cells' own centroid. `None` for a lens that covers under a twentieth of the window or whose
    /// window runs off the image.
    pub fn centres(&self, image: &UprightImage) -> [Option<Vec2>; 2] {
        self.outlines(image).map(|o| o.map(|o| o.centre))
    }

    /// Each lens's outline (image left, image right): the convex hull of the largest group of
    /// cells seen through it and that hull's centroid, as [`Lenses::centres`] finds them (one read
    /// of the window serves both the centres and the rims, [`crate::rim`]).
    pub fn outlines(&self, image: &UprightImage) -> [Option<LensOutline>; 2] {
        const CELLS: (usize, usize) = (60, 50);
        let [l, r] = self.eyes_px;
        let ipd = l.distance(r);
        if !(ipd.is_finite() && ipd > 4.0) {
            return [None, None];
        }
        let across = (r - l) / ipd;
        let down = Vec2::new(-across.y, across.x);
        let (half_a, half_b) = (0.5 * ipd, 0.42 * ipd);
        let cell = Vec2::new(2.0 * half_a / CELLS.0 as f32, 2.0 * half_b / CELLS.1 as f32);
        [0, 1].map(|i| {
            let eye = self.eyes_px[i];
            // Face coordinates (along the eye line, across it) of a cell's centre, and back.
            let local = |x: usize, y: usize| {
                Vec2::new(-half_a + (x as f32 + 0.5) * cell.x, -half_b + (y as f32 + 0.5) * cell.y)
            };
            let to_image = |q: Vec2| eye + across * q.x + down * q.y;
            let mut lens = vec![false; CELLS.0 * CELLS.1];
            for y in 0..CELLS.1 {
                for x in 0..CELLS.0 {
                    // Off the image: the window is not whole, no answer.
                    let rgb = image.colour_at(to_image(local(x, y)))?;
                    if linear(rgb[0].max(rgb[1]).max(rgb[2])) < 0.02 {
                        continue;
                    }
                    lens[y * CELLS.0 + x] = self.through_lens(i, rgb);
                }
            }
            let points: Vec<Vec2> = largest_group(&lens, CELLS.0, CELLS.1)
                .into_iter()
                .map(|k| local(k % CELLS.0, k / CELLS.0))
                .collect();
            if points.len() * 20 < lens.len() {
                return None;
            }
            let hull = convex_hull(&points);
            Some(LensOutline {
                centre: to_image(centroid_of_hull(&hull, &points)),
                hull_px: hull.into_iter().map(to_image).collect(),
            })
        })
    }
}

impl Lenses {
    /// The dark rims around the lenses whose `outlines` were found ([`crate::rim`]).
    pub fn rims(&self, image: &UprightImage, outlines: &[Option<LensOutline>; 2]) -> [Option<Rim>; 2] {
        [0, 1].map(|i| Rim::around(image, self, i, outlines[i].as_ref()?))
    }

    /// The eyes the lenses were found at (image left, image right), pixels.
    pub fn eyes_px(&self) -> [Vec2; 2] {
        self.eyes_px
    }

    /// The distance between the eyes the lenses were found at, pixels.
    pub fn eye_distance_px(&self) -> f32 {
        self.eyes_px[0].distance(self.eyes_px[1])
    }

    /// The cheek's colour beside lens `i` (0: image left), linear RGB.
    pub fn cheek(&self, i: usize) -> Option<[f32; 3]> {
        self.ln_cheek.get(i).map(|c| c.to_array().map(f32::exp))
    }
}

/// A lens's outline in the image: the convex hull of the cells seen through it (pixels, in hull
/// order) and the hull's centroid.
#[derive(Clone, Debug, PartialEq)]
pub struct LensOutline {
    pub centre: Vec2,
    pub hull_px: Vec<Vec2>,
}

/// How far, per axis, a lens's centre may sit from the pupil behind it, as a share of the eye
/// distance: an assumption, not measured here. Anaglyph glasses have a fixed lens spacing while
/// adults' eye distances span about 54–74 mm (so ±1.75 mm a side for one standard deviation), and
/// glasses sit a little higher or lower on each nose; about 2.5 mm of 63 in all. The glasses
/// test's main sets centre each lens on its eye and would favour a smaller value; its set with
/// lenses off the eyes (spaced wider or narrower, higher or lower, shifted to a side and turned:
/// 2–9 % off) shows the price of a smaller one (`benchmarks/face.md`). A model with the frame's
/// offsets correlated between the lenses (one rigid frame on the nose) was tried there and not
/// kept: it gains only where the frame sits better than assumed.
pub const LENS_OFFSET_IPD: f32 = 0.04;

/// The iris network's error per axis, as a share of the eye distance, for eyes `eye_distance_px`
/// pixels apart: about half a pixel plus 1.2 % of the eye distance (root-sum-square). Measured on
/// the glasses test's drawn lenses (per-axis RMS against the clean photo: 3.0 % for eyes under 16
/// px apart, 2.0–2.8 % at 16–36 px, 0.8–1.6 % from 36 px; `benchmarks/face.md`, "the lenses as fiducials").
pub fn network_error_ipd(eye_distance_px: f32) -> f32 {
    const PIXEL: f32 = 0.5;
    const SHARE: f32 = 0.012;
    ((PIXEL / eye_distance_px.max(1.0)).powi(2) + SHARE * SHARE).sqrt()
}

/// The eyes (image left, image right, pixels) from the iris network's `network_px` and the lens
/// centres behind which they sit ([`Lenses::centres`]): per eye the two weighted by the inverse
/// of their variances, the network's by [`network_error_ipd`] and the lens's by
/// [`LENS_OFFSET_IPD`] (its own measuring error, well under 1 % of the eye distance on the drawn
/// lenses, is left out). So a lens counts for little on a sharp, large face, whose irises the
/// network places to about 1.3 %, and for about half on a face with eyes 15 pixels apart.
pub fn with_lens_centres(network_px: [Vec2; 2], centres: [Option<Vec2>; 2]) -> [Vec2; 2] {
    let ipd = network_px[0].distance(network_px[1]);
    if !ipd.is_finite() {
        return network_px;
    }
    let net = network_error_ipd(ipd).powi(2);
    let lens_weight = net / (net + LENS_OFFSET_IPD * LENS_OFFSET_IPD);
    [0, 1].map(|i| match centres[i] {
        Some(c) if c.is_finite() => network_px[i] + (c - network_px[i]) * lens_weight,
        _ => network_px[i],
    })
}

/// The cells (indices, rows of `width`) of the largest 8-connected group of `set`'s cells.
fn largest_group(set: &[bool], width: usize, height: usize) -> Vec<usize> {
    let mut seen = vec![false; set.len()];
    let mut best: Vec<usize> = Vec::new();
    let mut stack = Vec::new();
    for start in 0..set.len() {
        if !set[start] || seen[start] {
            continue;
        }
        let mut group = Vec::new();
        seen[start] = true;
        stack.push(start);
        while let Some(k) = stack.pop() {
            group.push(k);
            let (x, y) = ((k % width) as isize, (k / width) as isize);
            for (dx, dy) in [(-1, -1), (0, -1), (1, -1), (-1, 0), (1, 0), (-1, 1), (0, 1), (1, 1)] {
                let (nx, ny) = (x + dx, y + dy);
                if nx < 0 || ny < 0 || nx >= width as isize || ny >= height as isize {
                    continue;
                }
                let n = ny as usize * width + nx as usize;
                if set[n] && !seen[n] {
                    seen[n] = true;
                    stack.push(n);
                }
            }
        }
        if group.len() > best.len() {
            best = group;
        }
    }
    best
}

/// The convex hull of `points` (Andrew's monotone chain), counter-clockwise in a y-down image;
/// fewer than three distinct points come back as they are.
fn convex_hull(points: &[Vec2]) -> Vec<Vec2> {
    let mut p = points.to_vec();
    p.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    p.dedup();
    if p.len() < 3 {
        return p;
    }
    // One chain (lower, then upper from the points reversed), its last point left to start the
    // other.
    let chain = |points: &mut dyn Iterator<Item = Vec2>| {
        let mut c: Vec<Vec2> = Vec::new();
        for q in points {
            while c.len() >= 2 && (c[c.len() - 1] - c[c.len() - 2]).perp_dot(q - c[c.len() - 2]) <= 0.0 {
                c.pop();
            }
            c.push(q);
        }
        c.pop();
        c
    };
    let mut hull = chain(&mut p.iter().copied());
    hull.extend(chain(&mut p.iter().rev().copied()));
    hull
}

/// The centroid of the polygon `hull` (the area's, not the vertices'); the mean of `points` when
/// the hull has no area.
fn centroid_of_hull(hull: &[Vec2], points: &[Vec2]) -> Vec2 {
    let mean = points.iter().copied().sum::<Vec2>() / points.len().max(1) as f32;
    if hull.len() < 3 {
        return mean;
    }
    // About the first vertex (for precision).
    let o = hull[0];
    let (mut area, mut sum) = (0.0f32, Vec2::ZERO);
    for k in 1..hull.len() - 1 {
        let (a, b) = (hull[k] - o, hull[k + 1] - o);
        let cross = a.perp_dot(b);
        area += cross;
        sum += (a + b) * cross;
    }
    if area.abs() < 1e-9 {
        return mean;
    }
    o + sum / (3.0 * area)
}

/// The centroid of the convex hull of `points` (see [`Lenses::centres`]).
#[cfg(test)]
fn hull_centroid(points: &[Vec2]) -> Vec2 {
    centroid_of_hull(&convex_hull(points), points)
}

/// One sRGB-coded colour ([0, 1]) seen through a lens of `transmission`, as it would be without:
/// each channel in linear light multiplied up to the lens's most transparent channel. The gain is
/// capped at 32 (a channel the lens passes 3 % of, against its clearest one) so that a channel it
/// all but stopped is not amplified without bound. The test set's drawn gels (made to resemble
/// cheap ones, not measured) stop their channels to 4–12 % of the clearest (gains 7–22): a cap of
/// 8 left opaque lenses part tinted, and the
/// glasses set's opaque lenses gained from 32 (90th percentile eye error 5.3 → 4.2 %), the
/// others unchanged (`benchmarks/face.md`, 2026-12-04, third session).
pub fn untint_colour(rgb: [f32; 3], transmission: [f32; 3]) -> [f32; 3] {
    const MAX_GAIN: f32 = 32.0;
    let top = transmission.iter().copied().fold(0.0f32, f32::max).max(1e-4);
    [0, 1, 2].map(|k| {
        let gain = (top / transmission[k].max(1e-4)).min(MAX_GAIN);
        from_linear_fast(to_linear_fast(rgb[k]) * gain)
    })
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

    /// A grey seen through a full-strength gel comes back grey: the stopped channels need gains
    /// of 17–22 here (a cap of 8 fails this); a channel that passes nothing stays bounded.
    #[test]
    fn untinting_restores_a_grey_behind_an_opaque_lens_and_bounds_a_stopped_channel() {
        use phantogram_geometry::srgb::{code_to_linear, linear_to_code};
        let grey = 0.4f32;
        for t in [[0.85, 0.05, 0.05], [0.9, 0.55, 0.04], [0.04, 0.75, 0.85]] {
            let seen = t.map(|k| f32::from(linear_to_code(grey * k)) / 255.0);
            let back = untint_colour(seen, t);
            let top = t.iter().copied().fold(0.0f32, f32::max);
            for c in back {
                let linear = code_to_linear((c * 255.0).round() as u8);
                // Within the 8-bit rounding of the dark channel, scaled up.
                assert!((linear - grey * top).abs() < 0.06 * grey, "{t:?}: {back:?}");
            }
        }
        let stopped = untint_colour([0.8, 0.02, 0.02], [0.9, 0.0, 0.0]);
        assert!(
            stopped.iter().all(|c| c.is_finite() && (0.0..=1.0).contains(c)),
            "{stopped:?}"
        );
    }

    use crate::{CameraFrame, Intrinsics, PixelFormat};
    use phantogram_geometry::srgb::{code_to_linear, linear_to_code};

    const SIZE: (u32, u32) = (200, 130);

    fn image(rgba: &[u8]) -> UprightImage<'_> {
        UprightImage::new(CameraFrame {
            width: SIZE.0,
            height: SIZE.1,
            row_stride: 4 * SIZE.0 as usize,
            format: PixelFormat::Rgba8,
            data: rgba,
            rotation_cw_deg: 0,
            intrinsics: Intrinsics::from_horizontal_fov(SIZE.0, SIZE.1, 1.0),
            capture_t_ns: 0,
            chroma: None,
        })
        .expect("a valid frame")
    }

    /// Skin of one colour with `paint` applied to every pixel (given its centre and its linear
    /// colour).
    fn face(paint: impl Fn(Vec2, [f32; 3]) -> [f32; 3]) -> Vec<u8> {
        let skin = [200u8, 150, 120].map(code_to_linear);
        let mut rgba = Vec::with_capacity((SIZE.0 * SIZE.1 * 4) as usize);
        for y in 0..SIZE.1 {
            for x in 0..SIZE.0 {
                let lin = paint(Vec2::new(x as f32 + 0.5, y as f32 + 0.5), skin);
                rgba.extend(lin.map(linear_to_code));
                rgba.push(255);
            }
        }
        rgba
    }

    /// Whether `p` is inside the axis-aligned ellipse about `centre` with half-axes `half` (also
    /// for [`super::search`]'s tests).
    pub(super) fn in_ellipse(p: Vec2, centre: Vec2, half: Vec2) -> bool {
        ((p - centre) / half).length_squared() <= 1.0
    }

    #[test]
    fn a_lens_centre_is_found_through_holes_and_beside_a_blob_of_its_colour() {
        let (left, right) = (Vec2::new(60.0, 60.0), Vec2::new(140.0, 60.0));
        // The left lens sits off its eye, as real glasses do; both 0.7 eye distances wide.
        let (left_lens, right_lens) = (Vec2::new(64.0, 56.0), right);
        let half = Vec2::new(28.0, 19.6);
        let rgba = face(|p, skin| {
            let filter = if in_ellipse(p, left_lens, half) {
                Some(transmission(Filter::Red))
            } else if in_ellipse(p, right_lens, half) {
                Some(transmission(Filter::Cyan))
            } else {
                None
            };
            // A blob tinted as the red lens tints skin, in the lens's window but apart from it.
            let blob = in_ellipse(p, Vec2::new(27.0, 88.0), Vec2::splat(5.0));
            let t = filter.or(blob.then(|| transmission(Filter::Red))).unwrap_or([1.0; 3]);
            let mut lin = [0, 1, 2].map(|k| skin[k] * t[k]);
            // Holes, both below and left of the left lens's centre: each dark iris (at the eye)
            // and, on the left lens, a white streak to its lower edge.
            if p.distance(left) < 8.0 || p.distance(right) < 8.0 {
                lin = lin.map(|v| v * 0.02);
            }
            if filter.is_some() && p.y > 62.0 && (p.x - 50.0 - (p.y - 62.0)).abs() < 4.0 {
                lin = lin.map(|v| v + 0.5);
            }
            lin
        });
        let image = image(&rgba);
        let lenses = find_at(&image, left, right).expect("the glasses");
        assert_eq!((lenses.image_left, lenses.image_right), (Filter::Red, Filter::Cyan));
        let [Some(a), Some(b)] = lenses.centres(&image) else {
            panic!("both lenses")
        };
        // A cell is 4/3 px along the eye line, 1.3 px across it.
        assert!(a.distance(left_lens) < 0.7, "{a} against {left_lens}");
        assert!(b.distance(right_lens) < 0.7, "{b} against {right_lens}");
        // A lens whose window runs off the image: no centre for it.
        let near_edge = Lenses {
            eyes_px: [Vec2::new(20.0, 60.0), Vec2::new(100.0, 60.0)],
            ..lenses
        };
        assert!(near_edge.centres(&image)[0].is_none());
        // No lens there (a bare face): no centres either.
        let bare = face(|_, skin| skin);
        let bare_image = super::tests::image(&bare);
        assert!(find_at(&bare_image, left, right).is_none());
        assert_eq!(lenses.centres(&bare_image), [None, None]);
    }

    /// A lens whose shift lies between two filters is named by its partner: this left lens
    /// (measured so on a drawn magenta lens, opacity 0.7, over the astronaut's eye, whose lids are
    /// less blue than her cheek) is nearer red than magenta, so beside a green lens it is the
    /// magenta one, beside a cyan lens the red one. Named eye by eye it was red beside green, no
    /// pair, and the glasses were missed.
    #[test]
    fn a_lens_between_two_filters_is_named_by_its_partner() {
        let (left, right) = (Vec2::new(60.0, 60.0), Vec2::new(140.0, 60.0));
        let between = [0.378, 0.130, 0.217];
        assert_eq!(nearest_filter(log_chroma(between)).0, Filter::Red);
        for (partner, named) in [(Filter::Green, Filter::Magenta), (Filter::Cyan, Filter::Red)] {
            let rgba = face(|p, skin| {
                let t = if p.distance(left) < 25.0 {
                    between
                } else if p.distance(right) < 25.0 {
                    transmission(partner)
                } else {
                    [1.0; 3]
                };
                [0, 1, 2].map(|k| skin[k] * t[k])
            });
            let lenses = find_at(&image(&rgba), left, right).expect("the glasses");
            assert_eq!((lenses.image_left, lenses.image_right), (named, partner));
        }
        // Both lenses that colour: not a pair of any kind.
        let rgba = face(|p, skin| {
            let t = if p.distance(left) < 25.0 || p.distance(right) < 25.0 {
                between
            } else {
                [1.0; 3]
            };
            [0, 1, 2].map(|k| skin[k] * t[k])
        });
        assert!(find_at(&image(&rgba), left, right).is_none());
    }

    /// A thin dark rim around both lenses is found and filled with the cheek's colour; the lens
    /// inside it and the skin beyond it are left alone; a rimless or a white rim is no rim.
    #[test]
    fn a_dark_rim_is_found_around_each_lens_and_filled_with_the_cheek() {
        let (left, right) = (Vec2::new(60.0, 60.0), Vec2::new(140.0, 60.0));
        let half = Vec2::new(28.0, 19.6);
        let glasses = |rim: Option<[f32; 3]>| {
            face(move |p, skin| {
                for (centre, f) in [(left, Filter::Red), (right, Filter::Cyan)] {
                    if in_ellipse(p, centre, half) {
                        let t = transmission(f);
                        return [0, 1, 2].map(|k| skin[k] * t[k]);
                    }
                    if let Some(colour) = rim
                        && in_ellipse(p, centre, half + Vec2::splat(3.0))
                    {
                        return colour;
                    }
                }
                skin
            })
        };
        let dark = [25u8, 22, 20].map(code_to_linear);
        let rgba = glasses(Some(dark));
        let image = image(&rgba);
        let lenses = find_at(&image, left, right).expect("the glasses");
        let rims = lenses.rims(&image, &lenses.outlines(&image));
        let [Some(a), Some(_)] = &rims else {
            panic!("both rims: {rims:?}")
        };
        // 3 px of rim, beyond a hull of cell centres up to a cell inside the lens's edge.
        assert!((3.0..=6.5).contains(&a.reach_px), "reach {}", a.reach_px);
        let coded = |lin: [f32; 3]| lin.map(|c| f32::from(linear_to_code(c)) / 255.0);
        let cheek = lenses.cheek(0).expect("a cheek").map(from_linear_fast);
        let on_rim = left + Vec2::new(half.x + 1.5, 0.0);
        let filled = a.filled(on_rim, coded(dark), false).expect("the rim is filled");
        assert!(
            filled.iter().zip(cheek).all(|(f, c)| (f - c).abs() < 1e-4),
            "{filled:?}"
        );
        let on_rim_above = left - Vec2::new(0.0, half.y + 1.5);
        assert!(
            a.filled(on_rim_above, coded(dark), false).is_some(),
            "above the lens too"
        );
        let grey = a.filled(on_rim, coded(dark), true).expect("a grey crop's rim");
        assert!(grey[0] == grey[1] && grey[1] == grey[2]);
        // Inside the lens, on skin beyond the rim, and a dark pixel far out: as they are.
        let inside = left + Vec2::new(half.x - 4.0, 0.0);
        assert!(a.filled(inside, coded(dark), false).is_none());
        let beyond = left + Vec2::new(half.x + 12.0, 0.0);
        assert!(a.filled(beyond, coded(dark), false).is_none());
        let skin = [200u8, 150, 120].map(|c| f32::from(c) / 255.0);
        assert!(a.filled(on_rim, skin, false).is_none(), "skin-coloured: not a rim");
        // Rimless, or a white cardboard rim: none.
        for (what, rim) in [
            ("rimless", None),
            ("white", Some([235u8, 232, 225].map(code_to_linear))),
        ] {
            let rgba = glasses(rim);
            let image = super::tests::image(&rgba);
            let lenses = find_at(&image, left, right).expect("the glasses");
            let rims = lenses.rims(&image, &lenses.outlines(&image));
            assert_eq!(rims, [None, None], "{what}");
        }
        // A rimless lens under a dark brow that hugs its top two fifths (±72° about straight
        // up): a dark run on 40 % of the rays, under the majority a rim needs.
        let browed = face(|p, skin| {
            for (centre, f) in [(left, Filter::Red), (right, Filter::Cyan)] {
                if in_ellipse(p, centre, half) {
                    let t = transmission(f);
                    return [0, 1, 2].map(|k| skin[k] * t[k]);
                }
                let up = (centre - p).normalize_or_zero().y;
                if in_ellipse(p, centre, half + Vec2::splat(3.0)) && up > 72f32.to_radians().cos() {
                    return dark;
                }
            }
            skin
        });
        let image = super::tests::image(&browed);
        let lenses = find_at(&image, left, right).expect("the glasses");
        let rims = lenses.rims(&image, &lenses.outlines(&image));
        assert_eq!(rims, [None, None], "a brow over the top two fifths");
    }

    #[test]
    fn a_hull_centroid_ignores_holes_and_inner_points() {
        // A 10 × 4 rectangle's corners with points crowded into its left part: the centroid of
        // the area, not of the points.
        let mut points = vec![
            Vec2::new(0.0, 0.0),
            Vec2::new(10.0, 0.0),
            Vec2::new(10.0, 4.0),
            Vec2::new(0.0, 4.0),
        ];
        points.extend((0..20).map(|k| Vec2::new(0.5 + 0.1 * k as f32, 1.0 + 0.1 * k as f32)));
        assert!(hull_centroid(&points).distance(Vec2::new(5.0, 2.0)) < 1e-4);
        // On a line, and one point: their mean.
        let line = [Vec2::new(0.0, 0.0), Vec2::new(1.0, 1.0), Vec2::new(3.0, 3.0)];
        assert!(hull_centroid(&line).distance(Vec2::new(4.0 / 3.0, 4.0 / 3.0)) < 1e-5);
        assert_eq!(hull_centroid(&[Vec2::new(2.0, 3.0)]), Vec2::new(2.0, 3.0));
    }

    #[test]
    fn lens_centres_count_more_where_the_network_sees_less() {
        let pull = |ipd: f32| {
            let net = [Vec2::new(0.0, 0.0), Vec2::new(ipd, 0.0)];
            let lens = [Some(Vec2::new(0.0, 1.0)), None];
            let [l, r] = with_lens_centres(net, lens);
            assert_eq!(r, net[1], "no lens, no change");
            l.y
        };
        // Eyes 120 px apart (a sharp face at arm's length): the lens counts for about a tenth.
        assert!((0.05..0.15).contains(&pull(120.0)), "{}", pull(120.0));
        // 15 px apart: about a half.
        assert!((0.35..0.6).contains(&pull(15.0)), "{}", pull(15.0));
        // Nonsense stays out.
        let net = [Vec2::new(1.0, 2.0), Vec2::new(30.0, 2.0)];
        assert_eq!(with_lens_centres(net, [Some(Vec2::NAN), None]), net);
    }
}
