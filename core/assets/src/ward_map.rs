//! Texture maps over a Ward material (tangiBook's ρd, ρs and α maps): how the albedos and
//! roughness vary across the surface, for the presets whose look is a structure — the grooves of
//! brushed metal, the plain weave of silk. A map scales the material's constants texel by texel,
//! so the material screen's sliders still set the whole.
//!
//! ## Texels
//! One RGBA8 texel (linear, not sRGB) holds: R the scale of ρs and G the scale of both
//! roughnesses, each over 2 (128 = ×1); B the share of the texel whose grain runs across the
//! tangent instead of along it (0 or 255 at full size: a weave's weft; averaged by the mip
//! chain; the shader then swaps αx and αy by that share); A the scale of ρd over 2. A map tiles:
//! texel `(i, j)` is at `(i, j) × tile / size` along the surface's tangent and bitangent, `tile`
//! being [`WardMap::tile_m`] (the shader lays it out in metres along the tangent frame, so a
//! thread is a millimetre whatever the model's texture coordinates).
//!
//! Each map's scales average 1 over a tile (within 2 %, tested), so a map changes the
//! structure of a preset, not its overall albedo. Energy: the shader keeps ρs ≤ 1 and
//! ρd ≤ 1 − ρs per texel, as [`crate::ward::WardMaterial::conserving`] does for the constants
//! ([`WardMap::material_at`] is that rule, tested with the white furnace).
//!
//! Pure functions; deterministic (a fixed hash, no random state); no panics.

use crate::ward::WardMaterial;

/// A map's texels along each side.
pub const WARD_MAP_SIZE: u32 = 256;

/// Which map a Ward material carries.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum WardMap {
    /// The constants everywhere.
    #[default]
    Uniform,
    /// Brushing grooves along the tangent: each groove (an eighth of a millimetre) its own
    /// gloss and roughness, varying slowly along it.
    Brushed,
    /// A plain weave of 1 mm threads: warp along the bitangent and weft along the tangent
    /// crossing over in turn, each thread rounded (its gloss highest along its middle), its
    /// roughness across the thread (αx for the warp, αy for the weft).
    Woven,
}

impl WardMap {
    pub const ALL: [Self; 3] = [Self::Uniform, Self::Brushed, Self::Woven];

    /// The side of one tile along the surface, metres (0 for [`WardMap::Uniform`]).
    pub fn tile_m(self) -> f32 {
        match self {
            Self::Uniform => 0.0,
            Self::Brushed => 0.032,
            Self::Woven => 0.016,
        }
    }

    /// The name kept in the appearance store.
    pub fn key(self) -> &'static str {
        match self {
            Self::Uniform => "uniform",
            Self::Brushed => "brushed",
            Self::Woven => "woven",
        }
    }

    /// The map with this [`Self::key`], if any.
    pub fn from_key(key: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|m| m.key() == key)
    }

    /// The map's texels, [`WARD_MAP_SIZE`]² RGBA8 rows (see the module docs); one neutral texel
    /// for [`WardMap::Uniform`].
    pub fn texels(self) -> (u32, Vec<u8>) {
        match self {
            Self::Uniform => (1, encode(Texel::NEUTRAL).to_vec()),
            Self::Brushed | Self::Woven => {
                let n = WARD_MAP_SIZE;
                let mut out = Vec::with_capacity((n * n * 4) as usize);
                for j in 0..n {
                    for i in 0..n {
                        out.extend_from_slice(&encode(self.texel(i, j)));
                    }
                }
                (n, out)
            }
        }
    }

    /// The scales at texel `(i, j)` (along the tangent, along the bitangent).
    fn texel(self, i: u32, j: u32) -> Texel {
        match self {
            Self::Uniform => Texel::NEUTRAL,
            Self::Brushed => {
                // A groove per row; along it, its character drifts over a quarter of the tile
                // (smoothly: value noise with a cosine blend), so the lines are not ruled.
                let along = i as f32 / 64.0;
                let k = along.floor() as u32;
                let f = along - along.floor();
                let blend = 0.5 - 0.5 * (std::f32::consts::PI * f).cos();
                let groove = |salt: u32| {
                    let at = |k: u32| unit(hash(j, k % (WARD_MAP_SIZE / 64), salt));
                    at(k) + (at(k + 1) - at(k)) * blend
                };
                Texel {
                    rho_s: 1.0 + 0.6 * (groove(1) - 0.5),
                    alpha: 1.0 + 0.5 * (groove(2) - 0.5),
                    across: 0.0,
                    rho_d: 1.0,
                }
            }
            Self::Woven => {
                // 16 threads a tile, 16 texels a thread; warp over weft where the cell's
                // indices add up even.
                let thread = WARD_MAP_SIZE / 16;
                let (a, b) = (i / thread, j / thread);
                let warp_over = (a + b) % 2 == 0;
                // Across the thread on top: x for the warp (it runs along y), y for the weft.
                let c = if warp_over { i % thread } else { j % thread };
                let rounded = (std::f32::consts::PI * (c as f32 + 0.5) / thread as f32).sin();
                // Threads differ a little from each other.
                let own = unit(hash(if warp_over { a } else { b }, u32::from(warp_over), 3)) - 0.5;
                Texel {
                    rho_s: 0.55 + 0.7 * rounded + 0.1 * own,
                    alpha: 1.0,
                    across: if warp_over { 0.0 } else { 1.0 },
                    rho_d: 0.8 + 0.3 * rounded,
                }
            }
        }
    }

    /// The material at a texel's scales, as the shader applies them: ρs scaled and kept ≤ 1, the
    /// roughnesses scaled (swapped by the share across), ρd scaled and kept ≤ 1 − ρs. For the
    /// tests and tools (the shader is the renderer's copy).
    pub fn material_at(base: &WardMaterial, scales: [f32; 4]) -> WardMaterial {
        let [rho_s, alpha, across, rho_d] = scales;
        let rho_s_out = base.rho_s.map(|s| (s * rho_s).clamp(0.0, 1.0));
        let swap = across.clamp(0.0, 1.0);
        let ax = base.alpha_x * (1.0 - swap) + base.alpha_y * swap;
        let ay = base.alpha_y * (1.0 - swap) + base.alpha_x * swap;
        WardMaterial {
            rho_d: std::array::from_fn(|c| (base.rho_d[c] * rho_d).clamp(0.0, 1.0 - rho_s_out[c])),
            rho_s: rho_s_out,
            alpha_x: ax * alpha,
            alpha_y: ay * alpha,
            map: WardMap::Uniform,
        }
        .conserving()
    }
}

/// A texel's scales before encoding.
#[derive(Clone, Copy, Debug)]
struct Texel {
    rho_s: f32,
    alpha: f32,
    across: f32,
    rho_d: f32,
}

impl Texel {
    const NEUTRAL: Self = Self {
        rho_s: 1.0,
        alpha: 1.0,
        across: 0.0,
        rho_d: 1.0,
    };
}

/// The module docs' encoding: scales over 2, the share across in full.
fn encode(t: Texel) -> [u8; 4] {
    let byte = |x: f32| (x.clamp(0.0, 1.0) * 255.0).round() as u8;
    [
        byte(t.rho_s / 2.0),
        byte(t.alpha / 2.0),
        byte(t.across),
        byte(t.rho_d / 2.0),
    ]
}

/// The scales a texel's bytes hold (the shader's reading).
pub fn decode(texel: [u8; 4]) -> [f32; 4] {
    let f = |b: u8| f32::from(b) / 255.0;
    [2.0 * f(texel[0]), 2.0 * f(texel[1]), f(texel[2]), 2.0 * f(texel[3])]
}

/// A 32-bit mix of three numbers (a few rounds of a multiply–xorshift hash).
fn hash(a: u32, b: u32, salt: u32) -> u32 {
    let mut x = a.wrapping_mul(0x9E37_79B1) ^ b.wrapping_mul(0x85EB_CA77) ^ salt.wrapping_mul(0xC2B2_AE3D);
    for _ in 0..3 {
        x ^= x >> 15;
        x = x.wrapping_mul(0x2C1B_3C6D);
        x ^= x >> 12;
    }
    x
}

/// A hash as a number in [0, 1).
fn unit(h: u32) -> f32 {
    (h >> 8) as f32 / (1u32 << 24) as f32
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ward::{WardLobe, WardPreset};

    fn texel_at(bytes: &[u8], size: u32, i: u32, j: u32) -> [f32; 4] {
        let k = ((j * size + i) * 4) as usize;
        decode([bytes[k], bytes[k + 1], bytes[k + 2], bytes[k + 3]])
    }

    #[test]
    fn each_map_keeps_the_presets_albedo_on_average_and_tiles() {
        for map in [WardMap::Brushed, WardMap::Woven] {
            let (size, bytes) = map.texels();
            assert_eq!(bytes.len(), (size * size * 4) as usize);
            let mut sum = [0.0f64; 4];
            for j in 0..size {
                for i in 0..size {
                    let t = texel_at(&bytes, size, i, j);
                    for c in 0..4 {
                        sum[c] += f64::from(t[c]);
                    }
                }
            }
            let mean = sum.map(|s| s / f64::from(size * size));
            for c in [0, 1, 3] {
                assert!((mean[c] - 1.0).abs() < 0.02, "{map:?}: mean scale {c} is {}", mean[c]);
            }
            // Tiling: the last column runs on into the first as any two neighbours do (no seam
            // larger than the largest step inside).
            let step = |a: [f32; 4], b: [f32; 4]| (0..4).map(|c| (a[c] - b[c]).abs()).fold(0.0, f32::max);
            let mut inside = 0.0f32;
            let mut seam = 0.0f32;
            for j in 0..size {
                for i in 1..size {
                    inside = inside.max(step(texel_at(&bytes, size, i - 1, j), texel_at(&bytes, size, i, j)));
                }
                seam = seam.max(step(texel_at(&bytes, size, size - 1, j), texel_at(&bytes, size, 0, j)));
            }
            assert!(seam <= inside + 1e-6, "{map:?}: seam {seam} vs inside {inside}");
        }
        // The weave's crossings: half the texels are weft on top.
        let (size, bytes) = WardMap::Woven.texels();
        let across = (0..size * size).filter(|k| bytes[(*k * 4 + 2) as usize] == 255).count();
        assert_eq!(across, (size * size / 2) as usize);
        assert_eq!(WardMap::Uniform.texels(), (1, vec![128, 128, 0, 128]));
    }

    #[test]
    fn every_texel_of_every_preset_conserves_energy() {
        // The white furnace at each texel's material: ρd + ρs ≤ 1 per channel and the lobe's
        // albedo ≤ 1 (its bound: the lobe's own albedo never exceeds one, tested in ward.rs).
        for map in [WardMap::Brushed, WardMap::Woven] {
            let (size, bytes) = map.texels();
            for preset in WardPreset::ALL {
                let base = preset.material();
                for k in (0..size * size).step_by(97) {
                    let (i, j) = (k % size, k / size);
                    let m = WardMap::material_at(&base, texel_at(&bytes, size, i, j));
                    for c in 0..3 {
                        assert!(
                            m.rho_d[c] + m.rho_s[c] <= 1.0 + 1e-6,
                            "{map:?} {preset:?} ({i}, {j}): {m:?}"
                        );
                        assert!(m.rho_d[c] >= 0.0 && m.rho_s[c] >= 0.0);
                    }
                    let lobe = WardLobe::new(m.alpha_x, m.alpha_y);
                    assert_eq!((lobe.alpha_x, lobe.alpha_y), (m.alpha_x, m.alpha_y), "in range");
                }
            }
        }
        // A texel that would create energy is held back: ρs × 2 of 0.7 → 1, ρd → 0.
        let brushed = WardPreset::BrushedMetal.material();
        let m = WardMap::material_at(&brushed, [2.0, 1.0, 0.0, 2.0]);
        assert_eq!((m.rho_s[0], m.rho_d[0]), (1.0, 0.0));
    }

    #[test]
    fn the_weft_turns_the_lobe_a_quarter() {
        let silk = WardPreset::Silk.material();
        let warp = WardMap::material_at(&silk, [1.0, 1.0, 0.0, 1.0]);
        let weft = WardMap::material_at(&silk, [1.0, 1.0, 1.0, 1.0]);
        assert_eq!((warp.alpha_x, warp.alpha_y), (silk.alpha_x, silk.alpha_y));
        assert_eq!((weft.alpha_x, weft.alpha_y), (silk.alpha_y, silk.alpha_x));
        // Half and half (a coarse mip level): both roughnesses the mean.
        let mixed = WardMap::material_at(&silk, [1.0, 1.0, 0.5, 1.0]);
        assert!((mixed.alpha_x - mixed.alpha_y).abs() < 1e-6);
        for m in WardMap::ALL {
            assert_eq!(WardMap::from_key(m.key()), Some(m));
        }
        assert_eq!(WardMap::from_key("plaid"), None);
    }
}
