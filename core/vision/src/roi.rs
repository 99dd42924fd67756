//! [`Roi`]: a rotated square region of the upright image, the crop a network reads, and its
//! resampling into a network's input tensor.

use crate::upright::REDUCED_LEVELS;
use crate::{UprightImage, reduced};
use glam::Vec2;

/// A rotated square region of the upright image, pixels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Roi {
    pub(crate) centre: Vec2,
    pub(crate) size: f32,
    /// Angle of the region's x axis from the image's x axis, towards +y (down), radians.
    pub(crate) angle: f32,
}

impl Roi {
    /// Image position of the region's normalised point `(a, b)` ∈ [0, 1]² (mirrored in a when
    /// `flip`).
    pub(crate) fn image_point(&self, a: f32, b: f32, flip: bool) -> Vec2 {
        let a = if flip { 1.0 - a } else { a };
        let (s, c) = self.angle.sin_cos();
        let (x, y) = ((a - 0.5) * self.size, (b - 0.5) * self.size);
        self.centre + Vec2::new(c * x - s * y, s * x + c * y)
    }

    /// The region resampled to `n × n`, NCHW, values mapped from [0, 1] to `range`.
    pub(crate) fn tensor(&self, image: &UprightImage, n: usize, range: (f32, f32), flip: bool) -> Vec<f32> {
        self.tensor_with(image, n, range, flip, |_, c| c)
    }

    /// As [`Self::tensor`], each output pixel's colour (in [0, 1]) passed through `correct` with
    /// its image position first (a lens's tint undone where it is).
    pub(crate) fn tensor_with(
        &self,
        image: &UprightImage,
        n: usize,
        range: (f32, f32),
        flip: bool,
        correct: impl Fn(Vec2, [f32; 3]) -> [f32; 3],
    ) -> Vec<f32> {
        let mut out = vec![0.0f32; 3 * n * n];
        // The pixel footprint may shrink a lot (a 1000-px face into 192): sample the reduced
        // level where an output pixel covers at most two of its pixels, and average a few samples
        // per output pixel beyond that so the crop does not alias. A bilinear sample already
        // averages over about two source pixels, so ⌈step / 2⌉ of them per axis cover one.
        let (level, step) = reduced::level_for(self.size / n as f32, REDUCED_LEVELS);
        let taps = ((step * 0.5).ceil() as usize).clamp(1, 3);
        let reduced = (level > 0).then(|| (image.level(level), 1.0 / (1u32 << level) as f32));
        let sample = |p: Vec2| match reduced {
            Some((r, scale)) => r.bilinear(p * scale),
            None => image.bilinear(p),
        };
        let (lo, hi) = range;
        // `image_point` is affine in (a, b): its origin and two steps, turned once (not per
        // sample: a sine and cosine per sample cost more than the sampling).
        let origin = self.image_point(0.0, 0.0, flip);
        let (du, dv) = (
            self.image_point(1.0, 0.0, flip) - origin,
            self.image_point(0.0, 1.0, flip) - origin,
        );
        // One output pixel is `du / n` and `dv / n` in the image, a tap a `taps`-th of that; the
        // offsets of the taps from a pixel's corner are the same for every pixel.
        let (pixel_u, pixel_v) = (du / n as f32, dv / n as f32);
        let tap_offsets: Vec<Vec2> = (0..taps * taps)
            .map(|t| {
                let (tx, ty) = ((t % taps) as f32 + 0.5, (t / taps) as f32 + 0.5);
                (pixel_u * tx + pixel_v * ty) / taps as f32
            })
            .collect();
        let norm = 1.0 / (taps * taps) as f32;
        let plane = n * n;
        for j in 0..n {
            let row = origin + pixel_v * j as f32;
            for i in 0..n {
                let corner = row + pixel_u * i as f32;
                let mut acc = [0.0f32; 3];
                for offset in &tap_offsets {
                    let c = sample(corner + *offset);
                    for k in 0..3 {
                        acc[k] += c[k];
                    }
                }
                let centre = corner + (pixel_u + pixel_v) * 0.5;
                let c = correct(centre, acc.map(|v| v * norm));
                for k in 0..3 {
                    out[k * plane + j * n + i] = lo + (hi - lo) * c[k];
                }
            }
        }
        out
    }

    /// The square region around `points` in the frame rotated so that `from → to` is
    /// horizontal, scaled by `scale`.
    pub(crate) fn around(points: impl Iterator<Item = Vec2> + Clone, from: Vec2, to: Vec2, scale: f32) -> Self {
        let angle = (to.y - from.y).atan2(to.x - from.x);
        let (s, c) = angle.sin_cos();
        // Into the rotated frame: x' = c·x + s·y, y' = −s·x + c·y.
        let (mut min, mut max) = (Vec2::splat(f32::INFINITY), Vec2::splat(f32::NEG_INFINITY));
        for p in points {
            let q = Vec2::new(c * p.x + s * p.y, -s * p.x + c * p.y);
            min = min.min(q);
            max = max.max(q);
        }
        let mid = (min + max) * 0.5;
        let centre = Vec2::new(c * mid.x - s * mid.y, s * mid.x + c * mid.y);
        let extent = max - min;
        Self {
            centre,
            size: extent.x.max(extent.y) * scale,
            angle,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn roi_maps_its_corners_with_rotation_and_flip() {
        let roi = Roi {
            centre: Vec2::new(100.0, 50.0),
            size: 20.0,
            angle: std::f32::consts::FRAC_PI_2,
        };
        // The region's x axis points down the image.
        assert!(roi.image_point(1.0, 0.5, false).distance(Vec2::new(100.0, 60.0)) < 1e-4);
        assert!(roi.image_point(1.0, 0.5, true).distance(Vec2::new(100.0, 40.0)) < 1e-4);
        // `around` recovers a rotated square from its corners.
        let corners: Vec<Vec2> = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]
            .iter()
            .map(|&(a, b)| roi.image_point(a, b, false))
            .collect();
        let back = Roi::around(corners.iter().copied(), corners[0], corners[1], 1.0);
        assert!(back.centre.distance(roi.centre) < 1e-3 && (back.size - 20.0).abs() < 1e-3);
        assert!((back.angle - roi.angle).abs() < 1e-5);
    }
}
