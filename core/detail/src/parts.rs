//! Splitting a big primitive into spatial parts.
//!
//! The parts are made by halving the triangles at the median of their centroids along the
//! longest side of the centroids' bounds, recursively, until each part holds at most the part
//! size: compact, similar-sized pieces of surface (a k-d tree's leaves). A part keeps its
//! triangles' order and copies the vertices it uses; a vertex on the seam between two parts is
//! copied into both with the same value, and the level-of-detail chain ([`crate::lod`]) keeps
//! those seam vertices in place, so that parts drawn at different levels still meet exactly.

use glam::Vec3;
use phantogram_assets::model::{Mesh, Primitive};

/// `primitive` split into parts of at most `max_triangles` triangles each (at least 1), each a
/// primitive of the same material; the primitive itself when it fits. Triangles whose indices
/// lie outside the vertices are dropped (the loader never makes them).
pub fn split(primitive: &Primitive, max_triangles: usize) -> Vec<Primitive> {
    let groups = split_triangles(primitive, max_triangles);
    if groups.len() == 1 && groups[0].len() * 3 == primitive.mesh.indices.len() {
        return vec![primitive.clone()];
    }
    let mut slot = Vec::new();
    groups.iter().map(|g| part_of(primitive, g, &mut slot)).collect()
}

/// The triangles (their indices in `primitive.mesh`, ascending) of each part [`split`] makes.
pub fn split_triangles(primitive: &Primitive, max_triangles: usize) -> Vec<Vec<u32>> {
    let max_triangles = max_triangles.max(1);
    let mesh = &primitive.mesh;
    let n_vertices = mesh.vertices.len();
    let mut triangles: Vec<(u32, Vec3)> = mesh
        .indices
        .chunks_exact(3)
        .enumerate()
        .filter(|(_, t)| t.iter().all(|&v| (v as usize) < n_vertices))
        .map(|(i, t)| {
            let c = t
                .iter()
                .map(|&v| Vec3::from(mesh.vertices[v as usize].position))
                .sum::<Vec3>()
                / 3.0;
            (i as u32, c)
        })
        .collect();
    let mut groups: Vec<&mut [(u32, Vec3)]> = Vec::new();
    halve(&mut triangles, max_triangles, &mut groups);
    groups
        .into_iter()
        .map(|group| {
            // Original order inside the part (the loader's order is often cache-friendly).
            let mut ids: Vec<u32> = group.iter().map(|&(i, _)| i).collect();
            ids.sort_unstable();
            ids
        })
        .collect()
}

/// The part of `primitive` made of `triangles` (indices of its triangles; ones out of range
/// are skipped): their vertices copied in first-use order. `slot` is scratch space, reused
/// between calls (left all `u32::MAX`).
pub fn part_of(primitive: &Primitive, triangles: &[u32], slot: &mut Vec<u32>) -> Primitive {
    let mesh = &primitive.mesh;
    if slot.len() < mesh.vertices.len() {
        slot.resize(mesh.vertices.len(), u32::MAX);
    }
    let mut part = Mesh::default();
    let mut used = Vec::new();
    for &i in triangles {
        let Some(t) = mesh.indices.get(i as usize * 3..i as usize * 3 + 3) else {
            continue;
        };
        if t.iter().any(|&v| v as usize >= mesh.vertices.len()) {
            continue;
        }
        for &v in t {
            let v = v as usize;
            if slot[v] == u32::MAX {
                slot[v] = part.vertices.len() as u32;
                part.vertices.push(mesh.vertices[v]);
                used.push(v);
            }
            part.indices.push(slot[v]);
        }
    }
    for v in used {
        slot[v] = u32::MAX;
    }
    Primitive {
        mesh: part,
        material: primitive.material,
        is_floor: primitive.is_floor,
        lods: Vec::new(),
    }
}

/// Splits `triangles` at the median centroid along the longest axis until each group holds at
/// most `max` triangles. Iterative (a deep scan must not overflow the stack).
fn halve<'a>(triangles: &'a mut [(u32, Vec3)], max: usize, out: &mut Vec<&'a mut [(u32, Vec3)]>) {
    let mut stack = vec![triangles];
    while let Some(group) = stack.pop() {
        if group.len() <= max {
            out.push(group);
            continue;
        }
        let (lo, hi) = group.iter().fold(
            (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |(lo, hi), &(_, c)| (lo.min(c), hi.max(c)),
        );
        let extent = hi - lo;
        let axis = if extent.x >= extent.y && extent.x >= extent.z {
            0
        } else if extent.y >= extent.z {
            1
        } else {
            2
        };
        let mid = group.len() / 2;
        group.select_nth_unstable_by(mid, |a, b| a.1[axis].total_cmp(&b.1[axis]));
        let (a, b) = group.split_at_mut(mid);
        stack.push(b);
        stack.push(a);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tests::grid;

    #[test]
    fn parts_hold_every_triangle_once_with_its_vertices() {
        let primitive = grid(40, 30);
        let parts = split(&primitive, 100);
        assert!(parts.len() >= 24, "{} parts", parts.len());
        assert!(parts.iter().all(|p| p.mesh.indices.len() / 3 <= 100));
        let mut seen: Vec<[[u32; 3]; 3]> = Vec::new();
        for p in &parts {
            for t in p.mesh.indices.chunks_exact(3) {
                seen.push([t[0], t[1], t[2]].map(|v| {
                    Vec3::from(p.mesh.vertices[v as usize].position)
                        .to_array()
                        .map(f32::to_bits)
                }));
            }
        }
        let mut whole: Vec<[[u32; 3]; 3]> = primitive
            .mesh
            .indices
            .chunks_exact(3)
            .map(|t| {
                [t[0], t[1], t[2]].map(|v| {
                    Vec3::from(primitive.mesh.vertices[v as usize].position)
                        .to_array()
                        .map(f32::to_bits)
                })
            })
            .collect();
        seen.sort_unstable();
        whole.sort_unstable();
        assert_eq!(seen, whole);
    }

    #[test]
    fn parts_are_compact() {
        // Each part of a 40 × 30 grid of unit cells covers a patch, not a scattered set: its
        // bounds hold not many more cells than it has.
        for p in split(&grid(40, 30), 100) {
            let b = p.mesh.bounds().unwrap();
            let cells = (b.max.x - b.min.x) * (b.max.y - b.min.y);
            let held = p.mesh.indices.len() as f32 / 6.0;
            assert!(cells <= held * 2.0, "a part of {held} cells spans {cells}");
        }
    }

    #[test]
    fn a_small_primitive_stays_whole_and_bad_indices_are_dropped() {
        let mut p = grid(4, 4);
        assert_eq!(split(&p, 100), vec![p.clone()]);
        p.mesh.indices.extend_from_slice(&[0, 1, 999_999]);
        let parts = split(&p, 10);
        let total: usize = parts.iter().map(|p| p.mesh.indices.len()).sum();
        assert_eq!(total, 4 * 4 * 6);
    }
}
