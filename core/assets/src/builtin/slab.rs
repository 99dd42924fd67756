//! A relief slab: a height field over a disc or a rectangle, closed by a wall down to a flat back —
//! the shape of a coin, a medal or a clay tablet lying in the glass.
//!
//! Frame: the device frame, metres; the slab lies in the glass's plane (x right, y up the screen),
//! its relief facing the viewer (+z), its back at `base_z_m`. Normals of the relief come from the
//! height field's central differences, so the light picks out relief finer than the grid's look.

use glam::{Vec2, Vec3};

use crate::model::{Mesh, Vertex};

/// The outline the relief is laid over.
#[derive(Clone, Copy, Debug)]
pub enum Outline {
    /// A disc of this radius, metres, sampled as `rings × sectors`.
    Disc { radius_m: f32, rings: u32, sectors: u32 },
    /// A rectangle of these half-sizes, metres, sampled as `columns × rows` cells.
    Rect { half_m: Vec2, columns: u32, rows: u32 },
}

/// A grid point's place in the glass's plane, from its column and row.
type GridPoint = Box<dyn Fn(u32, u32) -> Vec2>;

/// What the relief looks like at a point: its colour (linear RGBA) and `[metallic, roughness]`.
pub type Paint = ([f32; 4], [f32; 2]);

/// Builds the slab: the relief `height_m(p)` (above `base_z_m`, at a point `p` of the glass's
/// plane), painted by `paint(p, height_m)`, its wall and its back (painted as the outline's edge).
pub fn slab(
    outline: Outline,
    base_z_m: f32,
    height_m: &dyn Fn(Vec2) -> f32,
    paint: &dyn Fn(Vec2, f32) -> Paint,
) -> Mesh {
    let (columns, rows, at): (u32, u32, GridPoint) = match outline {
        // Columns go round clockwise (so that columns × rows is counter-clockwise, as for the
        // rectangle), rows go out: row 0 is the centre (a degenerate ring).
        Outline::Disc {
            radius_m,
            rings,
            sectors,
        } => (
            sectors,
            rings,
            Box::new(move |i, j| {
                let phi = -(i as f32) / sectors as f32 * std::f32::consts::TAU;
                Vec2::from_angle(phi) * (radius_m * j as f32 / rings as f32)
            }),
        ),
        Outline::Rect { half_m, columns, rows } => (
            columns,
            rows,
            Box::new(move |i, j| {
                Vec2::new(
                    -half_m.x + 2.0 * half_m.x * i as f32 / columns as f32,
                    -half_m.y + 2.0 * half_m.y * j as f32 / rows as f32,
                )
            }),
        ),
    };
    // Central differences over a fraction of a cell.
    let eps = match outline {
        Outline::Disc { radius_m, rings, .. } => radius_m / rings as f32 * 0.5,
        Outline::Rect { half_m, columns, .. } => half_m.x / columns as f32,
    };
    let mut mesh = Mesh::default();
    let row_len = columns + 1;
    for j in 0..=rows {
        for i in 0..=columns {
            let p = at(i, j);
            let h = height_m(p);
            let dx = (height_m(p + Vec2::X * eps) - height_m(p - Vec2::X * eps)) / (2.0 * eps);
            let dy = (height_m(p + Vec2::Y * eps) - height_m(p - Vec2::Y * eps)) / (2.0 * eps);
            let normal = Vec3::new(-dx, -dy, 1.0).normalize();
            let (color, material) = paint(p, h);
            mesh.vertices.push(Vertex {
                position: [p.x, p.y, base_z_m + h],
                normal: normal.to_array(),
                tangent: [1.0, 0.0, 0.0, 1.0],
                uv: [i as f32 / columns as f32, 1.0 - j as f32 / rows as f32, 0.0, 0.0],
                color,
                material,
            });
        }
    }
    for j in 0..rows {
        for i in 0..columns {
            let a = j * row_len + i;
            let b = a + row_len;
            // Counter-clockwise seen from +z for both parameterisations (i goes round
            // clockwise and j out, or i right and j up).
            mesh.indices.extend_from_slice(&[a, a + 1, b + 1, a, b + 1, b]);
        }
    }
    // The boundary, anticlockwise seen from +z: the disc's outer ring, or the rectangle's edges.
    let boundary: Vec<u32> = match outline {
        Outline::Disc { .. } => (0..columns).rev().map(|i| rows * row_len + i).collect(),
        Outline::Rect { .. } => {
            let bottom = 0..columns;
            let right = (0..rows).map(|j| j * row_len + columns);
            let top = (1..=columns).rev().map(|i| rows * row_len + i);
            let left = (1..=rows).rev().map(|j| j * row_len);
            bottom.chain(right).chain(top).chain(left).collect()
        }
    };
    // The wall: each boundary edge extruded down to the back, facing outwards.
    for (k, &a) in boundary.iter().enumerate() {
        let b = boundary[(k + 1) % boundary.len()];
        let (va, vb) = (mesh.vertices[a as usize], mesh.vertices[b as usize]);
        let (pa, pb) = (Vec3::from(va.position), Vec3::from(vb.position));
        let along = (pb - pa).normalize_or_zero();
        let out = along.cross(Vec3::Z).normalize_or_zero();
        let base = mesh.vertices.len() as u32;
        for (p, src) in [
            (pa, va),
            (pb, vb),
            (Vec3::new(pb.x, pb.y, base_z_m), vb),
            (Vec3::new(pa.x, pa.y, base_z_m), va),
        ] {
            mesh.vertices.push(Vertex {
                position: p.to_array(),
                normal: out.to_array(),
                tangent: along.extend(1.0).to_array(),
                uv: src.uv,
                color: src.color,
                material: src.material,
            });
        }
        // (a, b) runs anticlockwise seen from +z, so outward-facing is b→a on top.
        mesh.indices
            .extend_from_slice(&[base, base + 3, base + 2, base, base + 2, base + 1]);
    }
    // The back: a fan facing −z.
    let centre = mesh.vertices.len() as u32;
    let back = |p: Vec3, src: Vertex| Vertex {
        position: [p.x, p.y, base_z_m],
        normal: [0.0, 0.0, -1.0],
        tangent: [1.0, 0.0, 0.0, 1.0],
        uv: src.uv,
        color: src.color,
        material: src.material,
    };
    let edge = mesh.vertices[boundary[0] as usize];
    mesh.vertices.push(back(Vec3::ZERO, edge));
    for &a in &boundary {
        let v = mesh.vertices[a as usize];
        mesh.vertices.push(back(Vec3::from(v.position), v));
    }
    let n = boundary.len() as u32;
    for k in 0..n {
        mesh.indices
            .extend_from_slice(&[centre, centre + 1 + (k + 1) % n, centre + 1 + k]);
    }
    mesh
}

/// A smooth step from 0 at `a` to 1 at `b`.
pub fn smoothstep(a: f32, b: f32, x: f32) -> f32 {
    let u = ((x - a) / (b - a)).clamp(0.0, 1.0);
    u * u * (3.0 - 2.0 * u)
}

/// A deterministic hash of an integer to [0, 1), for the motifs' variety (not for security).
pub fn hash01(n: u32) -> f32 {
    let mut x = n.wrapping_mul(0x9E37_79B9) ^ 0x85EB_CA6B;
    x ^= x >> 16;
    x = x.wrapping_mul(0x7FEB_352D);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846C_A68B);
    x ^= x >> 16;
    (x >> 8) as f32 / (1u32 << 24) as f32
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every triangle faces away from the slab's centre (a closed convex-ish solid).
    fn assert_outward(mesh: &Mesh, centre: Vec3) {
        for tri in mesh.indices.chunks(3) {
            let [a, b, c] = [0, 1, 2].map(|k| Vec3::from(mesh.vertices[tri[k] as usize].position));
            let n = (b - a).cross(c - a);
            if n.length() < 1e-12 {
                continue; // the disc's degenerate centre ring
            }
            let mid = (a + b + c) / 3.0;
            assert!(n.dot(mid - centre) > 0.0, "inward triangle at {mid}");
        }
    }

    #[test]
    fn a_flat_disc_and_a_flat_rectangle_are_closed_outward_facing_solids() {
        let paint = |_: Vec2, _: f32| ([1.0; 4], [0.0, 0.5]);
        let disc = slab(
            Outline::Disc {
                radius_m: 0.02,
                rings: 8,
                sectors: 24,
            },
            -0.001,
            &|_| 0.002,
            &paint,
        );
        assert_outward(&disc, Vec3::new(0.0, 0.0, 0.0));
        let rect = slab(
            Outline::Rect {
                half_m: Vec2::new(0.03, 0.02),
                columns: 12,
                rows: 8,
            },
            -0.004,
            &|_| 0.008,
            &paint,
        );
        assert_outward(&rect, Vec3::ZERO);
        let b = rect.bounds().unwrap();
        assert!((b.min - Vec3::new(-0.03, -0.02, -0.004)).length() < 1e-6, "{b:?}");
        assert!((b.max - Vec3::new(0.03, 0.02, 0.004)).length() < 1e-6, "{b:?}");
        assert!(rect.indices.iter().all(|&i| (i as usize) < rect.vertices.len()));
    }

    #[test]
    fn relief_normals_lean_away_from_a_rise() {
        // A ramp rising along +x: its normals lean towards −x.
        let m = slab(
            Outline::Rect {
                half_m: Vec2::splat(0.01),
                columns: 4,
                rows: 4,
            },
            0.0,
            &|p| 0.001 + 0.1 * (p.x + 0.01),
            &|_, _| ([1.0; 4], [0.0, 0.5]),
        );
        let n = Vec3::from(m.vertices[12].normal);
        assert!(n.x < -0.05 && n.z > 0.9, "{n}");
    }

    #[test]
    fn the_hash_is_spread_over_the_unit_interval() {
        let values: Vec<f32> = (0..1000).map(hash01).collect();
        assert!(values.iter().all(|v| (0.0..1.0).contains(v)));
        let mean = values.iter().sum::<f32>() / 1000.0;
        assert!((mean - 0.5).abs() < 0.05, "{mean}");
    }
}
