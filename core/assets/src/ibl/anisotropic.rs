//! The image light of a stretched lobe (Ward's anisotropic one, and GGX stretched by
//! `KHR_materials_anisotropy`), read from the isotropic prefiltered levels.
//!
//! The prefiltered levels ([`super::prefiltered_levels`]) hold the environment blurred by a
//! round lobe. A Ward lobe ([`crate::ward`]) is an elliptical Gaussian in slope space: slopes
//! `(s_t, s_b)` of its half vectors have standard deviations `αx/√2` and `αy/√2`. A Gaussian of
//! two widths is a round one of the smaller width convolved with a one-dimensional one along the
//! longer axis, of standard deviation `σ = √((α_long² − α_short²)/2)`. So the lobe's image light
//! is a sum of [`STRETCHED_IMAGE_LIGHT_TAPS`] reads of the level of the *shorter* roughness, each
//! about the mirror direction of a half vector tilted along the long axis by one node of that
//! one-dimensional Gaussian ([`STRETCH_TAP_NODES`], equal weights).
//!
//! For an isotropic lobe every tap is the mirror direction, which is what the renderer read
//! before (the prefiltered level at the lobe's roughness). Brushed metal's highlight, which the
//! round read shows as a blob, is now stretched across the grooves as in the direct light.
//!
//! Measured against a Monte-Carlo integral of the lobe over the environment ([`super::accuracy`];
//! relative RMS error over 160 frames and views, release build, `cargo test -p phantogram-assets
//! --release anisotropic -- --nocapture`): brushed metal's αx 0.05 / αy 0.25 under the generated
//! studio 0.166 → 0.103, under a 2° sun with a bright band 0.438 → 0.266; silk's 0.35 / 0.10
//! 0.163 → 0.120 and 0.278 → 0.151. A round lobe's own error, which no tap count removes (the
//! levels assume n = v = r and a GGX shape), is 0.07–0.12 (studio) and 0.18–0.24 (sun). The
//! shared rooms: `ward_image_light_on_the_shared_rooms` in the integration tests.
//!
//! GGX stretched by `KHR_materials_anisotropy` takes the same taps, spread from its α's as if
//! they were Ward's ([`StretchedImageLight::for_alphas`]): 0.10–0.51 against GGX's own integral
//! where the normal bent across the stretch, which the renderer read before (Khronos's glTF
//! Sample Viewer's), was 0.75–1.8 ([`super::accuracy::stretched_ggx_read_errors`]; the shared
//! rooms: `stretched_ggx_image_light_on_the_shared_rooms`).
//!
//! The renderer's scene shader (`shaders/scene.wgsl`, `stretched_image_light`) does the same
//! with the same nodes; this module is its reference, used by the tests.
//!
//! Pure functions, no panics.

use glam::Vec3;

use super::{Environment, PREFILTER_LEVELS};
use crate::ward::WardLobe;

/// Reads per pixel for a Ward lobe's image light. Chosen by the Monte-Carlo comparison: 4 → 8 →
/// 16 taps, brushed metal under the sun and band 0.368 → 0.266 → 0.221, under the studio
/// 0.120 → 0.103 → 0.104; a 20:1 lobe (0.02 / 0.4) under the sun 0.510 → 0.470 → 0.422. A
/// phone's fragment shader affords eight reads where the visitor picked a Ward material or a
/// model's material is brushed.
pub const STRETCHED_IMAGE_LIGHT_TAPS: usize = 8;

/// The taps' positions along the long axis in units of the one-dimensional Gaussian's standard
/// deviation: the midpoints of eight equal-probability slices of the standard normal
/// (`Φ⁻¹((k + ½)/8)`), scaled by 1.0841 so that their variance is exactly 1 (the midpoints alone
/// have 0.851 and would narrow the highlight).
pub const STRETCH_TAP_NODES: [f32; STRETCHED_IMAGE_LIGHT_TAPS] = {
    const S: f32 = 1.084_1;
    [
        -1.534_1 * S,
        -0.887_1 * S,
        -0.488_8 * S,
        -0.157_3 * S,
        0.157_3 * S,
        0.488_8 * S,
        0.887_1 * S,
        1.534_1 * S,
    ]
};

/// How to read a Ward lobe's image light: the prefiltered level's roughness and the spread of
/// the taps. Directions are in the surface frame (`x` the tangent, `y` the bitangent, `z` the
/// normal), as in [`crate::ward`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StretchedImageLight {
    /// The prefiltered level's roughness (`√α` of the shorter axis: the levels are GGX with
    /// `α = roughness²`, equated to Ward's `α`, as the renderer has always done).
    pub level_roughness: f32,
    /// Standard deviation of the taps' slope along the long axis.
    pub spread_slope: f32,
    /// Whether the long axis is the tangent (`αx > αy`) rather than the bitangent.
    pub along_tangent: bool,
}

impl StretchedImageLight {
    pub fn for_lobe(lobe: WardLobe) -> Self {
        Self::for_alphas(lobe.alpha_x, lobe.alpha_y)
    }

    /// For a lobe of roughness `alpha_x` along the tangent and `alpha_y` along the bitangent.
    /// GGX's slopes are not Gaussian (their tails are heavier), but the levels are GGX, so the
    /// round part is exact and only the spread along the long axis is Ward's; measured against
    /// GGX's own integral in [`super::accuracy::stretched_ggx_read_errors`].
    pub fn for_alphas(alpha_x: f32, alpha_y: f32) -> Self {
        let (short, long) = (alpha_x.min(alpha_y), alpha_x.max(alpha_y));
        Self {
            level_roughness: short.max(0.0).sqrt().clamp(0.0, 1.0),
            spread_slope: ((long * long - short * short) / 2.0).max(0.0).sqrt(),
            along_tangent: alpha_x > alpha_y,
        }
    }

    /// The directions to read for the view `v` (unit, surface frame) with their weights (summing
    /// to 1). Taps whose mirror direction falls below the surface are left out and the others
    /// share their weight; when all would, the mirror direction about the normal is read.
    pub fn taps(&self, v: Vec3) -> Vec<(Vec3, f32)> {
        let axis = if self.along_tangent { Vec3::X } else { Vec3::Y };
        let mut taps: Vec<Vec3> = STRETCH_TAP_NODES
            .iter()
            .map(|&node| {
                let h = (Vec3::Z + axis * (node * self.spread_slope)).normalize();
                h * 2.0 * v.dot(h) - v
            })
            .filter(|l| l.z > 0.0)
            .collect();
        if taps.is_empty() {
            taps.push(Vec3::new(-v.x, -v.y, v.z));
        }
        let w = 1.0 / taps.len() as f32;
        taps.into_iter().map(|l| (l, w)).collect()
    }
}

/// The prefiltered levels read as the GPU reads its mip chain: bilinear within a level, linear
/// between the two levels about `roughness · (LEVELS − 1)`.
pub fn sample_levels(levels: &[Environment], d: Vec3, roughness: f32) -> [f32; 3] {
    if levels.is_empty() {
        return [0.0; 3];
    }
    let last = (levels.len().min(PREFILTER_LEVELS) - 1) as f32;
    let lod = (roughness * (PREFILTER_LEVELS - 1) as f32).clamp(0.0, last);
    let (k0, f) = (lod.floor() as usize, lod.fract());
    let a = levels[k0].sample(d);
    if f == 0.0 || k0 + 1 >= levels.len() {
        return a;
    }
    let b = levels[k0 + 1].sample(d);
    std::array::from_fn(|c| a[c] * (1.0 - f) + b[c] * f)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ibl::accuracy::{read_errors, stretched_ggx_read_errors, sun_and_band};

    #[test]
    fn an_isotropic_lobe_reads_the_mirror_direction_once_over() {
        let light = StretchedImageLight::for_lobe(WardLobe::new(0.2, 0.2));
        assert_eq!(light.spread_slope, 0.0);
        let v = Vec3::new(0.3, -0.2, 0.9).normalize();
        let taps = light.taps(v);
        let total: f32 = taps.iter().map(|t| t.1).sum();
        assert!((total - 1.0).abs() < 1e-5);
        for (l, _) in taps {
            assert!((l - Vec3::new(-v.x, -v.y, v.z)).length() < 1e-5, "{l}");
        }
    }

    #[test]
    fn the_nodes_have_unit_variance_and_no_mean() {
        let mean: f32 = STRETCH_TAP_NODES.iter().sum::<f32>() / STRETCHED_IMAGE_LIGHT_TAPS as f32;
        let var: f32 = STRETCH_TAP_NODES.iter().map(|x| x * x).sum::<f32>() / STRETCHED_IMAGE_LIGHT_TAPS as f32;
        assert!(
            mean.abs() < 1e-6 && (var - 1.0).abs() < 2e-3,
            "mean {mean} variance {var}"
        );
    }

    #[test]
    fn taps_spread_along_the_long_axis_only() {
        let v = Vec3::new(0.0, 0.0, 1.0);
        for (lobe, along_x) in [(WardLobe::new(0.3, 0.05), true), (WardLobe::new(0.05, 0.3), false)] {
            let taps = StretchedImageLight::for_lobe(lobe).taps(v);
            assert_eq!(taps.len(), STRETCHED_IMAGE_LIGHT_TAPS);
            let spread_x: f32 = taps.iter().map(|(l, _)| l.x.abs()).sum();
            let spread_y: f32 = taps.iter().map(|(l, _)| l.y.abs()).sum();
            if along_x {
                assert!(spread_x > 1.0 && spread_y < 1e-5, "{spread_x} {spread_y}");
            } else {
                assert!(spread_y > 1.0 && spread_x < 1e-5, "{spread_x} {spread_y}");
            }
        }
    }

    #[test]
    fn taps_follow_an_anisotropic_lobe_closer_than_one_round_read() {
        // Brushed metal and silk's roughnesses (ward.rs presets) and a stronger stretch, under
        // the generated studio and a sun with a band: the tapped read must be clearly nearer
        // the Monte-Carlo truth than the round read the renderer made before.
        for (name, env) in [("studio", Environment::studio()), ("sun and band", sun_and_band())] {
            for lobe in [
                WardLobe::new(0.05, 0.25),
                WardLobe::new(0.35, 0.10),
                WardLobe::new(0.02, 0.4),
            ] {
                let e = read_errors(&env, lobe, 160);
                println!(
                    "{name} αx {} αy {}: round {:.3} tapped {:.3}",
                    lobe.alpha_x, lobe.alpha_y, e.before, e.now
                );
                assert!(e.now < 0.75 * e.before, "{name} {lobe:?}: {e:?}");
            }
        }
    }

    #[test]
    fn taps_follow_a_stretched_ggx_lobe_far_closer_than_the_bent_normal() {
        // KHR_materials_anisotropy's lobe at roughnesses and strengths from a light brush to a
        // full stretch. The bent normal (Khronos's glTF Sample Viewer's read, the renderer's
        // before) is off by 0.75–1.8 of the light (relative RMS), further than not stretching at
        // all; the taps 0.10–0.51 (`benchmarks/ibl.md`).
        for (name, env) in [("studio", Environment::studio()), ("sun and band", sun_and_band())] {
            for (roughness, strength) in [(0.1f32, 0.5f32), (0.1, 1.0), (0.3, 0.6), (0.3, 1.0), (0.5, 0.8)] {
                let e = stretched_ggx_read_errors(&env, roughness, strength, 80);
                println!(
                    "{name} roughness {roughness} strength {strength}: bent normal {:.3} tapped {:.3}",
                    e.before, e.now
                );
                assert!(
                    e.now < 0.5 * e.before && e.now < 0.6,
                    "{name} {roughness} {strength}: {e:?}"
                );
            }
        }
    }

    #[test]
    fn taps_change_nothing_for_a_round_lobe() {
        let env = sun_and_band();
        for a in [0.05, 0.3] {
            let e = read_errors(&env, WardLobe::new(a, a), 60);
            assert!((e.before - e.now).abs() < 1e-4, "α {a}: {e:?}");
        }
    }
}
