//! What the camera never saw, filled: the room map's holes from what was seen around them
//! (`fill_unseen`, used by [`crate::RoomCapture::environment`]). Pull-push over a pyramid of
//! solid-angle-weighted means for gaps near what was seen, the band of elevation seen nearest
//! for larger regions, and a floor lit by the room where nothing below the horizon was seen.
//!
//! **Threading**: a pure function. **Panics**: none; its one caller, [`crate::RoomCapture`],
//! passes its own map, whose sizes agree.

use phantogram_assets::ibl::Environment;
use phantogram_geometry::srgb::luminance;

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
///   at the coarsest level of the pyramid (rows of [`LOCAL_FILL_DEG`]), that row's mean over
///   every azimuth, the same at every azimuth. A room's light changes mostly with elevation
///   (ceiling and lamps, walls and windows, floor), and the mean over a whole band keeps one
///   bright object near the edge of what was seen from standing for the floor. Where that band
///   was seen over part of its azimuths only, its mean is estimated from the band seen at every
///   azimuth nearer the horizon (`band_means`: a ratio estimate), because the part of a ring a
///   sweep sees first is not a fair sample of it;
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
/// Measured on the nine shared rooms swept to 80 % (`room_light.rs`, the floor seen last, from
/// azimuth 0), irradiance relative RMS: pull-push all the way (the strip seen nearest to each
/// hole) 0.4–20.6 %; the mean of everything seen on the hole's side of the horizon 0.6–8.9 %
/// (mean 2.7 %); the nearest band's seen mean 0.1–5.9 % (mean 1.8 %); with that mean estimated
/// for every azimuth (now) 0.2–3.4 % (the apartment). Over eight starting azimuths (every 45°,
/// 72 room × start cases): the seen mean 2.36 % on average, worst 11.1 %, 11 cases over 5 %;
/// the ratio estimate 2.09 %, 9.6 %, 8 cases (37 cases better, 15 worse by at most 1.8 points;
/// `benchmarks/ibl.md`, ninth session). Its auxiliary band is the nearest one seen everywhere:
/// the band just inside, itself often seen in part, gave 2.25 %, 10.1 %, 10 cases. The worst
/// is the apartment each time, where the band nearest the floor holds a window's sunlit patch.
/// Checked on two other sweep orders as well, with the seen mean (not in the test): the ceiling
/// seen last, where an unseen sun dominates any fill, mean 31.4 → 26.4 % against the mean of
/// the side (three rooms worse); bands taken alternately above and below the horizon, 17.0 →
/// 13.1 % (two worse).
/// The reach was set at 11.25° before any of this; with the nearest band's seen mean, 5.6°
/// gave a worst of 10.2 % (the apartment), 22.5° and 45° 6.1 %, the other rooms within 4.7 %
/// at every reach. With the ratio estimate, over the eight starts: 5.6° 2.27 % mean, 9.7 %
/// worst, 10 cases over 5 %; 22.5° 2.16 %, 9.1 %, 10 cases; 11.25° the best mean and fewest.
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
    // The coarsest level: holes there take the estimated mean of the row nearest to them, in
    // elevation and on their side of the horizon, that has seen cells.
    if let Some((w, h, rgb, weight)) = levels.last_mut() {
        let (w, h) = (*w, *h);
        let upper = |row: usize| above_horizon(row, h);
        let means = band_means(w, h, rgb, weight);
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

/// Each row's mean over every azimuth, estimated from its seen cells (`w` × `h` cells of the
/// coarsest level, row 0 the zenith; `None` for a row with nothing seen). A row seen at every
/// azimuth has its weighted mean. A row seen only in part would be judged by the azimuths the
/// sweep happened to reach, and those are not a fair sample: the part of a ring seen first is
/// where the camera turned first, and a window's light there stands for the whole band. So its
/// mean is a ratio estimate (Cochran, *Sampling Techniques*, ch. 6), with the nearest row
/// towards the horizon on the same side that is seen at every azimuth as the auxiliary band:
/// the seen cells' mean × that band's mean over every azimuth / its mean over the azimuths seen
/// in the row (the latter weighted by the row's weights; luminance only, so the row keeps its
/// colour).
/// Where the seen azimuths are brighter than the band's average one level nearer the horizon, a
/// bright thing there is taken to reach down into the row as well. Without such a band on its
/// side (early in a sweep) a row keeps its seen cells' mean.
fn band_means(w: usize, h: usize, rgb: &[[f32; 3]], weight: &[f32]) -> Vec<Option<[f32; 3]>> {
    let upper = |row: usize| above_horizon(row, h);
    let cells = |row: usize| row * w..(row + 1) * w;
    let seen_means: Vec<Option<[f32; 3]>> = (0..h)
        .map(|row| {
            let (mut sum, mut total) = ([0.0f32; 3], 0.0f32);
            for i in cells(row) {
                for c in 0..3 {
                    sum[c] += rgb[i][c] * weight[i];
                }
                total += weight[i];
            }
            (total > 0.0).then(|| sum.map(|s| s / total))
        })
        .collect();
    let seen_everywhere: Vec<bool> = (0..h).map(|row| cells(row).all(|i| weight[i] > 0.0)).collect();
    (0..h)
        .map(|row| {
            let mean = seen_means[row]?;
            if seen_everywhere[row] {
                return Some(mean);
            }
            let auxiliary = if upper(row) {
                (row + 1..h).find(|&r| upper(r) && seen_everywhere[r])
            } else {
                (0..row).rev().find(|&r| !upper(r) && seen_everywhere[r])
            };
            let Some(aux) = auxiliary else {
                return Some(mean);
            };
            let (mut at_seen, mut total) = (0.0f32, 0.0f32);
            for x in 0..w {
                let wt = weight[row * w + x];
                at_seen += wt * luminance(rgb[aux * w + x]);
                total += wt;
            }
            let everywhere = seen_means[aux].map_or(0.0, luminance);
            let at_seen = at_seen / total;
            if at_seen > 0.0 && everywhere > 0.0 {
                Some(mean.map(|v| v * everywhere / at_seen))
            } else {
                Some(mean)
            }
        })
        .collect()
}

/// Whether row `row` of a map `h` rows high (row 0 the zenith) lies above the horizon.
fn above_horizon(row: usize, h: usize) -> bool {
    2 * row + 1 < h
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

    #[test]
    fn a_band_seen_over_part_of_its_azimuths_is_judged_by_the_band_seen_everywhere_above_it() {
        // The default room map's size (256 × 128), each seen texel weighted by its solid angle.
        let (w, h) = (256usize, 128usize);
        let d_theta = std::f32::consts::PI / h as f32;
        let solid_angle = |y: usize| ((y as f32 + 0.5) * d_theta).sin() * d_theta * std::f32::consts::TAU / w as f32;
        let elevation_deg = |y: usize| 90.0 - (y as f32 + 0.5) * 180.0 / h as f32;
        let (mut rgb, mut weight) = (vec![[0.0f32; 3]; w * h], vec![0.0f32; w * h]);
        // Seen: everything from the zenith down to 22.5° below the horizon, and the band from
        // 22.5° to 33.75° down over the bright half of the azimuths only. Below the horizon the
        // bright half (a window's light) is 6 and the dark half 2 in the band seen everywhere,
        // so that band's mean is 4, and the bright half of the partly seen band is 3.
        for y in 0..h {
            let e = elevation_deg(y);
            for x in 0..w {
                let bright = x < w / 2;
                let v = if e > 0.0 {
                    10.0
                } else if e > -22.5 {
                    if bright { 6.0 } else { 2.0 }
                } else if e > -33.75 && bright {
                    3.0
                } else {
                    continue;
                };
                rgb[y * w + x] = [v; 3];
                weight[y * w + x] = solid_angle(y);
            }
        }
        let env = fill_unseen(w, h, rgb, weight);
        // The band above was seen 1.5 times brighter on the azimuths the partly seen band was
        // seen on than on its average: the partly seen band's estimate is 3 / 1.5 = 2, not 3.
        // Beyond the local reach (the dark half's middle and the floor) that is the fill.
        let want = 2.0;
        for y in (0..h).filter(|&y| elevation_deg(y) < -45.0) {
            for x in [0, w / 4, w / 2, w - 1] {
                let got = env.texels[y * w + x][0];
                assert!(
                    (got - want).abs() < 0.02 * want,
                    "floor at ({x}, {y}): {got}, want {want}"
                );
            }
        }
        let y = (0..h).find(|&y| elevation_deg(y) < -28.0).unwrap_or(h - 1);
        let got = env.texels[y * w + 3 * w / 4][0];
        assert!(
            (got - want).abs() < 0.02 * want,
            "the band's unseen half: {got}, want {want}"
        );
    }
}
