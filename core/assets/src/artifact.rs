//! The project's own museum piece: a turned amphora, generated procedurally and deterministically,
//! so the main command works on a fresh clone without downloads.
//!
//! It is a surface of revolution about the device z axis (standing out of the glass towards the
//! viewer, the classic phantogram pose), with a terracotta body, a black-glaze frieze of running
//! figures between meander borders, and a gilded band on the shoulder for specular highlights.
//! Dimensions are real: 62 mm tall, 38 mm across, standing 24 mm out of the glass, so it fits a
//! typical phone's diorama ([`phantogram_geometry::containment`] keeps it inside the front frustum).
//!
//! Colours are linear RGB. The mesh is plain data ([`Mesh`]); the renderer uploads it.

use glam::{Vec2, Vec3};

use crate::model::Model;

pub use crate::model::{Mesh, Vertex};

/// Linear-RGB colours and materials of the amphora.
const TERRACOTTA: [f32; 4] = [0.50, 0.19, 0.075, 1.0];
const BLACK_GLAZE: [f32; 4] = [0.018, 0.014, 0.012, 1.0];
const GOLD: [f32; 4] = [1.0, 0.766, 0.336, 1.0];
const CLAY_MATERIAL: [f32; 2] = [0.0, 0.62];
const GLAZE_MATERIAL: [f32; 2] = [0.0, 0.28];
const GOLD_MATERIAL: [f32; 2] = [1.0, 0.32];

/// The profile: radius (m) at height `t ∈ [0, 1]` along the 62 mm axis. A foot, an egg-shaped
/// body, a narrow neck and a flared lip.
fn profile_radius_m(t: f32) -> f32 {
    let smooth = |a: f32, b: f32, x: f32| {
        let u = ((x - a) / (b - a)).clamp(0.0, 1.0);
        u * u * (3.0 - 2.0 * u)
    };
    let foot = 0.0085 - 0.0025 * smooth(0.0, 0.06, t);
    let body = 0.019
        * (std::f32::consts::PI * ((t - 0.05) / 0.72).clamp(0.0, 1.0))
            .sin()
            .powf(0.75);
    let neck = 0.0075;
    let lip = 0.0105;
    let r = if t < 0.06 {
        foot
    } else if t < 0.70 {
        foot.max(body)
    } else if t < 0.90 {
        let w = smooth(0.70, 0.80, t);
        body.max(neck) * (1.0 - w) + neck * w
    } else {
        neck + (lip - neck) * smooth(0.90, 1.0, t)
    };
    r.max(0.0005)
}

/// Surface colour and material at height `t` and angle `phi` (rad).
fn paint(t: f32, phi: f32) -> ([f32; 4], [f32; 2]) {
    // Gilded band on the shoulder.
    if (0.655..0.685).contains(&t) {
        return (GOLD, GOLD_MATERIAL);
    }
    // Black glaze on the foot, the neck and the lip.
    if !(0.05..=0.80).contains(&t) {
        return (BLACK_GLAZE, GLAZE_MATERIAL);
    }
    // The frieze: borders and a meander above and below, running figures in between.
    let (lo, hi) = (0.36, 0.58);
    if (lo..hi).contains(&t) {
        let border = 0.012;
        if t < lo + border || t > hi - border {
            return (BLACK_GLAZE, GLAZE_MATERIAL);
        }
        let turns = 14.0;
        let u = (phi / std::f32::consts::TAU * turns).rem_euclid(1.0);
        let v = (t - lo - border) / (hi - lo - 2.0 * border);
        // Meander (Greek key) strips along the top and bottom fifth of the frieze.
        if !(0.2..=0.8).contains(&v) {
            let vv = if v < 0.2 { v / 0.2 } else { (v - 0.8) / 0.2 };
            let key = (u < 0.2) || (vv > 0.75 && u < 0.8) || (u > 0.6 && u < 0.8 && vv > 0.35) || (vv < 0.25);
            return if key {
                (BLACK_GLAZE, GLAZE_MATERIAL)
            } else {
                (TERRACOTTA, CLAY_MATERIAL)
            };
        }
        // Running figures: a head, a torso and striding legs in each of the 14 panels.
        let p = Vec2::new(u - 0.5, (v - 0.2) / 0.6);
        let head = p.distance(Vec2::new(0.0, 0.85)) < 0.09;
        let torso = p.x.abs() < 0.07 && (0.45..0.74).contains(&p.y);
        let stride = 0.9 * (0.45 - p.y).max(0.0);
        let legs = p.y < 0.45 && ((p.x - stride).abs() < 0.045 || (p.x + stride).abs() < 0.045);
        let arms = (0.62..0.68).contains(&p.y) && p.x.abs() < 0.22;
        if head || torso || legs || arms {
            return (BLACK_GLAZE, GLAZE_MATERIAL);
        }
    }
    (TERRACOTTA, CLAY_MATERIAL)
}

/// Height of the amphora, m.
pub const AMPHORA_HEIGHT_M: f32 = 0.062;

/// The default artifact, standing on the device z axis with its foot `base_z_m` from the glass
/// (negative: behind it).
pub fn amphora(base_z_m: f32) -> Mesh {
    let rings = 160usize;
    let segments = 128usize;
    let mut mesh = Mesh::default();
    for i in 0..=rings {
        let t = i as f32 / rings as f32;
        let r = profile_radius_m(t);
        // Profile slope for the normal: d(radius)/d(height).
        let dt = 1e-3;
        let slope = (profile_radius_m((t + dt).min(1.0)) - profile_radius_m((t - dt).max(0.0)))
            / (((t + dt).min(1.0) - (t - dt).max(0.0)) * AMPHORA_HEIGHT_M);
        let z = base_z_m + t * AMPHORA_HEIGHT_M;
        for j in 0..=segments {
            let phi = j as f32 / segments as f32 * std::f32::consts::TAU;
            let (s, c) = phi.sin_cos();
            // Outward normal of a surface of revolution: (cos φ, sin φ, −dr/dz), normalised.
            let n = Vec3::new(c, s, -slope).normalize();
            let (color, material) = paint(t, phi);
            mesh.vertices.push(Vertex {
                position: [r * c, r * s, z],
                normal: n.to_array(),
                // Along increasing φ; the frieze is painted per vertex, so no normal map uses it.
                tangent: [-s, c, 0.0, 1.0],
                uv: [j as f32 / segments as f32, 1.0 - t, 0.0, 0.0],
                color,
                material,
            });
        }
    }
    let row = (segments + 1) as u32;
    for i in 0..rings as u32 {
        for j in 0..segments as u32 {
            let a = i * row + j;
            let b = a + row;
            // Counter-clockwise seen from outside.
            mesh.indices.extend_from_slice(&[a, a + 1, b + 1, a, b + 1, b]);
        }
    }
    // Close the foot with a disc so the underside is not see-through.
    let centre = mesh.vertices.len() as u32;
    mesh.vertices.push(Vertex {
        position: [0.0, 0.0, base_z_m],
        normal: [0.0, 0.0, -1.0],
        tangent: [1.0, 0.0, 0.0, 1.0],
        uv: [0.5, 1.0, 0.0, 0.0],
        color: BLACK_GLAZE,
        material: GLAZE_MATERIAL,
    });
    for j in 0..segments as u32 {
        mesh.indices.extend_from_slice(&[centre, j + 1, j]);
    }
    mesh
}

/// The default artifact's mesh placed as it is shown: standing 24 mm out of the glass.
pub fn default_artifact() -> Mesh {
    amphora(0.024 - AMPHORA_HEIGHT_M)
}

/// The default artifact as a model (one vertex-painted material).
pub fn default_model() -> Model {
    Model::from_painted_mesh("amphora", default_artifact())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn amphora_has_the_documented_size_and_is_deterministic() {
        let m = default_artifact();
        let b = m.bounds().unwrap();
        assert!((b.max.z - 0.024).abs() < 1e-6 && (b.min.z + 0.038).abs() < 1e-6);
        let width = b.max.x - b.min.x;
        assert!((0.035..0.040).contains(&width), "{width}");
        assert_eq!(m, default_artifact());
        assert!(m.indices.iter().all(|&i| (i as usize) < m.vertices.len()));
        assert_eq!(m.indices.len() % 3, 0);
    }

    #[test]
    fn normals_point_outwards_and_paint_has_gold_and_glaze() {
        let m = default_artifact();
        for v in &m.vertices[..m.vertices.len() - 1] {
            let p = Vec3::from(v.position);
            let n = Vec3::from(v.normal);
            assert!((n.length() - 1.0).abs() < 1e-4);
            assert!(
                Vec2::new(p.x, p.y).dot(Vec2::new(n.x, n.y)) >= -1e-6,
                "inward normal at {p}"
            );
        }
        let count = |c: [f32; 4]| m.vertices.iter().filter(|v| v.color == c).count();
        assert!(count(GOLD) > 100 && count(BLACK_GLAZE) > 1000 && count(TERRACOTTA) > 1000);
    }
}
