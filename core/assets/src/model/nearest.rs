//! Nearest neighbours of points: a k-d tree (for the point clouds' discs, `point_cloud`).
//!
//! An index array split at the median of each node's widest axis: balanced whatever the points'
//! spread, so a dense clump beside a few far-off points costs O(log n) a query like an even scan
//! (a uniform grid would put the clump in one cell and look at all of it for each of its points).
//! Built in O(n log n); no recursion; no panics on any input (a NaN coordinate gives NaN
//! distances, which order as `f64::total_cmp` orders them).

use glam::DVec3;

/// A k-d tree over a slice of points (see the module docs), leaves of at most [`LEAF`] points.
pub struct KdTree {
    /// Point indices, each node's points a contiguous run.
    order: Vec<u32>,
    nodes: Vec<Node>,
    /// The bounding box's diagonal.
    pub extent: f64,
}

/// Points per leaf: a leaf is searched whole.
const LEAF: usize = 8;

enum Node {
    Leaf {
        start: usize,
        end: usize,
    },
    Split {
        axis: usize,
        at: f64,
        below: usize,
        above: usize,
    },
}

impl KdTree {
    pub fn new(points: &[DVec3]) -> KdTree {
        let (lo, hi) = points
            .iter()
            .fold((points[0], points[0]), |(lo, hi), &p| (lo.min(p), hi.max(p)));
        let mut tree = KdTree {
            order: (0..points.len() as u32).collect(),
            nodes: Vec::with_capacity(2 * points.len() / LEAF + 1),
            extent: (hi - lo).length(),
        };
        // Built iteratively (an explicit stack): a recursion's depth is fine at log₂ n, but the
        // stack needs no argument.
        tree.nodes.push(Node::Leaf { start: 0, end: 0 });
        let mut pending = vec![(0usize, 0usize, points.len())];
        while let Some((node, start, end)) = pending.pop() {
            if end - start <= LEAF {
                tree.nodes[node] = Node::Leaf { start, end };
                continue;
            }
            let run = &mut tree.order[start..end];
            let (lo, hi) = run.iter().fold(
                (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
                |(lo, hi), &i| (lo.min(points[i as usize]), hi.max(points[i as usize])),
            );
            let size = hi - lo;
            let axis = if size.x >= size.y && size.x >= size.z {
                0
            } else if size.y >= size.z {
                1
            } else {
                2
            };
            let mid = run.len() / 2;
            run.select_nth_unstable_by(mid, |&a, &b| {
                points[a as usize][axis].total_cmp(&points[b as usize][axis])
            });
            let at = points[run[mid] as usize][axis];
            let below = tree.nodes.len();
            tree.nodes.push(Node::Leaf { start: 0, end: 0 });
            let above = tree.nodes.len();
            tree.nodes.push(Node::Leaf { start: 0, end: 0 });
            tree.nodes[node] = Node::Split { axis, at, below, above };
            pending.push((below, start, start + mid));
            pending.push((above, start + mid, end));
        }
        tree
    }

    /// The `count` nearest other points of `points[k]` (squared distance, index), nearest
    /// first; fewer in a cloud of fewer points. `points` must be those the tree was built on.
    pub fn nearest(&self, points: &[DVec3], k: usize, count: usize, found: &mut Vec<(f64, usize)>) {
        let p = points[k];
        found.clear();
        if count == 0 {
            return;
        }
        let mut pending = vec![(0usize, 0.0f64)];
        while let Some((node, plane_d2)) = pending.pop() {
            // A side no nearer than the worst kept neighbour holds nothing better.
            if found.len() == count && plane_d2 >= found[count - 1].0 {
                continue;
            }
            match self.nodes[node] {
                Node::Leaf { start, end } => {
                    for &j in &self.order[start..end] {
                        let j = j as usize;
                        if j == k {
                            continue;
                        }
                        let d2 = points[j].distance_squared(p);
                        if found.len() < count || d2.total_cmp(&found[count - 1].0).is_lt() {
                            let at = found.partition_point(|&(e, _)| e.total_cmp(&d2).is_le());
                            found.insert(at, (d2, j));
                            found.truncate(count);
                        }
                    }
                }
                Node::Split { axis, at, below, above } => {
                    let d = p[axis] - at;
                    let (near, far) = if d < 0.0 { (below, above) } else { (above, below) };
                    // The far side first onto the stack, so the near side is searched first.
                    pending.push((far, d * d));
                    pending.push((near, 0.0));
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Against a brute-force search, on a cloud a uniform grid handles worst: a dense clump
    /// (with exact duplicates) beside a few far-off points.
    #[test]
    fn the_tree_finds_the_same_neighbours_as_brute_force() {
        let mut state = 12345u64;
        let mut next = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut points: Vec<DVec3> = (0..3000).map(|_| DVec3::new(next(), next(), next()) * 1e-3).collect();
        points.extend([DVec3::splat(100.0), DVec3::new(-50.0, 3.0, 0.0)]);
        points.extend(std::iter::repeat_n(DVec3::splat(5e-4), 20));
        let tree = KdTree::new(&points);
        let mut found = Vec::new();
        for k in (0..points.len()).step_by(7) {
            tree.nearest(&points, k, 6, &mut found);
            let mut all: Vec<f64> = (0..points.len())
                .filter(|&j| j != k)
                .map(|j| points[j].distance_squared(points[k]))
                .collect();
            all.sort_by(f64::total_cmp);
            let got: Vec<f64> = found.iter().map(|&(d2, _)| d2).collect();
            assert_eq!(got, all[..6], "point {k}");
        }
    }
}
