//! A clay tablet with an inscription, 56 × 38 mm, lying in the glass: a pillowed face with six
//! ruled lines of wedge-shaped impressions (cuneiform-like signs, generated, not a real text).
//! Impressions half a millimetre deep show only under a raking light: the tablet is the built-in
//! case for surface mode and for the light fixed in the room.

use glam::Vec2;

use super::slab::{Outline, Paint, hash01, slab, smoothstep};
use crate::model::{Mesh, Model};

pub const HALF_M: Vec2 = Vec2::new(0.028, 0.019);
/// The back, so that about 40 % of the tablet's thickness stands in front of the glass.
const BACK_Z_M: f32 = -0.0066;
/// Thickness at the edge and the pillow's rise to the middle.
const EDGE_M: f32 = 0.0090;
const PILLOW_M: f32 = 0.0022;

const CLAY: [f32; 4] = [0.36, 0.24, 0.14, 1.0];
const IMPRESSED: [f32; 4] = [0.15, 0.095, 0.055, 1.0];
const CLAY_MATERIAL: [f32; 2] = [0.0, 0.85];

const LINES: u32 = 6;
/// Sign slots per line and the wedges' size.
const SLOTS: u32 = 15;
const WEDGE_LEN_M: f32 = 0.0026;
const WEDGE_HALF_WIDTH_M: f32 = 0.0007;
const WEDGE_DEPTH_M: f32 = 0.0006;

/// The ruled area: lines from the top, between these margins.
const MARGIN_X_M: f32 = 0.0035;
const MARGIN_Y_M: f32 = 0.0030;

/// The depth of one wedge's impression at `q`, in the wedge's frame (head at the origin, pointing
/// along +x): deepest at the head, thinning to nothing at the tail.
fn wedge_depth(q: Vec2) -> f32 {
    let along = q.x / WEDGE_LEN_M;
    if !(0.0..=1.0).contains(&along) {
        return 0.0;
    }
    let half_width = WEDGE_HALF_WIDTH_M * (1.0 - along).max(0.15);
    let across = q.y.abs() / half_width;
    if across >= 1.0 {
        return 0.0;
    }
    WEDGE_DEPTH_M * (1.0 - along * 0.7) * (1.0 - across * across)
}

/// How deep the inscription is pressed in at `p` (the tablet's plane, metres): the wedges of the
/// sign whose slot holds `p`, and the ruling between lines.
fn impression_m(p: Vec2) -> f32 {
    let top = HALF_M.y - MARGIN_Y_M;
    let line_h = (2.0 * top) / LINES as f32;
    let line_f = (top - p.y) / line_h;
    if !(0.0..LINES as f32).contains(&line_f) || p.x.abs() > HALF_M.x - MARGIN_X_M {
        return 0.0;
    }
    let line = line_f.floor() as u32;
    // The ruling: a shallow groove at the top of each line after the first.
    let ruling = if line > 0 && line_f.fract() < 0.04 {
        0.00025
    } else {
        0.0
    };
    let width = 2.0 * (HALF_M.x - MARGIN_X_M);
    let slot_w = width / SLOTS as f32;
    let slot_f = (p.x + HALF_M.x - MARGIN_X_M) / slot_w;
    let slot = (slot_f.floor() as u32).min(SLOTS - 1);
    let sign = line * SLOTS + slot;
    // About one slot in six is a space between words.
    if hash01(sign * 7 + 1) < 0.17 {
        return ruling;
    }
    let centre = Vec2::new(
        -HALF_M.x + MARGIN_X_M + (slot as f32 + 0.5) * slot_w,
        top - (line as f32 + 0.55) * line_h,
    );
    // Two to four wedges per sign: horizontal, vertical (head up) or oblique.
    let wedges = 2 + (hash01(sign * 7 + 2) * 3.0) as u32;
    let mut depth: f32 = 0.0;
    for w in 0..wedges {
        let kind = (hash01(sign * 7 + 3 + w) * 3.0) as u32;
        let (dir, offset) = match kind {
            0 => (Vec2::X, Vec2::new(-0.45, 0.55 - 0.45 * w as f32)),
            1 => (Vec2::NEG_Y, Vec2::new(-0.45 + 0.4 * w as f32, 0.5)),
            _ => (Vec2::new(1.0, -1.0).normalize(), Vec2::new(-0.5 + 0.3 * w as f32, 0.45)),
        };
        let head = centre + offset * Vec2::new(slot_w, line_h * 0.8) * 0.6;
        let d = p - head;
        let q = Vec2::new(d.dot(dir), d.perp_dot(dir));
        depth = depth.max(wedge_depth(q));
    }
    depth.max(ruling)
}

/// The face's height above the back at `p`.
fn height_m(p: Vec2) -> f32 {
    let (x, y) = (p.x / HALF_M.x, p.y / HALF_M.y);
    let pillow = PILLOW_M * (1.0 - x.powi(4)).max(0.0) * (1.0 - y.powi(4)).max(0.0);
    // Rounded edges: within 2.5 mm of the outline the face falls by up to 2 mm.
    let to_edge = (HALF_M.x - p.x.abs()).min(HALF_M.y - p.y.abs());
    let round = 0.0020 * (1.0 - smoothstep(0.0, 0.0025, to_edge)).powi(2);
    EDGE_M + pillow - round - impression_m(p)
}

fn paint(p: Vec2, _height_m: f32) -> Paint {
    let t = smoothstep(0.0, WEDGE_DEPTH_M * 0.6, impression_m(p));
    let mix = |k: usize| CLAY[k] + (IMPRESSED[k] - CLAY[k]) * t;
    ([mix(0), mix(1), mix(2), 1.0], CLAY_MATERIAL)
}

pub fn tablet_mesh() -> Mesh {
    slab(
        Outline::Rect {
            half_m: HALF_M,
            columns: 280,
            rows: 190,
        },
        BACK_Z_M,
        &height_m,
        &paint,
    )
}

pub fn tablet() -> Model {
    Model::from_painted_mesh("tablet", tablet_mesh())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_tablet_has_its_size_and_an_inscription() {
        let m = tablet_mesh();
        let b = m.bounds().unwrap();
        assert!((b.max.x - HALF_M.x).abs() < 1e-6 && (b.min.y + HALF_M.y).abs() < 1e-6);
        assert!((b.min.z - BACK_Z_M).abs() < 1e-7);
        let thickness = b.max.z - b.min.z;
        assert!((0.010..0.0115).contains(&thickness), "{thickness}");
        let impressed = m.vertices.iter().filter(|v| v.color == IMPRESSED).count();
        let clay = m.vertices.iter().filter(|v| v.color == CLAY).count();
        assert!(
            impressed > 500 && clay > 10 * impressed,
            "{impressed} impressed, {clay} clay"
        );
        assert_eq!(m, tablet_mesh(), "deterministic");
    }

    #[test]
    fn every_line_has_signs_and_spaces() {
        let top = HALF_M.y - MARGIN_Y_M;
        let line_h = 2.0 * top / LINES as f32;
        for line in 0..LINES {
            let y = top - (line as f32 + 0.55) * line_h;
            let pressed = (0..400)
                .map(|k| -HALF_M.x + 2.0 * HALF_M.x * k as f32 / 400.0)
                .filter(|&x| impression_m(Vec2::new(x, y)) > 0.0)
                .count();
            assert!(
                (20..300).contains(&pressed),
                "line {line}: {pressed} of 400 samples pressed"
            );
        }
    }
}
