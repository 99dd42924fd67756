//! What the camera never saw, filled: the room map's holes from what was seen around them
//! (`fill_unseen`, used by [`crate::RoomCapture::environment`]). Pull-push over a pyramid of
//! solid-angle-weighted means for gaps near what was seen, the band of elevation seen nearest
//! for larger regions, and a floor lit by the room where nothing below the horizon was seen.
//!
//! **Threading**: a pure function. **Panics**: none; its one caller, [`crate::RoomCapture`],
//! passes its own map, whose sizes agree.

use phantogram_assets::ibl::Environment;

/// How far from what was seen a hole is filled from its neighbourhood, degrees; beyond, from the
/// band seen nearest to it on its side of the horizon ([`crate::RoomCapture::environment`]). A few
/// texels of the map's default 1.4°, and well under the 60–70° a phone camera sees at once: the
/// gaps between overlapping frames are filled locally, a region no frame has looked at is not.
pub const LOCAL_FILL_DEG: f32 = 11.25;

/// The reflectance of a floor or the ground, for a lower hemisphere nothing has been seen of
/// (`fill_unseen`): 0.2, daylighting practice's usual value for both (floors are
/// taken as 0.2–0.3, the ground outdoors as 0.2). Not fitted to the shared rooms; on their truth
/// the lower hemisphere's mean over the upper's cosine-weighted mean (an effective reflectance
/// that includes the walls below eye level) runs from 0.10 (a city street) to 0.91 (the
/// apartment), 0.26 geometric mean.
pub const UNSEEN_FLOOR_REFLECTANCE: f32 = 0.2;

/// The room map as an environment (relative radiance, world frame), what was never seen filled.
/// `rgb` and `weight` are the map's `width` × `height` texels, row 0 the zenith: the radiance
/// seen and its weight, the texel's solid angle where seen, 0 where not (its radiance is then
/// ignored). What was never seen is filled by its distance from what was:
/// - a gap within [`LOCAL_FILL_DEG`] of what was seen takes the light seen nearest to it, by
///   pull-push (Gortler et al., "The Lumigraph", 1996): a pyramid of solid-angle-weighted
///   means, each hole taking the value of the finest level that has data above it;
/// - a larger unseen region — in practice the floor, which a visitor's sweep sees last —
///   takes the light of the band seen nearest to it in elevation on its side of the horizon:
///   at the coarsest level of the pyramid (rows of [`LOCAL_FILL_DEG`]), the solid-angle-
///   weighted mean of that row's seen cells, the same at every azimuth. A room's light
///   changes mostly with elevation (ceiling and lamps, walls and windows, floor), and the
///   mean over a whole band keeps one bright object near the edge of what was seen from
///   standing for the floor;
/// - where nothing below the horizon has been seen (a front camera held up before the face
///   sees the ceiling and the room behind the viewer first), the lower hemisphere is a floor
///   lit by the upper one: [`UNSEEN_FLOOR_REFLECTANCE`] × the upper hemisphere's irradiance
///   on it / π, the same everywhere below. The horizon's band would stand for it otherwise,
///   and what lies along the horizon is often a window: along the shared `tilt-sweep` log in
///   the apartment (19 % seen, none of it below the horizon), the band just above the horizon
///   has 5.4 times the apartment's mean luminance, and the map's mean was 3.7 times the
///   room's. (An upper hemisphere wholly unseen still takes the lower's nearest band: the
///   lights a floor does not show cannot be guessed.)
///
/// Measured on the nine shared rooms swept to 80 % (`room_light.rs`, the floor seen last),
/// irradiance relative RMS: pull-push all the way (the strip seen nearest to each hole)
/// 0.4–20.6 %; the mean of everything seen on the hole's side of the horizon 0.6–8.9 % (mean
/// 2.7 %); the nearest band (now) 0.1–5.9 % (mean 1.8 %; worse only on the esplanade, 2.2 →
/// 2.7 %). The best single value for the unseen part, chosen knowing the truth, gives
/// 0.2–5.6 %; the worst is the apartment each time, whose floor darkens towards the nadir
/// below anything seen. Checked on two other sweep orders as well (not in the test): the
/// ceiling seen last, where an unseen sun dominates any fill, mean 31.4 → 26.4 % (three
/// rooms worse); bands taken alternately above and below the horizon, 17.0 → 13.1 % (two
/// worse).
/// Those figures are for a sweep started at azimuth 0. Started at each of eight azimuths, the
/// nearest band has a mean of 2.4 % and a worst of 11.1 % (the apartment, where the partly seen
/// band nearest the floor holds the window's sunlit patch), and is still the best of the fills
/// measured (`benchmarks/ibl.md`, eighth session).
/// The reach was set at 11.25° before any of this; with the nearest band, 5.6° gives a worst
/// of 10.2 % (the apartment), 22.5° and 45° 6.1 %, the other rooms within 4.7 % at every reach.
///
/// All zero where nothing was seen.
pub(crate) fn fill_unseen(width: usize, height: usize, rgb: Vec<[f32; 3]>, weight: Vec<f32>) -> Environment {
    // (width, height, radiance, weight) per level, finest first.
    type Level = (usize, usize, Vec<[f32; 3]>, Vec<f32>);
    let mut levels: Vec<Level> = vec![(width, height, rgb, weight)];
    // Pull: halve while a cell of the next level stays within the local reach, each cell the
    // weighted mean of its children.
    let coarsest_height = (180.0 / LOCAL_FILL_DEG).ceil() as usize;
    while let Some((w, h, rgb, weight)) = levels.last()
        && *h / 2 >= coarsest_height
    {
        let (pw, ph) = (w / 2, h / 2);
        let (mut prgb, mut pweight) = (vec![[0.0f32; 3]; pw * ph], vec![0.0f32; pw * ph]);
        for y in 0..ph {
            for x in 0..pw {
                let (mut acc, mut total) = ([0.0f32; 3], 0.0f32);
                for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                    let i = (2 * y + dy) * w + 2 * x + dx;
                    for c in 0..3 {
                        acc[c] += rgb[i][c] * weight[i];
                    }
                    total += weight[i];
                }
                if total > 0.0 {
                    prgb[y * pw + x] = acc.map(|v| v / total);
                    pweight[y * pw + x] = total;
                }
            }
        }
        levels.push((pw, ph, prgb, pweight));
    }
    // The coarsest level: holes there take the mean of the row nearest to them, in elevation
    // and on their side of the horizon, that has seen cells.
    if let Some((w, h, rgb, weight)) = levels.last_mut() {
        let (w, h) = (*w, *h);
        let upper = |row: usize| 2 * row + 1 < h;
        let row_mean = |row: usize| -> Option<[f32; 3]> {
            let (mut sum, mut total) = ([0.0f32; 3], 0.0f32);
            for i in row * w..(row + 1) * w {
                for c in 0..3 {
                    sum[c] += rgb[i][c] * weight[i];
                }
                total += weight[i];
            }
            (total > 0.0).then(|| sum.map(|s| s / total))
        };
        let means: Vec<Option<[f32; 3]>> = (0..h).map(row_mean).collect();
        let fill: Vec<Option<[f32; 3]>> = (0..h)
            .map(|row| {
                (0..h)
                    .filter(|&r| upper(r) == upper(row) && means[r].is_some())
                    .min_by_key(|&r| r.abs_diff(row))
                    .or_else(|| (0..h).filter(|&r| means[r].is_some()).min_by_key(|&r| r.abs_diff(row)))
                    .and_then(|r| means[r])
            })
            .collect();
        for (i, (v, wt)) in rgb.iter_mut().zip(weight.iter()).enumerate() {
            if *wt <= 0.0 {
                *v = fill[i / w].unwrap_or([0.0; 3]);
            }
        }
        let lower_unseen = (0..h).filter(|&r| !upper(r)).all(|r| means[r].is_none());
        let upper_seen = (0..h).any(|r| upper(r) && means[r].is_some());
        if lower_unseen && upper_seen {
            let floor = lit_floor(w, h, rgb).map(|e| e * UNSEEN_FLOOR_REFLECTANCE);
            for (i, v) in rgb.iter_mut().enumerate() {
                if !upper(i / w) {
                    *v = floor;
                }
            }
        }
    }
    // Push: each hole takes its parent's (already filled) value.
    for k in (0..levels.len() - 1).rev() {
        let (upper, lower) = levels.split_at_mut(k + 1);
        let (w, _, rgb, weight) = &mut upper[k];
        let (pw, ph, prgb, _) = &lower[0];
        for (i, v) in rgb.iter_mut().enumerate() {
            if weight[i] <= 0.0 {
                let (x, y) = (i % *w, i / *w);
                *v = prgb[(y / 2).min(ph - 1) * pw + (x / 2).min(pw - 1)];
            }
        }
    }
    let (width, height, texels, _) = levels.swap_remove(0);
    Environment { width, height, texels }
}

/// The irradiance that the upper half of an equirectangular map (`w` × `h` cells, row 0 the
/// zenith, every cell filled) casts on an upward-facing floor, over π: the radiance a white
/// Lambertian floor would have. Each row's cells share one solid angle, so a row counts by its
/// mean times cos θ sin θ over its band.
fn lit_floor(w: usize, h: usize, rgb: &[[f32; 3]]) -> [f32; 3] {
    let dtheta = std::f32::consts::PI / h as f32;
    let mut e = [0.0f32; 3];
    for row in 0..h / 2 {
        let theta = (row as f32 + 0.5) * dtheta;
        let mut mean = [0.0f32; 3];
        for t in &rgb[row * w..(row + 1) * w] {
            for c in 0..3 {
                mean[c] += t[c] / w as f32;
            }
        }
        // ∫ L cos θ dω / π over the band: 2π · mean · cos θ sin θ dθ / π.
        for c in 0..3 {
            e[c] += 2.0 * mean[c] * theta.cos() * theta.sin() * dtheta;
        }
    }
    e
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_large_hole_takes_the_nearest_band_seen_on_its_side_and_a_small_one_its_neighbours() {
        // The default room map's size (256 × 128), each seen texel weighted by its solid angle.
        let (w, h) = (256usize, 128usize);
        let row_solid_angle = |y: usize| {
            let d_theta = std::f32::consts::PI / h as f32;
            ((y as f32 + 0.5) * d_theta).sin() * d_theta * std::f32::consts::TAU / w as f32
        };
        let (mut rgb, mut weight) = (vec![[0.0f32; 3]; w * h], vec![0.0f32; w * h]);
        let elevation_deg = |y: usize| 90.0 - (y as f32 + 0.5) * 180.0 / h as f32;
        // Seen: from 67.5° up (a ceiling of 20, the zenith cap unseen) down to 30° below the
        // horizon, but for a gap one texel wide in the walls at column 10. Walls above the
        // horizon 10, below 1; on the lowest band seen (25–30° down) 4 over one half of the
        // azimuths and 2 over the other.
        let value = |x: usize, e: f32| {
            if e > 67.5 {
                20.0
            } else if e > 0.0 {
                10.0
            } else if e < -25.0 {
                if x < w / 2 { 4.0 } else { 2.0 }
            } else {
                1.0
            }
        };
        // The band of the coarsest level (11.25° rows) nearest the floor: 22.5° to 33.75° down.
        let (mut band_sum, mut band_weight) = (0.0f32, 0.0f32);
        for y in 0..h {
            let e = elevation_deg(y);
            for x in 0..w {
                if !(-30.0..=80.0).contains(&e) || (x == 10 && e.abs() < 20.0) {
                    continue;
                }
                let v = value(x, e);
                rgb[y * w + x] = [v; 3];
                weight[y * w + x] = row_solid_angle(y);
                if (-33.75..-22.5).contains(&e) {
                    band_sum += v * row_solid_angle(y);
                    band_weight += row_solid_angle(y);
                }
            }
        }
        let env = fill_unseen(w, h, rgb, weight);
        let at = |x: usize, y: usize| env.texels[y * w + x][0];
        let band_mean = band_sum / band_weight;
        // 1 from 22.5° to 25°, 3 (the halves' mean) from 25° to 30°.
        assert!((2.0..3.0).contains(&band_mean), "{band_mean}");
        // Beyond the local reach: the floor takes that band's light, the same at every azimuth
        // (not the half nearest to it, nor the mean of everything below the horizon, ~1.3).
        for y in (0..h).filter(|y| elevation_deg(*y) < -34.0) {
            for x in [0, w / 4, w / 2, w - 1] {
                assert!(
                    (at(x, y) - band_mean).abs() < 0.01 * band_mean,
                    "floor at ({x}, {y}): {} against the nearest band's {band_mean}",
                    at(x, y)
                );
            }
        }
        // Within the local reach: the zenith cap (80° to 90° up) from the ceiling around it, and
        // the one-texel gap in the walls from its neighbours.
        assert!((at(w / 3, 0) - 20.0).abs() < 1e-3, "zenith: {}", at(w / 3, 0));
        for (y, want) in [(h / 2 - 5, 10.0), (h / 2 + 5, 1.0)] {
            assert!((at(10, y) - want).abs() < 1e-3, "gap at row {y}: {}", at(10, y));
        }
    }
}
