//! What lies in the diorama's tray: procedural bodies (marbles, dice, coins, small vessels) and
//! any convex hull (a museum artifact's), with the default scene.

use glam::{Quat, Vec3};
use phantogram_geometry::screen::Screen;

/// A body's collision shape, in its own frame (centred on its centre of mass for the
/// symmetric ones), metres.
#[derive(Clone, Debug, PartialEq)]
pub enum BodyShape {
    Ball {
        radius_m: f32,
    },
    Cuboid {
        half_extents_m: Vec3,
    },
    /// A disc or a can, its axis along the body's `z`.
    Cylinder {
        radius_m: f32,
        half_height_m: f32,
    },
    /// The convex hull of these points (a vessel's lathe profile, an artifact's hull).
    Convex {
        points_m: Vec<Vec3>,
    },
}

impl BodyShape {
    /// The farthest extent of the shape along unit `direction` (body frame): `max p · d`.
    pub fn support_m(&self, direction: Vec3) -> f32 {
        match self {
            Self::Ball { radius_m } => *radius_m,
            Self::Cuboid { half_extents_m: h } => {
                direction.x.abs() * h.x + direction.y.abs() * h.y + direction.z.abs() * h.z
            }
            Self::Cylinder {
                radius_m,
                half_height_m,
            } => direction.truncate().length() * radius_m + direction.z.abs() * half_height_m,
            Self::Convex { points_m } => points_m.iter().map(|p| p.dot(direction)).fold(f32::MIN, f32::max),
        }
    }

    /// The radius of a sphere about the body's origin that holds the shape.
    pub fn bounding_radius_m(&self) -> f32 {
        match self {
            Self::Ball { radius_m } => *radius_m,
            Self::Cuboid { half_extents_m } => half_extents_m.length(),
            Self::Cylinder {
                radius_m,
                half_height_m,
            } => (radius_m * radius_m + half_height_m * half_height_m).sqrt(),
            Self::Convex { points_m } => points_m.iter().map(|p| p.length()).fold(0.0, f32::max),
        }
    }
}

/// What a body is (for drawing it).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BodyKind {
    Marble,
    Die,
    Coin,
    Vessel,
    /// A museum artifact's convex hull.
    Artifact,
}

/// One body of the scene: its shape, material and where it starts.
#[derive(Clone, Debug, PartialEq)]
pub struct BodySpec {
    pub kind: BodyKind,
    pub shape: BodyShape,
    pub density_kg_m3: f32,
    pub friction: f32,
    pub restitution: f32,
    /// Linear RGBA for drawing.
    pub colour: [f32; 4],
    pub start_m: Vec3,
    pub start_rotation: Quat,
}

/// A small vessel: the convex hull of a lathe profile (foot, belly, shoulder, lip), axis `z`,
/// 12 mm tall.
pub fn vessel_points() -> Vec<Vec3> {
    // (radius, height) from the foot up, millimetres.
    let profile = [(2.5, 0.0), (4.5, 3.0), (5.0, 6.0), (3.0, 10.0), (2.8, 12.0)];
    let mut points = Vec::new();
    for (r, z) in profile {
        for k in 0..12 {
            let a = k as f32 * std::f32::consts::TAU / 12.0;
            points.push(Vec3::new(r * a.cos(), r * a.sin(), z - 6.0) * 1e-3);
        }
    }
    points
}

/// The default scene: `count` bodies in turn marbles, dice, coins and vessels, in a palette of
/// glass, bone, bronze and terracotta, on a grid over the tray's floor and in layers above it
/// where the floor is full (deterministic: no randomness; no two overlap at the start).
pub fn default_scene(screen: &Screen, floor_z_m: f32, count: usize) -> Vec<BodySpec> {
    let kinds: Vec<(BodyKind, BodyShape, f32, [f32; 4])> = vec![
        (
            BodyKind::Marble,
            BodyShape::Ball { radius_m: 0.005 },
            2500.0,
            [0.15, 0.35, 0.8, 1.0],
        ),
        (
            BodyKind::Die,
            BodyShape::Cuboid {
                half_extents_m: Vec3::splat(0.004),
            },
            1200.0,
            [0.85, 0.82, 0.75, 1.0],
        ),
        (
            BodyKind::Coin,
            BodyShape::Cylinder {
                radius_m: 0.006,
                half_height_m: 0.00075,
            },
            8800.0,
            [0.75, 0.5, 0.2, 1.0],
        ),
        (
            BodyKind::Vessel,
            BodyShape::Convex {
                points_m: vessel_points(),
            },
            1800.0,
            [0.7, 0.3, 0.15, 1.0],
        ),
    ];
    let largest = kinds.iter().map(|k| k.1.bounding_radius_m()).fold(0.0, f32::max);
    let cell = 2.0 * largest + 0.001;
    let (w, h) = (screen.width_m() * 0.9, screen.height_m() * 0.9);
    let columns = ((w / cell) as usize).max(1);
    let rows = ((h / cell) as usize).max(1);
    let right = screen.right_device();
    let up = screen.up_device();
    (0..count)
        .map(|i| {
            let (kind, shape, density, colour) = kinds[i % kinds.len()].clone();
            let (col, row, layer) = (i % columns, (i / columns) % rows, i / (columns * rows));
            let x = (col as f32 + 0.5 - columns as f32 / 2.0) * cell;
            let y = (row as f32 + 0.5 - rows as f32 / 2.0) * cell;
            let z = floor_z_m + largest + 0.0005 + layer as f32 * cell;
            BodySpec {
                kind,
                shape,
                density_kg_m3: density,
                friction: 0.5,
                restitution: 0.2,
                colour,
                start_m: right * x + up * y + Vec3::Z * z,
                start_rotation: Quat::IDENTITY,
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn supports_and_bounds_hold_each_shape() {
        let shapes = [
            BodyShape::Ball { radius_m: 0.005 },
            BodyShape::Cuboid {
                half_extents_m: Vec3::new(0.004, 0.002, 0.001),
            },
            BodyShape::Cylinder {
                radius_m: 0.006,
                half_height_m: 0.001,
            },
            BodyShape::Convex {
                points_m: vessel_points(),
            },
        ];
        for s in shapes {
            let r = s.bounding_radius_m();
            for d in [
                Vec3::X,
                Vec3::Y,
                Vec3::Z,
                Vec3::new(1.0, 1.0, 1.0).normalize(),
                -Vec3::Z,
            ] {
                let support = s.support_m(d);
                assert!(support > 0.0 && support <= r + 1e-6, "{s:?} along {d}: {support} > {r}");
            }
        }
        let cube = BodyShape::Cuboid {
            half_extents_m: Vec3::splat(0.004),
        };
        assert!((cube.support_m(Vec3::new(1.0, 1.0, 0.0).normalize()) - 0.004 * 2f32.sqrt()).abs() < 1e-6);
    }

    #[test]
    fn the_default_scene_lies_on_the_floor_inside_the_screen() {
        let screen = Screen::default();
        let scene = default_scene(&screen, -0.03, 50);
        assert_eq!(scene.len(), 50);
        for (i, b) in scene.iter().enumerate() {
            let r = b.shape.bounding_radius_m();
            assert!(b.start_m.x.abs() + r < screen.width_m() / 2.0 && b.start_m.y.abs() + r < screen.height_m() / 2.0);
            assert!(b.start_m.z - r > -0.03);
            for c in &scene[..i] {
                let gap = b.start_m.distance(c.start_m) - r - c.shape.bounding_radius_m();
                assert!(gap > 0.0, "bodies overlap at the start");
            }
        }
        assert_eq!(scene[3].kind, BodyKind::Vessel);
    }
}
