//! Joining small primitives that share a material, so that a file of many parts is drawn in few
//! draw calls.
//!
//! A CAD export, a kit of pieces or a scene of thousands of nodes gives one primitive per part
//! and per node that places it, and each primitive is a draw call per eye and per pass. Twenty
//! thousand boxes of eight colours were 20 000 draws a pass (the file was refused by the budget
//! of drawn primitives); joined, they are 8. A museum scan's single big mesh is left as it is.
//!
//! What is joined: primitives with fewer than [`JOIN_MAX_TRIANGLES`] triangles, of the same
//! material, drawn over the opaque scene in any order (not blended nor transmitting: those are
//! sorted back to front one primitive at a time), not the floor and without levels of detail.
//! Those of one material are halved across the longest side of their centres' bounds (at the
//! median by triangles) until each half holds fewer than [`JOIN_MAX_TRIANGLES`] triangles, so
//! that each joined primitive is a compact piece of the model, as the detail crate's parts of a
//! big mesh are, which the renderer culls and the chooser weighs as one.
//!
//! Invariants: every triangle and vertex keeps its value (positions are already in the model's
//! frame); a joined primitive stands where its first member stood in [`Model::primitives`], the
//! others keep their order. Nothing here panics; the work is linear in the vertices, plus sorting
//! the primitives of a material once per level of halving.

use glam::Vec3;

use super::{AlphaMode, Mesh, Model, Primitive};

/// Largest joined primitive, triangles; primitives this size or larger are never joined. The
/// same order as the detail crate's part size (32 768): a piece the renderer can cull and the
/// chooser can weigh alone, and whose vertices fit any index and buffer limit.
pub const JOIN_MAX_TRIANGLES: usize = 32_768;

impl Model {
    /// Joins the small primitives that share a material (module docs); returns how many
    /// primitives fewer there are.
    pub fn join_small_primitives(&mut self) -> usize {
        let before = self.primitives.len();
        let joinable: Vec<bool> = self.primitives.iter().map(|p| self.joinable(p)).collect();
        if joinable.iter().filter(|&&j| j).count() < 2 {
            return 0;
        }
        let groups = groups(&self.primitives, &joinable);
        // `leader[i]`: the group primitive i leads (its first member in `Model::primitives`), if any.
        let mut leader = vec![None; before];
        let mut member = vec![false; before];
        for (g, group) in groups.iter().enumerate() {
            if group.len() < 2 {
                continue;
            }
            if let Some(&first) = group.iter().min() {
                leader[first] = Some(g);
            }
            for &i in group {
                member[i] = true;
            }
        }
        let mut old: Vec<Option<Primitive>> = std::mem::take(&mut self.primitives).into_iter().map(Some).collect();
        let mut out = Vec::with_capacity(before);
        for i in 0..before {
            if let Some(g) = leader[i] {
                out.push(joined(&groups[g], &mut old));
            } else if !member[i]
                && let Some(p) = old[i].take()
            {
                out.push(p);
            }
        }
        self.primitives = out;
        before - self.primitives.len()
    }

    fn joinable(&self, p: &Primitive) -> bool {
        let drawn_in_any_order = self
            .materials
            .get(p.material)
            .is_some_and(|m| m.alpha != AlphaMode::Blend && !m.transmits());
        drawn_in_any_order && !p.is_floor && p.lods.is_empty() && p.mesh.indices.len() / 3 < JOIN_MAX_TRIANGLES
    }
}

/// The joinable primitives (by index) gathered into groups: by material, then split in halves
/// of about equal triangles across the longest side of their centres' bounds until each holds
/// under [`JOIN_MAX_TRIANGLES`] triangles (a k-d tree's leaves: compact pieces).
fn groups(primitives: &[Primitive], joinable: &[bool]) -> Vec<Vec<usize>> {
    let centre = |i: usize| {
        primitives[i]
            .mesh
            .bounds()
            .map_or(Vec3::ZERO, |b| (b.min + b.max) * 0.5)
    };
    let mut by_material: Vec<(usize, Vec3, usize)> = (0..primitives.len())
        .filter(|&i| joinable[i])
        .map(|i| (primitives[i].material, centre(i), i))
        .collect();
    by_material.sort_by_key(|&(m, _, i)| (m, i));
    let triangles = |i: usize| primitives[i].mesh.indices.len() / 3;
    let mut groups = Vec::new();
    for same in by_material.chunk_by(|a, b| a.0 == b.0) {
        let mut items: Vec<(Vec3, usize)> = same.iter().map(|&(_, c, i)| (c, i)).collect();
        split(&mut items, &triangles, &mut groups);
    }
    groups
}

/// Appends `items` (centre, primitive) to `groups`, halved recursively while they hold
/// [`JOIN_MAX_TRIANGLES`] triangles or more.
fn split(items: &mut [(Vec3, usize)], triangles: &impl Fn(usize) -> usize, groups: &mut Vec<Vec<usize>>) {
    let total: usize = items.iter().map(|&(_, i)| triangles(i)).sum();
    if total < JOIN_MAX_TRIANGLES || items.len() < 2 {
        groups.push(items.iter().map(|&(_, i)| i).collect());
        return;
    }
    let (lo, hi) = items
        .iter()
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &(c, _)| {
            (lo.min(c), hi.max(c))
        });
    let axis = (hi - lo).max_position();
    items.sort_by(|a, b| a.0[axis].total_cmp(&b.0[axis]).then(a.1.cmp(&b.1)));
    // The first index past half the triangles, within 1..len so that both halves hold some.
    let mut seen = 0;
    let half = items
        .iter()
        .position(|&(_, i)| {
            seen += triangles(i);
            2 * seen >= total
        })
        .map_or(1, |k| k + 1)
        .clamp(1, items.len() - 1);
    let (a, b) = items.split_at_mut(half);
    split(a, triangles, groups);
    split(b, triangles, groups);
}

/// The members of `group`, taken out of `old`, as one primitive.
fn joined(group: &[usize], old: &mut [Option<Primitive>]) -> Primitive {
    let members: Vec<Primitive> = group.iter().filter_map(|&i| old.get_mut(i)?.take()).collect();
    let material = members.first().map_or(0, |p| p.material);
    let mut mesh = Mesh {
        vertices: Vec::with_capacity(members.iter().map(|p| p.mesh.vertices.len()).sum()),
        indices: Vec::with_capacity(members.iter().map(|p| p.mesh.indices.len()).sum()),
    };
    for p in members {
        let base = mesh.vertices.len() as u32;
        mesh.indices.extend(p.mesh.indices.iter().map(|&i| base + i));
        mesh.vertices.extend(p.mesh.vertices);
    }
    Primitive {
        mesh,
        material,
        is_floor: false,
        lods: Vec::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{Material, Vertex};

    fn quad(at: Vec3, material: usize) -> Primitive {
        let corners = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        Primitive {
            mesh: Mesh {
                vertices: corners
                    .iter()
                    .map(|&[x, y]| Vertex {
                        position: (at + Vec3::new(x, y, 0.0)).to_array(),
                        ..Vertex::default()
                    })
                    .collect(),
                indices: vec![0, 1, 2, 0, 2, 3],
            },
            material,
            is_floor: false,
            lods: Vec::new(),
        }
    }

    fn model(primitives: Vec<Primitive>, materials: Vec<Material>) -> Model {
        Model {
            primitives,
            materials,
            ..Model::default()
        }
    }

    /// Every triangle as its three corner positions, sorted: what is drawn, whatever the
    /// primitives and indices that hold it.
    fn triangles_of(model: &Model) -> Vec<[[u32; 3]; 3]> {
        let mut all: Vec<[[u32; 3]; 3]> = model
            .primitives
            .iter()
            .flat_map(|p| {
                p.mesh
                    .indices
                    .chunks_exact(3)
                    .map(|t| [t[0], t[1], t[2]].map(|i| p.mesh.vertices[i as usize].position.map(f32::to_bits)))
            })
            .collect();
        all.sort_unstable();
        all
    }

    #[test]
    fn many_parts_of_few_materials_become_one_primitive_a_material() {
        let parts: Vec<Primitive> = (0..300)
            .map(|k| quad(Vec3::new((k % 17) as f32 * 2.0, (k / 17) as f32 * 2.0, 0.0), k % 3))
            .collect();
        let mut m = model(parts, vec![Material::default(); 3]);
        let before = triangles_of(&m);
        assert_eq!(m.join_small_primitives(), 297);
        assert_eq!(m.primitives.len(), 3);
        assert_eq!(triangles_of(&m), before, "every triangle kept, none added");
        let materials: Vec<usize> = m.primitives.iter().map(|p| p.material).collect();
        assert_eq!(materials, [0, 1, 2], "each where its first member stood");
    }

    #[test]
    fn blended_glass_the_floor_and_big_or_detailed_primitives_stay_apart() {
        let glass = Material {
            alpha: AlphaMode::Blend,
            ..Material::default()
        };
        let mut floor = quad(Vec3::ZERO, 0);
        floor.is_floor = true;
        let mut big = quad(Vec3::ONE, 0);
        let tri = big.mesh.indices.clone();
        big.mesh.indices = tri.iter().cycle().take(JOIN_MAX_TRIANGLES * 3).copied().collect();
        let mut detailed = quad(Vec3::ONE, 0);
        detailed.lods.push(crate::model::Lod {
            indices: vec![0, 1, 2],
            error_m: 0.1,
        });
        let mut m = model(
            vec![
                quad(Vec3::X, 1),
                quad(Vec3::Y, 1),
                floor,
                big,
                detailed,
                quad(Vec3::Z, 0),
                quad(Vec3::ONE, 0),
            ],
            vec![Material::default(), glass],
        );
        let before = triangles_of(&m);
        assert_eq!(m.join_small_primitives(), 1, "only the two small opaque quads join");
        assert_eq!(m.primitives.len(), 6);
        assert_eq!(triangles_of(&m), before);
        assert!(m.primitives[2].is_floor && m.primitives[4].lods.len() == 1);
        let glasses = m.primitives.iter().filter(|p| p.material == 1).count();
        assert_eq!(glasses, 2, "blended primitives keep their own back-to-front order");
    }

    #[test]
    fn a_joined_primitive_stays_under_the_cap_and_near_its_neighbours() {
        // 40 000 quads (80 000 triangles) of one material on a 200 × 200 grid, in a scrambled
        // file order: joined as they come, every piece would span the whole grid.
        let parts: Vec<Primitive> = (0..40_000u32)
            .map(|k| k.wrapping_mul(7919) % 40_000)
            .map(|k| quad(Vec3::new((k % 200) as f32 * 2.0, (k / 200) as f32 * 2.0, 0.0), 0))
            .collect();
        let mut m = model(parts, vec![Material::default()]);
        let before = triangles_of(&m);
        m.join_small_primitives();
        assert_eq!(
            m.primitives.len(),
            4,
            "80 000 triangles in halves, then quarters, under 32 768"
        );
        assert_eq!(triangles_of(&m), before);
        for p in &m.primitives {
            assert!(p.mesh.indices.len() / 3 < JOIN_MAX_TRIANGLES);
            // A quarter of the 400 × 400 grid each.
            let b = p.mesh.bounds().unwrap();
            let size = b.max - b.min;
            assert!(size.x * size.y < 0.26 * 400.0 * 400.0, "{size}");
        }
    }

    #[test]
    fn nothing_to_join_changes_nothing() {
        let mut m = model(
            vec![quad(Vec3::ZERO, 0), quad(Vec3::X, 1)],
            vec![Material::default(); 2],
        );
        let before = m.clone();
        assert_eq!(m.join_small_primitives(), 0);
        assert_eq!(m, before);
    }
}
