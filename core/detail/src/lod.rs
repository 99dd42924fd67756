//! A part's level-of-detail chain, made by meshoptimizer's simplifier.
//!
//! Each level aims at a quarter of the previous level's triangles (a chain of ~log₄ n levels,
//! adding a third to the index memory), over the part's own vertices. The simplifier measures
//! each level's error, which the chooser turns into pixels per eye: how far its surface lies from
//! the full part's, with the vertices' shading attributes counted alongside (a painted or
//! vertex-coloured scan loses its colours long before its shape). Positions are measured relative
//! to the part's extent, attributes in their own units times [`ATTRIBUTE_WEIGHTS`]: a colour
//! error of 0.1 weighs like a tenth of the part's size — a mis-coloured patch grows with the
//! part it is on. The result times the part's extent is the level's error in metres. The
//! weights follow meshoptimizer's advice (normals ½, colours 1); the part's border —
//! its seams with other parts, and any hole in the scan — is locked (`LockBorder`), so a part
//! at any level meets its neighbours at any level without a crack. A level that the simplifier
//! cannot make markedly smaller (locked borders and attribute seams bound it) ends the chain.

use meshopt::{SimplifyOptions, VertexDataAdapter};
use phantogram_assets::model::{Lod, Primitive, Vertex};

/// The fraction of the previous level's triangles each level aims at.
pub const LEVEL_RATIO: f32 = 0.25;

/// The chain ends when the simplifier keeps more than this fraction of the previous level (its
/// locked borders and seams leave little to remove).
const LEAST_GAIN: f32 = 0.75;

/// Weights of the attributes the simplifier keeps: normal (x, y, z), linear colour (r, g, b),
/// metallic and roughness multipliers. See the module docs.
pub const ATTRIBUTE_WEIGHTS: [f32; 8] = [0.5, 0.5, 0.5, 1.0, 1.0, 1.0, 0.5, 0.5];

/// Fills `primitive.lods` with its coarser levels, finest first (replacing any). Levels below
/// `min_triangles` triangles are not made.
pub fn build(primitive: &mut Primitive, min_triangles: usize) {
    primitive.lods.clear();
    let mesh = &primitive.mesh;
    let bytes: &[u8] = bytemuck::cast_slice(&mesh.vertices);
    let Ok(adapter) = VertexDataAdapter::new(bytes, std::mem::size_of::<Vertex>(), 0) else {
        return;
    };
    let n = mesh.vertices.len();
    if mesh.indices.iter().any(|&v| v as usize >= n) || !mesh.indices.len().is_multiple_of(3) {
        // meshoptimizer requires valid indices; such a primitive is drawn at full detail only.
        return;
    }
    let attributes: Vec<f32> = mesh
        .vertices
        .iter()
        .flat_map(|v| {
            let [nx, ny, nz] = v.normal;
            let [r, g, b, _] = v.color;
            let [m, rough] = v.material;
            [nx, ny, nz, r, g, b, m, rough]
        })
        .collect();
    // Nothing locked beyond the border (a slice the length of the vertices: meshoptimizer reads
    // one flag per vertex).
    let unlocked = vec![false; n];
    let extent_m = meshopt::simplify_scale(&adapter);
    let mut previous = mesh.indices.len();
    loop {
        let target = ((previous / 3) as f32 * LEVEL_RATIO) as usize * 3;
        if target / 3 < min_triangles.max(1) {
            break;
        }
        let mut error = 0.0f32;
        // Always from the full mesh: errors are then measured against it, not against the last
        // level.
        let indices = meshopt::simplify_with_attributes_and_locks(
            &mesh.indices,
            &adapter,
            &attributes,
            &ATTRIBUTE_WEIGHTS,
            std::mem::size_of::<[f32; 8]>(),
            &unlocked,
            target,
            f32::MAX,
            SimplifyOptions::LockBorder,
            Some(&mut error),
        );
        let error = error * extent_m;
        if indices.is_empty() || indices.len() as f32 > previous as f32 * LEAST_GAIN {
            break;
        }
        let indices = meshopt::optimize_vertex_cache(&indices, n);
        previous = indices.len();
        let error_m = error.max(primitive.lods.last().map_or(0.0, |l: &Lod| l.error_m));
        primitive.lods.push(Lod { indices, error_m });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tests::{bumpy_grid, grid};
    use glam::Vec3;

    #[test]
    fn levels_shrink_by_about_four_and_their_error_grows() {
        let mut p = bumpy_grid(64, 64, 0.02);
        build(&mut p, 16);
        assert!(p.lods.len() >= 3, "{} levels", p.lods.len());
        let mut triangles = p.mesh.indices.len() / 3;
        let mut error = 0.0;
        for lod in &p.lods {
            let t = lod.indices.len() / 3;
            assert!(t * 2 <= triangles && t * 8 >= triangles, "{triangles} → {t}");
            assert!(lod.error_m >= error && lod.error_m.is_finite());
            assert!(lod.indices.iter().all(|&v| (v as usize) < p.mesh.vertices.len()));
            triangles = t;
            error = lod.error_m;
        }
        assert!(error > 0.0, "a bumpy surface simplifies with some error");
    }

    #[test]
    fn a_flat_grid_simplifies_without_error_and_keeps_its_border() {
        let mut p = grid(32, 32);
        build(&mut p, 4);
        let last = p.lods.last().expect("levels");
        // Within 1 % of a cell (the simplifier's quadrics carry a small regularising term).
        assert!(last.error_m < 0.01, "{}", last.error_m);
        // Every border vertex of the full grid is still used by the coarsest level.
        let border = |v: &Vertex| {
            let q = Vec3::from(v.position);
            q.x == 0.0 || q.y == 0.0 || q.x == 32.0 || q.y == 32.0
        };
        for (i, v) in p.mesh.vertices.iter().enumerate() {
            if border(v) {
                assert!(last.indices.contains(&(i as u32)), "border vertex {i} lost");
            }
        }
    }

    #[test]
    fn painted_detail_counts_as_error_even_on_a_flat_surface() {
        // A flat grid painted as a checkerboard of 4-cell squares: its shape simplifies for
        // free, its paint does not.
        let mut p = grid(32, 32);
        for v in &mut p.mesh.vertices {
            let stripe = (v.position[0] as i32 / 4 + v.position[1] as i32 / 4) % 2 == 0;
            v.color = if stripe {
                [1.0, 0.1, 0.1, 1.0]
            } else {
                [0.1, 0.1, 1.0, 1.0]
            };
        }
        build(&mut p, 4);
        let mut plain = grid(32, 32);
        build(&mut plain, 4);
        let triangles = |p: &Primitive| p.lods.last().map_or(p.mesh.indices.len(), |l| l.indices.len()) / 3;
        let (painted_last, plain_last) = (p.lods.last().expect("levels"), plain.lods.last().expect("levels"));
        println!(
            "coarsest: painted {} triangles, error {}; plain {} triangles, error {}",
            triangles(&p),
            painted_last.error_m,
            triangles(&plain),
            plain_last.error_m
        );
        // The stripes are kept (more triangles), or what was lost is counted (more error).
        assert!(
            triangles(&p) > 4 * triangles(&plain) || painted_last.error_m > 10.0 * plain_last.error_m,
            "the paint was simplified away unnoticed"
        );
    }

    #[test]
    fn a_broken_mesh_gets_no_levels() {
        let mut p = grid(16, 16);
        p.mesh.indices.push(10_000);
        build(&mut p, 4);
        assert!(p.lods.is_empty());
    }
}
