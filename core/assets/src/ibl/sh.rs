//! The diffuse part of the image-based light: nine spherical-harmonic coefficients of the
//! environment's radiance (see the [parent module](super)).

use glam::Vec3;

use super::Environment;

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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ibl::tests::uniform;

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
