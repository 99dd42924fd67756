//! How close the renderer's image light of a stretched lobe ([`super::anisotropic`]) comes to
//! the truth: a Monte-Carlo integral of the lobe over the environment, compared with the tapped
//! read and with the single read the renderer made before, over a spread of surface frames and
//! views; for a Ward lobe ([`read_errors`]), for GGX stretched by `KHR_materials_anisotropy`
//! ([`stretched_ggx_read_errors`]) and for the sheen of cloth ([`sheen_read_errors`]). Used by
//! the tests here and by the integration tests over the shared rooms.
//!
//! Pure functions; slow (thousands of samples per case), no panics.

use glam::Vec3;
use phantogram_geometry::srgb::luminance;

use super::anisotropic::{StretchedImageLight, sample_levels};
use super::anisotropic_albedo::{smith_lambda, visible_normal};
use super::{Environment, prefiltered_levels};
use crate::ward::WardLobe;

/// Relative RMS error (luminance) of two reads of a lobe's image light, each scaled by the
/// lobe's true directional albedo so that only the direction-dependent part (what the albedo
/// tables do not hold) is compared.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReadErrors {
    /// The read the renderer made before (each function says which).
    pub before: f32,
    /// The renderer's read now.
    pub now: f32,
}

/// The `i`-th of `n` points of a 2-D low-discrepancy set (Hammersley, centred).
fn hammersley(i: u32, n: u32) -> (f32, f32) {
    (
        (i as f32 + 0.5) / n as f32,
        (i.reverse_bits() as f64 / 4_294_967_296.0) as f32,
    )
}

/// A world-from-surface frame: tangent, bitangent, normal.
#[derive(Clone, Copy)]
struct Frame {
    t: Vec3,
    b: Vec3,
    n: Vec3,
}

impl Frame {
    fn world(&self, d: Vec3) -> Vec3 {
        self.t * d.x + self.b * d.y + self.n * d.z
    }

    /// The world direction `d` in the surface frame.
    fn local(&self, d: Vec3) -> Vec3 {
        Vec3::new(self.t.dot(d), self.b.dot(d), self.n.dot(d))
    }
}

/// A deterministic spread of frames and views: normals over the sphere, tangents turned about
/// them by the golden angle, views from 15° to 75° off the normal at every azimuth.
fn cases(count: usize) -> Vec<(Frame, Vec3)> {
    (0..count)
        .map(|i| {
            let (u1, u2) = hammersley(i as u32, count as u32);
            let z = 1.0 - 2.0 * u1;
            let r = (1.0 - z * z).max(0.0).sqrt();
            let phi = std::f32::consts::TAU * u2;
            let n = Vec3::new(r * phi.cos(), r * phi.sin(), z);
            let helper = if n.z.abs() < 0.9 { Vec3::Z } else { Vec3::X };
            let t0 = helper.cross(n).normalize();
            let turn = 2.399_963 * i as f32;
            let t = (t0 * turn.cos() + n.cross(t0) * turn.sin()).normalize();
            let b = n.cross(t);
            let elevation = (15.0 + 60.0 * ((i * 7 % 11) as f32 / 10.0)).to_radians();
            let azimuth = 1.3 * i as f32;
            let v = Vec3::new(
                elevation.sin() * azimuth.cos(),
                elevation.sin() * azimuth.sin(),
                elevation.cos(),
            );
            (Frame { t, b, n }, v)
        })
        .collect()
}

/// Monte-Carlo radiance reflected by the unit-albedo lobe towards `v`, and the lobe's
/// directional albedo (the same samples under a white environment).
fn reference(env: &Environment, lobe: WardLobe, frame: Frame, v: Vec3, samples: u32) -> ([f32; 3], f32) {
    weighted_sum(env, frame, samples, |u1, u2| {
        let (l, pdf) = lobe.sample(v, u1, u2)?;
        Some((l, f64::from(lobe.eval(l, v) * l.z / pdf.max(1e-12))))
    })
}

/// The mean over `samples` Hammersley points of the environment's radiance in the direction each
/// draws (surface frame) times its weight, and the mean weight: `draw` gives both, or `None` for a
/// sample that counts as zero.
fn weighted_sum(
    env: &Environment,
    frame: Frame,
    samples: u32,
    draw: impl Fn(f32, f32) -> Option<(Vec3, f64)>,
) -> ([f32; 3], f32) {
    let mut sum = [0.0f64; 3];
    let mut albedo = 0.0f64;
    for i in 0..samples {
        let (u1, u2) = hammersley(i, samples);
        if let Some((l, w)) = draw(u1, u2) {
            let c = env.sample(frame.world(l));
            for ch in 0..3 {
                sum[ch] += c[ch] as f64 * w;
            }
            albedo += w;
        }
    }
    let n = f64::from(samples.max(1));
    (sum.map(|s| (s / n) as f32), (albedo / n) as f32)
}

/// Both reads' errors for `lobe` under `env` over `count` frames and views (2048 samples each
/// for the truth; levels prefiltered at the renderer's 256-texel base width): `before` one read of
/// the level at the lobe's geometric-mean roughness about the mirror direction, `now`
/// [`StretchedImageLight`]'s taps.
pub fn read_errors(env: &Environment, lobe: WardLobe, count: usize) -> ReadErrors {
    let levels = prefiltered_levels(env, 256);
    let light = StretchedImageLight::for_lobe(lobe);
    compare_reads(count, |frame, v| {
        let (truth, albedo) = reference(env, lobe, frame, v, 2048);
        let mirror = Vec3::new(-v.x, -v.y, v.z);
        let round_read = sample_levels(
            &levels,
            frame.world(mirror),
            (lobe.alpha_x * lobe.alpha_y).sqrt().sqrt(),
        );
        let albedo = f64::from(albedo);
        [
            f64::from(luminance(truth)),
            f64::from(luminance(round_read)) * albedo,
            f64::from(tapped_read(&levels, &light, frame, v)) * albedo,
        ]
    })
}

/// The relative RMS errors of two reads over [`cases`]`(count)`: `case` gives, for each surface
/// frame and view, the truth and the two reads (luminance, each scaled by the lobe's albedo).
fn compare_reads(count: usize, mut case: impl FnMut(Frame, Vec3) -> [f64; 3]) -> ReadErrors {
    let (mut before, mut now, mut norm) = (0.0f64, 0.0f64, 0.0f64);
    for (frame, v) in cases(count) {
        let [truth, before_read, now_read] = case(frame, v);
        before += (before_read - truth).powi(2);
        now += (now_read - truth).powi(2);
        norm += truth * truth;
    }
    let norm = norm.max(1e-30);
    ReadErrors {
        before: (before / norm).sqrt() as f32,
        now: (now / norm).sqrt() as f32,
    }
}

/// [`StretchedImageLight`]'s taps for the view `v` in `frame`, read from `levels` (luminance).
fn tapped_read(levels: &[Environment], light: &StretchedImageLight, frame: Frame, v: Vec3) -> f32 {
    light
        .taps(v)
        .into_iter()
        .map(|(l, w)| luminance(sample_levels(levels, frame.world(l), light.level_roughness)) * w)
        .sum()
}

/// A dim sky with a small bright sun (2° across) and a thin bright band along half the horizon:
/// the light whose reflection a brushed surface stretches into a streak.
pub fn sun_and_band() -> Environment {
    let sun = Vec3::new(0.5, 0.3, 0.81).normalize();
    let sun_cos = 1f32.to_radians().cos();
    Environment::from_directions(512, 256, |d| {
        if d.z.abs() < 0.03 && d.x > 0.0 {
            [8.0; 3]
        } else if d.dot(sun) > sun_cos {
            [200.0; 3]
        } else {
            [0.2 + 0.1 * d.z.max(0.0); 3]
        }
    })
}

/// The two reads' errors for GGX stretched by `KHR_materials_anisotropy` (roughness `roughness`,
/// strength `strength`: α along the tangent `mix(α, 1, strength²)`, α = roughness² across),
/// relative RMS (luminance) over `count` frames and views, each scaled by the lobe's true albedo
/// as in [`read_errors`]: `before` the read `scene.wgsl` made before, the level of the short
/// roughness about the mirror direction of a normal bent across the stretch (Khronos's glTF
/// Sample Viewer's, after Filament), `now` [`StretchedImageLight`]'s taps. The truth: 4096
/// visible normals (Heitz 2018) per case.
pub fn stretched_ggx_read_errors(env: &Environment, roughness: f32, strength: f32, count: usize) -> ReadErrors {
    let levels = prefiltered_levels(env, 256);
    let alpha = roughness * roughness;
    let alpha_t = alpha + (1.0 - alpha) * strength * strength;
    let light = StretchedImageLight::for_alphas(alpha_t, alpha);
    compare_reads(count, |frame, v| {
        let (truth, albedo) = ggx_reference(env, alpha_t, alpha, frame, v, 4096);
        let bent_read = luminance(sample_levels(
            &levels,
            frame.world(bent_reflection(v, roughness, strength)),
            roughness,
        ));
        let albedo = f64::from(albedo);
        [
            f64::from(luminance(truth)),
            f64::from(bent_read) * albedo,
            f64::from(tapped_read(&levels, &light, frame, v)) * albedo,
        ]
    })
}

/// Monte-Carlo radiance reflected by the stretched GGX lobe (αx along the tangent, αy along the
/// bitangent; F = 1, single bounce) towards `v`, and its albedo: visible normals, each weighted
/// by G2 / G1(v) (height-correlated Smith).
fn ggx_reference(
    env: &Environment,
    alpha_x: f32,
    alpha_y: f32,
    frame: Frame,
    v: Vec3,
    samples: u32,
) -> ([f32; 3], f32) {
    let lambda_v = smith_lambda(v, alpha_x, alpha_y);
    weighted_sum(env, frame, samples, |u1, u2| {
        let h = visible_normal(v, alpha_x, alpha_y, u1, u2);
        let l = h * 2.0 * v.dot(h) - v;
        (l.z > 0.0).then(|| {
            let w = (1.0 + lambda_v) / (1.0 + lambda_v + smith_lambda(l, alpha_x, alpha_y));
            (l, f64::from(w))
        })
    })
}

/// The reflection about the bent normal that the renderer read for a stretched GGX lobe before
/// (surface frame, the stretch along +x; Khronos's glTF Sample Viewer's
/// `getIBLRadianceAnisotropy`): the normal turned towards the one that faces the view across the
/// stretch, the more the stronger the stretch and the smoother the surface.
fn bent_reflection(v: Vec3, roughness: f32, strength: f32) -> Vec3 {
    let across = Vec3::X.cross(v);
    let facing = across.cross(Vec3::X);
    let bend = (1.0 - strength * (1.0 - roughness)).powi(4);
    let bent = facing.lerp(Vec3::Z, bend);
    let bent = if bent.length_squared() < 1e-8 {
        Vec3::Z
    } else {
        bent.normalize()
    };
    bent * 2.0 * v.dot(bent) - v
}

/// The two reads' errors for the sheen of cloth (`KHR_materials_sheen`'s Charlie lobe, colour 1,
/// at sheen roughness `roughness`) under `env` over `count` frames and views, relative RMS
/// (luminance), each scaled by the lobe's albedo as in [`read_errors`]: `before` the roughest
/// level about the normal (the renderer's read until 2026-12-07; before that it read the level of
/// the sheen's roughness about the mirror direction, Filament's and Khronos's glTF Sample
/// Viewer's), `now` the roughest level about the lobe's mean direction
/// ([`super::sheen_direction`], read from its table as the shader reads it). The truth: a
/// midpoint rule over the hemisphere of light directions (64 × 256 cells).
pub fn sheen_read_errors(env: &Environment, roughness: f32, count: usize) -> ReadErrors {
    use super::sheen::sheen_albedo;
    use super::sheen_direction::{read, sheen_direction_table};
    let levels = prefiltered_levels(env, 256);
    let table = sheen_direction_table();
    compare_reads(count, |frame, v| {
        let truth = sheen_integral(env, roughness, frame, v);
        let albedo = f64::from(sheen_albedo(v.z, roughness, SHEEN_STEPS));
        let at_normal = luminance(sample_levels(&levels, frame.world(Vec3::Z), 1.0));
        let at_mean = luminance(sample_levels(&levels, frame.world(read(&table, v, roughness)), 1.0));
        [truth, f64::from(at_normal) * albedo, f64::from(at_mean) * albedo]
    })
}

/// [`sheen_read_errors`] with `env`'s sun ([`super::sun::Sun::find`]) apart: `before` the
/// renderer's read of the whole room about the lobe's mean direction, `now` the same read of the
/// room without its sun plus the sun's light through the lobe exactly (as the renderer's
/// directional light gives it). The truth is the lobe's integral over the room without its sun
/// plus the sun's exact term, for both (a grid of directions would hit or miss a sun a fraction
/// of a degree across). `None` when the room has no sun.
pub fn sheen_read_errors_sun_apart(env: &Environment, roughness: f32, count: usize) -> Option<ReadErrors> {
    use super::sheen::{charlie_distribution, sheen_albedo, sheen_visibility};
    use super::sheen_direction::{read, sheen_direction_table};
    let (sun, rest) = super::sun::Sun::find(env)?;
    let sun_lum = luminance(sun.irradiance_rgb);
    let whole = prefiltered_levels(env, 256);
    let levels = prefiltered_levels(&rest, 256);
    let table = sheen_direction_table();
    Some(compare_reads(count, |frame, v| {
        let truth = sheen_integral(&rest, roughness, frame, v);
        let to_sun = frame.local(sun.toward);
        let sun_term = if to_sun.z > 0.0 {
            let h = (to_sun + v).normalize();
            let lobe = charlie_distribution(roughness, h.z) * sheen_visibility(roughness, to_sun.z, v.z) * to_sun.z;
            f64::from(sun_lum * lobe)
        } else {
            0.0
        };
        let albedo = f64::from(sheen_albedo(v.z, roughness, SHEEN_STEPS));
        let toward = frame.world(read(&table, v, roughness));
        let whole_read = luminance(sample_levels(&whole, toward, 1.0));
        let rest_read = luminance(sample_levels(&levels, toward, 1.0));
        [
            truth + sun_term,
            f64::from(whole_read) * albedo,
            f64::from(rest_read) * albedo + sun_term,
        ]
    }))
}

/// [`stretched_ggx_read_errors`] with `env`'s sun ([`super::sun::Sun::find`]) apart: `before`
/// the renderer's taps over the whole room, `now` its taps over the room without its sun plus the
/// sun through the lobe exactly (the directional light). The truth: the visible-normal integral
/// over the room without its sun plus the same exact term, for both (4096 samples would hit or
/// miss a sun a fraction of a degree across). The sun is taken as a point: the lobes measured
/// (roughness 0.3 and more) are far wider than it. `None` when the room has no sun.
pub fn stretched_ggx_read_errors_sun_apart(
    env: &Environment,
    roughness: f32,
    strength: f32,
    count: usize,
) -> Option<ReadErrors> {
    let (sun, rest) = super::sun::Sun::find(env)?;
    let sun_lum = luminance(sun.irradiance_rgb);
    let (whole, levels) = (prefiltered_levels(env, 256), prefiltered_levels(&rest, 256));
    let alpha = roughness * roughness;
    let alpha_t = alpha + (1.0 - alpha) * strength * strength;
    let light = StretchedImageLight::for_alphas(alpha_t, alpha);
    Some(compare_reads(count, |frame, v| {
        let (sky, albedo) = ggx_reference(&rest, alpha_t, alpha, frame, v, 4096);
        let l = frame.local(sun.toward);
        let sun_term = if l.z > 0.0 {
            // D · G2 / (4 n·l n·v) · n·l · E (F = 1).
            let h = (l + v).normalize();
            let s = Vec3::new(h.x / alpha_t, h.y / alpha, h.z);
            let d = 1.0 / (std::f32::consts::PI * alpha_t * alpha * s.length_squared().powi(2));
            let g2 = 1.0 / (1.0 + smith_lambda(v, alpha_t, alpha) + smith_lambda(l, alpha_t, alpha));
            f64::from(d * g2 / (4.0 * v.z.max(1e-4)) * sun_lum)
        } else {
            0.0
        };
        let albedo = f64::from(albedo);
        [
            f64::from(luminance(sky)) + sun_term,
            f64::from(tapped_read(&whole, &light, frame, v)) * albedo,
            f64::from(tapped_read(&levels, &light, frame, v)) * albedo + sun_term,
        ]
    }))
}

/// Cells of the sheen's truth along the polar angle (four times as many in azimuth).
const SHEEN_STEPS: usize = 64;

/// The sheen lobe's light from `env` towards `v` in `frame` (luminance): a midpoint rule over
/// the hemisphere of light directions.
fn sheen_integral(env: &Environment, roughness: f32, frame: Frame, v: Vec3) -> f64 {
    use super::sheen::{charlie_distribution, sheen_visibility};
    let (d_theta, d_phi) = (
        std::f32::consts::FRAC_PI_2 / SHEEN_STEPS as f32,
        std::f32::consts::TAU / (4 * SHEEN_STEPS) as f32,
    );
    let mut sum = 0.0f64;
    for i in 0..SHEEN_STEPS {
        let (sin_t, cos_t) = ((i as f32 + 0.5) * d_theta).sin_cos();
        for j in 0..4 * SHEEN_STEPS {
            let (sin_p, cos_p) = ((j as f32 + 0.5) * d_phi).sin_cos();
            let l = Vec3::new(sin_t * cos_p, sin_t * sin_p, cos_t);
            let h = (l + v).normalize();
            let f = charlie_distribution(roughness, h.z) * sheen_visibility(roughness, l.z, v.z);
            sum += f64::from(luminance(env.sample(frame.world(l))) * f * cos_t * sin_t * d_theta * d_phi);
        }
    }
    sum
}

/// The irradiance's error (relative RMS of luminance over `count` normals spread evenly) of the
/// room's nine harmonics (`before`) and of its sun apart ([`super::sun::Sun::find`]: nine
/// harmonics of the room without it plus its exact cosine term, `now`). The truth: the room
/// without its sun summed texel by texel (on a copy at most 256 texels wide) plus the same
/// exact term. `None` when the room has no sun.
pub fn irradiance_errors_sun_apart(env: &Environment, count: usize) -> Option<ReadErrors> {
    use super::IrradianceSh;
    let (sun, rest) = super::sun::Sun::find(env)?;
    let (whole_sh, rest_sh) = (
        IrradianceSh::from_environment(env),
        IrradianceSh::from_environment(&rest),
    );
    let mut factor = 1;
    while rest.width / factor > 256 && rest.width % (2 * factor) == 0 && rest.height % (2 * factor) == 0 {
        factor *= 2;
    }
    let small = rest.box_filtered(factor);
    let sun_lum = luminance(sun.irradiance_rgb);
    let (mut before, mut now, mut norm) = (0.0f64, 0.0f64, 0.0f64);
    for n in phantogram_geometry::sphere::fibonacci(count) {
        let sun_term = f64::from(sun_lum * n.dot(sun.toward).max(0.0));
        let sky: f64 = (0..small.texels.len())
            .map(|i| {
                let d = small.direction(i % small.width, i / small.width);
                f64::from(luminance(small.texels[i]) * n.dot(d).max(0.0) * small.texel_solid_angle_sr(i / small.width))
            })
            .sum();
        let truth = sky + sun_term;
        before += (f64::from(luminance(whole_sh.irradiance(n))) - truth).powi(2);
        now += (f64::from(luminance(rest_sh.irradiance(n))) + sun_term - truth).powi(2);
        norm += truth * truth;
    }
    let norm = norm.max(1e-30);
    Some(ReadErrors {
        before: (before / norm).sqrt() as f32,
        now: (now / norm).sqrt() as f32,
    })
}
