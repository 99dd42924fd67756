//! Image-based light: an environment of radiance around the artifact, fixed in the room like the
//! directional light, reduced to the nine spherical-harmonic coefficients of its irradiance
//! (Ramamoorthi & Hanrahan, "An efficient representation for irradiance environment maps",
//! SIGGRAPH 2001) for diffuse lighting.
//!
//! * Environments are equirectangular, linear radiance, in the **world frame** (x east, y north,
//!   z up): column `u ∈ [0, 1)` is the azimuth `φ = 2π·u` measured from east towards north, row
//!   `v ∈ [0, 1)` the polar angle `θ = π·v` from the zenith. Files: Radiance `.hdr` and OpenEXR
//!   (feature `models`, through the `image` crate); [`Environment::studio`] generates the default.
//! * [`IrradianceSh`] holds `L_lm` (RGB) of the environment's radiance; [`IrradianceSh::irradiance`]
//!   evaluates `E(n)`, so a Lambertian surface of albedo `ρ` reflects `ρ/π · E(n)`.
//!
//! * Specular: the split-sum approximation (Karis, "Real Shading in Unreal Engine 4", 2013):
//!   [`prefiltered_levels`] convolves the environment with the GGX lobe for a ladder of
//!   roughnesses (one equirectangular mip level each, assuming n = v = r), and [`brdf_lut`]
//!   tabulates the scale and bias applied to F0 as a function of n·v and roughness.
//!
//!   The renderer uploads the levels as an `Rgba16Float` mip chain and the table as an `Rg16Float`
//!   texture and samples them with the roughness as the level of detail.
//!
//! **Threading**: everything here is plain data and pure functions; [`prefiltered_levels`] spreads
//! its rows over the cores ([`crate::parallel::map`]; same result as in series) and returns when
//! done.

use glam::Vec3;

/// Widest environment [`Environment::load`] reads: 4096 × 2048 (128 MiB as RGBA floats while
/// decoding). The image-based light is prefiltered down to a few hundred texels a side.
pub const MAX_WIDTH_PX: u32 = 4096;

/// An equirectangular environment, linear RGB radiance, world frame (see the module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct Environment {
    pub width: usize,
    pub height: usize,
    pub texels: Vec<[f32; 3]>,
}

#[derive(Debug, thiserror::Error)]
pub enum EnvironmentError {
    #[error("{}: {message}", path.display())]
    Load { path: std::path::PathBuf, message: String },
    #[error("{}: environment maps must be equirectangular (width = 2 × height), got {width}×{height}", path.display())]
    NotEquirectangular {
        path: std::path::PathBuf,
        width: usize,
        height: usize,
    },
}

impl Environment {
    /// The world direction of texel centre `(x, y)`.
    pub fn direction(&self, x: usize, y: usize) -> Vec3 {
        let phi = std::f32::consts::TAU * (x as f32 + 0.5) / self.width as f32;
        let theta = std::f32::consts::PI * (y as f32 + 0.5) / self.height as f32;
        Vec3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos())
    }

    /// A neutral studio, made here: a soft overhead key panel towards the north-west, a dimmer fill
    /// from the south-east, a grey horizon and a darker floor. Values are linear radiance, tuned so
    /// that a white surface facing up receives about the same irradiance as from the directional
    /// light's ambient share.
    pub fn studio() -> Self {
        let (width, height) = (64usize, 32usize);
        let key = Vec3::new(-0.4, 0.4, 0.82).normalize();
        let fill = Vec3::new(0.5, -0.6, 0.62).normalize();
        let mut env = Self {
            width,
            height,
            texels: vec![[0.0; 3]; width * height],
        };
        for y in 0..height {
            for x in 0..width {
                let d = env.direction(x, y);
                // Horizon band and floor: neutral grey, slightly warm above, darker below.
                let base = if d.z >= 0.0 { 0.10 + 0.06 * d.z } else { 0.045 };
                let soft = |centre: Vec3, width: f32, power: f32| power * ((d.dot(centre) - 1.0) / width).exp();
                let k = soft(key, 0.08, 1.6);
                let f = soft(fill, 0.15, 0.35);
                env.texels[y * width + x] = [
                    base + k + f * 0.95,
                    base + k * 0.98 + f * 0.97,
                    base * 1.04 + k * 0.95 + f,
                ];
            }
        }
        env
    }

    /// Loads a Radiance `.hdr` or OpenEXR file, equirectangular, at most [`MAX_WIDTH_PX`] wide.
    pub fn load(path: &std::path::Path) -> Result<Self, EnvironmentError> {
        let err = |message: String| EnvironmentError::Load {
            path: path.to_path_buf(),
            message,
        };
        // Regular files only: a pipe would block, a device never end.
        let open = || {
            let file = phantogram_files::open_regular_file(path).map_err(|e| err(e.to_string()))?;
            image::ImageReader::new(std::io::BufReader::new(file))
                .with_guessed_format()
                .map_err(|e| err(e.to_string()))
        };
        let reader = open()?;
        if reader.format() == Some(image::ImageFormat::OpenExr) {
            // A damaged EXR can otherwise abort the process (see `exr_guard`).
            let file = phantogram_files::open_regular_file(path).map_err(|e| err(e.to_string()))?;
            crate::exr_guard::check(file).map_err(err)?;
        }
        // The size from the header, checked before anything is decoded.
        let (w, h) = reader.into_dimensions().map_err(|e| err(e.to_string()))?;
        if w > MAX_WIDTH_PX || h > MAX_WIDTH_PX / 2 {
            return Err(err(format!(
                "{w}×{h} pixels, larger than an environment may be ({MAX_WIDTH_PX}×{}): the light \
                 prefiltered from it needs no more, and as floats it would take {} MiB; scale it down",
                MAX_WIDTH_PX / 2,
                (u64::from(w) * u64::from(h) * 16) >> 20
            )));
        }
        let mut reader = open()?;
        let mut limits = image::Limits::default();
        limits.max_image_width = Some(w);
        limits.max_image_height = Some(h);
        // RGBA f32 while decoding, RGB f32 after: room for both.
        limits.max_alloc = Some(u64::from(w) * u64::from(h) * 32);
        reader.limits(limits);
        // `exr` is young: its B44 decoder panics on some damaged files. That is this file's
        // error, not the app's end.
        let img = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| reader.decode()))
            .map_err(|_| err("the decoder failed on this file (damaged?)".to_owned()))?
            .map_err(|e| err(e.to_string()))?
            .into_rgb32f();
        let (width, height) = (img.width() as usize, img.height() as usize);
        if width != 2 * height || height == 0 {
            return Err(EnvironmentError::NotEquirectangular {
                path: path.to_path_buf(),
                width,
                height,
            });
        }
        let texels = img
            .pixels()
            .map(|p| p.0.map(|c| if c.is_finite() { c.max(0.0) } else { 0.0 }))
            .collect();
        Ok(Self { width, height, texels })
    }
}

/// Nine RGB spherical-harmonic coefficients of an environment's radiance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IrradianceSh {
    pub coefficients: [[f32; 3]; 9],
}

/// The real SH basis up to l = 2 at unit direction `d`.
fn basis(d: Vec3) -> [f32; 9] {
    let (x, y, z) = (d.x, d.y, d.z);
    [
        0.282_095,
        0.488_603 * y,
        0.488_603 * z,
        0.488_603 * x,
        1.092_548 * x * y,
        1.092_548 * y * z,
        0.315_392 * (3.0 * z * z - 1.0),
        1.092_548 * x * z,
        0.546_274 * (x * x - y * y),
    ]
}

/// Convolution of radiance with the clamped cosine, per band (Ramamoorthi & Hanrahan):
/// `Â_0 = π`, `Â_1 = 2π/3`, `Â_2 = π/4`.
const BAND_WEIGHTS: [f32; 9] = {
    use std::f32::consts::{FRAC_PI_4, PI};
    const A1: f32 = 2.0 * PI / 3.0;
    [PI, A1, A1, A1, FRAC_PI_4, FRAC_PI_4, FRAC_PI_4, FRAC_PI_4, FRAC_PI_4]
};

impl IrradianceSh {
    /// Projects the environment onto the SH basis, each texel weighted by its solid angle.
    pub fn from_environment(env: &Environment) -> Self {
        let mut c = [[0.0f64; 3]; 9];
        let d_phi = std::f64::consts::TAU / env.width as f64;
        let d_theta = std::f64::consts::PI / env.height as f64;
        for y in 0..env.height {
            let theta = (y as f64 + 0.5) * d_theta;
            let solid_angle = theta.sin() * d_theta * d_phi;
            for x in 0..env.width {
                let b = basis(env.direction(x, y));
                let l = env.texels[y * env.width + x];
                for (k, bk) in b.iter().enumerate() {
                    for ch in 0..3 {
                        c[k][ch] += (l[ch] as f64) * (*bk as f64) * solid_angle;
                    }
                }
            }
        }
        Self {
            coefficients: c.map(|v| v.map(|x| x as f32)),
        }
    }

    /// Irradiance `E(n)` (RGB) on a surface with world normal `n`.
    pub fn irradiance(&self, n: Vec3) -> [f32; 3] {
        let b = basis(n.normalize_or(Vec3::Z));
        let mut e = [0.0f32; 3];
        for k in 0..9 {
            for (ch, ek) in e.iter_mut().enumerate() {
                *ek += BAND_WEIGHTS[k] * self.coefficients[k][ch] * b[k];
            }
        }
        e.map(|v| v.max(0.0))
    }

    /// The coefficients pre-multiplied by the band weights and basis constants, as the shader
    /// evaluates them: `E(n) = Σ k_i · c_i · poly_i(n)` with the polynomial parts of the real SH
    /// basis up to l = 2.
    pub fn shader_coefficients(&self) -> [[f32; 4]; 9] {
        let constants = [
            0.282_095, 0.488_603, 0.488_603, 0.488_603, 1.092_548, 1.092_548, 0.315_392, 1.092_548, 0.546_274,
        ];
        let mut out = [[0.0f32; 4]; 9];
        for (k, row) in out.iter_mut().enumerate() {
            for (ch, v) in row.iter_mut().take(3).enumerate() {
                *v = BAND_WEIGHTS[k] * constants[k] * self.coefficients[k][ch];
            }
        }
        out
    }
}

impl Environment {
    /// Bilinear lookup in the direction `d` (world frame), wrapping in azimuth.
    pub fn sample(&self, d: Vec3) -> [f32; 3] {
        let d = d.normalize_or(Vec3::Z);
        let u = (d.y.atan2(d.x) / std::f32::consts::TAU).rem_euclid(1.0) * self.width as f32 - 0.5;
        let v = (d.z.clamp(-1.0, 1.0).acos() / std::f32::consts::PI) * self.height as f32 - 0.5;
        let (x0, y0) = (u.floor(), v.floor());
        let (fx, fy) = (u - x0, v - y0);
        let texel = |x: f32, y: f32| {
            let xi = (x as i64).rem_euclid(self.width as i64) as usize;
            let yi = (y as i64).clamp(0, self.height as i64 - 1) as usize;
            self.texels[yi * self.width + xi]
        };
        let mut out = [0.0f32; 3];
        for (dx, dy, w) in [
            (0.0, 0.0, (1.0 - fx) * (1.0 - fy)),
            (1.0, 0.0, fx * (1.0 - fy)),
            (0.0, 1.0, (1.0 - fx) * fy),
            (1.0, 1.0, fx * fy),
        ] {
            let t = texel(x0 + dx, y0 + dy);
            for c in 0..3 {
                out[c] += t[c] * w;
            }
        }
        out
    }

    /// Half the resolution, each texel the mean of four (keeps the integral for prefiltering).
    fn downsampled(&self) -> Self {
        let (w, h) = ((self.width / 2).max(2), (self.height / 2).max(1));
        let mut texels = vec![[0.0f32; 3]; w * h];
        for y in 0..h {
            for x in 0..w {
                let mut acc = [0.0f32; 3];
                for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                    let t = self.texels
                        [((2 * y + dy).min(self.height - 1)) * self.width + (2 * x + dx).min(self.width - 1)];
                    for c in 0..3 {
                        acc[c] += t[c] * 0.25;
                    }
                }
                texels[y * w + x] = acc;
            }
        }
        Self {
            width: w,
            height: h,
            texels,
        }
    }
}

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

/// The environment convolved with the GGX lobe: level `k` (roughness `k / (LEVELS − 1)`) at
/// `base_width / 2^k` × `base_width / 2^(k+1)`, so the levels form the first [`PREFILTER_LEVELS`]
/// levels of a texture mip chain. Level 0 is the environment itself, resampled to
/// `base_width × base_width / 2`.
///
/// `base_width` is rounded up to a power of two of at least `2^PREFILTER_LEVELS` so that every
/// level has whole texels.
pub fn prefiltered_levels(env: &Environment, base_width: usize) -> Vec<Environment> {
    let base_width = base_width.max(1 << PREFILTER_LEVELS).next_power_of_two();
    // Sample from a source a little coarser than each level, so few samples suffice.
    let mut source = env.clone();
    while source.width >= 2 * base_width && source.width > 8 {
        source = source.downsampled();
    }
    if source.width != base_width || source.height != base_width / 2 {
        let mut level0 = Environment {
            width: base_width,
            height: base_width / 2,
            texels: Vec::new(),
        };
        level0.texels = (0..level0.height)
            .flat_map(|y| (0..level0.width).map(move |x| (x, y)))
            .map(|(x, y)| source.sample(level0.direction(x, y)))
            .collect();
        source = level0;
    }
    let mut levels = vec![source.clone()];
    let samples = 96u32;
    for k in 1..PREFILTER_LEVELS {
        let roughness = k as f32 / (PREFILTER_LEVELS - 1) as f32;
        let alpha = roughness * roughness;
        let (w, h) = (base_width >> k, base_width >> (k + 1));
        while source.width > 2 * w && source.width > 8 {
            source = source.downsampled();
        }
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

/// The split-sum BRDF table: `size × size` entries of `(scale, bias)` with n·v along x (0 → 1)
/// and roughness along y (0 → 1), so that the specular image-based light is
/// `prefiltered(r, roughness) · (F0 · scale + bias)`.
pub fn brdf_lut(size: usize) -> Vec<[f32; 2]> {
    let samples = 256u32;
    let mut out = Vec::with_capacity(size * size);
    for j in 0..size {
        let roughness = (j as f32 + 0.5) / size as f32;
        let alpha = roughness * roughness;
        // Schlick–GGX geometry with k = α/2 for image-based light (Karis 2013).
        let k = alpha / 2.0;
        let g1 = |c: f32| c / (c * (1.0 - k) + k);
        for i in 0..size {
            let n_dot_v = ((i as f32 + 0.5) / size as f32).max(1e-3);
            let v = Vec3::new((1.0 - n_dot_v * n_dot_v).sqrt(), 0.0, n_dot_v);
            let (mut a, mut b) = (0.0f32, 0.0f32);
            for s in 0..samples {
                let (u1, u2) = hammersley(s, samples);
                let h = ggx_half_vector(u1, u2, alpha, Vec3::Z);
                let l = h * 2.0 * v.dot(h) - v;
                let (n_dot_l, n_dot_h, v_dot_h) = (l.z, h.z.max(0.0), v.dot(h).max(0.0));
                if n_dot_l > 0.0 {
                    let g_vis = g1(n_dot_l) * g1(n_dot_v) * v_dot_h / (n_dot_h * n_dot_v).max(1e-6);
                    let fc = (1.0 - v_dot_h).powi(5);
                    a += (1.0 - fc) * g_vis;
                    b += fc * g_vis;
                }
            }
            out.push([a / samples as f32, b / samples as f32]);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

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

    #[test]
    fn sampling_a_texel_centre_direction_returns_that_texel() {
        let env = Environment::studio();
        for (x, y) in [(0, 0), (13, 5), (40, 16), (63, 31)] {
            let got = env.sample(env.direction(x, y));
            let want = env.texels[y * env.width + x];
            for c in 0..3 {
                assert!(
                    (got[c] - want[c]).abs() < 1e-4 * (1.0 + want[c]),
                    "({x},{y}): {got:?} vs {want:?}"
                );
            }
        }
    }

    fn uniform(value: f32) -> Environment {
        Environment {
            width: 128,
            height: 64,
            texels: vec![[value; 3]; 128 * 64],
        }
    }

    #[test]
    fn constant_radiance_gives_pi_times_radiance_everywhere() {
        let sh = IrradianceSh::from_environment(&uniform(0.5));
        for n in [Vec3::Z, -Vec3::Z, Vec3::X, Vec3::new(0.3, -0.7, 0.2)] {
            let e = sh.irradiance(n);
            assert!((e[0] - std::f32::consts::PI * 0.5).abs() < 0.01, "{n}: {e:?}");
        }
    }

    #[test]
    fn sky_lights_upward_faces_and_the_direction_convention_holds() {
        // Radiance 1 above the horizon, 0 below: E(up) = π, E(down) ≈ 0, sideways ≈ π/2.
        let mut env = uniform(0.0);
        for y in 0..env.height / 2 {
            for x in 0..env.width {
                env.texels[y * env.width + x] = [1.0; 3];
            }
        }
        let sh = IrradianceSh::from_environment(&env);
        let pi = std::f32::consts::PI;
        assert!((sh.irradiance(Vec3::Z)[0] - pi).abs() < 0.12 * pi);
        assert!(sh.irradiance(-Vec3::Z)[0] < 0.12 * pi);
        assert!((sh.irradiance(Vec3::X)[0] - pi / 2.0).abs() < 0.05 * pi);
        // Column 0 is east (φ = 0), a quarter turn later north.
        assert!(env.direction(0, env.height / 2).distance(Vec3::X) < 0.1);
        assert!(env.direction(env.width / 4, env.height / 2).distance(Vec3::Y) < 0.1);
    }

    #[test]
    fn studio_is_brighter_from_above_and_towards_its_key_light() {
        let sh = IrradianceSh::from_environment(&Environment::studio());
        let up = sh.irradiance(Vec3::Z)[0];
        assert!(up > 2.0 * sh.irradiance(-Vec3::Z)[0]);
        let towards_key = sh.irradiance(Vec3::new(-0.4, 0.4, 0.82))[0];
        let away = sh.irradiance(Vec3::new(0.4, -0.4, 0.82))[0];
        assert!(towards_key > away);
        // The shader's pre-multiplied form evaluates to the same irradiance.
        let k = sh.shader_coefficients();
        let n = Vec3::new(0.2, 0.5, 0.84).normalize();
        let poly = [
            1.0,
            n.y,
            n.z,
            n.x,
            n.x * n.y,
            n.y * n.z,
            3.0 * n.z * n.z - 1.0,
            n.x * n.z,
            n.x * n.x - n.y * n.y,
        ];
        let e: f32 = (0..9).map(|i| k[i][0] * poly[i]).sum();
        assert!((e - sh.irradiance(n)[0]).abs() < 1e-4);
    }
}
