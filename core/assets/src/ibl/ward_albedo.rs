//! The Ward lobe's directional albedo as a table (n·v × roughness), for the image light of a
//! Ward material: `scene.wgsl` reads the environment prefiltered along the lobe
//! ([`super::anisotropic`]) and scales it by this albedo, what the lobe itself sends back, so
//! that the room's light and a lamp's agree. (Before, the split-sum table's GGX albedo at the
//! roughness of the same RMS slope stood in: up to 19 % below Ward's at α = 1.)
//!
//! The table is isotropic: entry (i, j) holds the albedo of the round lobe of α = y², y the
//! roughness axis ([`super::table_axis`]), at n·v the other axis. A stretched lobe reads
//! [`super::anisotropic_albedo`] instead; the round lobe of the same mean square slope, which
//! `scene.wgsl` read for it before, is within 2.5 % of its albedo seen across its axes but up to
//! 11 % off seen along one near grazing, for roughnesses five times apart (`benchmarks/ibl.md`).
//!
//! Pure function; rows on every core ([`crate::parallel::map`]); no panics.

use glam::Vec3;

use crate::ward::WardLobe;

/// Stratified samples per entry, as a side of their grid: 16 × 16 keeps each entry within
/// 1.5 % of a 128 × 128 grid's, within 0.5 % above n·v 0.1 (tested); 32 × 32 took 0.2 s on
/// this machine's two cores, too long for the renderer's start-up.
pub const TABLE_GRID: usize = 16;

/// The round Ward lobe's directional albedo, `size × size` entries laid out as the split-sum
/// table ([`super::brdf_lut`]): row j at α = [`super::table_axis`]`(j)²` (held at 0.01, the
/// sharpest lobe), column i at n·v `table_axis(i)` (at least 0.001).
pub fn ward_albedo_table(size: usize) -> Vec<f32> {
    let rows: Vec<usize> = (0..size).collect();
    crate::parallel::map(&rows, |&j| {
        let y = super::table_axis(j, size);
        let lobe = WardLobe::new(y * y, y * y);
        (0..size)
            .map(|i| {
                let n_dot_v = super::table_axis(i, size).max(1e-3);
                let v = Vec3::new((1.0 - n_dot_v * n_dot_v).sqrt(), 0.0, n_dot_v);
                round_albedo(&lobe, v, TABLE_GRID)
            })
            .collect::<Vec<f32>>()
    })
    .concat()
}

/// [`WardLobe::directional_albedo`] of a round lobe seen from `v` in the xz-plane, at half the
/// cost: the lobe and the view are symmetric about that plane, and so is the stratified grid
/// (the first uniform's cells at `u` and `1 − u` draw half vectors mirrored across it), so the
/// grid's first half of rows, counted twice, gives the same sum. `grid` even.
fn round_albedo(lobe: &WardLobe, v: Vec3, grid: usize) -> f32 {
    (2.0 * lobe.sampled_sum(v, grid, grid / 2) / (grid * grid).max(1) as f64) as f32
}

#[cfg(test)]
mod tests {
    use super::*;

    fn view(n_dot_v: f32, azimuth_rad: f32) -> Vec3 {
        let s = (1.0 - n_dot_v * n_dot_v).sqrt();
        Vec3::new(s * azimuth_rad.cos(), s * azimuth_rad.sin(), n_dot_v)
    }

    #[test]
    fn half_the_grid_counted_twice_is_the_whole_grid() {
        for (alpha, n_dot_v) in [(0.01f32, 0.5f32), (0.2, 0.9), (0.6, 0.3), (1.0, 0.05)] {
            let lobe = WardLobe::new(alpha, alpha);
            let v = view(n_dot_v, 0.0);
            let (half, whole) = (round_albedo(&lobe, v, 16), lobe.directional_albedo(v, 16));
            assert!(
                (half - whole).abs() < 1e-5,
                "α {alpha}, n·v {n_dot_v}: {half} vs {whole}"
            );
        }
    }

    #[test]
    fn the_table_holds_the_round_lobes_albedo() {
        let size = 16;
        let table = ward_albedo_table(size);
        assert!(table.iter().all(|a| a.is_finite() && (0.0..=1.0 + 2e-3).contains(a)));
        for i in [1usize, 5, 10, 15] {
            for j in [2usize, 6, 11, 15] {
                let (n_dot_v, y) = (super::super::table_axis(i, size), super::super::table_axis(j, size));
                let fine = WardLobe::new(y * y, y * y).directional_albedo(view(n_dot_v, 0.0), 128);
                let entry = table[j * size + i];
                let allowed = if n_dot_v < 0.1 { 0.015 } else { 0.005 };
                assert!(
                    (entry - fine).abs() < allowed * fine,
                    "n·v {n_dot_v}, α {}: table {entry}, 128 × 128 grid {fine}",
                    y * y
                );
            }
        }
    }
}
