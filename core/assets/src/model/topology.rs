//! Triangle lists from glTF's two other triangle topologies, strips and fans, so that the rest of
//! the loader and the renderer know one topology only.
//!
//! The order of each triangle's corners is glTF 2.0's ("Meshes", primitive modes), which keeps
//! one winding across the whole strip or fan, so the front faces stay front faces:
//! - strip: triangle `i` is `(v[i], v[i + 1 + i % 2], v[i + 2 - i % 2])`;
//! - fan: triangle `i` is `(v[i + 1], v[i + 2], v[0])`.
//!
//! Triangles with a repeated corner (strips joined by repeated indices, a common way to chain
//! them) have no area and are left out. Pure functions; no panics.

use gltf::mesh::Mode;

/// The triangle list drawn by a primitive of `mode` over the vertex sequence `sequence` (its
/// indices, or `0..count` without). `None` for the modes that draw no triangles (points and
/// lines); `sequence` as it is for [`Mode::Triangles`].
pub(super) fn triangle_list(mode: Mode, sequence: Vec<u32>) -> Option<Vec<u32>> {
    let corners = |n: usize, corner: &dyn Fn(usize) -> [u32; 3]| {
        (0..n.saturating_sub(2))
            .map(corner)
            .filter(|[a, b, c]| a != b && b != c && a != c)
            .flatten()
            .collect::<Vec<u32>>()
    };
    let v = &sequence;
    match mode {
        Mode::Triangles => Some(sequence),
        Mode::TriangleStrip => Some(corners(v.len(), &|i| [v[i], v[i + 1 + i % 2], v[i + 2 - i % 2]])),
        Mode::TriangleFan => Some(corners(v.len(), &|i| [v[i + 1], v[i + 2], v[0]])),
        Mode::Points | Mode::Lines | Mode::LineLoop | Mode::LineStrip => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    /// The normal (unnormalised) of each triangle of `list` over `positions`.
    fn normals(list: &[u32], positions: &[Vec3]) -> Vec<Vec3> {
        list.chunks(3)
            .map(|t| {
                let p = |k: usize| positions[t[k] as usize];
                (p(1) - p(0)).cross(p(2) - p(0))
            })
            .collect()
    }

    #[test]
    fn a_strip_is_its_triangles_all_wound_one_way() {
        // A zig-zag along x in the z = 0 plane: 0, 2, 4 below, 1, 3, 5 above.
        let positions: Vec<Vec3> = (0..6).map(|i| Vec3::new((i / 2) as f32, (i % 2) as f32, 0.0)).collect();
        let list = triangle_list(Mode::TriangleStrip, (0..6).collect()).expect("triangles");
        assert_eq!(list, vec![0, 1, 2, 1, 3, 2, 2, 3, 4, 3, 5, 4]);
        let n = normals(&list, &positions);
        assert!(n.iter().all(|n| n.z < 0.0 && n.x == 0.0 && n.y == 0.0), "{n:?}");
    }

    #[test]
    fn a_fan_is_its_triangles_about_the_first_vertex_all_wound_one_way() {
        // The centre, then four points counter-clockwise around it.
        let positions = [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::NEG_X, Vec3::NEG_Y];
        let list = triangle_list(Mode::TriangleFan, (0..5).collect()).expect("triangles");
        assert_eq!(list, vec![1, 2, 0, 2, 3, 0, 3, 4, 0]);
        assert!(normals(&list, &positions).iter().all(|n| n.z > 0.0));
    }

    #[test]
    fn repeated_corners_joining_strips_draw_nothing() {
        // Two strips joined by repeating the last index of one and the first of the next.
        let list = triangle_list(Mode::TriangleStrip, vec![0, 1, 2, 3, 3, 4, 4, 5, 6, 7]).expect("triangles");
        assert_eq!(list.len() % 3, 0);
        for t in list.chunks(3) {
            assert!(t[0] != t[1] && t[1] != t[2] && t[0] != t[2], "{t:?}");
        }
        // Both strips' two triangles each.
        assert_eq!(list.len(), 4 * 3);
    }

    #[test]
    fn too_few_vertices_and_non_triangle_modes() {
        assert_eq!(triangle_list(Mode::TriangleStrip, vec![0, 1]), Some(vec![]));
        assert_eq!(triangle_list(Mode::TriangleFan, vec![]), Some(vec![]));
        assert_eq!(triangle_list(Mode::Triangles, vec![2, 1, 0]), Some(vec![2, 1, 0]));
        for mode in [Mode::Points, Mode::Lines, Mode::LineLoop, Mode::LineStrip] {
            assert_eq!(triangle_list(mode, vec![0, 1, 2]), None);
        }
    }
}
