//! Skinned meshes in their rest pose: each vertex carried by the joints it is bound to, as glTF
//! 2.0 defines skinning ("Skins"): `Σ wᵢ · (joint i's world matrix · its inverse bind matrix)`,
//! with the skinned mesh node's own transform ignored. A phantogram shows an artifact still, so
//! the pose is the one the file's node hierarchy holds (no animation is played).
//!
//! Without this a rigged model (a figure, a puppet, an animal scan) would be drawn with its
//! node's transform applied to the unskinned vertices, which glTF says to ignore: often the
//! right place, but wrong wherever the bind pose and the node hierarchy differ (rotated roots,
//! scaled skeletons).
//!
//! Pure functions over the loader's data; errors name what is wrong; no panics.

use glam::{Mat3, Mat4, Vec3, Vec4};

use super::Mesh;

/// The world matrix of every node (index by node), each its parents' product with its own local
/// matrix. `parent[i]` is node i's parent. Each node is computed once (a chain of many nodes
/// costs no more than as many products); a cycle (which the loader refuses elsewhere) is cut
/// where it closes.
pub(super) fn node_worlds(local: &[Mat4], parent: &[Option<usize>]) -> Vec<Mat4> {
    let n = local.len();
    let mut world: Vec<Option<Mat4>> = vec![None; n];
    let mut on_path = vec![false; n];
    let mut path = Vec::new();
    for start in 0..n {
        // Up to the first ancestor already known (or the root), then back down.
        let mut at = Some(start);
        while let Some(i) = at.filter(|&i| i < n && world[i].is_none() && !on_path[i]) {
            on_path[i] = true;
            path.push(i);
            at = parent.get(i).copied().flatten();
        }
        let mut above = at
            .and_then(|i| world.get(i).copied().flatten())
            .unwrap_or(Mat4::IDENTITY);
        while let Some(i) = path.pop() {
            above *= local[i];
            world[i] = Some(above);
            on_path[i] = false;
        }
    }
    world.into_iter().map(|w| w.unwrap_or(Mat4::IDENTITY)).collect()
}

/// Moves `mesh`'s vertices (positions, normals, tangents) by their joints: `joints` and
/// `weights` hold four per vertex (`JOINTS_0`, `WEIGHTS_0`), `matrices` one per joint of the skin
/// (world · inverse bind). Weights are normalised; a vertex with no weight stays where it is.
/// Triangles are turned over where the skin mirrors them (the mean determinant is negative), as
/// a node transform's mirror does.
pub(super) fn apply(mesh: &mut Mesh, joints: &[f32], weights: &[f32], matrices: &[Mat4]) -> Result<(), String> {
    let n = mesh.vertices.len();
    if joints.len() != n * 4 || weights.len() != n * 4 {
        return Err(format!(
            "JOINTS_0 and WEIGHTS_0 hold {} and {} values for {n} vertices (four each)",
            joints.len(),
            weights.len()
        ));
    }
    let mut determinant_sum = 0.0f32;
    for (i, v) in mesh.vertices.iter_mut().enumerate() {
        let (mut m, mut total) = (Mat4::ZERO, 0.0f32);
        for k in 0..4 {
            let w = weights[i * 4 + k];
            if !(w.is_finite() && w >= 0.0) {
                return Err(format!("vertex {i}: weight {w} is not a non-negative number"));
            }
            if w == 0.0 {
                continue;
            }
            let j = joints[i * 4 + k];
            let joint = matrices
                .get(j as usize)
                .filter(|_| j.is_finite() && j >= 0.0 && j.fract() == 0.0)
                .ok_or_else(|| format!("vertex {i}: joint {j} is not one of the skin's {}", matrices.len()))?;
            m += *joint * w;
            total += w;
        }
        if total <= 0.0 {
            continue;
        }
        let m = m * (1.0 / total);
        let linear = Mat3::from_mat4(m);
        determinant_sum += linear.determinant();
        let normal_m = linear.inverse().transpose();
        v.position = m.transform_point3(Vec3::from(v.position)).to_array();
        v.normal = (normal_m * Vec3::from(v.normal)).normalize_or_zero().to_array();
        let t = Vec4::from(v.tangent);
        v.tangent = (linear * t.truncate()).normalize_or_zero().extend(t.w).to_array();
    }
    if determinant_sum < 0.0 {
        for tri in mesh.indices.chunks_mut(3) {
            tri.swap(1, 2);
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Vertex;

    fn mesh(points: &[[f32; 3]]) -> Mesh {
        Mesh {
            vertices: points
                .iter()
                .map(|p| Vertex {
                    position: *p,
                    normal: [0.0, 0.0, 1.0],
                    tangent: [1.0, 0.0, 0.0, 1.0],
                    uv: [0.0; 4],
                    color: [1.0; 4],
                    material: [1.0, 1.0],
                })
                .collect(),
            indices: vec![0, 1, 2],
        }
    }

    #[test]
    fn worlds_compose_down_the_hierarchy() {
        let t = |x: f32| Mat4::from_translation(Vec3::new(x, 0.0, 0.0));
        let worlds = node_worlds(&[t(1.0), t(10.0), t(100.0)], &[None, Some(0), Some(1)]);
        assert_eq!(worlds[2].transform_point3(Vec3::ZERO), Vec3::new(111.0, 0.0, 0.0));
        // A cycle is cut where it closes.
        let looped = node_worlds(&[t(1.0), t(1.0)], &[Some(1), Some(0)]);
        assert!(looped.iter().all(|m| m.is_finite()));
        // A long chain, listed leaf first: each node's world once, every one right.
        let n = 20_000;
        let parent: Vec<Option<usize>> = (0..n).map(|i| (i + 1 < n).then_some(i + 1)).collect();
        let worlds = node_worlds(&vec![t(1.0); n], &parent);
        assert_eq!(worlds[0].transform_point3(Vec3::ZERO).x, n as f32);
        assert_eq!(worlds[n - 1].transform_point3(Vec3::ZERO).x, 1.0);
    }

    #[test]
    fn vertices_follow_their_joints_blended_by_weight() {
        let up = Mat4::from_translation(Vec3::new(0.0, 2.0, 0.0));
        let out = Mat4::from_translation(Vec3::new(0.0, 0.0, 2.0));
        let mut m = mesh(&[[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
        // Vertex 0 on joint 0, vertex 1 half on each (weights 2 and 2: normalised), vertex 2 on
        // joint 1 through its second slot.
        let joints = [0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0];
        let weights = [1.0, 0.0, 0.0, 0.0, 2.0, 2.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0];
        apply(&mut m, &joints, &weights, &[up, out]).expect("valid");
        assert_eq!(m.vertices[0].position, [0.0, 2.0, 0.0]);
        assert_eq!(m.vertices[1].position, [1.0, 1.0, 1.0]);
        assert_eq!(m.vertices[2].position, [0.0, 1.0, 2.0]);
        assert_eq!(m.indices, vec![0, 1, 2]);
    }

    #[test]
    fn a_mirroring_skin_turns_the_triangles_over_and_bad_data_is_named() {
        let mirror = Mat4::from_scale(Vec3::new(-1.0, 1.0, 1.0));
        let mut m = mesh(&[[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
        let joints = [0.0; 12];
        let weights = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0];
        apply(&mut m, &joints, &weights, &[mirror]).expect("valid");
        assert_eq!(m.indices, vec![0, 2, 1]);
        let mut m = mesh(&[[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
        let past = [0.0, 0.0, 0.0, 0.0, 3.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
        let weights_all = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0];
        assert!(apply(&mut m, &past, &weights_all, &[mirror]).is_err());
        let nan = [f32::NAN, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0];
        assert!(apply(&mut m, &joints, &nan, &[mirror]).is_err());
        assert!(apply(&mut m, &joints[..8], &weights_all[..8], &[mirror]).is_err());
    }
}
