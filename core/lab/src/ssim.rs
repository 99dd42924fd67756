//! The structural similarity index (SSIM, Wang, Bovik, Sheikh and Simoncelli 2004) of two
//! RGBA8 frames: how alike a simplified render looks to the full one, as a viewer judges it
//! (structure and contrast, not exact values).
//!
//! As the paper defines it: on luma (Rec. 601 weights of the stored 8-bit values), Gaussian
//! windows of σ = 1.5 px (11 taps), C₁ = (0.01·255)², C₂ = (0.03·255)², the mean over every
//! pixel whose window lies inside the frame.

/// Errors of [`ssim_rgba8`].
#[derive(Debug, thiserror::Error, PartialEq, Eq)]
pub enum SsimError {
    #[error("the frames are not {width}×{height} RGBA8 ({a} and {b} bytes)")]
    Size {
        width: u32,
        height: u32,
        a: usize,
        b: usize,
    },
    #[error("a {width}×{height} frame is smaller than the 11-pixel window")]
    TooSmall { width: u32, height: u32 },
}

const RADIUS: usize = 5;

/// The mean SSIM of two `width × height` RGBA8 frames (1 for identical frames).
pub fn ssim_rgba8(a: &[u8], b: &[u8], width: u32, height: u32) -> Result<f64, SsimError> {
    let (w, h) = (width as usize, height as usize);
    if a.len() != w * h * 4 || b.len() != w * h * 4 {
        return Err(SsimError::Size {
            width,
            height,
            a: a.len(),
            b: b.len(),
        });
    }
    if w < 2 * RADIUS + 1 || h < 2 * RADIUS + 1 {
        return Err(SsimError::TooSmall { width, height });
    }
    let luma = |p: &[u8]| -> Vec<f32> {
        p.chunks_exact(4)
            .map(|c| 0.299 * f32::from(c[0]) + 0.587 * f32::from(c[1]) + 0.114 * f32::from(c[2]))
            .collect()
    };
    let (x, y) = (luma(a), luma(b));
    let xx: Vec<f32> = x.iter().map(|v| v * v).collect();
    let yy: Vec<f32> = y.iter().map(|v| v * v).collect();
    let xy: Vec<f32> = x.iter().zip(&y).map(|(p, q)| p * q).collect();
    let kernel = gaussian();
    let [mx, my, sxx, syy, sxy] = [&x, &y, &xx, &yy, &xy].map(|f| blur(f, w, h, &kernel));
    let (c1, c2) = ((0.01f64 * 255.0).powi(2), (0.03f64 * 255.0).powi(2));
    let mut sum = 0.0f64;
    let mut count = 0usize;
    for row in RADIUS..h - RADIUS {
        for col in RADIUS..w - RADIUS {
            let i = row * w + col;
            let (mx, my) = (f64::from(mx[i]), f64::from(my[i]));
            let vx = f64::from(sxx[i]) - mx * mx;
            let vy = f64::from(syy[i]) - my * my;
            let cov = f64::from(sxy[i]) - mx * my;
            sum += ((2.0 * mx * my + c1) * (2.0 * cov + c2)) / ((mx * mx + my * my + c1) * (vx + vy + c2));
            count += 1;
        }
    }
    Ok(sum / count as f64)
}

fn gaussian() -> [f32; 2 * RADIUS + 1] {
    let mut k = [0.0f32; 2 * RADIUS + 1];
    for (i, v) in k.iter_mut().enumerate() {
        let d = i as f32 - RADIUS as f32;
        *v = (-d * d / (2.0 * 1.5 * 1.5)).exp();
    }
    let total: f32 = k.iter().sum();
    k.map(|v| v / total)
}

/// Separable blur; only the interior (where the window fits) is meaningful.
fn blur(f: &[f32], w: usize, h: usize, k: &[f32]) -> Vec<f32> {
    let mut across = vec![0.0f32; w * h];
    for row in 0..h {
        for col in RADIUS..w - RADIUS {
            across[row * w + col] = k
                .iter()
                .enumerate()
                .map(|(t, kv)| kv * f[row * w + col + t - RADIUS])
                .sum();
        }
    }
    let mut out = vec![0.0f32; w * h];
    for row in RADIUS..h - RADIUS {
        for col in 0..w {
            out[row * w + col] = k
                .iter()
                .enumerate()
                .map(|(t, kv)| kv * across[(row + t - RADIUS) * w + col])
                .sum();
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame(w: usize, h: usize, f: impl Fn(usize, usize) -> u8) -> Vec<u8> {
        (0..w * h)
            .flat_map(|i| [f(i % w, i / w); 3].into_iter().chain([255]))
            .collect()
    }

    #[test]
    fn identical_frames_score_one_and_damage_scores_less() {
        let (w, h) = (64, 48);
        let a = frame(w, h, |x, y| ((x * 7 + y * 3) % 200) as u8);
        assert!((ssim_rgba8(&a, &a, 64, 48).unwrap() - 1.0).abs() < 1e-9);
        // A one-pixel shift of a textured frame is a visible change.
        let shifted = frame(w, h, |x, y| (((x + 1) * 7 + y * 3) % 200) as u8);
        let s = ssim_rgba8(&a, &shifted, 64, 48).unwrap();
        assert!(s < 0.9, "{s}");
        // Adding a small constant barely matters (luminance term only).
        let brighter = frame(w, h, |x, y| ((x * 7 + y * 3) % 200) as u8 + 2);
        let s = ssim_rgba8(&a, &brighter, 64, 48).unwrap();
        assert!(s > 0.99, "{s}");
    }

    #[test]
    fn wrong_sizes_are_errors() {
        let a = vec![0u8; 64 * 48 * 4];
        assert!(matches!(ssim_rgba8(&a, &a[4..], 64, 48), Err(SsimError::Size { .. })));
        assert_eq!(
            ssim_rgba8(&a[..8 * 8 * 4], &a[..8 * 8 * 4], 8, 8),
            Err(SsimError::TooSmall { width: 8, height: 8 })
        );
    }
}
