//! The sheen of cloth (`KHR_materials_sheen`: velvet, silk, felt): the "Charlie" distribution of
//! fibre directions and its masking–shadowing, as glTF's extension specifies them (Estevez &
//! Kulla, "Production friendly microfacet sheen BRDF", 2017: Λ from their fitted profile,
//! interpolated by (1 − α)²), and the table of the lobe's directional albedo: the share of a
//! white, uniform light that a sheen of colour 1 reflects towards the eye, by n·v and sheen
//! roughness. (Neubelt and Pettineo's cheaper visibility, which Filament uses, was tried first:
//! its albedo reaches 2.7 at grazing angles and low roughness, more light than came in.) The renderer keeps it beside the split-sum table (its third channel) and uses it
//! twice, as glTF's extension and Filament do: the layer under the sheen is scaled by
//! 1 − max(sheen colour) × albedo, so the two together reflect no more than came in, and the
//! sheen's image light is the albedo times the environment read as the lobe gathers it: not about
//! the mirror direction (the fibres send light that grazes the surface, from a ring near the
//! horizon), but as the roughest level about the direction the lobe gathers from on average
//! ([`super::sheen_direction`]; `ibl::accuracy::sheen_read_errors`).
//!
//! Roughness is the extension's, 0–1 (α = roughness²), kept at least [`MIN_SHEEN_ROUGHNESS`]: the
//! distribution narrows to a line at grazing angles below it, which neither a table nor a pixel
//! resolves.
//!
//! Pure functions; no panics.

use std::f32::consts::PI;

/// Sheen roughness below which the lobe is taken as this (the renderer clamps it the same way).
pub const MIN_SHEEN_ROUGHNESS: f32 = 0.07;

/// The Charlie distribution of half vectors, normalised (∫ D (n·h) dω = 1), at sheen roughness
/// `roughness`: (2 + 1/α) sin(θh)^(1/α) / 2π.
pub fn charlie_distribution(roughness: f32, n_dot_h: f32) -> f32 {
    let alpha = roughness.clamp(MIN_SHEEN_ROUGHNESS, 1.0).powi(2);
    let sin2 = (1.0 - n_dot_h * n_dot_h).max(0.0);
    (2.0 + 1.0 / alpha) * sin2.powf(0.5 / alpha) / (2.0 * PI)
}

/// The fitted profile of Λ's logarithm (Estevez & Kulla's table, at α and by (1 − α)²).
fn lambda_profile(x: f32, alpha: f32) -> f32 {
    let t = (1.0 - alpha) * (1.0 - alpha);
    let mix = |a: f32, b: f32| a + (b - a) * t;
    let (a, b, c) = (mix(21.5473, 25.3245), mix(3.82987, 3.32435), mix(0.19823, 0.16801));
    let (d, e) = (mix(-1.97760, -1.27393), mix(-4.32054, -4.85967));
    a / (1.0 + b * x.powf(c)) + d * x + e
}

/// Λ of the Charlie distribution at an angle of cosine `cos_theta` from the normal (the profile
/// mirrored about 0.5 above it, as the paper has it).
fn lambda(cos_theta: f32, alpha: f32) -> f32 {
    if cos_theta < 0.5 {
        lambda_profile(cos_theta, alpha).exp()
    } else {
        (2.0 * lambda_profile(0.5, alpha) - lambda_profile(1.0 - cos_theta, alpha)).exp()
    }
}

/// The sheen's visibility, G / (4 n·l n·v) with G = 1 / (1 + Λ(l) + Λ(v)), at sheen roughness
/// `roughness`.
pub fn sheen_visibility(roughness: f32, n_dot_l: f32, n_dot_v: f32) -> f32 {
    let alpha = roughness.clamp(MIN_SHEEN_ROUGHNESS, 1.0).powi(2);
    let g = 1.0 / (1.0 + lambda(n_dot_l, alpha) + lambda(n_dot_v, alpha));
    (g / (4.0 * n_dot_l * n_dot_v).max(1e-6)).clamp(0.0, 1.0)
}

/// Directional albedo of the sheen lobe at `n_dot_v` and `roughness`: its reflectance integrated
/// over the hemisphere of light directions, by the midpoint rule on `steps` × `steps` cells over
/// the half of it on one side of the plane of `v` and the normal (the other half mirrors it),
/// uniform in polar angle and azimuth (the lobe's peak at grazing angles gets as many cells as
/// the pole). Λ of each polar angle is taken once, not per cell.
pub fn sheen_albedo(n_dot_v: f32, roughness: f32, steps: usize) -> f32 {
    let n_dot_v = n_dot_v.clamp(1e-4, 1.0);
    let sin_v = (1.0 - n_dot_v * n_dot_v).sqrt();
    let alpha = roughness.clamp(MIN_SHEEN_ROUGHNESS, 1.0).powi(2);
    let lambda_v = lambda(n_dot_v, alpha);
    let d_scale = (2.0 + 1.0 / alpha) / (2.0 * PI);
    let d_exponent = 0.5 / alpha;
    let (d_theta, d_phi) = (0.5 * PI / steps as f32, PI / steps as f32);
    let cos_phi: Vec<f32> = (0..steps).map(|j| ((j as f32 + 0.5) * d_phi).cos()).collect();
    let mut sum = 0.0f64;
    for i in 0..steps {
        let (sin_t, cos_t) = ((i as f32 + 0.5) * d_theta).sin_cos();
        let g = 1.0 / (1.0 + lambda(cos_t, alpha) + lambda_v);
        let visibility = (g / (4.0 * cos_t * n_dot_v)).min(1.0);
        let mut row = 0.0f32;
        for &c in &cos_phi {
            // |l + v|² = 2 + 2 l·v; n·h = (n·l + n·v) / |l + v|.
            let len2 = 2.0 + 2.0 * (sin_t * sin_v * c + cos_t * n_dot_v);
            if len2 <= 1e-12 {
                continue;
            }
            let n_dot_h = (cos_t + n_dot_v) / len2.sqrt();
            let sin2 = (1.0 - n_dot_h * n_dot_h).max(0.0);
            row += d_scale * sin2.powf(d_exponent);
        }
        sum += f64::from(row * visibility * cos_t * sin_t);
    }
    (2.0 * sum * f64::from(d_theta * d_phi)) as f32
}

/// Cells per quarter turn of polar angle in [`sheen_albedo_table`]: 0.01 of the albedo from a
/// four times finer rule at every roughness and angle the table holds (tested).
pub const TABLE_STEPS: usize = 32;

/// The sheen albedo as a `size × size` table laid out as the split-sum table
/// ([`super::brdf_lut`]): row j at roughness, column i at n·v [`super::table_axis`]. Kept
/// at most 1: the fitted Λ lets the albedo pass 1 where n·v is under 0.045 and the roughness
/// under 0.2 (up to 1.58 at n·v 0.008; tested), within 3° of grazing, where no more light can
/// leave than came in.
pub fn sheen_albedo_table(size: usize) -> Vec<f32> {
    let at = |k: usize| super::table_axis(k, size);
    let rows: Vec<usize> = (0..size).collect();
    crate::parallel::map(&rows, |&j| {
        (0..size)
            .map(|i| sheen_albedo(at(i), at(j), TABLE_STEPS).min(1.0))
            .collect::<Vec<f32>>()
    })
    .concat()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The sheen's reflectance towards `v` from `l` (both unit vectors about the normal +z), for a
    /// sheen colour of 1, times n·l: the integrand of its albedo.
    fn reflected(roughness: f32, l: [f32; 3], v: [f32; 3]) -> f32 {
        let (n_dot_l, n_dot_v) = (l[2], v[2]);
        if n_dot_l <= 0.0 || n_dot_v <= 0.0 {
            return 0.0;
        }
        let h = [l[0] + v[0], l[1] + v[1], l[2] + v[2]];
        let len = (h[0] * h[0] + h[1] * h[1] + h[2] * h[2]).sqrt();
        if len <= 0.0 {
            return 0.0;
        }
        charlie_distribution(roughness, h[2] / len) * sheen_visibility(roughness, n_dot_l, n_dot_v) * n_dot_l
    }

    /// ∫ f over the hemisphere of `l` by plain random sampling (uniform in solid angle): another
    /// rule than the table's, to check it against.
    fn monte_carlo_albedo(n_dot_v: f32, roughness: f32, samples: u32) -> f32 {
        let v = [(1.0 - n_dot_v * n_dot_v).sqrt(), 0.0, n_dot_v];
        // A fixed linear congruential sequence: reproducible, and unrelated to the midpoint grid.
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = || {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            ((state >> 40) as f32 + 0.5) / (1u64 << 24) as f32
        };
        let mut sum = 0.0f64;
        for _ in 0..samples {
            let (z, phi) = (next(), 2.0 * PI * next());
            let r = (1.0 - z * z).sqrt();
            sum += f64::from(reflected(roughness, [r * phi.cos(), r * phi.sin(), z], v));
        }
        (sum / f64::from(samples) * 2.0 * std::f64::consts::PI) as f32
    }

    #[test]
    fn the_distribution_is_normalised() {
        for roughness in [0.07, 0.2, 0.5, 1.0] {
            let steps = 20_000;
            let d_theta = 0.5 * PI / steps as f32;
            let total: f32 = (0..steps)
                .map(|i| {
                    let theta = (i as f32 + 0.5) * d_theta;
                    charlie_distribution(roughness, theta.cos()) * theta.cos() * theta.sin() * 2.0 * PI * d_theta
                })
                .sum();
            assert!((total - 1.0).abs() < 2e-3, "roughness {roughness}: {total}");
        }
    }

    #[test]
    fn the_albedo_is_at_most_one_and_agrees_with_another_rule() {
        let table = sheen_albedo_table(16);
        assert!(
            table.iter().all(|e| e.is_finite() && *e >= 0.0 && *e <= 1.0),
            "{table:?}"
        );
        // Beyond the fit's corner (grazing and smooth), no more light leaves than came in.
        for i in 0..32 {
            for j in 0..32 {
                let (n_dot_v, roughness) = ((i as f32 + 0.5) / 32.0, (j as f32 + 0.5) / 32.0);
                let e = sheen_albedo(n_dot_v, roughness, TABLE_STEPS);
                assert!(
                    e <= 1.0 || (n_dot_v < 0.045 && roughness < 0.2),
                    "({n_dot_v}, {roughness}): {e}"
                );
            }
        }
        for (n_dot_v, roughness) in [(0.9, 0.3), (0.5, 0.5), (0.2, 0.8), (0.7, 1.0), (0.1, 0.1)] {
            let rule = sheen_albedo(n_dot_v, roughness, TABLE_STEPS);
            let finer = sheen_albedo(n_dot_v, roughness, 4 * TABLE_STEPS);
            let random = monte_carlo_albedo(n_dot_v, roughness, 400_000);
            assert!(
                (rule - finer).abs() < 0.01,
                "({n_dot_v}, {roughness}): {rule} vs {finer}"
            );
            assert!(
                (finer - random).abs() < 0.01 + 0.03 * finer,
                "({n_dot_v}, {roughness}): {finer} vs {random}"
            );
        }
    }

    #[test]
    fn the_lobe_is_reciprocal() {
        let dir = |t: f32, p: f32| [t.sin() * p.cos(), t.sin() * p.sin(), t.cos()];
        for (a, b) in [((0.3, 0.0), (1.2, 2.0)), ((1.4, 1.0), (0.2, 4.0))] {
            let (l, v) = (dir(a.0, a.1), dir(b.0, b.1));
            // f(l, v) n·l / n·l = f(v, l) n·v / n·v.
            let f_lv = reflected(0.4, l, v) / l[2];
            let f_vl = reflected(0.4, v, l) / v[2];
            assert!((f_lv - f_vl).abs() < 1e-5 * f_lv.max(1.0), "{f_lv} vs {f_vl}");
        }
    }

    #[test]
    fn the_sheens_room_light_is_read_about_the_lobes_mean_direction() {
        // Against a midpoint-rule integral of the lobe over the room (`ibl::accuracy`): the
        // roughest level about the lobe's mean direction (`ibl::sheen_direction`) must come nearer
        // the truth than the same level about the normal, which the renderer read before.
        // Measured (40 frames and views): studio 0.54 → 0.29 at roughness 0.3, 0.16 → 0.11 at 1;
        // sun and band 0.28 → 0.19, 0.09 → 0.06.
        use crate::ibl::Environment;
        use crate::ibl::accuracy::{sheen_read_errors, sun_and_band};
        for (name, env) in [("studio", Environment::studio()), ("sun and band", sun_and_band())] {
            for roughness in [0.3f32, 1.0] {
                let e = sheen_read_errors(&env, roughness, 40);
                println!(
                    "{name}, sheen roughness {roughness}: about the normal {:.3}, about the mean {:.3}",
                    e.before, e.now
                );
                assert!(e.now < 0.8 * e.before, "{name}, sheen roughness {roughness}: {e:?}");
            }
        }
    }
}
