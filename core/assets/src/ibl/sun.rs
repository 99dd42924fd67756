//! A room's sun: the small, bright source some environments hold (the sun in an outdoor
//! panorama, a bare lamp in a studio), taken out of the map and handed to the renderer as its
//! directional light.
//!
//! Why: the image light reads a room through prefiltered levels and nine spherical harmonics,
//! both of which blur a source a fraction of a degree wide over tens of degrees. The sheen's and
//! the stretched lobes' reads are furthest from their integrals under such a source
//! (`benchmarks/ibl.md`), the nine harmonics ring (light on the side away from the sun), and the
//! sun casts no shadow while the directional light shadows from a direction of its own. A
//! directional light is exact for a source that small: each lobe evaluates it analytically and
//! it casts the shadow. This is the common practice of real-time engines with captured skies
//! (the dominant light of an environment made a punctual one).
//!
//! What counts as a sun ([`Sun::find`]): the texels connected to the map's brightest one whose
//! radiance is at least [`EDGE_OF_PEAK`] of its, covering a cone no wider than
//! [`MAX_HALF_ANGLE_RAD`] and carrying at least [`MIN_SHARE`] of the room's light (its
//! irradiance at normal incidence against the whole map's `∫L dΩ`). The texels taken keep the
//! radiance of the ring around them (the sky behind the sun), so the map and the sun together
//! hold the same light as the map alone.
//!
//! Pure functions, no panics; one pass over the map (a few milliseconds for a 1024-wide map).

use glam::Vec3;

use super::Environment;
use phantogram_geometry::srgb::luminance;

/// The sun's edge: texels at least this share of the brightest one's luminance belong to it.
pub const EDGE_OF_PEAK: f32 = 0.1;
/// The widest source taken for a sun: a cone of this half-angle (radians).
pub const MAX_HALF_ANGLE_RAD: f32 = 0.1;
/// The least share of the room's light a sun carries.
pub const MIN_SHARE: f32 = 0.1;

/// A small source taken out of an environment.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sun {
    /// Towards the sun, world frame, unit length.
    pub toward: Vec3,
    /// Its irradiance on a surface facing it, linear RGB (`∫ L dΩ` over it above the sky behind:
    /// the map without it keeps the lesser of its radiance and the sky's, so that the two add up
    /// to the map).
    pub irradiance_rgb: [f32; 3],
    /// The solid angle it covers, steradians.
    pub solid_angle_sr: f32,
    /// Its share of the room's light (its `∫L dΩ` luminance over the map's).
    pub share: f32,
}

/// What [`Sun::measure`] finds around the brightest texel, whether or not it counts as a sun.
#[derive(Clone, Debug, PartialEq)]
pub struct Candidate {
    pub sun: Sun,
    /// The texels it covers (indices into the map).
    pub texels: Vec<usize>,
    /// The radiance left in them: the mean of the ring of texels around them.
    pub fill_rgb: [f32; 3],
}

impl Environment {
    /// The map's four neighbours of texel `i`, wrapping in azimuth (none past the poles).
    fn neighbours(&self, i: usize) -> impl Iterator<Item = usize> {
        let (w, h) = (self.width, self.height);
        let (x, y) = (i % w, i / w);
        let left = y * w + (x + w - 1) % w;
        let right = y * w + (x + 1) % w;
        let up = (y > 0).then(|| i - w);
        let down = (y + 1 < h).then(|| i + w);
        [Some(left), Some(right), up, down].into_iter().flatten()
    }
}

impl Sun {
    /// Half the angle the sun spans: the cone of its solid angle.
    pub fn half_angle_rad(&self) -> f32 {
        (1.0 - self.solid_angle_sr / std::f32::consts::TAU)
            .clamp(-1.0, 1.0)
            .acos()
    }

    /// The source around `env`'s brightest texel, measured (`None` for an empty or black map).
    /// `edge`: the share of the peak's luminance a texel needs to belong to it.
    pub fn measure(env: &Environment, edge: f32) -> Option<Candidate> {
        let (w, h) = (env.width, env.height);
        if w == 0 || h == 0 || env.texels.len() != w * h {
            return None;
        }
        let lum: Vec<f32> = env.texels.iter().map(|&c| luminance(c)).collect();
        let (peak, peak_lum) = lum
            .iter()
            .copied()
            .enumerate()
            .filter(|(_, l)| l.is_finite())
            .max_by(|a, b| a.1.total_cmp(&b.1))?;
        if peak_lum <= 0.0 {
            return None;
        }
        // Flood fill from the peak over texels at least `edge` of it.
        let threshold = peak_lum * edge;
        let mut inside = vec![false; w * h];
        let mut texels = vec![peak];
        inside[peak] = true;
        let mut next = 0;
        while next < texels.len() {
            let i = texels[next];
            next += 1;
            for j in env.neighbours(i) {
                if !inside[j] && lum[j] >= threshold {
                    inside[j] = true;
                    texels.push(j);
                }
            }
        }
        // The ring around it: the sky behind the sun.
        let (mut ring_sum, mut ring_weight) = ([0.0f64; 3], 0.0f64);
        let mut in_ring = vec![false; w * h];
        for &i in &texels {
            for j in env.neighbours(i) {
                if !inside[j] && !in_ring[j] {
                    in_ring[j] = true;
                    let dw = f64::from(env.texel_solid_angle_sr(j / w));
                    for (sum, &c) in ring_sum.iter_mut().zip(&env.texels[j]) {
                        *sum += f64::from(c) * dw;
                    }
                    ring_weight += dw;
                }
            }
        }
        let fill_rgb = if ring_weight > 0.0 {
            ring_sum.map(|s| (s / ring_weight) as f32)
        } else {
            [0.0; 3]
        };
        let (mut power, mut direction, mut solid_angle) = ([0.0f64; 3], glam::DVec3::ZERO, 0.0f64);
        for &i in &texels {
            let dw = f64::from(env.texel_solid_angle_sr(i / w));
            let above: [f32; 3] = std::array::from_fn(|c| (env.texels[i][c] - fill_rgb[c]).max(0.0));
            for (p, a) in power.iter_mut().zip(above) {
                *p += f64::from(a) * dw;
            }
            let l = f64::from(luminance(above));
            direction += env.direction(i % w, i / w).as_dvec3() * (l * dw);
            solid_angle += dw;
        }
        // The room's ∫L dΩ: its mean luminance over the sphere times the sphere the texels cover.
        let sphere_sr: f64 = (0..h).map(|y| w as f64 * f64::from(env.texel_solid_angle_sr(y))).sum();
        let total = f64::from(env.mean_luminance()) * sphere_sr;
        let power_lum = f64::from(luminance(power.map(|p| p as f32)));
        let toward = direction
            .try_normalize()
            .unwrap_or(env.direction(peak % w, peak / w).as_dvec3());
        Some(Candidate {
            sun: Sun {
                toward: toward.as_vec3(),
                irradiance_rgb: power.map(|p| p as f32),
                solid_angle_sr: solid_angle as f32,
                share: if total > 0.0 { (power_lum / total) as f32 } else { 0.0 },
            },
            texels,
            fill_rgb,
        })
    }

    /// The sun in `env`, if it has one (see the module docs), and the map without it.
    pub fn find(env: &Environment) -> Option<(Sun, Environment)> {
        let candidate = Self::candidate(env)?;
        let mut rest = env.clone();
        candidate.take_out_of(&mut rest);
        Some((candidate.sun, rest))
    }

    /// [`Self::find`] on a map the caller gives up: the sun, if there is one, is taken out of it
    /// in place (no copy of a map that may be a hundred megabytes).
    pub fn take_out(mut env: Environment) -> (Option<Sun>, Environment) {
        let candidate = Self::candidate(&env);
        if let Some(c) = &candidate {
            c.take_out_of(&mut env);
        }
        (candidate.map(|c| c.sun), env)
    }

    /// What [`Self::measure`] finds around the brightest texel, if it counts as a sun.
    fn candidate(env: &Environment) -> Option<Candidate> {
        let candidate = Self::measure(env, EDGE_OF_PEAK)?;
        let widest_sr = std::f32::consts::TAU * (1.0 - MAX_HALF_ANGLE_RAD.cos());
        (candidate.sun.solid_angle_sr <= widest_sr && candidate.sun.share >= MIN_SHARE).then_some(candidate)
    }
}

impl Candidate {
    /// Leaves in `env`'s texels under it the lesser of their radiance and the sky's.
    fn take_out_of(&self, env: &mut Environment) {
        for &i in &self.texels {
            if let Some(t) = env.texels.get_mut(i) {
                *t = std::array::from_fn(|c| t[c].min(self.fill_rgb[c]));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A sky of `sky` radiance with a disc of `half_angle_rad` around `toward` at `disc` radiance.
    fn sky_with_disc(width: usize, toward: Vec3, half_angle_rad: f32, disc: [f32; 3], sky: [f32; 3]) -> Environment {
        let (toward, cos_edge) = (toward.normalize(), half_angle_rad.cos());
        Environment::from_directions(width, width / 2, |d| {
            // A little gradient, so the sky behind the sun is not one value.
            let g = 1.0 + 0.2 * d.z;
            if d.dot(toward) >= cos_edge {
                disc
            } else {
                sky.map(|c| c * g)
            }
        })
    }

    fn integral(env: &Environment) -> [f64; 3] {
        let mut sum = [0.0f64; 3];
        for (i, t) in env.texels.iter().enumerate() {
            let dw = f64::from(env.texel_solid_angle_sr(i / env.width));
            for c in 0..3 {
                sum[c] += f64::from(t[c]) * dw;
            }
        }
        sum
    }

    #[test]
    fn a_small_bright_disc_is_taken_out_whole_with_its_direction_and_light() {
        // 2° across, 2000 times the sky: as a low sun over a pale sky, and one across the map's
        // seam (azimuth 0) and one at the zenith, where the equirectangular texels are oddest.
        for toward in [
            Vec3::new(0.3, -0.8, 0.35),
            Vec3::new(1.0, 0.0, 0.3),
            Vec3::new(0.0, 0.0, 1.0),
        ] {
            let toward = toward.normalize();
            let env = sky_with_disc(
                1024,
                toward,
                1f32.to_radians(),
                [2000.0, 1800.0, 1500.0],
                [0.5, 0.6, 0.8],
            );
            let (sun, rest) = Sun::find(&env).unwrap_or_else(|| panic!("no sun towards {toward}"));
            let off_deg = sun.toward.angle_between(toward).to_degrees();
            assert!(off_deg < 0.1, "towards {toward}: {off_deg}° off");
            // The disc's light above the sky behind it, as the map's texels hold it (near the
            // pole a row of texels takes a disc 2° across in steps of a tenth of it).
            let cos_edge = 1f32.to_radians().cos();
            let expected: f32 = (0..env.texels.len())
                .filter(|&i| env.direction(i % env.width, i / env.width).dot(toward) >= cos_edge)
                .map(|i| (luminance(env.texels[i]) - 0.6 * 1.2) * env.texel_solid_angle_sr(i / env.width))
                .sum();
            let lum = luminance(sun.irradiance_rgb);
            assert!(
                (lum / expected - 1.0).abs() < 0.05,
                "towards {toward}: {lum} against {expected}"
            );
            // Nothing lost or made: the map without it and it hold what the map held.
            let (before, after) = (integral(&env), integral(&rest));
            for c in 0..3 {
                let total = after[c] + f64::from(sun.irradiance_rgb[c]);
                assert!(
                    (total / before[c] - 1.0).abs() < 1e-4,
                    "channel {c}: {total} against {}",
                    before[c]
                );
            }
            // The same when the map is given up rather than copied.
            let (taken, taken_rest) = Sun::take_out(env.clone());
            assert_eq!((taken, &taken_rest), (Some(sun), &rest));
            // And the map without it is sky: nothing left near the sun's radiance.
            let brightest = rest.texels.iter().map(|&t| luminance(t)).fold(0.0f32, f32::max);
            assert!(brightest < 1.5, "towards {toward}: {brightest} left");
        }
    }

    #[test]
    fn wide_or_weak_sources_and_plain_rooms_have_no_sun() {
        let toward = Vec3::new(0.3, -0.8, 0.35);
        // A soft box 15° across holding most of the light: the image light reads it well.
        let wide = sky_with_disc(512, toward, 7.5f32.to_radians(), [50.0; 3], [0.5; 3]);
        assert!(Sun::measure(&wide, EDGE_OF_PEAK).is_some_and(|c| c.sun.share > MIN_SHARE));
        assert!(Sun::find(&wide).is_none(), "a wide source");
        // A small lamp with about a twentieth of the room's light: the key light stays the
        // default.
        let weak = sky_with_disc(512, toward, 1f32.to_radians(), [300.0; 3], [0.5; 3]);
        let share = Sun::measure(&weak, EDGE_OF_PEAK).map(|c| c.sun.share).unwrap_or(0.0);
        assert!(share > 0.02 && share < MIN_SHARE, "{share}");
        assert!(Sun::find(&weak).is_none(), "a weak source");
        // The generated studio (soft panels), an even room, a black one, a broken one.
        assert!(Sun::find(&Environment::studio()).is_none());
        assert!(Sun::find(&Environment::from_directions(64, 32, |_| [1.0; 3])).is_none());
        assert!(Sun::find(&Environment::from_directions(64, 32, |_| [0.0; 3])).is_none());
        let broken = Environment {
            width: 4,
            height: 2,
            texels: vec![[1.0; 3]; 3],
        };
        assert!(Sun::find(&broken).is_none());
    }

    #[test]
    fn the_diffuse_light_of_a_room_with_its_sun_apart_is_nearer_the_truth() {
        // Nine harmonics cannot hold a source a degree across: they spread it and ring (light
        // on the side away from it, a dip beside it). With the sun apart, its cosine term is
        // exact and the harmonics hold only the sky.
        let toward = Vec3::new(0.3, -0.8, 0.45).normalize();
        let env = sky_with_disc(256, toward, 1f32.to_radians(), [5000.0; 3], [0.3; 3]);
        let errors = crate::ibl::accuracy::irradiance_errors_sun_apart(&env, 400).expect("a sun");
        let (whole_err, apart_err) = (errors.before, errors.now);
        println!(
            "irradiance relative RMS: the whole room in nine harmonics {whole_err:.4}, the sun apart {apart_err:.4}"
        );
        assert!(
            apart_err < 0.01 && apart_err < whole_err / 5.0,
            "{whole_err} → {apart_err}"
        );
    }
}
