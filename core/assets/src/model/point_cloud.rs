//! Point clouds drawn as surfaces: a scanner's PLY with vertices and no faces, or a glTF primitive
//! of mode POINTS, becomes a mesh of small flat discs ("surfels", Pfister et al., SIGGRAPH 2000),
//! one per kept point, each lying in the plane its neighbours lie in and as wide as the gaps to
//! them, so that the discs overlap into a closed skin. The renderer then lights, shadows and
//! draws it in stereo like any mesh.
//!
//! * **Points kept**: at most [`MAX_SURFELS`] (or fewer where the budget is smaller), thinned
//!   evenly in space ([`kept`]: one point per cell of a grid), each kept point's disc wide enough
//!   to cover the points dropped beside it, so that a thinned cloud stays closed.
//! * **Size**: a disc reaches the farthest corner of its point's Voronoi cell in the disc's plane
//!   among its 12 nearest neighbours ([`cell_radius`]), so the discs cover the surface between
//!   the points however irregular their spacing. On a hexagonal lattice of spacing `s` that is
//!   `s/√3`. (The rule it replaced, the 6th neighbour's distance / √3 × 1.25, left 1.5–1.8 % of
//!   a sphere of 2 k–20 k uniformly random points uncovered, as holes; this one none.)
//! * **Normal**: the point's where it has a non-zero one; else the direction in which the point
//!   and its neighbours spread least (the covariance's smallest eigenvector, Hoppe et al.,
//!   SIGGRAPH 1992), turned away from the cloud's centre, as a scanned object is seen from
//!   outside. Draw the discs double-sided, so that one turned the wrong way still shows.
//! * **Neighbours** come from a k-d tree (`nearest`): O(n log n) for any spread of points.
//! * Every corner of a disc carries its point's colour, texture coordinates and material values.
//!
//! Panics: none. Cost: O(n log n) for n points, whatever their spread.

use glam::{DMat3, DVec3};

use super::nearest::KdTree;
use super::{Mesh, Vertex};
use crate::budget::{OverBudget, ResourceBudget, Spending};

/// Most points drawn: 150 k discs are 600 k triangles and 72 MB of vertices, a fifth of a
/// phone's memory budget for one artifact; a denser cloud is thinned.
pub const MAX_SURFELS: usize = 150_000;

/// Vertices and indices of one disc (a hexagon as four triangles).
const VERTICES_PER_SURFEL: u64 = 6;
const INDICES_PER_SURFEL: u64 = 12;

/// Neighbours that set a disc's plane.
const NEIGHBOURS: usize = 6;

/// Neighbours whose bisectors bound a disc's Voronoi cell ([`cell_radius`]): twice the six of a
/// regular lattice, as an irregular point has more cell edges.
const CELL_NEIGHBOURS: usize = 12;

/// Charges `spending` for the discs of a cloud of `points` and says how many to make: as many
/// as the budget left holds, up to [`MAX_SURFELS`], and at least one (with no room even for
/// that, the error names the budget rather than the model coming out empty).
pub fn charge_discs(
    spending: &mut Spending,
    points: usize,
    what: impl FnOnce() -> String,
) -> Result<usize, OverBudget> {
    let per_point = ResourceBudget::mesh_bytes(VERTICES_PER_SURFEL, INDICES_PER_SURFEL);
    let affordable = usize::try_from(spending.bytes_left() / per_point).unwrap_or(usize::MAX);
    let discs = points.min(MAX_SURFELS).min(affordable).max(1);
    spending.charge_bytes(
        what,
        ResourceBudget::mesh_bytes(discs as u64 * VERTICES_PER_SURFEL, discs as u64 * INDICES_PER_SURFEL),
    )?;
    Ok(discs)
}

/// Which points to keep, at most `max`, in their order: all of them, or one per cell of the
/// finest grid that leaves no more than `max` cells occupied (the point nearest its cell's
/// centre). Spatially even: every dropped point has a kept one within its cell, so the gaps
/// stay under a cell's diagonal. Neither every k-th point (a scanner's lines kept whole and each
/// thinned, leaving gaps across them wider than the discs that neighbours along them size; on a
/// Fibonacci sphere, a ring of holes where its spiral's arms alias) nor a random choice (its
/// clumps and gaps) keeps the surface closed.
pub fn kept(positions: &[[f32; 3]], max: usize) -> Thinned {
    let n = positions.len();
    let all = |n: usize| Thinned {
        indices: (0..n).collect(),
        cell_m: None,
    };
    if n <= max {
        return all(n);
    }
    if max == 0 {
        return all(0);
    }
    let points: Vec<DVec3> = positions.iter().map(|p| DVec3::from(p.map(f64::from))).collect();
    let (lo, hi) = points
        .iter()
        .fold((points[0], points[0]), |(lo, hi), &p| (lo.min(p), hi.max(p)));
    let extent = (hi - lo).length();
    if !(extent.is_finite() && extent > 0.0) {
        return all(max);
    }
    let cell_of = |p: DVec3, h: f64| {
        let c = ((p - lo) / h).floor();
        [c.x as i64, c.y as i64, c.z as i64]
    };
    let occupied = |h: f64| {
        let mut cells = std::collections::HashSet::with_capacity(max + 1);
        for &p in &points {
            cells.insert(cell_of(p, h));
            if cells.len() > max {
                return None;
            }
        }
        Some(cells.len())
    };
    // The finest cell (to 1 %) with at most `max` occupied: bisected in log scale between a cell
    // too fine (a billionth of the extent holds each point alone, as n > max) and the whole
    // extent (one cell).
    let (mut fine, mut coarse) = (extent * 1e-9, extent * 1.01);
    while coarse / fine > 1.01 {
        let mid = (fine * coarse).sqrt();
        if occupied(mid).is_some() {
            coarse = mid;
        } else {
            fine = mid;
        }
    }
    let h = coarse;
    let mut best: std::collections::HashMap<[i64; 3], (f64, usize)> = std::collections::HashMap::with_capacity(max);
    for (i, &p) in points.iter().enumerate() {
        let cell = cell_of(p, h);
        let centre = lo + (DVec3::new(cell[0] as f64, cell[1] as f64, cell[2] as f64) + 0.5) * h;
        let d2 = p.distance_squared(centre);
        let entry = best.entry(cell).or_insert((d2, i));
        if d2 < entry.0 {
            *entry = (d2, i);
        }
    }
    let mut indices: Vec<usize> = best.into_values().map(|(_, i)| i).collect();
    indices.sort_unstable();
    Thinned {
        indices,
        cell_m: Some(h),
    }
}

/// The points [`kept`] chose, and the side of the cells each stands for when it thinned.
#[derive(Debug)]
pub struct Thinned {
    pub indices: Vec<usize>,
    pub cell_m: Option<f64>,
}

/// The surfel mesh of a cloud (each point a vertex; a zero normal is none), with at most
/// `max_points` discs. Empty for an empty cloud or one whose points all coincide.
pub fn surfels(cloud: &[Vertex], max_points: usize) -> Mesh {
    let positions: Vec<[f32; 3]> = cloud.iter().map(|v| v.position).collect();
    surfels_of(&positions, max_points, |i| cloud[i])
}

/// The same for a cloud held as its `positions`, point `i`'s vertex made by `vertex(i)`: only
/// for the points kept (a vertex is 80 bytes against a position's 12), after thinning.
pub fn surfels_of(positions: &[[f32; 3]], max_points: usize, vertex: impl Fn(usize) -> Vertex) -> Mesh {
    let thinned = kept(positions, max_points.max(1));
    let points: Vec<Vertex> = thinned.indices.iter().map(|&i| vertex(i)).collect();
    discs(&points, thinned.cell_m)
}

/// A disc for every point of `kept` (the points [`kept`] chose; `cell_m` its cell side when it
/// thinned). A point that stands for a thinning cell covers the points dropped from it: its disc
/// is at least the cell's diagonal (√3 sides) in radius, the farthest a dropped point can lie
/// from it. (At one side, single-pixel holes showed on a 400 k-point sphere thinned to 133 k.)
pub fn discs(kept: &[Vertex], cell_m: Option<f64>) -> Mesh {
    let points: Vec<DVec3> = kept.iter().map(|v| DVec3::from(v.position.map(f64::from))).collect();
    if points.is_empty() {
        return Mesh::default();
    }
    let tree = KdTree::new(&points);
    let centre = points.iter().copied().sum::<DVec3>() / points.len() as f64;
    // Each point's plane and cell on every core, in chunks that each keep their search buffers.
    let indices: Vec<usize> = (0..points.len()).collect();
    let chunks: Vec<&[usize]> = indices.chunks(4096).collect();
    let (normals, radii): (Vec<DVec3>, Vec<Option<f64>>) = crate::parallel::map(&chunks, |chunk| {
        let mut found = Vec::with_capacity(64);
        let mut around = Vec::with_capacity(CELL_NEIGHBOURS);
        chunk
            .iter()
            .map(|&k| {
                let p = points[k];
                tree.nearest(&points, k, CELL_NEIGHBOURS, &mut found);
                let given = Some(DVec3::from(kept[k].normal.map(f64::from)))
                    .filter(|v| v.is_finite() && v.length_squared() > 0.0)
                    .map(DVec3::normalize);
                let normal = given.unwrap_or_else(|| {
                    let spread = least_spread(p, found.iter().take(NEIGHBOURS).map(|&(_, j)| points[j]));
                    if spread.dot(p - centre) < 0.0 { -spread } else { spread }
                });
                around.clear();
                around.extend(found.iter().map(|&(_, j)| points[j]));
                (normal, cell_radius(p, normal, &around))
            })
            .collect::<Vec<_>>()
    })
    .into_iter()
    .flatten()
    .unzip();
    // A point whose neighbours all lie on it (or the one point of a cloud of one) takes the
    // median radius; a cloud where none has another beside it takes a hundredth of its size.
    let mut known: Vec<f64> = radii.iter().flatten().copied().filter(|r| *r > 0.0).collect();
    let fallback = if known.is_empty() {
        tree.extent * 0.01
    } else {
        let mid = known.len() / 2;
        *known.select_nth_unstable_by(mid, f64::total_cmp).1
    };
    // Every point in one place: no surface to show.
    if fallback.is_nan() || fallback <= 0.0 {
        return Mesh::default();
    }
    let mut mesh = Mesh {
        vertices: Vec::with_capacity(points.len() * VERTICES_PER_SURFEL as usize),
        indices: Vec::with_capacity(points.len() * INDICES_PER_SURFEL as usize),
    };
    for (k, &p) in points.iter().enumerate() {
        let r = radii[k]
            .filter(|r| *r > 0.0)
            .unwrap_or(fallback)
            .max(cell_m.unwrap_or(0.0) * 3f64.sqrt());
        let n = normals[k].as_vec3();
        let (u, v) = n.any_orthonormal_pair();
        // The hexagon holds the disc of radius r: its corners at r / cos 30°.
        let corner_m = r * 2.0 / 3f64.sqrt();
        let first = mesh.vertices.len() as u32;
        for corner in 0..6 {
            let angle = corner as f32 * std::f32::consts::FRAC_PI_3;
            let offset = (u * angle.cos() + v * angle.sin()) * corner_m as f32;
            mesh.vertices.push(Vertex {
                position: (p.as_vec3() + offset).to_array(),
                normal: n.to_array(),
                tangent: [u.x, u.y, u.z, 1.0],
                ..kept[k]
            });
        }
        // u × v = n: corners in increasing angle wind counter-clockwise seen from the front.
        for t in 1..5 {
            mesh.indices.extend([first, first + t, first + t + 1]);
        }
    }
    mesh
}

/// The radius of a disc about `p` in the plane normal to `n` that covers `p`'s Voronoi cell
/// there among `neighbours` (projected onto the plane): the distance to the cell's farthest
/// corner, so that the discs of all points cover the plane between them however irregular their
/// spacing. A cell open on one side (a point at the edge of a scan, or one whose neighbours all
/// lie to one side) is closed by the octagon about `p` that reaches the farthest neighbour.
/// `None` without a neighbour off `p`.
fn cell_radius(p: DVec3, n: DVec3, neighbours: &[DVec3]) -> Option<f64> {
    let (u, v) = n.any_orthonormal_pair();
    let offsets: Vec<glam::DVec2> = neighbours
        .iter()
        .map(|q| {
            let d = *q - p;
            glam::DVec2::new(d.dot(u), d.dot(v))
        })
        .filter(|d| d.length_squared() > 0.0)
        .collect();
    let reach = offsets.iter().map(|d| d.length()).fold(0.0, f64::max);
    if !(reach.is_finite() && reach > 0.0) {
        return None;
    }
    let mut cell: Vec<glam::DVec2> = (0..8)
        .map(|i| glam::DVec2::from_angle(f64::from(i) * std::f64::consts::FRAC_PI_4) * reach)
        .collect();
    let mut clipped = Vec::with_capacity(16);
    for d in &offsets {
        // The side of the bisector between p and its neighbour that p is on: x·d ≤ |d|²/2.
        let limit = d.length_squared() * 0.5;
        clipped.clear();
        for (i, &a) in cell.iter().enumerate() {
            let b = cell[(i + 1) % cell.len()];
            let (fa, fb) = (a.dot(*d) - limit, b.dot(*d) - limit);
            if fa <= 0.0 {
                clipped.push(a);
            }
            if (fa < 0.0 && fb > 0.0) || (fa > 0.0 && fb < 0.0) {
                clipped.push(a + (b - a) * (fa / (fa - fb)));
            }
        }
        std::mem::swap(&mut cell, &mut clipped);
    }
    cell.iter().map(|c| c.length()).reduce(f64::max)
}

/// The unit direction in which `p` and `others` spread least: the smallest eigenvector of their
/// covariance. +z where they do not span a plane's worth (fewer than three points).
fn least_spread(p: DVec3, others: impl Iterator<Item = DVec3>) -> DVec3 {
    let mut sum = p;
    let mut outer = DMat3::from_cols(p * p.x, p * p.y, p * p.z);
    let mut count = 1.0;
    for q in others {
        sum += q;
        outer += DMat3::from_cols(q * q.x, q * q.y, q * q.z);
        count += 1.0;
    }
    if count < 3.0 {
        return DVec3::Z;
    }
    let mean = sum / count;
    let covariance = outer * (1.0 / count) - DMat3::from_cols(mean * mean.x, mean * mean.y, mean * mean.z);
    smallest_eigenvector(covariance)
}

/// The eigenvector of the smallest eigenvalue of a symmetric 3 × 3 matrix, by Jacobi rotations
/// (each zeroes one off-diagonal element; a few sweeps converge to machine precision).
fn smallest_eigenvector(m: DMat3) -> DVec3 {
    let mut a = m.to_cols_array_2d();
    let mut v = DMat3::IDENTITY.to_cols_array_2d();
    for _sweep in 0..12 {
        let off = a[0][1] * a[0][1] + a[0][2] * a[0][2] + a[1][2] * a[1][2];
        let scale = a[0][0] * a[0][0] + a[1][1] * a[1][1] + a[2][2] * a[2][2];
        if off <= 1e-30 * scale.max(f64::MIN_POSITIVE) {
            break;
        }
        for (p, q) in [(0, 1), (0, 2), (1, 2)] {
            if a[p][q] == 0.0 {
                continue;
            }
            let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
            let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
            let t = if theta == 0.0 { 1.0 } else { t };
            let c = 1.0 / (t * t + 1.0).sqrt();
            let s = t * c;
            // A ← Jᵀ A J with J the rotation in the (p, q) plane; V ← V J.
            for row in &mut a {
                let (akp, akq) = (row[p], row[q]);
                row[p] = c * akp - s * akq;
                row[q] = s * akp + c * akq;
            }
            let (rp, rq) = (a[p], a[q]);
            a[p] = std::array::from_fn(|k| c * rp[k] - s * rq[k]);
            a[q] = std::array::from_fn(|k| s * rp[k] + c * rq[k]);
            for row in &mut v {
                let (vp, vq) = (row[p], row[q]);
                row[p] = c * vp - s * vq;
                row[q] = s * vp + c * vq;
            }
        }
    }
    let smallest = (0..3).min_by(|&i, &j| a[i][i].total_cmp(&a[j][j])).unwrap_or(2);
    let e = DVec3::new(v[0][smallest], v[1][smallest], v[2][smallest]);
    e.try_normalize().unwrap_or(DVec3::Z)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    /// Points on a sphere of radius 1, spread evenly (a Fibonacci lattice).
    fn sphere(n: usize) -> Vec<[f32; 3]> {
        phantogram_geometry::sphere::fibonacci(n)
            .iter()
            .map(|p| p.to_array())
            .collect()
    }

    fn cloud(positions: &[[f32; 3]]) -> Vec<Vertex> {
        positions
            .iter()
            .map(|&position| Vertex {
                position,
                normal: [0.0; 3],
                tangent: [1.0, 0.0, 0.0, 1.0],
                uv: [0.0; 4],
                color: [1.0; 4],
                material: [1.0, 1.0],
            })
            .collect()
    }

    #[test]
    fn a_sphere_of_points_becomes_discs_facing_out_that_cover_it() {
        let n = 4000;
        let mesh = surfels(&cloud(&sphere(n)), MAX_SURFELS);
        assert_eq!(mesh.vertices.len(), n * 6);
        assert_eq!(mesh.indices.len(), n * 12);
        // Each disc's normal is the sphere's outward normal at its point (estimated: no normals
        // in the file), within a few degrees.
        for disc in mesh.vertices.chunks(6) {
            let centre = disc.iter().map(|v| Vec3::from(v.position)).sum::<Vec3>() / 6.0;
            let n = Vec3::from(disc[0].normal);
            assert!(n.dot(centre.normalize()) > 0.99, "{n:?} at {centre:?}");
            // Wound counter-clockwise seen from the front.
            let (a, b, c) = (
                Vec3::from(disc[0].position),
                Vec3::from(disc[1].position),
                Vec3::from(disc[2].position),
            );
            assert!((b - a).cross(c - a).dot(n) > 0.0);
        }
        let discs = discs_of(&mesh);
        assert_covers_the_unit_sphere(&discs);
        // A hexagonal lattice of n points on the unit sphere (area 4π) has spacing
        // √(8π / (√3·n)).
        let spacing = (8.0 * std::f32::consts::PI / (3f32.sqrt() * n as f32)).sqrt();
        // Not grossly larger than needed (1.25/√3 = 0.72 spacings on a perfect lattice).
        for &(_, _, r) in &discs {
            assert!(
                r > 0.5 * spacing && r < 1.2 * spacing,
                "radius {r} for spacing {spacing}"
            );
        }
    }

    /// Each disc of a surfel mesh: centre, normal, and the radius of the circle its hexagon holds
    /// (the hexagon's inradius, cos 30° of its corners' distance).
    fn discs_of(mesh: &Mesh) -> Vec<(Vec3, Vec3, f32)> {
        mesh.vertices
            .chunks(6)
            .map(|d| {
                let c = d.iter().map(|v| Vec3::from(v.position)).sum::<Vec3>() / 6.0;
                let inradius = Vec3::from(d[0].position).distance(c) * 3f32.sqrt() / 2.0;
                (c, Vec3::from(d[0].normal), inradius)
            })
            .collect()
    }

    /// Every one of 997 directions from the centre meets some disc (each tested as a flat circle).
    fn assert_covers_the_unit_sphere(discs: &[(Vec3, Vec3, f32)]) {
        for probe in sphere(997) {
            let dir = Vec3::from(probe).normalize();
            let covered = discs.iter().any(|&(c, nrm, r)| {
                // Where the ray from the centre along `dir` meets the disc's plane.
                let t = c.dot(nrm) / dir.dot(nrm);
                t > 0.0 && (dir * t).distance(c) <= r
            });
            assert!(covered, "a hole at {dir:?}");
        }
    }

    /// Points spread at random (uniformly over the sphere, as a photogrammetry cloud is irregular)
    /// leave gaps up to twice the mean spacing: each disc reaches its Voronoi cell's farthest
    /// corner, so none stays open. (The 6th neighbour's distance / √3 × 1.25 left 1.5–1.8 % of
    /// such spheres of 2 k–20 k points uncovered.) Nor are the discs grossly larger than needed.
    #[test]
    fn a_sphere_of_random_points_is_covered() {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut random = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let n = 4000;
        let points: Vec<[f32; 3]> = (0..n)
            .map(|_| {
                let z = random() * 2.0 - 1.0;
                let azimuth = random() * std::f64::consts::TAU;
                let r = (1.0 - z * z).sqrt();
                [(r * azimuth.cos()) as f32, (r * azimuth.sin()) as f32, z as f32]
            })
            .collect();
        let discs = discs_of(&surfels(&cloud(&points), MAX_SURFELS));
        assert_eq!(discs.len(), n);
        assert_covers_the_unit_sphere(&discs);
        let spacing = (8.0 * std::f32::consts::PI / (3f32.sqrt() * n as f32)).sqrt();
        let mean = discs.iter().map(|d| d.2).sum::<f32>() / n as f32;
        println!("mean radius {:.3} spacings (a lattice needs 0.577)", mean / spacing);
        // Measured 0.97: a random point's cell reaches farther than a lattice point's.
        assert!(mean < 1.1 * spacing, "mean radius {mean} for spacing {spacing}");
    }

    /// A thinned cloud stays closed. Every third point of a Fibonacci sphere would not: its
    /// spiral's arms alias into seven near the poles, with gaps between them wider than the
    /// discs that neighbours along an arm size.
    #[test]
    fn a_thinned_sphere_stays_closed() {
        let mesh = surfels(&cloud(&sphere(12_000)), 4_000);
        assert!(
            (3_600 * 6..=4_000 * 6).contains(&mesh.vertices.len()),
            "{}",
            mesh.vertices.len()
        );
        assert_covers_the_unit_sphere(&discs_of(&mesh));
    }

    #[test]
    fn given_normals_and_colours_are_kept_and_a_dense_cloud_is_thinned() {
        let positions = sphere(1000);
        let mut points = cloud(&positions);
        for v in &mut points {
            v.normal = v.position.map(|c| -c);
            v.color = [1.0, 0.5, 0.0, 1.0];
            v.uv = [0.25, 0.75, 0.0, 0.0];
        }
        let mesh = surfels(&points, 250);
        assert!(
            (200 * 6..=250 * 6).contains(&mesh.vertices.len()),
            "about a quarter of the points kept"
        );
        let first = &mesh.vertices[0];
        // The point's normal (pointing in), not the estimate (pointing out).
        assert!(Vec3::from(first.normal).dot(Vec3::from(positions[0])) < -0.99);
        assert_eq!(first.color, [1.0, 0.5, 0.0, 1.0]);
        assert_eq!(first.uv, [0.25, 0.75, 0.0, 0.0]);
    }

    #[test]
    fn degenerate_clouds_give_discs_without_panicking() {
        for positions in [
            vec![[0.0, 0.0, 0.0]],
            vec![[1.0, 2.0, 3.0]; 50],
            (0..50).map(|i| [i as f32, 0.0, 0.0]).collect(),
            vec![[0.0, 0.0, 0.0], [1e9, -1e9, 1e9]],
        ] {
            let mesh = surfels(&cloud(&positions), MAX_SURFELS);
            let expected = if positions.iter().all(|p| *p == positions[0]) {
                0
            } else {
                positions.len() * 6
            };
            assert_eq!(mesh.vertices.len(), expected);
            assert!(mesh.vertices.iter().all(|v| v.position.iter().all(|c| c.is_finite())));
        }
        assert!(surfels(&[], 10).vertices.is_empty());
    }

    /// Thinning keeps no more than asked (and not far fewer), in order, spread evenly: no two
    /// kept points of a dense line much nearer than the kept spacing.
    #[test]
    fn thinning_keeps_an_even_spread_of_at_most_the_asked_number() {
        let line: Vec<[f32; 3]> = (0..5).map(|i| [i as f32, 0.0, 0.0]).collect();
        assert_eq!(kept(&line, 10).indices, [0, 1, 2, 3, 4]);
        assert!(kept(&line, 0).indices.is_empty());
        let points = sphere(30_000);
        let k = kept(&points, 10_000).indices;
        assert!((8_000..=10_000).contains(&k.len()), "{}", k.len());
        assert!(k.windows(2).all(|w| w[0] < w[1]));
        // Each tenth of the sphere's height (equal areas) holds about a tenth of the kept points.
        for tenth in 0..10 {
            let inside = k.iter().filter(|&&i| i / 3000 == tenth).count();
            assert!(
                (k.len() / 10 * 8 / 10..=k.len() / 10 * 12 / 10).contains(&inside),
                "{inside} in tenth {tenth}"
            );
        }
        // Coincident points: a few kept, no panic.
        assert!(kept(&vec![[1.0, 2.0, 3.0]; 50], 10).indices.len() <= 10);
    }

    #[test]
    fn the_least_spread_of_a_tilted_plane_is_its_normal() {
        let normal = DVec3::new(1.0, 2.0, 2.0).normalize();
        let (u, v) = normal.any_orthonormal_pair();
        let pts: Vec<DVec3> = (0..30)
            .map(|i| {
                u * (i as f64 * 0.37).sin() * 3.0 + v * (i as f64 * 0.91).cos() * 2.0 + normal * 1e-4 * (i % 3) as f64
            })
            .collect();
        let e = least_spread(pts[0], pts[1..].iter().copied());
        assert!(e.dot(normal).abs() > 0.9999, "{e:?}");
    }
}
