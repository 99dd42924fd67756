//! Splitting a mesh so that each piece fits one GPU buffer.
//!
//! A GPU buffer has a largest size (`wgpu::Limits::max_buffer_size`, 256 MiB by default and on
//! many phones): a valid scan of 3.6 M unindexed vertices does not fit one vertex buffer. The
//! renderer draws such a mesh as several pieces, each with its own vertex and index buffer. The
//! triangles keep their order and their vertices' values; a vertex shared by triangles that land
//! in two pieces is copied into both.

use super::Mesh;

impl Mesh {
    /// Pieces of this mesh with at most `max_vertices` vertices and `max_indices` indices each
    /// (both at least 3): the mesh itself when it fits.
    pub fn split_to_fit(&self, max_vertices: usize, max_indices: usize) -> Vec<Mesh> {
        let max_vertices = max_vertices.max(3);
        let max_indices = max_indices.max(3) / 3 * 3;
        if self.vertices.len() <= max_vertices && self.indices.len() <= max_indices {
            return vec![self.clone()];
        }
        // `slot[v]`: vertex v's index in the current piece, or u32::MAX.
        let mut slot = vec![u32::MAX; self.vertices.len()];
        let mut touched: Vec<usize> = Vec::new();
        let mut pieces = Vec::new();
        let mut piece = Mesh::default();
        for tri in self.indices.chunks_exact(3) {
            let new_vertices = tri
                .iter()
                .enumerate()
                .filter(|&(k, &v)| slot[v as usize] == u32::MAX && !tri[..k].contains(&v))
                .count();
            if piece.vertices.len() + new_vertices > max_vertices || piece.indices.len() + 3 > max_indices {
                pieces.push(std::mem::take(&mut piece));
                for v in touched.drain(..) {
                    slot[v] = u32::MAX;
                }
            }
            for &v in tri {
                let v = v as usize;
                if slot[v] == u32::MAX {
                    slot[v] = piece.vertices.len() as u32;
                    piece.vertices.push(self.vertices[v]);
                    touched.push(v);
                }
                piece.indices.push(slot[v]);
            }
        }
        if !piece.indices.is_empty() {
            pieces.push(piece);
        }
        pieces
    }
}

#[cfg(test)]
mod tests {
    use super::super::Vertex;
    use super::*;

    fn vertex(i: usize) -> Vertex {
        Vertex {
            position: [i as f32, (i * 7 % 13) as f32, 0.5],
            normal: [0.0, 0.0, 1.0],
            tangent: [1.0, 0.0, 0.0, 1.0],
            uv: [0.0; 4],
            color: [1.0; 4],
            material: [1.0, 1.0],
        }
    }

    #[test]
    fn pieces_fit_and_draw_the_same_triangles() {
        // A strip of 1000 triangles sharing vertices, and an unindexed soup.
        let strip = Mesh {
            vertices: (0..1002).map(vertex).collect(),
            indices: (0..1000u32).flat_map(|i| [i, i + 1, i + 2]).collect(),
        };
        let soup = Mesh {
            vertices: (0..999).map(vertex).collect(),
            indices: (0..999).collect(),
        };
        for mesh in [strip, soup] {
            for (max_v, max_i) in [(64, 1 << 20), (1 << 20, 90), (3, 3), (100, 100)] {
                let pieces = mesh.split_to_fit(max_v, max_i);
                assert!(pieces.len() > 1, "{max_v}/{max_i}: not split");
                let triangles = |m: &Mesh| -> Vec<[[f32; 3]; 3]> {
                    m.indices
                        .chunks_exact(3)
                        .map(|t| [t[0], t[1], t[2]].map(|i| m.vertices[i as usize].position))
                        .collect()
                };
                let rejoined: Vec<_> = pieces.iter().flat_map(triangles).collect();
                assert_eq!(rejoined, triangles(&mesh), "{max_v}/{max_i}");
                for p in &pieces {
                    assert!(p.vertices.len() <= max_v && p.indices.len() <= max_i);
                    assert!(p.indices.iter().all(|&i| (i as usize) < p.vertices.len()));
                }
            }
            assert_eq!(mesh.split_to_fit(1 << 20, 1 << 20).len(), 1);
        }
    }
}
