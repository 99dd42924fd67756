//! A big test scan made from a smaller one: every triangle split into four, `levels` times, and
//! the surface displaced along its normal by a fine, deterministic relief — the millions of
//! triangles of a museum scan's full-resolution mesh, with detail that a simplifier cannot
//! remove for free. The generator is committed; the mesh it makes is not (it is made from a
//! shared scan in `$PHANTOGRAM_DATA` when a test or benchmark needs it).
//!
//! Subdivision shares each edge's midpoint between the triangles on either side (an indexed
//! mesh stays watertight); texture coordinates, colours and tangents are interpolated, normals
//! recomputed from the displaced surface.

use std::collections::HashMap;

use glam::{Vec3, Vec4};
use phantogram_assets::model::{Mesh, Model, Vertex};

/// Subdivides every non-floor primitive of `model` `levels` times (×4ⁿ triangles) and displaces
/// it by a relief of `amplitude` × the model's bounding diagonal with a wavelength of
/// `wavelength` × the diagonal. Primitives that already have levels of detail lose them.
pub fn subdivide_and_displace(model: &mut Model, levels: u32, amplitude: f32, wavelength: f32) {
    let Some(bounds) = model.bounds() else {
        return;
    };
    let diagonal = (bounds.max - bounds.min).length();
    let amplitude_m = amplitude * diagonal;
    let k = std::f32::consts::TAU / (wavelength * diagonal).max(f32::MIN_POSITIVE);
    for p in model.primitives.iter_mut().filter(|p| !p.is_floor) {
        p.lods.clear();
        for _ in 0..levels {
            p.mesh = subdivide(&p.mesh);
        }
        for v in &mut p.mesh.vertices {
            let q = Vec3::from(v.position);
            let n = Vec3::from(v.normal);
            v.position = (q + n * amplitude_m * relief(q * k)).to_array();
        }
        recompute_normals(&mut p.mesh);
    }
}

/// A smooth relief in [−1, 1]: three octaves of crossed sines (deterministic, no hashing).
fn relief(q: Vec3) -> f32 {
    let octave = |s: f32, q: Vec3| (q.x * s).sin() * (q.y * s * 1.13 + 0.7).sin() * (q.z * s * 0.91 + 1.9).sin();
    (octave(1.0, q) * 0.57
        + octave(2.3, Vec3::new(q.z, q.x, q.y)) * 0.29
        + octave(5.1, Vec3::new(q.y, q.z, q.x)) * 0.14)
        .clamp(-1.0, 1.0)
}

/// One 1-to-4 split of every triangle, edges' midpoints shared.
fn subdivide(mesh: &Mesh) -> Mesh {
    let mut out = Mesh {
        vertices: mesh.vertices.clone(),
        indices: Vec::with_capacity(mesh.indices.len() * 4),
    };
    let n = mesh.vertices.len() as u32;
    let mut midpoints: HashMap<(u32, u32), u32> = HashMap::new();
    let mut midpoint = |a: u32, b: u32, out: &mut Mesh| -> u32 {
        let key = (a.min(b), a.max(b));
        *midpoints.entry(key).or_insert_with(|| {
            let (va, vb) = (&mesh.vertices[a as usize], &mesh.vertices[b as usize]);
            out.vertices.push(mix(va, vb));
            out.vertices.len() as u32 - 1
        })
    };
    for t in mesh.indices.chunks_exact(3) {
        if t.iter().any(|&v| v >= n) {
            continue;
        }
        let (a, b, c) = (t[0], t[1], t[2]);
        let ab = midpoint(a, b, &mut out);
        let bc = midpoint(b, c, &mut out);
        let ca = midpoint(c, a, &mut out);
        out.indices
            .extend_from_slice(&[a, ab, ca, ab, b, bc, ca, bc, c, ab, bc, ca]);
    }
    out
}

fn mix(a: &Vertex, b: &Vertex) -> Vertex {
    let half = |x: &[f32], y: &[f32]| -> Vec<f32> { x.iter().zip(y).map(|(p, q)| (p + q) * 0.5).collect() };
    let p = half(&a.position, &b.position);
    let n = (Vec3::from(a.normal) + Vec3::from(b.normal)).normalize_or(Vec3::from(a.normal));
    let t = Vec4::from(a.tangent);
    let tt = (t.truncate() + Vec4::from(b.tangent).truncate()).normalize_or(t.truncate());
    let uv = half(&a.uv, &b.uv);
    let color = half(&a.color, &b.color);
    let material = half(&a.material, &b.material);
    Vertex {
        position: [p[0], p[1], p[2]],
        normal: n.to_array(),
        tangent: tt.extend(t.w).to_array(),
        uv: [uv[0], uv[1], uv[2], uv[3]],
        color: [color[0], color[1], color[2], color[3]],
        material: [material[0], material[1]],
    }
}

/// Area-weighted vertex normals of the displaced surface. A vertex duplicated at a texture seam
/// gets the normals of its own triangles only (as the file's own normals are at seams).
fn recompute_normals(mesh: &mut Mesh) {
    let mut sums = vec![Vec3::ZERO; mesh.vertices.len()];
    for t in mesh.indices.chunks_exact(3) {
        let q = |k: usize| Vec3::from(mesh.vertices[t[k] as usize].position);
        let n = (q(1) - q(0)).cross(q(2) - q(0));
        for &v in t {
            sums[v as usize] += n;
        }
    }
    for (v, s) in mesh.vertices.iter_mut().zip(sums) {
        let n = s.normalize_or(Vec3::from(v.normal));
        // Keep the tangent across the new normal (Gram–Schmidt), its handedness as it was.
        let t = Vec4::from(v.tangent);
        let tt = (t.truncate() - n * n.dot(t.truncate())).normalize_or(t.truncate());
        v.normal = n.to_array();
        v.tangent = tt.extend(t.w).to_array();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn octahedron() -> Model {
        let mut mesh = Mesh::default();
        for p in [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z] {
            mesh.vertices.push(Vertex {
                position: (p * 0.05).to_array(),
                normal: p.to_array(),
                tangent: [1.0, 0.0, 0.0, 1.0],
                color: [1.0; 4],
                material: [1.0, 1.0],
                ..Vertex::default()
            });
        }
        mesh.indices = vec![0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5];
        Model::from_painted_mesh("octahedron", mesh)
    }

    #[test]
    fn four_times_the_triangles_per_level_and_still_closed() {
        let mut m = octahedron();
        subdivide_and_displace(&mut m, 3, 0.0, 0.1);
        let mesh = &m.primitives[0].mesh;
        assert_eq!(mesh.indices.len() / 3, 8 * 64);
        // Closed: every edge is used by exactly two triangles, once each way.
        let mut edges: HashMap<(u32, u32), i32> = HashMap::new();
        for t in mesh.indices.chunks_exact(3) {
            for (a, b) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
                *edges.entry((a.min(b), a.max(b))).or_default() += if a < b { 1 } else { -1 };
            }
        }
        assert!(edges.values().all(|&e| e == 0), "open or inconsistent edges");
        // Euler: V − E + F = 2 for a sphere.
        let v = mesh.vertices.len() as i64;
        assert_eq!(v - edges.len() as i64 + (mesh.indices.len() / 3) as i64, 2);
    }

    #[test]
    fn the_relief_moves_the_surface_by_at_most_its_amplitude() {
        let flat = {
            let mut m = octahedron();
            subdivide_and_displace(&mut m, 2, 0.0, 0.1);
            m
        };
        let mut m = octahedron();
        subdivide_and_displace(&mut m, 2, 0.01, 0.1);
        let diagonal = 0.1 * 3f32.sqrt();
        let moved: Vec<f32> = flat.primitives[0]
            .mesh
            .vertices
            .iter()
            .zip(&m.primitives[0].mesh.vertices)
            .map(|(a, b)| Vec3::from(a.position).distance(Vec3::from(b.position)))
            .collect();
        let most = moved.iter().copied().fold(0.0, f32::max);
        assert!(most <= 0.01 * diagonal * 1.0001 && most > 0.002 * diagonal, "{most}");
    }
}
