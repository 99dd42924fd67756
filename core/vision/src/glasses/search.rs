//! Finding the lens pair on a face without knowing where its eyes are: for the detector's box
//! when its eye keypoints do not lead to glasses ([`super::find_at`] reads the skin at fixed
//! places around each eye, so an eye estimate a third of the eye distance off reads the lens as
//! cheek or the forehead as lens).
//!
//! Why it is needed: the tinted eyes mislead the face detector itself. On the face bench's
//! swaying face with thin-rimmed red/cyan glasses, at some positions BlazeFace returns all six
//! keypoints coherently turned by about 30° (the face is upright), so neither its eyes nor the
//! FaceMesh run on the crop turned by them lead to the glasses, and the face is lost through YUV
//! frames (`benchmarks/face.md`, 2026-12-04, fifth session).
//!
//! How: a grid of 32 × 32 samples over the box, each sample's linear colour relative to the
//! median of the box's lower middle (cheeks, nose and mouth, below where any lens sits), and each
//! sample named for the filter its colour shift points at, by the thresholds [`super::find_at`]
//! uses for a whole eye. For each kind of glasses the largest connected group of each of its two
//! filters' samples is a lens candidate; a pair is kept only where it could be a face's two
//! lenses (each at least 1/80 of the box, their centres 0.2–0.8 box widths apart and side by side
//! — a face turned by 45° at most —, the pair's middle in the box's upper middle). Each pair's
//! centres (of its groups' hulls, as [`super::Lenses::centres`] finds them), the largest pair
//! first, are then handed to [`super::find_at`] as the eyes, and the first it confirms is the
//! answer: glasses found here pass exactly the test that glasses found at the keypoints pass, so
//! the search adds places to look, not a looser rule. 1024 pixel reads (about 0.03 ms on a bare face here,
//! on the detection frames that do not find glasses at the keypoints); no panics.

use glam::Vec2;

use super::{
    Filter, Lenses, MIN_COSINE, MIN_STRENGTH, centroid_of_hull, convex_hull, find_at, largest_group, linear,
    log_chroma, nearest_filter,
};
use crate::UprightImage;

/// Samples per side of the box.
const GRID: usize = 32;

/// The glasses on the face in the detector's box `min`–`max` (pixels), looked for by colour
/// alone; `None` without colour or without a pair that [`find_at`] confirms.
///
/// The skin's colour is the lower middle's median, which is the cheeks and chin on a face turned
/// by up to 45°; on a bare face an orange forehead or hair and a blue collar can name large
/// "amber" and "blue" groups, which the shape test or [`find_at`] then turns down.
pub fn find_in_box(image: &UprightImage, min: Vec2, max: Vec2) -> Option<Lenses> {
    if !image.has_colour() {
        return None;
    }
    let size = max - min;
    if !(size.x.is_finite() && size.y.is_finite() && size.x > 8.0 && size.y > 8.0) {
        return None;
    }
    let at = |u: f32, v: f32| min + size * Vec2::new(u, v);
    let cell = |x: usize, y: usize| at((x as f32 + 0.5) / GRID as f32, (y as f32 + 0.5) / GRID as f32);
    // Every sample's linear colour (None: off the image or too dark to have a colour).
    let samples: Vec<Option<[f32; 3]>> = (0..GRID * GRID)
        .map(|k| {
            let rgb = image.colour_at(cell(k % GRID, k / GRID))?.map(linear);
            (rgb.iter().copied().fold(0.0f32, f32::max) >= 0.02).then_some(rgb)
        })
        .collect();
    // The skin's colour: the median of the box's lower middle, per channel.
    let mut lower: [Vec<f32>; 3] = Default::default();
    for y in GRID * 55 / 100..GRID * 95 / 100 {
        for x in GRID / 5..GRID * 4 / 5 {
            if let Some(rgb) = samples[y * GRID + x] {
                for k in 0..3 {
                    lower[k].push(rgb[k]);
                }
            }
        }
    }
    if lower[0].len() < 20 {
        return None;
    }
    let skin = lower.map(|mut c| {
        c.sort_by(f32::total_cmp);
        c[c.len() / 2].max(1e-4)
    });
    // Each sample's filter, where its colour is shifted as a lens shifts skin.
    let named: Vec<Option<Filter>> = samples
        .iter()
        .map(|s| {
            let s = (*s)?;
            let shift = log_chroma([0, 1, 2].map(|k| s[k].max(1e-4) / skin[k]));
            if shift.length() < MIN_STRENGTH {
                return None;
            }
            let (filter, cosine) = nearest_filter(shift);
            (cosine >= MIN_COSINE).then_some(filter)
        })
        .collect();
    // Each filter's largest group: its cell count and hull centre in the image.
    let groups = Filter::ALL.map(|f| {
        let set: Vec<bool> = named.iter().map(|n| *n == Some(f)).collect();
        let cells = largest_group(&set, GRID, GRID);
        let points: Vec<Vec2> = cells.iter().map(|k| cell(k % GRID, k / GRID)).collect();
        (cells.len(), centroid_of_hull(&convex_hull(&points), &points))
    });
    let group = |f: Filter| groups[Filter::ALL.iter().position(|g| *g == f).unwrap_or(0)];
    let min_cells = GRID * GRID / 80;
    let plausible = |(na, a): (usize, Vec2), (nb, b): (usize, Vec2)| {
        let gap = a.distance(b) / size.x;
        let d = (b - a).abs();
        let mid = ((a + b) * 0.5 - min) / size;
        na >= min_cells
            && nb >= min_cells
            && (0.2..=0.8).contains(&gap)
            && d.y <= d.x
            && (0.2..=0.8).contains(&mid.x)
            && (0.15..=0.65).contains(&mid.y)
    };
    let mut pairs: Vec<((usize, Vec2), (usize, Vec2))> = [Filter::Red, Filter::Green, Filter::Amber]
        .into_iter()
        .map(|f| (group(f), group(f.partner())))
        .filter(|(a, b)| plausible(*a, *b))
        .collect();
    // The largest pair first; the first that the eye test confirms.
    pairs.sort_by_key(|(a, b)| std::cmp::Reverse(a.0.min(b.0)));
    pairs.into_iter().find_map(|((_, a), (_, b))| {
        let (left, right) = if a.x <= b.x { (a, b) } else { (b, a) };
        find_at(image, left, right)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::glasses::tests::in_ellipse;
    use crate::glasses::transmission;
    use crate::{CameraFrame, Intrinsics, PixelFormat};
    use phantogram_geometry::srgb::{code_to_linear, linear_to_code};

    const SIZE: u32 = 240;
    /// The eyes, 72 px apart, and the detector's box around the face.
    const LEFT: Vec2 = Vec2::new(84.0, 100.0);
    const RIGHT: Vec2 = Vec2::new(156.0, 100.0);
    const BOX: (Vec2, Vec2) = (Vec2::new(40.0, 50.0), Vec2::new(200.0, 210.0));

    fn image(rgba: &[u8]) -> UprightImage<'_> {
        UprightImage::new(CameraFrame {
            width: SIZE,
            height: SIZE,
            row_stride: 4 * SIZE as usize,
            format: PixelFormat::Rgba8,
            data: rgba,
            rotation_cw_deg: 0,
            intrinsics: Intrinsics::from_horizontal_fov(SIZE, SIZE, 1.0),
            capture_t_ns: 0,
            chroma: None,
        })
        .expect("a valid frame")
    }

    /// Skin with dark irises at the eyes, each pixel's linear colour then multiplied by
    /// `filter(p)` where it gives one.
    fn face(filter: impl Fn(Vec2) -> Option<[f32; 3]>) -> Vec<u8> {
        let skin = [200u8, 150, 120].map(code_to_linear);
        let mut rgba = Vec::new();
        for y in 0..SIZE {
            for x in 0..SIZE {
                let p = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
                let mut lin = skin;
                if p.distance(LEFT) < 6.0 || p.distance(RIGHT) < 6.0 {
                    lin = lin.map(|v| v * 0.03);
                }
                let t = filter(p).unwrap_or([1.0; 3]);
                rgba.extend([0, 1, 2].map(|k| linear_to_code(lin[k] * t[k])));
                rgba.push(255);
            }
        }
        rgba
    }

    /// Lenses 0.7 eye distances wide of `left` and `right` over the eyes.
    fn glasses(left: Filter, right: Filter) -> Vec<u8> {
        let half = Vec2::new(25.0, 18.0);
        face(|p| {
            if in_ellipse(p, LEFT, half) {
                Some(transmission(left))
            } else if in_ellipse(p, RIGHT, half) {
                Some(transmission(right))
            } else {
                None
            }
        })
    }

    #[test]
    fn lenses_are_found_in_the_box_where_turned_eyes_miss_them() {
        let rgba = glasses(Filter::Red, Filter::Cyan);
        let frame = image(&rgba);
        // The eyes turned by 33° about a point 16 px low, as the detector gave them on a face
        // with tinted eyes: the eye test there does not see the glasses.
        let (mid, half) = (Vec2::new(120.0, 116.0), Vec2::from_angle(-0.58) * 36.0);
        assert!(find_at(&frame, mid - half, mid + half).is_none());
        let lenses = find_in_box(&frame, BOX.0, BOX.1).expect("the glasses, found in the box");
        assert_eq!((lenses.image_left, lenses.image_right), (Filter::Red, Filter::Cyan));
        let [l, r] = lenses.eyes_px();
        // A cell is 5 px: the lenses' hull centres within a cell of their eyes.
        assert!(l.distance(LEFT) < 5.0 && r.distance(RIGHT) < 5.0, "{l} {r}");
        // The other kinds, either way round.
        for (a, b) in [(Filter::Blue, Filter::Amber), (Filter::Green, Filter::Magenta)] {
            let lenses = find_in_box(&image(&glasses(a, b)), BOX.0, BOX.1).expect("the glasses");
            assert_eq!((lenses.image_left, lenses.image_right), (a, b));
        }
    }

    #[test]
    fn colours_that_are_not_a_lens_pair_are_not_glasses() {
        // Bare skin.
        assert!(find_in_box(&image(&face(|_| None)), BOX.0, BOX.1).is_none());
        // Two lenses of one colour.
        assert!(find_in_box(&image(&glasses(Filter::Red, Filter::Red)), BOX.0, BOX.1).is_none());
        // A red and a cyan patch of lens size, one above the other (lips under an eye shadow).
        let stacked = face(|p| {
            if in_ellipse(p, Vec2::new(120.0, 100.0), Vec2::new(25.0, 18.0)) {
                Some(transmission(Filter::Cyan))
            } else if in_ellipse(p, Vec2::new(120.0, 170.0), Vec2::new(25.0, 18.0)) {
                Some(transmission(Filter::Red))
            } else {
                None
            }
        });
        assert!(find_in_box(&image(&stacked), BOX.0, BOX.1).is_none());
        // A red and a cyan patch side by side, below the eyes (a collar).
        let low = face(|p| {
            let (a, b) = (Vec2::new(84.0, 195.0), Vec2::new(156.0, 195.0));
            if in_ellipse(p, a, Vec2::new(25.0, 14.0)) {
                Some(transmission(Filter::Red))
            } else if in_ellipse(p, b, Vec2::new(25.0, 14.0)) {
                Some(transmission(Filter::Cyan))
            } else {
                None
            }
        });
        assert!(find_in_box(&image(&low), BOX.0, BOX.1).is_none());
        // Degenerate boxes.
        let rgba = glasses(Filter::Red, Filter::Cyan);
        let frame = image(&rgba);
        assert!(find_in_box(&frame, BOX.0, BOX.0).is_none());
        assert!(find_in_box(&frame, Vec2::splat(f32::NAN), BOX.1).is_none());
    }
}
