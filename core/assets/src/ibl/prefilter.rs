//! The specular part of the image-based light: the environment convolved with the GGX lobe for a
//! ladder of roughnesses, and the split-sum table (see the [parent module](super)).

use glam::Vec3;

use super::Environment;

/// Number of roughness levels in the prefiltered environment (roughness `k / (LEVELS − 1)`).
pub const PREFILTER_LEVELS: usize = 6;

/// The `i`-th point of the Hammersley set of `n`.
fn hammersley(i: u32, n: u32) -> (f32, f32) {
    (i as f32 / n as f32, (i.reverse_bits() as f64 / 4_294_967_296.0) as f32)
}

/// A GGX half vector about `n` for the sample `(u1, u2)` and `alpha = roughness²`.
fn ggx_half_vector(u1: f32, u2: f32, alpha: f32, n: Vec3) -> Vec3 {
    let phi = std::f32::consts::TAU * u1;
    let cos_theta = ((1.0 - u2) / (1.0 + (alpha * alpha - 1.0) * u2)).max(0.0).sqrt();
    let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    let up = if n.z.abs() < 0.999 { Vec3::Z } else { Vec3::X };
    let t = up.cross(n).normalize();
    let b = n.cross(t);
    (t * (sin_theta * phi.cos()) + b * (sin_theta * phi.sin()) + n * cos_theta).normalize()
}

/// Width of [`prefiltered_levels`]' sharpest level for a requested `base_width`: a power of two
/// of at least `2^PREFILTER_LEVELS`, so that every level has whole texels.
pub fn prefilter_base_width(base_width: usize) -> usize {
    base_width.max(1 << PREFILTER_LEVELS).next_power_of_two()
}

/// Level 0 of [`prefiltered_levels`]: the environment resampled to
/// [`prefilter_base_width`]` × half that` (box-filtered down first where it is at least twice as
/// wide). Every rougher level is convolved from it and its box-filtered halvings
/// ([`Environment::downsampled`]), on the CPU here or on the GPU by the renderer.
pub fn prefilter_base(env: &Environment, base_width: usize) -> Environment {
    let base_width = prefilter_base_width(base_width);
    // Sample from a source a little coarser than each level, so few samples suffice: halved while
    // at least twice the base's width.
    let (mut halvings, mut w) = (0u32, env.width);
    while w >= 2 * base_width && w > 8 {
        (halvings, w) = (halvings + 1, (w / 2).max(2));
    }
    let factor = 1usize << halvings;
    let source = if halvings == 0 {
        std::borrow::Cow::Borrowed(env)
    } else if env.width.is_multiple_of(factor) && env.height.is_multiple_of(factor) {
        // The halvings in one pass, rows on every core (a 4096-wide map took 74 ms as four
        // halvings on one core of this machine).
        std::borrow::Cow::Owned(env.box_filtered(factor))
    } else {
        let mut source = env.downsampled();
        for _ in 1..halvings {
            source = source.downsampled();
        }
        std::borrow::Cow::Owned(source)
    };
    if source.width == base_width && source.height == base_width / 2 {
        return source.into_owned();
    }
    let mut level0 = Environment {
        width: base_width,
        height: base_width / 2,
        texels: Vec::new(),
    };
    level0.texels = (0..level0.height)
        .flat_map(|y| (0..level0.width).map(move |x| (x, y)))
        .map(|(x, y)| source.sample(level0.direction(x, y)))
        .collect();
    level0
}

/// GGX samples per texel of a rough level (Hammersley points; the GPU path uses the same).
pub const PREFILTER_SAMPLES: u32 = 96;

/// What the rough levels are convolved from: level 0 and its box-filtered halvings, and which of
/// them each level reads — the first no more than twice its width (never below 8 texels wide),
/// so that [`PREFILTER_SAMPLES`] samples suffice. The CPU ([`prefiltered_levels`]) and the
/// renderer's GPU path read the same ones.
pub struct PrefilterSources {
    /// Level 0 ([`prefilter_base`]) first, then each halving ([`Environment::downsampled`]).
    pub halvings: Vec<Environment>,
    /// `read_by[k]`: the index in `halvings` level `k` reads (level 0 is `halvings[0]` itself).
    pub read_by: [usize; PREFILTER_LEVELS],
}

impl PrefilterSources {
    /// The sources for level 0 `base` (from [`prefilter_base`]).
    pub fn new(base: Environment) -> Self {
        let base_width = base.width;
        let mut halvings = vec![base];
        let mut read_by = [0; PREFILTER_LEVELS];
        for (k, read) in read_by.iter_mut().enumerate().skip(1) {
            let w = base_width >> k;
            while let Some(last) = halvings.last().filter(|s| s.width > 2 * w && s.width > 8) {
                let next = last.downsampled();
                halvings.push(next);
            }
            *read = halvings.len() - 1;
        }
        Self { halvings, read_by }
    }
}

/// The environment convolved with the GGX lobe: level `k` (roughness `k / (LEVELS − 1)`) at
/// `base_width / 2^k` × `base_width / 2^(k+1)`, so the levels form the first [`PREFILTER_LEVELS`]
/// levels of a texture mip chain. Level 0 is [`prefilter_base`]; level `k ≥ 1` reads the
/// halving of level 0 twice its width (bilinear), [`PREFILTER_SAMPLES`] GGX samples a texel
/// weighted by n·l.
///
/// `base_width` is rounded up as [`prefilter_base_width`] says.
pub fn prefiltered_levels(env: &Environment, base_width: usize) -> Vec<Environment> {
    let base_width = prefilter_base_width(base_width);
    let sources = PrefilterSources::new(prefilter_base(env, base_width));
    let mut levels = vec![sources.halvings[0].clone()];
    let samples = PREFILTER_SAMPLES;
    for k in 1..PREFILTER_LEVELS {
        let roughness = k as f32 / (PREFILTER_LEVELS - 1) as f32;
        let alpha = roughness * roughness;
        let (w, h) = (base_width >> k, base_width >> (k + 1));
        let source = &sources.halvings[sources.read_by[k]];
        let grid = Environment {
            width: w,
            height: h,
            texels: Vec::new(),
        };
        let convolve = |x: usize, y: usize| {
            let n = grid.direction(x, y);
            let mut acc = [0.0f32; 3];
            let mut weight = 0.0f32;
            for i in 0..samples {
                let (u1, u2) = hammersley(i, samples);
                let hv = ggx_half_vector(u1, u2, alpha, n);
                let l = (hv * 2.0 * n.dot(hv) - n).normalize();
                let n_dot_l = n.dot(l);
                if n_dot_l > 0.0 {
                    let c = source.sample(l);
                    for ch in 0..3 {
                        acc[ch] += c[ch] * n_dot_l;
                    }
                    weight += n_dot_l;
                }
            }
            acc.map(|a| a / weight.max(1e-6))
        };
        // Rows on every core: this runs when a renderer starts or the environment changes, on
        // the phone's CPU, and each texel is independent (same result as in series).
        let rows: Vec<usize> = (0..h).collect();
        let level = Environment {
            width: w,
            height: h,
            texels: crate::parallel::map(&rows, |&y| (0..w).map(|x| convolve(x, y)).collect::<Vec<_>>()).concat(),
        };
        levels.push(level);
    }
    levels
}

/// Where entry `k` of an albedo table's axis of `size` entries stands (n·v along a row, roughness
/// down a column): `k / (size − 1)`, so that the first and last entries are at 0 and 1 exactly
/// and a bilinear read at any value in [0, 1] interpolates and never extrapolates. Read on the
/// GPU at texture coordinate `(x · (size − 1) + 0.5) / size` (`scene.wgsl`'s `table_uv`).
///
/// (Entries at `(k + ½) / size`, as before, left a half entry at each end that a clamped read
/// takes from its neighbour: at roughness 1 the albedo falls by 2.5 % over that half entry of a
/// 64-entry table, so the table read 3 % high and a white rough metal under lamps sent back 3 %
/// too little.)
pub fn table_axis(k: usize, size: usize) -> f32 {
    if size < 2 { 0.0 } else { k as f32 / (size - 1) as f32 }
}

/// A block of `side × side` entries laid out at [`table_axis`] (its first entry at column
/// `corner.0`, row `corner.1` of a table `width` entries wide, row by row) read at `at` (each in
/// [0, 1], clamped) as the GPU's bilinear filter reads it: the CPU twin of the shader's table
/// reads. An entry the table lacks reads as zero.
pub fn table_bilinear<const N: usize>(
    table: &[[f32; N]],
    width: usize,
    corner: (usize, usize),
    side: usize,
    at: [f32; 2],
) -> [f32; N] {
    let side = side.max(2);
    let [x, y] = at.map(|a| a.clamp(0.0, 1.0) * (side - 1) as f32);
    let (x0, y0) = ((x.floor() as usize).min(side - 2), (y.floor() as usize).min(side - 2));
    let (tx, ty) = (x - x0 as f32, y - y0 as f32);
    let entry = |i: usize, j: usize| {
        table
            .get((corner.1 + j) * width + corner.0 + i)
            .copied()
            .unwrap_or([0.0; N])
    };
    let mix = |a: [f32; N], b: [f32; N], t: f32| std::array::from_fn(|k| a[k] + (b[k] - a[k]) * t);
    mix(
        mix(entry(x0, y0), entry(x0 + 1, y0), tx),
        mix(entry(x0, y0 + 1), entry(x0 + 1, y0 + 1), tx),
        ty,
    )
}

/// The split-sum BRDF table: `size × size` entries of `(scale, bias)` with n·v along x and
/// roughness along y, both from 0 to 1 ([`table_axis`]), so that the specular image-based light
/// is `prefiltered(r, roughness) · (F0 · scale + bias)`.
///
/// It integrates the BRDF the renderer's lights use (glTF's: GGX with the height-correlated
/// Smith visibility, `scene.wgsl`'s `smith_visibility`), so that a surface reflects the room's
/// light and a lamp's alike. (Karis's separable Schlick–GGX, k = α/2, gave up to a fifth less
/// at grazing angles on rough surfaces.)
pub fn brdf_lut(size: usize) -> Vec<[f32; 2]> {
    // Hammersley samples of the GGX half vector per entry: 1024 keep every entry within 0.5 % of
    // a plain hemisphere integral (256 were up to 1.6 % off, at middling roughness and grazing
    // views), tested.
    let samples = 1024u32;
    // Rows on every core: the table is made when the renderer starts (on the lighting tables'
    // background thread), and each row is independent (same result as in series).
    let rows: Vec<usize> = (0..size).collect();
    crate::parallel::map(&rows, |&j| {
        let roughness = table_axis(j, size);
        let alpha = roughness * roughness;
        let a2 = alpha * alpha;
        // V = G / (4 n·l n·v), height-correlated (Heitz 2014).
        let visibility = |n_dot_l: f32, n_dot_v: f32| {
            let gv = n_dot_l * (n_dot_v * n_dot_v * (1.0 - a2) + a2).sqrt();
            let gl = n_dot_v * (n_dot_l * n_dot_l * (1.0 - a2) + a2).sqrt();
            0.5 / (gv + gl).max(1e-7)
        };
        (0..size)
            .map(|i| {
                let n_dot_v = table_axis(i, size).max(1e-3);
                let v = Vec3::new((1.0 - n_dot_v * n_dot_v).sqrt(), 0.0, n_dot_v);
                let (mut a, mut b) = (0.0f32, 0.0f32);
                for s in 0..samples {
                    let (u1, u2) = hammersley(s, samples);
                    let h = ggx_half_vector(u1, u2, alpha, Vec3::Z);
                    let l = h * 2.0 * v.dot(h) - v;
                    let (n_dot_l, n_dot_h, v_dot_h) = (l.z, h.z.max(0.0), v.dot(h).max(0.0));
                    if n_dot_l > 0.0 {
                        // f · n·l / pdf with the half vector's pdf D · n·h / (4 v·h): D cancels.
                        let g_vis = 4.0 * visibility(n_dot_l, n_dot_v) * n_dot_l * v_dot_h / n_dot_h.max(1e-6);
                        let fc = (1.0 - v_dot_h).powi(5);
                        a += (1.0 - fc) * g_vis;
                        b += fc * g_vis;
                    }
                }
                [a / samples as f32, b / samples as f32]
            })
            .collect::<Vec<_>>()
    })
    .concat()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ibl::tests::uniform;

    #[test]
    fn split_sum_table_matches_known_values() {
        let lut = brdf_lut(32);
        let at = |nv: f32, r: f32| lut[((r * 32.0) as usize).min(31) * 32 + ((nv * 32.0) as usize).min(31)];
        // Smooth surface seen head-on: all of F0, no bias.
        let smooth = at(0.99, 0.0);
        assert!((smooth[0] - 1.0).abs() < 0.05 && smooth[1] < 0.02, "{smooth:?}");
        // Rough and grazing: the reflectance drops well below 1.
        let rough = at(0.5, 0.99);
        assert!(rough[0] + rough[1] < 0.8 && rough[0] > 0.2, "{rough:?}");
        // Every entry is a reflectance in [0, 1].
        assert!(lut.iter().all(|[a, b]| *a >= 0.0 && *b >= 0.0 && a + b <= 1.05));
    }

    /// The table holds the albedo of the BRDF the lights use (GGX, height-correlated Smith,
    /// Schlick's Fresnel): checked against that BRDF integrated over the hemisphere of light
    /// directions on a plain grid (no importance sampling), for F0 = 1 (scale + bias) and F0 = 0
    /// (bias), where the lobe is wide enough for the grid; entries where [`table_axis`] puts
    /// them, the last row at roughness 1 and the last column at n·v 1. Within 0.006 (the
    /// table's sampling noise is up to 0.004; a table of 256 samples per entry is 0.011 off, and
    /// one whose entries stand at (k + ½) / size fails too).
    #[test]
    fn split_sum_table_is_the_albedo_of_the_lights_brdf() {
        let size = 16usize;
        let lut = brdf_lut(size);
        let albedo = |n_dot_v: f32, roughness: f32| {
            let (a2, v) = (
                (roughness * roughness).powi(2),
                Vec3::new((1.0 - n_dot_v * n_dot_v).sqrt(), 0.0, n_dot_v),
            );
            let (rows, cols) = (400usize, 800usize);
            let (d_theta, d_phi) = (
                std::f64::consts::FRAC_PI_2 / rows as f64,
                std::f64::consts::TAU / cols as f64,
            );
            let (mut white, mut black) = (0.0f64, 0.0f64);
            for r in 0..rows {
                let theta = (r as f64 + 0.5) * d_theta;
                for c in 0..cols {
                    let phi = (c as f64 + 0.5) * d_phi;
                    let l = Vec3::new(
                        (theta.sin() * phi.cos()) as f32,
                        (theta.sin() * phi.sin()) as f32,
                        theta.cos() as f32,
                    );
                    let h = (l + v).normalize();
                    let (n_dot_l, n_dot_h, v_dot_h) = (l.z, h.z, v.dot(h).max(0.0));
                    let d = a2 / (std::f32::consts::PI * (n_dot_h * n_dot_h * (a2 - 1.0) + 1.0).powi(2));
                    let vis = 0.5
                        / (n_dot_l * (n_dot_v * n_dot_v * (1.0 - a2) + a2).sqrt()
                            + n_dot_v * (n_dot_l * n_dot_l * (1.0 - a2) + a2).sqrt());
                    let f = f64::from(d * vis * n_dot_l) * theta.sin() * d_theta * d_phi;
                    white += f;
                    black += f * f64::from((1.0 - v_dot_h).powi(5));
                }
            }
            (white as f32, black as f32)
        };
        for i in [4usize, 9, 15] {
            for j in [7usize, 11, 15] {
                let (n_dot_v, roughness) = (table_axis(i, size), table_axis(j, size));
                let [scale, bias] = lut[j * size + i];
                let (white, black) = albedo(n_dot_v, roughness);
                assert!(
                    (scale + bias - white).abs() < 0.006 && (bias - black).abs() < 0.003,
                    "n·v {n_dot_v}, roughness {roughness}: table {scale} + {bias}, integrated {white} (F0 = 0: {black})"
                );
            }
        }
    }

    #[test]
    fn prefiltering_keeps_constant_light_and_blurs_a_sun() {
        let levels = prefiltered_levels(&uniform(0.7), 64);
        assert_eq!(levels.len(), PREFILTER_LEVELS);
        // A mip chain: each level halves both sizes (a 64-wide request is already the minimum).
        for (k, l) in levels.iter().enumerate() {
            assert_eq!((l.width, l.height), (64 >> k, 32 >> k));
        }
        // A small environment is resampled up to the requested base.
        let small = Environment {
            width: 16,
            height: 8,
            texels: vec![[0.7; 3]; 128],
        };
        assert_eq!(prefiltered_levels(&small, 100)[0].width, 128);
        for l in &levels {
            assert!(
                l.texels.iter().all(|t| (t[0] - 0.7).abs() < 0.01),
                "{}x{}",
                l.width,
                l.height
            );
        }
        // A small bright patch: the rough levels spread it (lower peak, light further away).
        let mut sun = uniform(0.0);
        sun.texels[10 * sun.width + 40] = [1000.0; 3];
        let levels = prefiltered_levels(&sun, 64);
        let peak = |e: &Environment| e.texels.iter().map(|t| t[0]).fold(0.0, f32::max);
        assert!(peak(&levels[5]) < peak(&levels[1]));
        let lit = |e: &Environment| e.texels.iter().filter(|t| t[0] > 1e-3).count() as f32 / e.texels.len() as f32;
        assert!(lit(&levels[5]) > lit(&levels[1]));
    }
}
