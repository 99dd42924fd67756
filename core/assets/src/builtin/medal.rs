//! A struck bronze medal, 42 mm across, lying in the glass: a raised rim, a ring of beads, a
//! legend of raised letters round the edge and an eight-petalled rosette in the middle, with a
//! dark patina in the sunk field. Shallow relief (1.2 mm) under a moving light is what the
//! tangiBook's surface mode shows best; it is also a flat artifact for the facing placement.

use glam::Vec2;

use super::slab::{Outline, Paint, hash01, slab, smoothstep};
use crate::model::{Mesh, Model};

pub const RADIUS_M: f32 = 0.021;
/// The back of the medal, so that about 40 % of its thickness stands in front of the glass.
const BACK_Z_M: f32 = -0.0018;
/// The sunk field's height above the back.
const FIELD_M: f32 = 0.0020;

const BRONZE: [f32; 4] = [0.50, 0.30, 0.12, 1.0];
const BRONZE_MATERIAL: [f32; 2] = [1.0, 0.30];
const PATINA: [f32; 4] = [0.055, 0.075, 0.045, 1.0];
const PATINA_MATERIAL: [f32; 2] = [0.2, 0.7];

const BEADS: u32 = 40;
const GLYPHS: u32 = 26;

/// A hemispherical bump of `radius` (in units of the medal's radius) and `height_m` at `d` from
/// its centre.
fn dome(d: f32, radius: f32, height_m: f32) -> f32 {
    height_m * (1.0 - (d / radius).powi(2)).max(0.0).sqrt()
}

/// One letter of the legend, in its cell's coordinates (`u` across, `v` up, both −1 to 1): raised
/// or not. Strokes chosen by the glyph's hash: three verticals, three horizontals, a diagonal.
fn letter(glyph: u32, u: f32, v: f32) -> bool {
    let bits = (hash01(glyph) * 128.0) as u32 | 0b1; // at least the left stem
    let w = 0.22; // stroke half-width, in cell units
    let strokes = [
        (bits & 1 != 0) && (u + 0.8).abs() < w,
        (bits & 2 != 0) && (u - 0.8).abs() < w,
        (bits & 4 != 0) && u.abs() < w,
        (bits & 8 != 0) && (v - 0.8).abs() < w,
        (bits & 16 != 0) && v.abs() < w,
        (bits & 32 != 0) && (v + 0.8).abs() < w,
        (bits & 64 != 0) && (u - v).abs() < w * 1.4,
    ];
    u.abs() <= 1.0 && v.abs() <= 1.0 && strokes.into_iter().any(|s| s)
}

/// The relief's height above the back at `p` (metres, the medal's plane).
fn height_m(p: Vec2) -> f32 {
    let r = p.length() / RADIUS_M;
    let theta = p.y.atan2(p.x);
    let mut h = FIELD_M;
    // The rim, rounded at its outer edge.
    h += 0.0009 * smoothstep(0.86, 0.90, r) * (1.0 - 0.6 * smoothstep(0.96, 1.0, r));
    // The ring of beads.
    let step = std::f32::consts::TAU / BEADS as f32;
    let k = (theta / step).round();
    let bead = Vec2::from_angle(k * step) * 0.81;
    h += dome((p / RADIUS_M).distance(bead), 0.022, 0.0005);
    // The legend between r = 0.64 and 0.76, reading clockwise over the top from the lower left,
    // with a gap at the bottom where a medal's legend starts and ends.
    if (0.64..0.76).contains(&r) {
        let from_top = std::f32::consts::FRAC_PI_2 - theta; // clockwise from the top
        let span = std::f32::consts::TAU * 0.84;
        let s = (from_top + span * 0.5).rem_euclid(std::f32::consts::TAU) / span;
        if (0.0..1.0).contains(&s) {
            let cell = s * GLYPHS as f32;
            let glyph = cell.floor() as u32;
            let u = (cell.fract() - 0.5) * 2.0 / 0.7;
            let v = (r - 0.70) / 0.045;
            if letter(glyph, u, v) {
                h += 0.0004;
            }
        }
    }
    // The rosette: eight domed petals round a boss.
    let petal_r = 0.50 * (0.30 + 0.70 * (4.0 * theta).cos().abs().powf(0.6));
    h += dome(r, petal_r, 0.0009);
    h += dome(r, 0.12, 0.0005);
    h
}

fn paint(_p: Vec2, height_m: f32) -> Paint {
    // Raised parts are rubbed bright; the sunk field keeps its patina.
    let t = smoothstep(0.00003, 0.00025, height_m - FIELD_M);
    let mix = |a: f32, b: f32| a + (b - a) * t;
    (
        [
            mix(PATINA[0], BRONZE[0]),
            mix(PATINA[1], BRONZE[1]),
            mix(PATINA[2], BRONZE[2]),
            1.0,
        ],
        [
            mix(PATINA_MATERIAL[0], BRONZE_MATERIAL[0]),
            mix(PATINA_MATERIAL[1], BRONZE_MATERIAL[1]),
        ],
    )
}

pub fn medal_mesh() -> Mesh {
    slab(
        Outline::Disc {
            radius_m: RADIUS_M,
            rings: 150,
            sectors: 360,
        },
        BACK_Z_M,
        &height_m,
        &paint,
    )
}

pub fn medal() -> Model {
    Model::from_painted_mesh("medal", medal_mesh())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_medal_has_its_size_relief_and_patina() {
        let m = medal_mesh();
        let b = m.bounds().unwrap();
        assert!(
            (b.max.x - RADIUS_M).abs() < 1e-5 && (b.min.y + RADIUS_M).abs() < 1e-4,
            "{b:?}"
        );
        assert!((b.min.z - BACK_Z_M).abs() < 1e-7);
        let relief = b.max.z - (BACK_Z_M + FIELD_M);
        assert!((0.0008..0.0015).contains(&relief), "relief {relief}");
        let bright = m.vertices.iter().filter(|v| v.color == BRONZE).count();
        let dark = m.vertices.iter().filter(|v| v.color == PATINA).count();
        assert!(bright > 5000 && dark > 5000, "{bright} bright, {dark} dark");
        assert_eq!(m, medal_mesh(), "deterministic");
    }

    #[test]
    fn the_legend_has_raised_letters_that_differ() {
        let glyphs: Vec<Vec<bool>> = (0..GLYPHS)
            .map(|g| {
                (0..64)
                    .map(|k| letter(g, (k % 8) as f32 / 3.5 - 1.0, (k / 8) as f32 / 3.5 - 1.0))
                    .collect()
            })
            .collect();
        let distinct: std::collections::HashSet<&Vec<bool>> = glyphs.iter().collect();
        assert!(distinct.len() > GLYPHS as usize / 2, "{} distinct", distinct.len());
        assert!(glyphs.iter().all(|g| g.iter().any(|&x| x) && !g.iter().all(|&x| x)));
    }
}
