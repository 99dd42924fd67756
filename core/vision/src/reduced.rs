//! The upright camera image at half and a quarter of its resolution, for crops that shrink a lot.
//!
//! A crop whose output pixel covers `step` source pixels must average about `step²` of them or
//! it aliases. Sampling the full image with ⌈step/2⌉² bilinear taps per output pixel (up to 9)
//! was a fifth of the face tracker's time (perf, 2026-12-03: `UprightImage::bilinear` and
//! `Roi::tensor` 20 % of the face bench's samples): BlazeFace's crop of a whole 640 × 480 frame
//! into 128² and FaceMesh's of a large face into 192² each took ~150 000 taps. A level made once
//! per frame by 2 × 2 box averages (each level a quarter of the one above) lets such a crop take
//! one tap per output pixel from the level where its step is at most two pixels, as the taps
//! did before; crops that shrink little (the irises) still read the frame itself.
//!
//! Coordinates: a level-`k` pixel `(i, j)` covers upright pixels `[2ᵏ·i, 2ᵏ·(i + 1))` and likewise
//! in y, so upright position `p` (pixel centres at half-integers) is `p / 2ᵏ` there. An odd last
//! row or column of the level above is left out (half a pixel at the border).
//!
//! **Panics**: none; a level of an image smaller than 2 × 2 is empty and reads black.

use glam::Vec2;

/// One reduced level: RGB, 8 bits per channel (a 2 × 2 mean rounded: within half a code of the
/// exact mean), rows top to bottom, upright.
#[derive(Debug, Default)]
pub(crate) struct Reduced {
    pub width: u32,
    pub height: u32,
    rgb: Vec<[u8; 3]>,
}

impl Reduced {
    /// Half of an image of `width × height`; `row(y)` gives the reader of upright row `y`'s
    /// pixels by x (in range). A reader per row lets the caller find the row's start once
    /// instead of per pixel (the camera frame's rotation and stride: this was a millisecond a
    /// frame when every pixel was placed afresh).
    pub fn half_of<R: Fn(u32) -> [u8; 3]>(width: u32, height: u32, row: impl Fn(u32) -> R) -> Self {
        let (w, h) = (width / 2, height / 2);
        let mut rgb = Vec::with_capacity(w as usize * h as usize);
        for j in 0..h {
            let (upper, lower) = (row(2 * j), row(2 * j + 1));
            for i in 0..w {
                let mut sum = [2u16; 3]; // + 2: round the quarter to nearest
                for c in [upper(2 * i), upper(2 * i + 1), lower(2 * i), lower(2 * i + 1)] {
                    for k in 0..3 {
                        sum[k] += u16::from(c[k]);
                    }
                }
                rgb.push(sum.map(|s| (s / 4) as u8));
            }
        }
        Self {
            width: w,
            height: h,
            rgb,
        }
    }

    /// Half of this level.
    pub fn half(&self) -> Self {
        let w = self.width as usize;
        Self::half_of(self.width, self.height, |y| {
            let row = &self.rgb[y as usize * w..(y as usize + 1) * w];
            move |x: u32| row[x as usize]
        })
    }

    /// Bilinear RGB in [0, 1] at position `p` of this level (pixel centres at half-integers);
    /// black outside, as the full image reads.
    pub fn bilinear(&self, p: Vec2) -> [f32; 3] {
        let (x, y) = (p.x - 0.5, p.y - 0.5);
        if !(x.is_finite() && y.is_finite()) {
            return [0.0; 3];
        }
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let (xi, yi) = (x0 as i64, y0 as i64);
        let mut out = [0.0f32; 3];
        for (dx, dy, w) in [
            (0, 0, (1.0 - fx) * (1.0 - fy)),
            (1, 0, fx * (1.0 - fy)),
            (0, 1, (1.0 - fx) * fy),
            (1, 1, fx * fy),
        ] {
            let (px, py) = (xi + dx, yi + dy);
            if px < 0 || py < 0 || px >= i64::from(self.width) || py >= i64::from(self.height) {
                continue;
            }
            let c = self.rgb[py as usize * self.width as usize + px as usize];
            for k in 0..3 {
                out[k] += f32::from(c[k]) * w;
            }
        }
        out.map(|v| v * (1.0 / 255.0))
    }
}

/// The level a crop whose output pixel covers `step` upright pixels samples (0: the image
/// itself), and the step there: the first level where the step is at most two pixels, at most
/// `levels`.
pub(crate) fn level_for(step: f32, levels: usize) -> (usize, f32) {
    let mut k = 0;
    let mut s = step;
    while s > 2.0 && k < levels {
        k += 1;
        s *= 0.5;
    }
    (k, s)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_level_averages_its_two_by_two_blocks_and_samples_at_the_same_places() {
        // 5 × 4: the odd last column is left out.
        let px = |y: u32| move |x: u32| [(x * 40 + y * 3) as u8, (y * 50) as u8, 200];
        let half = Reduced::half_of(5, 4, px);
        assert_eq!((half.width, half.height), (2, 2));
        // Block (1, 1): upright pixels x 2–3, y 2–3, which cover [2, 4)²: centre upright (3, 3),
        // the level's (1.5, 1.5).
        let want = [
            (86 + 126 + 89 + 129) as f32 / 4.0,
            (100 + 100 + 150 + 150) as f32 / 4.0,
            200.0,
        ];
        let got = half.bilinear(Vec2::new(3.0, 3.0) / 2.0).map(|v| v * 255.0);
        for k in 0..3 {
            assert!((got[k] - want[k]).abs() <= 0.501, "channel {k}: {got:?} vs {want:?}");
        }
        // Between the centres, the bilinear mix; outside, black.
        let mid = half.bilinear(Vec2::new(1.0, 1.5));
        let (a, b) = (half.bilinear(Vec2::new(0.5, 1.5)), half.bilinear(Vec2::new(1.5, 1.5)));
        assert!((mid[0] - 0.5 * (a[0] + b[0])).abs() < 1e-6);
        assert_eq!(half.bilinear(Vec2::new(-3.0, 1.0)), [0.0; 3]);
        assert_eq!(half.bilinear(Vec2::new(f32::NAN, 1.0)), [0.0; 3]);
        // A level of a level; an image too small for one.
        assert_eq!((half.half().width, half.half().height), (1, 1));
        assert_eq!(Reduced::half_of(1, 7, px).rgb.len(), 0);
    }

    #[test]
    fn the_level_is_the_first_where_a_step_is_two_pixels_or_less() {
        assert_eq!(level_for(0.7, 2), (0, 0.7));
        assert_eq!(level_for(2.0, 2), (0, 2.0));
        assert_eq!(level_for(2.7, 2), (1, 1.35));
        assert_eq!(level_for(5.0, 2), (2, 1.25));
        assert_eq!(level_for(12.0, 2), (2, 3.0));
    }
}
