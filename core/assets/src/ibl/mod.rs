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
//!   The renderer uploads the levels as an `Rgba16Float` mip chain, sampled with the roughness as
//!   the level of detail, and the albedo tables as one `Rgba16Float` texture: the round lobes'
//!   (split sum, sheen, Ward) above, the stretched lobes' ([`anisotropic_albedo`]) below them and
//!   where to read the sheen's light from ([`sheen_direction`]) at the bottom.
//!
//! **Threading**: everything here is plain data and pure functions; [`prefiltered_levels`] and
//! [`IrradianceSh::from_environment`] spread their rows over the cores ([`crate::parallel::map`])
//! and return when done.
//!
//! Files: [`sh`] (the irradiance's nine coefficients), [`prefilter`] (the specular levels and
//! the split-sum table), [`sheen`] and [`ward_albedo`] (those lobes' albedo tables, beside the
//! split sum's), [`anisotropic_albedo`] (the stretched GGX and Ward lobes' albedo, by view
//! azimuth and stretch), [`anisotropic`] (a stretched lobe's light read from those levels),
//! [`sheen_direction`] (where the sheen's light is read from), [`accuracy`] (those reads against
//! integrals of their lobes over the room), [`sun`] (a room's small bright source, taken out to
//! light as the directional light); this one holds the environment map itself.

use glam::Vec3;

pub mod accuracy;
pub mod anisotropic;
pub mod anisotropic_albedo;
pub mod prefilter;
pub mod sh;
pub mod sheen;
pub mod sheen_direction;
pub mod sun;
pub mod ward_albedo;

pub use anisotropic::{STRETCH_TAP_NODES, STRETCHED_IMAGE_LIGHT_TAPS, StretchedImageLight, sample_levels};
pub use prefilter::{
    PREFILTER_LEVELS, PREFILTER_SAMPLES, PrefilterSources, brdf_lut, prefilter_base, prefilter_base_width,
    prefiltered_levels, table_axis, table_bilinear,
};
pub use sh::IrradianceSh;
pub use sheen::sheen_albedo_table;
pub use ward_albedo::ward_albedo_table;

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

    /// Solid angle of a texel in row `y`, steradians.
    pub fn texel_solid_angle_sr(&self, y: usize) -> f32 {
        let theta = std::f32::consts::PI * (y as f32 + 0.5) / self.height as f32;
        (std::f32::consts::TAU / self.width as f32) * (std::f32::consts::PI / self.height as f32) * theta.sin()
    }

    /// A neutral studio, made here: a soft overhead key panel towards the north-west, a dimmer fill
    /// from the south-east, a grey horizon and a darker floor. Values are linear radiance, tuned so
    /// that a white surface facing up receives about the same irradiance as from the directional
    /// light's ambient share.
    pub fn studio() -> Self {
        let key = Vec3::new(-0.4, 0.4, 0.82).normalize();
        let fill = Vec3::new(0.5, -0.6, 0.62).normalize();
        Self::from_directions(64, 32, |d| {
            // Horizon band and floor: neutral grey, slightly warm above, darker below.
            let base = if d.z >= 0.0 { 0.10 + 0.06 * d.z } else { 0.045 };
            let soft = |centre: Vec3, width: f32, power: f32| power * ((d.dot(centre) - 1.0) / width).exp();
            let k = soft(key, 0.08, 1.6);
            let f = soft(fill, 0.15, 0.35);
            [
                base + k + f * 0.95,
                base + k * 0.98 + f * 0.97,
                base * 1.04 + k * 0.95 + f,
            ]
        })
    }

    /// A `width` × `height` map whose texel in each direction ([`Environment::direction`]) has
    /// the radiance `radiance` gives it: rooms made from a formula.
    pub fn from_directions(width: usize, height: usize, radiance: impl Fn(Vec3) -> [f32; 3]) -> Self {
        let mut env = Self {
            width,
            height,
            texels: Vec::with_capacity(width * height),
        };
        for y in 0..height {
            for x in 0..width {
                let texel = radiance(env.direction(x, y));
                env.texels.push(texel);
            }
        }
        env
    }

    /// The benchmarks' map (`benches/ibl.rs` here, `prefilter.rs` in the renderer): `width` ×
    /// `width / 2` texels of a sky gradient, a 5000× sun and per-texel noise, so that no part of an
    /// update meets a constant run. Deterministic.
    pub fn benchmark_sky(width: usize) -> Self {
        let height = width / 2;
        let mut env = Self {
            width,
            height,
            texels: Vec::with_capacity(width * height),
        };
        let sun = Vec3::new(0.3, -0.5, 0.8).normalize();
        let mut state = 0x2545_f491_4f6c_dd1du64;
        for y in 0..height {
            for x in 0..width {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                let noise = (state >> 40) as f32 / (1u64 << 24) as f32;
                let d = env.direction(x, y);
                let s = if d.dot(sun) > 0.9995 { 5000.0 } else { 0.0 };
                let sky = 0.2 + 0.8 * d.z.max(0.0) + 0.1 * noise;
                env.texels.push([sky + s, sky * 1.1 + s, sky * 1.3 + s]);
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

    /// `1/factor` of the resolution, each texel the mean of a `factor × factor` block: what
    /// `log2(factor)` calls of [`Self::downsampled`] give (to rounding), in one pass with rows on
    /// every core. `factor` must divide both sides (the caller checks; otherwise the edge blocks
    /// would be short).
    pub fn box_filtered(&self, factor: usize) -> Self {
        let factor = factor.max(1);
        let (w, h) = (self.width / factor, self.height / factor);
        let rows: Vec<usize> = (0..h).collect();
        let scale = 1.0 / (factor * factor) as f32;
        let texels = crate::parallel::map(&rows, |&y| {
            let mut row = vec![[0.0f32; 3]; w];
            for sy in y * factor..(y + 1) * factor {
                let source = &self.texels[sy * self.width..(sy + 1) * self.width];
                for (out, block) in row.iter_mut().zip(source.chunks_exact(factor)) {
                    for t in block {
                        for c in 0..3 {
                            out[c] += t[c];
                        }
                    }
                }
            }
            for t in &mut row {
                *t = t.map(|c| c * scale);
            }
            row
        })
        .concat();
        Self {
            width: w,
            height: h,
            texels,
        }
    }

    /// The mean luminance (Rec. 709) over the sphere, each texel weighted by its solid angle: the
    /// level an averaging light meter reads in the middle of this environment. 0 for an empty map;
    /// non-finite texels count as 0.
    pub fn mean_luminance(&self) -> f32 {
        if self.width == 0 || self.height == 0 || self.texels.len() != self.width * self.height {
            return 0.0;
        }
        let (mut sum, mut total) = (0.0f64, 0.0f64);
        for (y, row) in self.texels.chunks_exact(self.width).enumerate() {
            let solid = (std::f64::consts::PI * (y as f64 + 0.5) / self.height as f64).sin();
            let row_sum: f64 = row
                .iter()
                .map(|t| phantogram_geometry::srgb::luminance(*t))
                .filter(|l| l.is_finite())
                .map(f64::from)
                .sum();
            sum += row_sum * solid;
            total += solid * self.width as f64;
        }
        if total > 0.0 { (sum / total) as f32 } else { 0.0 }
    }

    /// Half the resolution, each texel the mean of four (keeps the integral for prefiltering).
    pub fn downsampled(&self) -> Self {
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

#[cfg(test)]
mod tests {
    use super::*;

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

    #[test]
    fn one_box_filter_equals_repeated_halvings() {
        // Noise, a gradient and a 5000× sun: every texel differs from its neighbours.
        let env = Environment::benchmark_sky(256);
        let twice = env.downsampled().downsampled().downsampled();
        let once = env.box_filtered(8);
        assert_eq!((once.width, once.height), (twice.width, twice.height));
        for (a, b) in once.texels.iter().zip(&twice.texels) {
            for c in 0..3 {
                assert!((a[c] - b[c]).abs() <= 1e-5 * b[c].abs().max(1.0), "{a:?} vs {b:?}");
            }
        }
        // A block mean, not a point sample: the mean radiance is kept.
        let mean = |e: &Environment| e.texels.iter().map(|t| f64::from(t[0])).sum::<f64>() / e.texels.len() as f64;
        assert!((mean(&once) - mean(&env)).abs() < 1e-4 * mean(&env));
    }

    #[test]
    fn the_mean_luminance_weights_each_texel_by_its_solid_angle() {
        assert!((uniform(2.0).mean_luminance() - 2.0).abs() < 1e-5);
        // Lit above the horizon only: half the sphere, whatever the rows' count near the poles.
        let mut half = uniform(1.0);
        let (w, h) = (half.width, half.height);
        for t in &mut half.texels[w * h / 2..] {
            *t = [0.0; 3];
        }
        assert!((half.mean_luminance() - 0.5).abs() < 1e-3, "{}", half.mean_luminance());
        // Only the polar caps (a fifth of the rows, about 5 % of the sphere): an unweighted mean
        // of the texels would read 20 %.
        let mut caps = uniform(0.0);
        let cap_rows = h / 10;
        for y in (0..cap_rows).chain(h - cap_rows..h) {
            for t in &mut caps.texels[y * w..(y + 1) * w] {
                *t = [1.0; 3];
            }
        }
        let want = 1.0 - (std::f32::consts::PI * cap_rows as f32 / h as f32).cos();
        assert!(
            (caps.mean_luminance() - want).abs() < 2e-3,
            "{} vs {want}",
            caps.mean_luminance()
        );
        // Rec. 709's weights; the same as the irradiance's constant term.
        let red = Environment {
            texels: vec![[1.0, 0.0, 0.0]; w * h],
            ..uniform(0.0)
        };
        assert!((red.mean_luminance() - 0.2126).abs() < 1e-5);
        let studio = Environment::studio();
        let c0 = IrradianceSh::from_environment(&studio).coefficients[0];
        let from_sh = 0.282_095 * phantogram_geometry::srgb::luminance(c0);
        assert!(
            (studio.mean_luminance() - from_sh).abs() < 1e-3 * from_sh,
            "{} vs {from_sh}",
            studio.mean_luminance()
        );
        assert_eq!(
            Environment {
                width: 0,
                height: 0,
                texels: vec![]
            }
            .mean_luminance(),
            0.0
        );
    }

    /// An environment of one radiance everywhere.
    pub(crate) fn uniform(value: f32) -> Environment {
        Environment {
            width: 128,
            height: 64,
            texels: vec![[value; 3]; 128 * 64],
        }
    }
}
