//! `EXT_mesh_gpu_instancing`: one node's mesh drawn at many places. The node carries per-instance
//! `TRANSLATION`, `ROTATION` and `SCALE` accessors; instance `i` is drawn at
//! `node world · T_i · R_i · S_i` (the extension's order, the same as a node's), and the mesh
//! itself not at all.
//!
//! The copies are baked into one mesh per primitive, as node transforms are (one draw call per
//! primitive however many instances; every copy's bytes charged to the budget by the loader
//! before they are made). Custom attributes (`_ID`, `_COLOR` …) have no meaning for us and are
//! ignored. Pure functions: no panics, no shared state.

use glam::{Mat4, Quat, Vec3};

use super::Mesh;

/// The instances' transforms from their attribute rows (`translation` and `scale` 3 floats a
/// row, `rotation` 4, x y z w), `count` of them; an attribute the node leaves out is the
/// identity. A rotation of length zero (not a rotation) is an error naming the instance; others
/// are normalised, as the quantised forms the extension allows are not exactly unit length.
pub fn matrices(
    count: usize,
    translation: Option<&[f32]>,
    rotation: Option<&[f32]>,
    scale: Option<&[f32]>,
) -> Result<Vec<Mat4>, String> {
    (0..count)
        .map(|i| {
            let vec3 = |rows: Option<&[f32]>, default: Vec3| {
                rows.and_then(|r| r.get(3 * i..3 * i + 3))
                    .map_or(default, Vec3::from_slice)
            };
            let t = vec3(translation, Vec3::ZERO);
            let s = vec3(scale, Vec3::ONE);
            let r = match rotation.and_then(|r| r.get(4 * i..4 * i + 4)) {
                Some(q) => {
                    let q = Quat::from_slice(q);
                    if !q.is_finite() || q.length() <= 1e-6 {
                        return Err(format!("instance {i}'s rotation {q} is not a rotation"));
                    }
                    q.normalize()
                }
                None => Quat::IDENTITY,
            };
            Ok(Mat4::from_scale_rotation_translation(s, r, t))
        })
        .collect()
}

/// `mesh` (in its node's model space) once at each of `worlds`, as one mesh.
pub fn replicate(mesh: &Mesh, worlds: &[Mat4]) -> Mesh {
    let mut out = Mesh {
        vertices: Vec::with_capacity(mesh.vertices.len() * worlds.len()),
        indices: Vec::with_capacity(mesh.indices.len() * worlds.len()),
    };
    for world in worlds {
        let mut copy = mesh.clone();
        copy.transform(*world);
        // The loader charged every copy and holds the vertex count within u32 (the budget's
        // bytes are far fewer than 2^32 vertices).
        let base = out.vertices.len() as u32;
        out.indices.extend(copy.indices.iter().map(|i| base + i));
        out.vertices.extend(copy.vertices);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Vertex;

    fn triangle() -> Mesh {
        let vertex = |x: f32, y: f32| Vertex {
            position: [x, y, 0.0],
            normal: [0.0, 0.0, 1.0],
            ..Vertex::default()
        };
        Mesh {
            vertices: vec![vertex(0.0, 0.0), vertex(1.0, 0.0), vertex(0.0, 1.0)],
            indices: vec![0, 1, 2],
        }
    }

    #[test]
    fn each_instance_is_translated_rotated_and_scaled_in_that_order() {
        // Scaled ×2, turned 90° about z, moved 10 along x: (1, 0, 0) → (2, 0, 0) → (0, 2, 0) →
        // (10, 2, 0). Any other order lands elsewhere.
        let q = Quat::from_rotation_z(std::f32::consts::FRAC_PI_2);
        let m = matrices(
            1,
            Some(&[10.0, 0.0, 0.0]),
            Some(&[q.x, q.y, q.z, q.w]),
            Some(&[2.0, 2.0, 2.0]),
        )
        .expect("valid");
        let p = m[0].transform_point3(Vec3::X);
        assert!((p - Vec3::new(10.0, 2.0, 0.0)).length() < 1e-5, "{p}");
    }

    #[test]
    fn left_out_attributes_are_the_identity_and_quantised_rotations_are_normalised() {
        // A rotation as normalised shorts: (0, 0, 0.7071, 0.7071) read as 23170 / 32767.
        let r = [0.0, 0.0, 23170.0 / 32767.0, 23170.0 / 32767.0];
        let m = matrices(2, None, Some(&[0.0, 0.0, 0.0, 1.0, r[0], r[1], r[2], r[3]]), None).expect("valid");
        assert_eq!(m[0], Mat4::IDENTITY);
        let p = m[1].transform_point3(Vec3::X);
        assert!((p - Vec3::Y).length() < 1e-5, "{p}");
    }

    #[test]
    fn a_zero_rotation_is_named() {
        let error = matrices(2, None, Some(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0]), None).unwrap_err();
        assert!(error.contains("instance 1"), "{error}");
        let error = matrices(1, None, Some(&[f32::NAN, 0.0, 0.0, 1.0]), None).unwrap_err();
        assert!(error.contains("instance 0"), "{error}");
    }

    #[test]
    fn copies_are_one_mesh_with_their_own_indices_and_mirrored_ones_keep_facing_out() {
        let worlds = [
            Mat4::from_translation(Vec3::new(5.0, 0.0, 0.0)),
            Mat4::from_scale(Vec3::new(-1.0, 1.0, 1.0)),
        ];
        let out = replicate(&triangle(), &worlds);
        assert_eq!(out.vertices.len(), 6);
        assert_eq!(out.vertices[4].position, [-1.0, 0.0, 0.0]);
        // The second copy's indices point at its own vertices, wound the other way round (a
        // mirror), so that its front still faces +z.
        assert_eq!(&out.indices[..3], &[0, 1, 2]);
        assert_eq!(&out.indices[3..], &[3, 5, 4]);
    }
}
