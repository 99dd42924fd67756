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
    ///
    /// The basis up to l = 2 separates on an equirectangular map into a polynomial in `cos θ`
    /// (per row) times `1, cos φ, sin φ, cos 2φ, sin 2φ` (per column). So each row is reduced to
    /// those five column sums first, and the texel φ + π is folded onto φ (the odd harmonics flip
    /// sign, the even ones repeat): about three multiply-adds per texel and channel, on flat `f32`
    /// runs that the compiler vectorises, instead of nine basis evaluations per texel. Rows are
    /// spread over the cores for large maps; sums of rows are kept in `f64`. Same result as the
    /// texel-by-texel projection to `f32` precision (tested).
    pub fn from_environment(env: &Environment) -> Self {
        let (w, h) = (env.width, env.height);
        if w == 0 || h == 0 || env.texels.len() != w * h {
            return Self {
                coefficients: [[0.0; 3]; 9],
            };
        }
        let columns = ColumnHarmonics::new(w);
        let d_phi = std::f64::consts::TAU / w as f64;
        let d_theta = std::f64::consts::PI / h as f64;
        let project_rows = |rows: &std::ops::Range<usize>| {
            let mut c = [[0.0f64; 3]; 9];
            for y in rows.clone() {
                let sums = columns.row_sums(&env.texels[y * w..(y + 1) * w]);
                let theta = (y as f64 + 0.5) * d_theta;
                let (st, ct) = theta.sin_cos();
                let solid_angle = st * d_theta * d_phi;
                // Row factors of each basis function (see `basis`), times the column sum it uses.
                let terms: [(f64, usize); 9] = [
                    (0.282_095, 0),
                    (0.488_603 * st, 2),
                    (0.488_603 * ct, 0),
                    (0.488_603 * st, 1),
                    (1.092_548 * st * st * 0.5, 4),
                    (1.092_548 * st * ct, 2),
                    (0.315_392 * (3.0 * ct * ct - 1.0), 0),
                    (1.092_548 * st * ct, 1),
                    (0.546_274 * st * st, 3),
                ];
                for (k, (factor, m)) in terms.into_iter().enumerate() {
                    for ch in 0..3 {
                        c[k][ch] += factor * solid_angle * f64::from(sums[m][ch]);
                    }
                }
            }
            c
        };
        // Large maps: blocks of rows on every core (a thread costs tens of microseconds, a
        // 1024 × 512 row block about as much); small ones on this thread.
        let blocks = if w * h >= 1 << 16 { 16.min(h) } else { 1 };
        let ranges: Vec<std::ops::Range<usize>> = (0..blocks).map(|b| b * h / blocks..(b + 1) * h / blocks).collect();
        let partial = if blocks > 1 {
            crate::parallel::map(&ranges, project_rows)
        } else {
            vec![project_rows(&ranges[0])]
        };
        let mut c = [[0.0f64; 3]; 9];
        for p in partial {
            for (ck, pk) in c.iter_mut().zip(p) {
                for ch in 0..3 {
                    ck[ch] += pk[ch];
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

/// The projection texel by texel, as the basis is written: the definition that
/// [`IrradianceSh::from_environment`] computes faster, kept as its reference for the tests and
/// the benchmark (one thread, `f64` sums; tens of milliseconds at 1024 × 512).
pub fn reference_projection(env: &Environment) -> [[f64; 3]; 9] {
    let mut c = [[0.0f64; 3]; 9];
    if env.width == 0 || env.height == 0 || env.texels.len() != env.width * env.height {
        return c;
    }
    let d_phi = std::f64::consts::TAU / env.width as f64;
    let d_theta = std::f64::consts::PI / env.height as f64;
    for y in 0..env.height {
        let solid_angle = ((y as f64 + 0.5) * d_theta).sin() * d_theta * d_phi;
        for x in 0..env.width {
            let b = basis(env.direction(x, y));
            let l = env.texels[y * env.width + x];
            for (k, bk) in b.iter().enumerate() {
                for ch in 0..3 {
                    c[k][ch] += f64::from(l[ch]) * f64::from(*bk) * solid_angle;
                }
            }
        }
    }
    c
}

/// The column harmonics `cos φ, sin φ, cos 2φ, sin 2φ` of an equirectangular map's width, each
/// repeated for the three channels so that a row is summed as flat runs of floats.
struct ColumnHarmonics {
    width: usize,
    /// Columns summed per row: half the width when it is even (φ and φ + π folded), else all.
    folded: usize,
    /// `[cos φ, sin φ, cos 2φ, sin 2φ]`, three floats per column.
    tables: [Vec<f32>; 4],
}

impl ColumnHarmonics {
    fn new(width: usize) -> Self {
        let folded = if width.is_multiple_of(2) { width / 2 } else { width };
        let tables = std::array::from_fn(|i| {
            (0..folded)
                .flat_map(|x| {
                    let phi = std::f64::consts::TAU * (x as f64 + 0.5) / width as f64;
                    let v = match i {
                        0 => phi.cos(),
                        1 => phi.sin(),
                        2 => (2.0 * phi).cos(),
                        _ => (2.0 * phi).sin(),
                    } as f32;
                    [v; 3]
                })
                .collect()
        });
        Self { width, folded, tables }
    }

    /// `Σ_x L(x)·t(φ_x)` for `t = 1, cos φ, sin φ, cos 2φ, sin 2φ`, RGB, over one row.
    fn row_sums(&self, row: &[[f32; 3]]) -> [[f32; 3]; 5] {
        debug_assert_eq!(row.len(), self.width);
        let flat = row.as_flattened();
        let n = 3 * self.folded;
        let [cos1, sin1, cos2, sin2] = &self.tables;
        let mut acc = [[0.0f32; LANES]; 5];
        let mut add = |i: usize, even: f32, odd: f32| {
            let l = i % LANES;
            acc[0][l] += even;
            acc[1][l] += odd * cos1[i];
            acc[2][l] += odd * sin1[i];
            acc[3][l] += even * cos2[i];
            acc[4][l] += even * sin2[i];
        };
        if self.folded == self.width {
            // Odd width: every column once, nothing folded (rare; not worth vectorising).
            for (i, &v) in flat.iter().enumerate() {
                add(i, v, v);
            }
        } else {
            // L(φ) + L(φ + π) carries the even harmonics, L(φ) − L(φ + π) the odd ones.
            let (front, back) = (&flat[..n], &flat[n..2 * n]);
            let whole = n / LANES * LANES;
            for i in whole..n {
                add(i, front[i] + back[i], front[i] - back[i]);
            }
            let chunks = folded_sums(&front[..whole], &back[..whole], &self.tables);
            for (a, c) in acc.iter_mut().zip(chunks) {
                for (a, c) in a.iter_mut().zip(c) {
                    *a += c;
                }
            }
        }
        // Lane `l` holds channel `l % 3`.
        acc.map(|lanes| {
            let mut rgb = [0.0f32; 3];
            for (lane, v) in lanes.iter().enumerate() {
                rgb[lane % 3] += v;
            }
            rgb
        })
    }
}

/// Floats per chunk of the column sums: 8 RGB texels (a multiple of 4- and 8-lane vectors).
const LANES: usize = 3 * 8;

/// The folded column sums over whole chunks (`front`, `back` and the tables' first
/// `front.len()` floats; `front.len()` a multiple of [`LANES`]), with 8-lane AVX2 where the CPU
/// has it (half the time of SSE2's 4 lanes here), else as compiled (NEON on phones). Both give
/// the same result: the same operations in the same order per lane.
fn folded_sums(front: &[f32], back: &[f32], tables: &[Vec<f32>; 4]) -> [[f32; LANES]; 5] {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the function is compiled for AVX2, which the CPU has just been found to have.
        return unsafe { folded_sums_avx2(front, back, tables) };
    }
    folded_sums_portable(front, back, tables)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn folded_sums_avx2(front: &[f32], back: &[f32], tables: &[Vec<f32>; 4]) -> [[f32; LANES]; 5] {
    folded_sums_portable(front, back, tables)
}

#[inline(always)]
fn folded_sums_portable(front: &[f32], back: &[f32], tables: &[Vec<f32>; 4]) -> [[f32; LANES]; 5] {
    let mut acc = [[0.0f32; LANES]; 5];
    let [s0, s1, s2, s3, s4] = &mut acc;
    let [cos1, sin1, cos2, sin2] = tables;
    let chunks = front
        .chunks_exact(LANES)
        .zip(back.chunks_exact(LANES))
        .zip(cos1.chunks_exact(LANES))
        .zip(sin1.chunks_exact(LANES))
        .zip(cos2.chunks_exact(LANES))
        .zip(sin2.chunks_exact(LANES));
    // Fixed-size arrays: no bounds checks in the lane loop, which the compiler vectorises.
    let lanes = |v: &[f32]| -> [f32; LANES] { v.try_into().unwrap_or([0.0; LANES]) };
    for (((((a, b), c1), n1), c2), n2) in chunks {
        let (a, b, c1, n1, c2, n2) = (lanes(a), lanes(b), lanes(c1), lanes(n1), lanes(c2), lanes(n2));
        for l in 0..LANES {
            let (even, odd) = (a[l] + b[l], a[l] - b[l]);
            s0[l] += even;
            s1[l] += odd * c1[l];
            s2[l] += odd * n1[l];
            s3[l] += even * c2[l];
            s4[l] += even * n2[l];
        }
    }
    acc
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

    #[test]
    fn the_separable_projection_equals_the_texel_by_texel_one() {
        // Even widths (folded) and odd ones, maps with and without a bright sun, large enough to
        // be split over threads, and texels with different colours in every channel.
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut random = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 40) as f32 / (1u64 << 24) as f32
        };
        for (w, h) in [(64, 32), (33, 17), (512, 256), (1024, 512), (6, 3)] {
            let mut env = Environment {
                width: w,
                height: h,
                texels: (0..w * h).map(|_| [random(), 2.0 * random(), 0.5 * random()]).collect(),
            };
            env.texels[(h / 3) * w + w / 5] = [5000.0, 4000.0, 3000.0];
            let want = reference_projection(&env);
            let got = IrradianceSh::from_environment(&env).coefficients;
            let scale = want.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
            for k in 0..9 {
                for ch in 0..3 {
                    let err = (f64::from(got[k][ch]) - want[k][ch]).abs();
                    assert!(
                        err <= 2e-5 * scale,
                        "{w}×{h} c[{k}][{ch}]: {} vs {}",
                        got[k][ch],
                        want[k][ch]
                    );
                }
            }
        }
        // A malformed map projects to nothing instead of panicking.
        let broken = Environment {
            width: 4,
            height: 2,
            texels: vec![[1.0; 3]; 3],
        };
        assert_eq!(IrradianceSh::from_environment(&broken).coefficients, [[0.0; 3]; 9]);
    }

    #[test]
    fn the_vector_paths_agree_to_the_bit() {
        let n = LANES * 20;
        let v = |k: usize| {
            (0..n)
                .map(|i| ((i * 7 + k * 13) % 101) as f32 * 0.37 - 11.0)
                .collect::<Vec<f32>>()
        };
        let tables = [v(1), v(2), v(3), v(4)];
        assert_eq!(
            folded_sums(&v(5), &v(6), &tables),
            folded_sums_portable(&v(5), &v(6), &tables)
        );
    }
}
