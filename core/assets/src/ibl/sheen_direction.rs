//! Where the sheen's image light is read from: one read of the roughest prefiltered level about
//! the direction the sheen's lobe gathers from on average, instead of about the normal (the
//! renderer's read until 2026-12-07). The lobe ([`super::sheen`]) gathers light from a ring near
//! the horizon, more of it on the view's side, so its mean direction leans from the normal
//! towards the view's azimuth, the more the more obliquely it is seen. The roughest level keeps
//! the read as smooth as the lobe is broad.
//!
//! Tried first and not kept (`benchmarks/ibl.md`): eight taps around the normal, one per eighth
//! of a turn, each its sector's share of the lobe read at a level fitted to the sector's spread.
//! Against an integral of the lobe over the room it came nearer the truth than this read, but a
//! small bright sun, imaged by eight taps, drew star and streak patterns across a velvet sphere
//! that the lobe's own integral does not show.
//!
//! The table: [`SIDE`] × [`SIDE`] entries by (n·v, sheen roughness) at [`super::table_axis`],
//! each the sine and cosine of the mean direction's angle from the normal (the sine positive
//! towards the view's azimuth; the lobe is mirror-symmetric about the plane of the view and the
//! normal, so the mean lies in it). The renderer keeps it at the bottom of its lighting tables,
//! [`TABLE_WIDTH`] texels wide (`scene.wgsl`'s `sheen_direction`); [`read`] is the CPU twin of the
//! shader's read. Made in about 10 ms on two cores (`cargo bench -p phantogram-assets --bench
//! ibl`).
//!
//! Pure functions; rows on every core ([`crate::parallel::map`]); no panics.

use std::f32::consts::{FRAC_PI_2, PI};

use glam::Vec3;

use super::sheen::{MIN_SHEEN_ROUGHNESS, charlie_distribution, sheen_visibility};

/// Entries along each axis of the table (n·v and sheen roughness).
pub const SIDE: usize = 16;
/// The table's width in texels: the lighting tables' (the entries in the first [`SIDE`] columns).
pub const TABLE_WIDTH: usize = 64;
/// Midpoint cells per quarter turn of polar angle (and per quarter turn of azimuth).
const CELLS: usize = 32;

/// The sine and cosine of the angle between the normal and the mean direction of the light the
/// sheen at `n_dot_v` and `roughness` gathers (the sine positive towards the view's azimuth), by
/// the midpoint rule over the hemisphere.
pub fn mean_direction(n_dot_v: f32, roughness: f32) -> [f32; 2] {
    let n_dot_v = n_dot_v.clamp(1e-3, 1.0);
    let roughness = roughness.clamp(MIN_SHEEN_ROUGHNESS, 1.0);
    let v = Vec3::new((1.0 - n_dot_v * n_dot_v).sqrt(), 0.0, n_dot_v);
    let (d_theta, d_phi) = (FRAC_PI_2 / CELLS as f32, PI / (2 * CELLS) as f32);
    // The half turn y ≥ 0: the other half mirrors it and adds nothing across the plane of v.
    let mut sum = Vec3::ZERO;
    for i in 0..CELLS {
        let (sin_t, cos_t) = ((i as f32 + 0.5) * d_theta).sin_cos();
        let visibility = sheen_visibility(roughness, cos_t, n_dot_v);
        for j in 0..2 * CELLS {
            let (sin_p, cos_p) = ((j as f32 + 0.5) * d_phi).sin_cos();
            let l = Vec3::new(sin_t * cos_p, sin_t * sin_p, cos_t);
            let p = charlie_distribution(roughness, (l + v).normalize_or_zero().z) * visibility * cos_t;
            sum += l * (p * sin_t);
        }
    }
    Vec3::new(sum.x, 0.0, sum.z)
        .try_normalize()
        .map_or([0.0, 1.0], |m| [m.x, m.z])
}

/// The table: [`TABLE_WIDTH`] texels wide, [`SIDE`] high, row by row; entry (i, j) at column i
/// of row j holds `[sin, cos, 0, 1]` (see the module docs), the columns past [`SIDE`] zero.
pub fn sheen_direction_table() -> Vec<[f32; 4]> {
    let rows: Vec<usize> = (0..SIDE).collect();
    crate::parallel::map(&rows, |&j| {
        (0..TABLE_WIDTH)
            .map(|i| {
                if i < SIDE {
                    let [s, c] = mean_direction(super::table_axis(i, SIDE), super::table_axis(j, SIDE));
                    [s, c, 0.0, 1.0]
                } else {
                    [0.0; 4]
                }
            })
            .collect::<Vec<_>>()
    })
    .concat()
}

/// The mean direction for the view `v` (unit, surface frame: the normal +z) at sheen
/// `roughness`, read from `table` ([`sheen_direction_table`]) bilinearly as the shader reads it.
pub fn read(table: &[[f32; 4]], v: Vec3, roughness: f32) -> Vec3 {
    let [sin, cos, _, _] = super::table_bilinear(table, TABLE_WIDTH, (0, 0), SIDE, [v.z, roughness]);
    let facing = Vec3::new(v.x, v.y, 0.0).try_normalize().unwrap_or(Vec3::X);
    (facing * sin + Vec3::Z * cos).try_normalize().unwrap_or(Vec3::Z)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn seen_face_on_the_lobe_gathers_about_the_normal() {
        let [s, c] = mean_direction(1.0, 0.5);
        assert!(s.abs() < 1e-3 && (c - 1.0).abs() < 1e-3, "{s} {c}");
    }

    #[test]
    fn seen_obliquely_a_fine_sheen_gathers_from_low_on_the_views_side() {
        // Its half vectors lie near the surface: the light comes in grazing from the view's side.
        let [s, c] = mean_direction(0.3, 0.2);
        assert!(s > 0.5, "{s} {c}");
        let [s_rough, _] = mean_direction(0.3, 1.0);
        assert!(s_rough < s, "the roughest sheen leans less: {s_rough} against {s}");
    }

    #[test]
    fn the_table_read_between_entries_comes_near_the_mean_itself() {
        let table = sheen_direction_table();
        assert_eq!(table.len(), TABLE_WIDTH * SIDE);
        let mut worst = 0.0f32;
        for (n_dot_v, roughness) in [(0.23f32, 0.41), (0.71, 0.77), (0.47, 0.19), (0.9, 0.55), (0.08, 0.3)] {
            let v = Vec3::new(
                (1.0 - n_dot_v * n_dot_v).sqrt() * 0.6,
                (1.0 - n_dot_v * n_dot_v).sqrt() * 0.8,
                n_dot_v,
            );
            let [s, c] = mean_direction(n_dot_v, roughness);
            let exact = Vec3::new(0.6 * s, 0.8 * s, c);
            worst = worst.max(read(&table, v, roughness).angle_between(exact));
        }
        assert!(worst < 2f32.to_radians(), "{}°", worst.to_degrees());
    }
}
