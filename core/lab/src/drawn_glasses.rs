//! Anaglyph glasses drawn over a face photograph, for testing the glasses-aware face tracker
//! with ground truth: the same photo without them is the reference.
//!
//! A lens is drawn as a filter is seen: in linear light each pixel under it is multiplied by the
//! lens's transmission (mixed with clear for a partly transparent lens), then a frame rim
//! (cardboard or plastic: dark, of a given width) around it, and optionally a specular
//! reflection (a soft white streak) on it. The lens is centred on the eye's centre, of a width
//! given as a fraction of the eye distance, and turned with the eye line, unless the style
//! moves the frame off the eyes as real glasses sit (spaced wider or narrower, higher or lower,
//! to a side, turned).
//!
//! Pure function of its inputs. **Panics**: none (positions outside the image draw nothing).

use glam::Vec2;
use phantogram_geometry::srgb::{code_to_linear, linear_to_code};
use phantogram_sensing::glasses::Filter;

/// A lens's outline.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LensShape {
    Ellipse,
    /// A rectangle with corners rounded by this fraction of the lens's height.
    RoundedRect(f32),
}

/// How to draw one pair of glasses.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GlassesStyle {
    /// The filters over the image-left and image-right eye.
    pub filters: (Filter, Filter),
    pub shape: LensShape,
    /// Lens width / eye distance.
    pub width_ipd: f32,
    /// Lens height / lens width.
    pub aspect: f32,
    /// Share of the light the filter acts on (1: the full filter; 0.5: half passes unfiltered).
    pub opacity: f32,
    /// The rim's width / eye distance (0: rimless) and its colour (sRGB).
    pub rim_ipd: f32,
    pub rim_rgb: [u8; 3],
    /// A specular reflection's peak brightness (0: none) — a soft streak across the lens.
    pub reflection: f32,
    /// Where the lenses sit on the eyes, as shares of the eye distance: the lens centres'
    /// spacing over the eye distance (1: each lens centred on its eye; real glasses have one
    /// spacing for every wearer), and how far below the eyes they sit (negative: above).
    pub spacing_ipd: f32,
    pub drop_ipd: f32,
    /// How far the frame sits to the side of the eyes' midpoint (share of the eye distance,
    /// positive towards the image-right eye) and how far it is turned against the eye line
    /// (radians, positive clockwise in the image: the image-right lens lower).
    pub shift_ipd: f32,
    pub tilt_rad: f32,
    /// The two lenses' own linear transmissions (image left, image right) in place of the
    /// filters': ordinary glasses — clear, grey or both one colour — which are not anaglyph
    /// glasses (`None`: the filters').
    pub tints: Option<[[f32; 3]; 2]>,
}

/// Linear transmission of a drawn filter: values chosen to resemble cheap anaglyph gels (not
/// measured), and on purpose not the detector's own prototypes (`phantogram_vision::glasses`),
/// so that the test does not find exactly what it drew.
pub fn filter_transmission(filter: Filter) -> [f32; 3] {
    match filter {
        Filter::Red => [0.85, 0.06, 0.05],
        Filter::Cyan => [0.05, 0.75, 0.85],
        Filter::Green => [0.06, 0.8, 0.12],
        Filter::Magenta => [0.8, 0.05, 0.8],
        Filter::Amber => [0.9, 0.55, 0.04],
        Filter::Blue => [0.04, 0.12, 0.85],
    }
}

/// Draws `style`'s glasses into `rgba` (`width × height`, rows packed) over the eyes at
/// `image_left_eye` and `image_right_eye` (pixels).
pub fn draw(
    rgba: &mut [u8],
    width: u32,
    height: u32,
    image_left_eye: Vec2,
    image_right_eye: Vec2,
    style: &GlassesStyle,
) {
    let ipd = image_left_eye.distance(image_right_eye);
    if !(ipd.is_finite() && ipd > 1.0) || rgba.len() < (width * height * 4) as usize {
        return;
    }
    let eye_line = (image_right_eye - image_left_eye) / ipd;
    // The frame's own axes: the eye line turned by the frame's tilt.
    let across = Vec2::from_angle(style.tilt_rad).rotate(eye_line);
    let down = Vec2::new(-across.y, across.x);
    let half = Vec2::new(style.width_ipd * 0.5, style.width_ipd * style.aspect * 0.5) * ipd;
    let rim = style.rim_ipd * ipd;
    let (mid, spread) = (
        (image_left_eye + image_right_eye) * 0.5
            + Vec2::new(-eye_line.y, eye_line.x) * (style.drop_ipd * ipd)
            + eye_line * (style.shift_ipd * ipd),
        across * (0.5 * style.spacing_ipd * ipd),
    );
    let [left_t, right_t] = style.tints.unwrap_or([
        filter_transmission(style.filters.0),
        filter_transmission(style.filters.1),
    ]);
    let lenses = [(mid - spread, left_t), (mid + spread, right_t)];
    // Signed distance-like measure: < 1 inside the lens outline, scaled by the half sizes.
    let inside = |q: Vec2, grow: f32| -> bool {
        let h = half + Vec2::splat(grow);
        match style.shape {
            LensShape::Ellipse => (q.x / h.x).powi(2) + (q.y / h.y).powi(2) <= 1.0,
            LensShape::RoundedRect(r) => {
                let radius = (r.clamp(0.0, 0.5) * 2.0 * half.y).min(h.x).min(h.y);
                let d = q.abs() - (h - Vec2::splat(radius));
                let outside = d.max(Vec2::ZERO).length() + d.x.max(d.y).min(0.0);
                outside <= radius
            }
        }
    };
    let reach = (half.x.max(half.y) + rim + 2.0).ceil();
    for (centre, t) in lenses {
        let (x0, x1) = (
            (centre.x - reach).max(0.0) as u32,
            ((centre.x + reach).max(0.0) as u32).min(width),
        );
        let (y0, y1) = (
            (centre.y - reach).max(0.0) as u32,
            ((centre.y + reach).max(0.0) as u32).min(height),
        );
        for y in y0..y1 {
            for x in x0..x1 {
                let p = Vec2::new(x as f32 + 0.5, y as f32 + 0.5) - centre;
                let q = Vec2::new(p.dot(across), p.dot(down));
                let at = ((y * width + x) * 4) as usize;
                if inside(q, 0.0) {
                    // A streak from upper left to lower right, brightest on its centre line.
                    let streak = style.reflection
                        * (-((q.x + q.y * 1.5 + 0.2 * half.x) / (0.12 * half.x)).powi(2)).exp()
                        * (q.y < 0.0) as u8 as f32;
                    for k in 0..3 {
                        let v = code_to_linear(rgba[at + k]);
                        let filtered = v * (1.0 - style.opacity + style.opacity * t[k]);
                        rgba[at + k] = linear_to_code(filtered + streak);
                    }
                } else if rim > 0.0 && inside(q, rim) {
                    rgba[at..at + 3].copy_from_slice(&style.rim_rgb);
                }
            }
        }
    }
}

/// A spread of styles for one photo: shapes, sizes (0.6–0.8 of the eye distance), the three kinds
/// of glasses either way round, full and partly transparent lenses, cardboard and plastic rims,
/// with and without reflections. `seed` picks which (deterministic).
pub fn style_for(seed: u32) -> GlassesStyle {
    let pairs = [
        (Filter::Cyan, Filter::Red),
        (Filter::Magenta, Filter::Green),
        (Filter::Blue, Filter::Amber),
        (Filter::Red, Filter::Cyan),
    ];
    // The viewer's left eye is on the image's right: red, green or amber on the right is the
    // usual way; the fourth pair is worn the other way round.
    let shapes = [
        LensShape::Ellipse,
        LensShape::RoundedRect(0.3),
        LensShape::RoundedRect(0.1),
    ];
    // Each property from its own hash of the seed, so that every combination occurs: a
    // multiplicative hash's neighbouring bits (as this used before) tied properties together —
    // width and aspect took 6 of their 9 pairs, and a thin dark rim always came with a reflection.
    let pick = |n: u32, salt: u32| mix(mix(seed) ^ salt.wrapping_mul(0x9E37_79B9)) % n;
    let cardboard = pick(2, 3) == 0;
    GlassesStyle {
        filters: pairs[(seed % 4) as usize],
        shape: shapes[pick(3, 1) as usize],
        width_ipd: 0.6 + 0.1 * pick(3, 2) as f32,
        aspect: 0.6 + 0.1 * pick(3, 4) as f32,
        opacity: [1.0, 0.85, 0.7][pick(3, 5) as usize],
        rim_ipd: if cardboard {
            0.06
        } else {
            [0.0, 0.025][pick(2, 6) as usize]
        },
        rim_rgb: if cardboard { [235, 232, 225] } else { [25, 22, 20] },
        reflection: [0.0, 0.25][pick(2, 7) as usize],
        spacing_ipd: 1.0,
        drop_ipd: 0.0,
        shift_ipd: 0.0,
        tilt_rad: 0.0,
        tints: None,
    }
}

/// A 32-bit integer hash with good avalanche (Chris Wellons' "lowbias32"): every input bit
/// flips each output bit with probability close to a half.
fn mix(mut x: u32) -> u32 {
    x ^= x >> 16;
    x = x.wrapping_mul(0x7feb_352d);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846c_a68b);
    x ^ (x >> 16)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Over 320 styles (the glasses test's), every pair of properties takes every combination of
    /// its values, each within half of its even share.
    #[test]
    fn styles_cover_every_combination_of_two_properties() {
        // A property: its name, its value's index, how many values it takes.
        type Property = (&'static str, fn(&GlassesStyle) -> u32, u32);
        let styles: Vec<GlassesStyle> = (0..320).map(style_for).collect();
        let props: [Property; 6] = [
            (
                "shape",
                |s| match s.shape {
                    LensShape::Ellipse => 0,
                    LensShape::RoundedRect(r) => 1 + (r < 0.2) as u32,
                },
                3,
            ),
            ("width", |s| ((s.width_ipd - 0.6) * 10.0).round() as u32, 3),
            ("aspect", |s| ((s.aspect - 0.6) * 10.0).round() as u32, 3),
            ("opacity", |s| ((1.0 - s.opacity) / 0.15).round() as u32, 3),
            (
                "rim",
                |s| if s.rim_ipd > 0.05 { 2 } else { (s.rim_ipd > 0.0) as u32 },
                3,
            ),
            ("reflection", |s| (s.reflection > 0.0) as u32, 2),
        ];
        for (i, (a, fa, na)) in props.iter().enumerate() {
            for (b, fb, nb) in &props[i + 1..] {
                let mut counts = vec![0u32; (na * nb) as usize];
                for s in &styles {
                    counts[(fa(s) * nb + fb(s)) as usize] += 1;
                }
                let share = styles.len() as f32 / (na * nb) as f32;
                // The rim's three values are not even (cardboard half, plastic and none a quarter).
                let least = if *a == "rim" || *b == "rim" { 0.25 } else { 0.5 } * share;
                assert!(
                    counts.iter().all(|&c| c as f32 >= least),
                    "{a} × {b}: {counts:?} (even share {share})"
                );
            }
        }
    }

    #[test]
    fn a_lens_filters_what_is_under_it_and_nothing_else() {
        let (w, h) = (64u32, 32u32);
        let mut img = vec![180u8; (w * h * 4) as usize];
        let style = GlassesStyle {
            filters: (Filter::Red, Filter::Cyan),
            shape: LensShape::Ellipse,
            width_ipd: 0.7,
            aspect: 0.7,
            opacity: 1.0,
            rim_ipd: 0.0,
            rim_rgb: [0, 0, 0],
            reflection: 0.0,
            spacing_ipd: 1.0,
            drop_ipd: 0.0,
            shift_ipd: 0.0,
            tilt_rad: 0.0,
            tints: None,
        };
        draw(&mut img, w, h, Vec2::new(16.0, 16.0), Vec2::new(48.0, 16.0), &style);
        let px = |x: u32, y: u32| {
            let i = ((y * w + x) * 4) as usize;
            [img[i], img[i + 1], img[i + 2]]
        };
        let (red, cyan, between) = (px(16, 16), px(48, 16), px(32, 2));
        assert!(red[0] > 150 && red[1] < 80 && red[2] < 80, "{red:?}");
        assert!(cyan[0] < 80 && cyan[1] > 140 && cyan[2] > 150, "{cyan:?}");
        assert_eq!(between, [180, 180, 180]);
        // A fresh grey picture with `style` drawn over eyes at (16, y) and (48, y), and one of
        // its pixels.
        let drawn = |style: GlassesStyle, eye_y: f32| {
            let mut img = vec![180u8; (w * h * 4) as usize];
            draw(&mut img, w, h, Vec2::new(16.0, eye_y), Vec2::new(48.0, eye_y), &style);
            img
        };
        let at = |img: &[u8], x: u32, y: u32| {
            let i = ((y * w + x) * 4) as usize;
            [img[i], img[i + 1], img[i + 2]]
        };
        // Lenses sitting low (by 0.3 of the eye distance, more than half a lens height) leave
        // the eye's own pixel clear and tint below it.
        let low = drawn(GlassesStyle { drop_ipd: 0.3, ..style }, 10.0);
        assert_eq!(at(&low, 16, 10), [180, 180, 180]);
        assert!(at(&low, 16, 20)[1] < 80, "{:?}", at(&low, 16, 20));
        // Lenses spaced wider than the eyes: the pixel beside the eye, outwards, is tinted, the
        // one inwards (still inside a centred lens) is not.
        let wide = drawn(
            GlassesStyle {
                spacing_ipd: 1.5,
                ..style
            },
            16.0,
        );
        assert!(at(&wide, 6, 16)[1] < 80, "{:?}", at(&wide, 6, 16));
        assert_eq!(at(&wide, 24, 16), [180, 180, 180]);
        // A frame shifted towards the image-right eye by 0.5 of the eye distance: the red lens
        // sits on the midpoint, the left eye is clear.
        let shifted = drawn(
            GlassesStyle {
                shift_ipd: 0.5,
                ..style
            },
            16.0,
        );
        assert_eq!(at(&shifted, 10, 16), [180, 180, 180]);
        assert!(at(&shifted, 32, 16)[1] < 80, "{:?}", at(&shifted, 32, 16));
        // A frame turned by 20° clockwise: the image-right lens sits lower (by about 5 px at 16
        // px from the middle), so below the right eye is tinted and above it is not.
        let tilted = drawn(
            GlassesStyle {
                tilt_rad: 20f32.to_radians(),
                width_ipd: 0.4,
                aspect: 0.5,
                ..style
            },
            16.0,
        );
        assert!(at(&tilted, 48, 23)[0] < 80, "{:?}", at(&tilted, 48, 23));
        assert_eq!(at(&tilted, 48, 14), [180, 180, 180]);
        assert!(at(&tilted, 16, 9)[1] < 80, "{:?}", at(&tilted, 16, 9));
        // Ordinary glasses: both lenses grey, the filters ignored.
        let grey = drawn(
            GlassesStyle {
                tints: Some([[0.2; 3]; 2]),
                ..style
            },
            16.0,
        );
        for x in [16, 48] {
            let c = at(&grey, x, 16);
            assert!(c[0] == c[1] && c[1] == c[2] && c[0] < 120, "{c:?}");
        }
        // Eyes on one pixel, or nonsense: nothing drawn, no panic.
        let before = img.clone();
        draw(&mut img, w, h, Vec2::new(5.0, 5.0), Vec2::new(5.0, 5.0), &style);
        draw(&mut img, w, h, Vec2::new(f32::NAN, 5.0), Vec2::new(5.0, 5.0), &style);
        draw(&mut img, w, h, Vec2::new(-500.0, 5.0), Vec2::new(900.0, 5.0), &style);
        assert!(img.len() == before.len());
    }
}
