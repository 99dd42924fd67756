//! USD's primitive shapes (`UsdGeom` Cube, Sphere, Cylinder and Cylinder_1, Cone, Capsule and
//! Capsule_1, Plane) as meshes: each made from its attributes as the schema defines them (the
//! schema's fallback where one is not authored, e.g. a Cube of size 2, a Capsule of height 1 and
//! radius 0.5, a Plane double-sided), then placed, bound and coloured as a `Mesh` prim is
//! ([`super::usd_mesh`]). Stages made by hand or by scene tools use them for plinths, stands,
//! cards and props beside a scanned mesh.
//!
//! Frames: each shape centred on its own origin, its spine (`axis`) along X, Y or Z; the
//! revolved shapes are made about Z and turned onto their axis by a cyclic permutation of the
//! coordinates (a rotation, so the triangles keep facing out). Normals are the surface's own:
//! smooth over the curved parts, creased where a cap meets a side.
//!
//! Capsule_1 and Cylinder_1 take a radius at each end of the spine; a capsule's end caps are the
//! spheres tangent to the side there (so a capsule of unequal radii reaches past its radii), as
//! UsdGeom computes its extent; tested against the extents Pixar's library computes.
//!
//! Pure apart from reading the stage; no panics (a shape with a size that is not a positive
//! finite number is left out with a warning).

use glam::{DMat3, DMat4, DVec3};
use openusd::{sdf, usd};

use super::usd_mesh::{ReadMesh, attribute_value, look_of};
use super::usd_preview_surface::{scalar, token};

/// The prim kinds this module draws.
pub(super) const SHAPE_KINDS: [&str; 8] = [
    "Cube",
    "Sphere",
    "Cylinder",
    "Cylinder_1",
    "Cone",
    "Capsule",
    "Capsule_1",
    "Plane",
];

/// Segments around a revolved shape, and along a quarter turn of its round parts: a sphere
/// of 64 × 32 quads, its outline within 0.12 % of the true radius.
const AROUND: usize = 64;
const QUARTER: usize = 16;

/// A shape's dimensions, in its own units.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Shape {
    /// Edge length.
    Cube {
        size: f64,
    },
    Sphere {
        radius: f64,
    },
    /// A cylinder or a cone: radii at the bottom (−height/2) and the top (+height/2).
    Frustum {
        bottom: f64,
        top: f64,
        height: f64,
    },
    /// A cylinder of these end radii capped by the spheres tangent to it at its ends.
    Capsule {
        bottom: f64,
        top: f64,
        height: f64,
    },
    /// A rectangle `width` × `length` across its axis.
    Plane {
        width: f64,
        length: f64,
    },
}

/// Which coordinate the spine runs along: 0 X, 1 Y, 2 Z.
type Axis = usize;

/// A primitive shape read from the stage, not yet made: made ([`ReadShape::into_mesh`]) only when
/// the model is built, one at a time after the one before was charged to the budget, so that a
/// small file declaring a great many shapes is refused by the budget before their meshes exist
/// (a shape of a few bytes becomes two thousand vertices).
pub(super) struct ReadShape {
    name: String,
    shape: Shape,
    axis: Axis,
    /// Its placement in the model's frame.
    world: DMat4,
    left_handed: bool,
    /// An index into the looks [`read_shape`] was given.
    look: usize,
}

/// The shape of kind `kind` at `p`, placed by `world` into the model's frame; `None` (with a
/// warning) where a dimension is not a positive finite number.
pub(super) fn read_shape(
    stage: &usd::Stage,
    p: &sdf::Path,
    kind: &str,
    world: DMat4,
    looks: &mut Vec<super::usd_mesh::Look>,
    warnings: &mut Vec<String>,
) -> Result<Option<ReadShape>, String> {
    let name = p.as_str().to_owned();
    let number = |attribute: &str, fallback: f64| -> Result<f64, String> {
        Ok(attribute_value(stage, p, attribute)?
            .as_ref()
            .and_then(scalar)
            .unwrap_or(fallback))
    };
    let shape = match kind {
        "Cube" => Shape::Cube {
            size: number("size", 2.0)?,
        },
        "Sphere" => Shape::Sphere {
            radius: number("radius", 1.0)?,
        },
        "Cylinder" => {
            let radius = number("radius", 1.0)?;
            Shape::Frustum {
                bottom: radius,
                top: radius,
                height: number("height", 2.0)?,
            }
        }
        "Cylinder_1" => Shape::Frustum {
            bottom: number("radiusBottom", 1.0)?,
            top: number("radiusTop", 1.0)?,
            height: number("height", 2.0)?,
        },
        "Cone" => Shape::Frustum {
            bottom: number("radius", 1.0)?,
            top: 0.0,
            height: number("height", 2.0)?,
        },
        "Capsule" => {
            let radius = number("radius", 0.5)?;
            Shape::Capsule {
                bottom: radius,
                top: radius,
                height: number("height", 1.0)?,
            }
        }
        "Capsule_1" => Shape::Capsule {
            bottom: number("radiusBottom", 0.5)?,
            top: number("radiusTop", 0.5)?,
            height: number("height", 1.0)?,
        },
        "Plane" => Shape::Plane {
            width: number("width", 2.0)?,
            length: number("length", 2.0)?,
        },
        _ => return Ok(None),
    };
    if !shape.is_drawable() {
        warnings.push(format!(
            "{kind} {name:.80}: a size that is not a positive number: left out"
        ));
        return Ok(None);
    }
    let axis = match attribute_value(stage, p, "axis")?.as_ref().and_then(token) {
        Some("X") => 0,
        Some("Y") => 1,
        _ => 2,
    };
    let double_sided = attribute_value(stage, p, "doubleSided")?
        .as_ref()
        .and_then(scalar)
        .map_or(matches!(shape, Shape::Plane { .. }), |d| d != 0.0);
    let left_handed = attribute_value(stage, p, "orientation")?.as_ref().and_then(token) == Some("leftHanded");
    let look = look_of(stage, p, looks, double_sided)?;
    Ok(Some(ReadShape {
        name,
        shape,
        axis,
        world,
        left_handed,
        look,
    }))
}

impl ReadShape {
    /// The shape's triangles, in the model's frame, as a mesh prim's are read.
    pub(super) fn into_mesh(self) -> ReadMesh {
        let (positions, normals, triangles) = self.shape.tessellate(self.axis);
        let normal_matrix = DMat3::from_mat4(self.world).inverse().transpose();
        // A left-handed prim's faces are wound the other way round; so are those of a mirroring
        // placement.
        let flip = self.left_handed != (DMat3::from_mat4(self.world).determinant() < 0.0);
        ReadMesh {
            name: self.name,
            positions: positions
                .iter()
                .map(|&q| self.world.transform_point3(q).as_vec3().to_array())
                .collect(),
            normals: Some(
                normals
                    .iter()
                    .map(|&n| {
                        let n = (normal_matrix * n).normalize_or_zero();
                        // A left-handed prim's normals follow its winding: they point in.
                        if self.left_handed { -n } else { n }.as_vec3().to_array()
                    })
                    .collect(),
            ),
            uvs: [None, None],
            colours: None,
            triangles: triangles
                .into_iter()
                .map(|[a, b, c]| (if flip { [a, c, b] } else { [a, b, c] }, self.look))
                .collect(),
        }
    }
}

/// One ring of a revolved shape's profile: its distance from the spine and height along it,
/// and the outward normal there in those two directions.
#[derive(Clone, Copy, Debug)]
struct Ring {
    rho: f64,
    z: f64,
    normal: [f64; 2],
}

impl Shape {
    fn is_drawable(&self) -> bool {
        let positive = |x: f64| x.is_finite() && x > 0.0;
        let radius = |x: f64| x.is_finite() && x >= 0.0;
        match *self {
            Shape::Cube { size } => positive(size),
            Shape::Sphere { radius: r } => positive(r),
            Shape::Frustum { bottom, top, height } => {
                radius(bottom) && radius(top) && bottom.max(top) > 0.0 && positive(height)
            }
            // A capsule without a spine is a sphere.
            Shape::Capsule { bottom, top, height } => {
                radius(bottom) && radius(top) && bottom.max(top) > 0.0 && radius(height)
            }
            Shape::Plane { width, length } => positive(width) && positive(length),
        }
    }

    /// Vertices (positions and unit normals) and outward-facing triangles (counter-clockwise
    /// seen from outside), in the shape's own frame with its spine along `axis`.
    fn tessellate(&self, axis: Axis) -> (Vec<DVec3>, Vec<DVec3>, Vec<[u32; 3]>) {
        let (mut positions, mut normals, triangles) = match *self {
            Shape::Cube { size } => box_faces(size * 0.5),
            Shape::Plane { width, length } => {
                // The schema's table: width along z, x, x and length along y, z, y for axis X,
                // Y, Z. Made about Z (its x and y) and turned like the revolved shapes, whose
                // turn takes x to y and y to z for X, x to z and y to x for Y: there the two
                // sides are given the other way round.
                let (along_x, along_y) = if axis == 2 { (width, length) } else { (length, width) };
                rectangle(along_x * 0.5, along_y * 0.5)
            }
            Shape::Sphere { radius } => revolve(&arc(0.0, radius, -90f64.to_radians(), 90f64.to_radians())),
            Shape::Frustum { bottom, top, height } => revolve(&frustum_profile(bottom, top, height)),
            Shape::Capsule { bottom, top, height } => revolve(&capsule_profile(bottom, top, height)),
        };
        for v in positions.iter_mut().chain(normals.iter_mut()) {
            *v = onto_axis(*v, axis);
        }
        (positions, normals, triangles)
    }
}

/// `v`, made about Z, turned so that Z runs along `axis`: a cyclic permutation of the
/// coordinates (X: (z, x, y), Y: (y, z, x)), which is a rotation.
fn onto_axis(v: DVec3, axis: Axis) -> DVec3 {
    match axis {
        0 => DVec3::new(v.z, v.x, v.y),
        1 => DVec3::new(v.y, v.z, v.x),
        _ => v,
    }
}

/// Rings along a circle of `radius` about the spine point at height `centre_z`, from elevation
/// `from` to `to` (radians, −π/2 the bottom pole), each a normal of the circle; as many steps
/// as [`QUARTER`] a quarter turn, at least one.
fn arc(centre_z: f64, radius: f64, from: f64, to: f64) -> Vec<Ring> {
    let steps = ((to - from).abs() / std::f64::consts::FRAC_PI_2 * QUARTER as f64)
        .ceil()
        .max(1.0) as usize;
    (0..=steps)
        .map(|k| {
            let e = from + (to - from) * k as f64 / steps as f64;
            let (s, c) = e.sin_cos();
            // At a pole the ring is one point (cos ±π/2 is not quite 0 in floating point).
            let c = if c.abs() < 1e-12 { 0.0 } else { c };
            Ring {
                rho: radius * c.max(0.0),
                z: centre_z + radius * s,
                normal: [c, s],
            }
        })
        .collect()
}

/// A cylinder (or cone, where a radius is 0) with its end discs: bottom disc from its centre out,
/// the side up, the top disc in to its centre; the normals creased between them.
fn frustum_profile(bottom: f64, top: f64, height: f64) -> Vec<Ring> {
    let (z0, z1) = (-height * 0.5, height * 0.5);
    let side = DVec3::new(height, bottom - top, 0.0).normalize();
    let side = [side.x, side.y];
    let mut rings = Vec::new();
    if bottom > 0.0 {
        rings.push(Ring {
            rho: 0.0,
            z: z0,
            normal: [0.0, -1.0],
        });
        rings.push(Ring {
            rho: bottom,
            z: z0,
            normal: [0.0, -1.0],
        });
    }
    rings.push(Ring {
        rho: bottom,
        z: z0,
        normal: side,
    });
    rings.push(Ring {
        rho: top,
        z: z1,
        normal: side,
    });
    if top > 0.0 {
        rings.push(Ring {
            rho: top,
            z: z1,
            normal: [0.0, 1.0],
        });
        rings.push(Ring {
            rho: 0.0,
            z: z1,
            normal: [0.0, 1.0],
        });
    }
    rings
}

/// A capsule: the side from radius `bottom` at −height/2 to `top` at +height/2, capped by the
/// spheres tangent to it there (each sphere's radius is its end's radius over the cosine of the
/// side's slope, its centre below or above the end).
fn capsule_profile(bottom: f64, top: f64, height: f64) -> Vec<Ring> {
    let half_pi = std::f64::consts::FRAC_PI_2;
    if height <= 0.0 {
        // No spine: the larger end's sphere.
        return arc(0.0, bottom.max(top), -half_pi, half_pi);
    }
    // The side's outward normal, (height, bottom − top) / length, at elevation `tilt`.
    let length = (height * height + (bottom - top) * (bottom - top)).sqrt();
    let tilt = (bottom - top).atan2(height);
    let (big_bottom, big_top) = (bottom * length / height, top * length / height);
    let centre_bottom = -height * 0.5 - bottom * (bottom - top) / height;
    let centre_top = height * 0.5 - top * (bottom - top) / height;
    let mut rings = arc(centre_bottom, big_bottom, -half_pi, tilt);
    // The side joins the caps with their own normal (tangent continuous): no crease.
    rings.extend(arc(centre_top, big_top, tilt, half_pi));
    rings
}

/// The surface made by turning `profile` (bottom to top, round the outside) about Z.
fn revolve(profile: &[Ring]) -> (Vec<DVec3>, Vec<DVec3>, Vec<[u32; 3]>) {
    let mut positions = Vec::with_capacity(profile.len() * AROUND);
    let mut normals = Vec::with_capacity(profile.len() * AROUND);
    for ring in profile {
        for j in 0..AROUND {
            let (s, c) = (std::f64::consts::TAU * j as f64 / AROUND as f64).sin_cos();
            positions.push(DVec3::new(ring.rho * c, ring.rho * s, ring.z));
            normals.push(DVec3::new(ring.normal[0] * c, ring.normal[0] * s, ring.normal[1]));
        }
    }
    let at = |k: usize, j: usize| (k * AROUND + j % AROUND) as u32;
    let mut triangles = Vec::new();
    for (k, pair) in profile.windows(2).enumerate() {
        let (lower, upper) = (pair[0], pair[1]);
        // Two rings at one place (a crease) make no band.
        if (lower.rho - upper.rho).abs() < 1e-12 && (lower.z - upper.z).abs() < 1e-12 {
            continue;
        }
        for j in 0..AROUND {
            // Counter-clockwise seen from outside: around (+φ) then up the profile.
            if lower.rho > 0.0 {
                triangles.push([at(k, j), at(k, j + 1), at(k + 1, j + 1)]);
            }
            if upper.rho > 0.0 {
                triangles.push([at(k, j), at(k + 1, j + 1), at(k + 1, j)]);
            }
        }
    }
    (positions, normals, triangles)
}

/// A cube of half-edge `h`: six faces of four vertices, each its face's normal.
fn box_faces(h: f64) -> (Vec<DVec3>, Vec<DVec3>, Vec<[u32; 3]>) {
    let (mut positions, mut normals, mut triangles) = (Vec::new(), Vec::new(), Vec::new());
    for axis in 0..3 {
        for sign in [-1.0, 1.0] {
            let mut n = DVec3::ZERO;
            n[axis] = sign;
            // Two directions across the face with u × v = n.
            let u = onto_axis(DVec3::X, axis) * sign;
            let v = n.cross(u);
            let first = positions.len() as u32;
            for (a, b) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
                positions.push((n + u * a + v * b) * h);
                normals.push(n);
            }
            triangles.push([first, first + 1, first + 2]);
            triangles.push([first, first + 2, first + 3]);
        }
    }
    (positions, normals, triangles)
}

/// A rectangle in the plane z = 0 facing +z, `hw` to each side along x and `hl` along y.
fn rectangle(hw: f64, hl: f64) -> (Vec<DVec3>, Vec<DVec3>, Vec<[u32; 3]>) {
    let positions = vec![
        DVec3::new(-hw, -hl, 0.0),
        DVec3::new(hw, -hl, 0.0),
        DVec3::new(hw, hl, 0.0),
        DVec3::new(-hw, hl, 0.0),
    ];
    (positions, vec![DVec3::Z; 4], vec![[0, 1, 2], [0, 2, 3]])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bounds(positions: &[DVec3]) -> (DVec3, DVec3) {
        positions.iter().fold(
            (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
            |(lo, hi), &p| (lo.min(p), hi.max(p)),
        )
    }

    #[test]
    fn shapes_fill_the_extents_pixars_library_computes() {
        // `UsdGeom.Boundable.ComputeExtentFromPlugins` (usd-core 26.11) for each shape: the
        // schema's fallbacks, and authored sizes along each axis.
        let cases: [(Shape, Axis, [f64; 3], [f64; 3]); 13] = [
            (Shape::Cube { size: 2.0 }, 2, [-1.0; 3], [1.0; 3]),
            (Shape::Cube { size: 0.5 }, 2, [-0.25; 3], [0.25; 3]),
            (Shape::Sphere { radius: 1.0 }, 2, [-1.0; 3], [1.0; 3]),
            (
                Shape::Frustum {
                    bottom: 1.0,
                    top: 1.0,
                    height: 2.0,
                },
                2,
                [-1.0; 3],
                [1.0; 3],
            ),
            (
                Shape::Frustum {
                    bottom: 1.0,
                    top: 0.0,
                    height: 2.0,
                },
                2,
                [-1.0; 3],
                [1.0; 3],
            ),
            (
                Shape::Capsule {
                    bottom: 0.5,
                    top: 0.5,
                    height: 1.0,
                },
                2,
                [-0.5, -0.5, -1.0],
                [0.5, 0.5, 1.0],
            ),
            (
                Shape::Plane {
                    width: 2.0,
                    length: 2.0,
                },
                2,
                [-1.0, -1.0, 0.0],
                [1.0, 1.0, 0.0],
            ),
            (
                Shape::Frustum {
                    bottom: 1.0,
                    top: 0.5,
                    height: 3.0,
                },
                0,
                [-1.5, -1.0, -1.0],
                [1.5, 1.0, 1.0],
            ),
            (
                Shape::Capsule {
                    bottom: 0.5,
                    top: 0.25,
                    height: 1.0,
                },
                1,
                [-0.5153882, -1.1403883, -0.5153882],
                [0.5153882, 0.6951941, 0.5153882],
            ),
            (
                Shape::Capsule {
                    bottom: 0.1,
                    top: 0.9,
                    height: 0.5,
                },
                2,
                [-1.6981167, -1.6981167, -0.2786796],
                [1.6981167, 1.6981167, 3.3881166],
            ),
            (
                Shape::Frustum {
                    bottom: 2.0,
                    top: 0.0,
                    height: 1.0,
                },
                1,
                [-2.0, -0.5, -2.0],
                [2.0, 0.5, 2.0],
            ),
            (
                Shape::Plane {
                    width: 3.0,
                    length: 1.0,
                },
                0,
                [0.0, -0.5, -1.5],
                [0.0, 0.5, 1.5],
            ),
            (
                Shape::Plane {
                    width: 3.0,
                    length: 1.0,
                },
                1,
                [-1.5, 0.0, -0.5],
                [1.5, 0.0, 0.5],
            ),
        ];
        for (shape, axis, lo, hi) in cases {
            let (positions, _, _) = shape.tessellate(axis);
            let (min, max) = bounds(&positions);
            // The round parts' outline is a polygon: within 0.2 % of the extent's size.
            let tolerance = 2e-3 * (DVec3::from(hi) - DVec3::from(lo)).max_element();
            assert!(
                min.distance(DVec3::from(lo)) < tolerance && max.distance(DVec3::from(hi)) < tolerance,
                "{shape:?} along axis {axis}: {min:?} – {max:?}, USD's {lo:?} – {hi:?}"
            );
        }
    }

    #[test]
    fn every_triangle_faces_out_and_its_normals_agree() {
        let shapes = [
            Shape::Cube { size: 2.0 },
            Shape::Sphere { radius: 1.0 },
            Shape::Frustum {
                bottom: 1.0,
                top: 0.5,
                height: 2.0,
            },
            Shape::Frustum {
                bottom: 1.0,
                top: 0.0,
                height: 2.0,
            },
            Shape::Capsule {
                bottom: 0.5,
                top: 0.5,
                height: 1.0,
            },
            Shape::Capsule {
                bottom: 0.5,
                top: 0.25,
                height: 1.0,
            },
            Shape::Capsule {
                bottom: 0.3,
                top: 0.3,
                height: 0.0,
            },
            Shape::Plane {
                width: 2.0,
                length: 1.0,
            },
        ];
        for shape in shapes {
            for axis in 0..3 {
                let (positions, normals, triangles) = shape.tessellate(axis);
                assert!(!triangles.is_empty());
                for [a, b, c] in triangles {
                    let [pa, pb, pc] = [a, b, c].map(|i| positions[i as usize]);
                    let facing = (pb - pa).cross(pc - pa);
                    assert!(facing.length() > 1e-12, "{shape:?}: a triangle of no area");
                    let centre = (pa + pb + pc) / 3.0;
                    // Convex shapes about the origin: out is away from it (a plane: its +axis).
                    let out = if matches!(shape, Shape::Plane { .. }) {
                        onto_axis(DVec3::Z, axis)
                    } else {
                        centre
                    };
                    assert!(
                        facing.dot(out) > 0.0,
                        "{shape:?} along {axis}: a triangle faces in at {centre:?}"
                    );
                    for i in [a, b, c] {
                        let n = normals[i as usize];
                        assert!((n.length() - 1.0).abs() < 1e-9);
                        assert!(
                            n.dot(facing.normalize()) > 0.5,
                            "{shape:?}: normal {n:?} against face {facing:?}"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn sizes_that_are_not_positive_numbers_are_not_drawn() {
        assert!(!Shape::Sphere { radius: 0.0 }.is_drawable());
        assert!(!Shape::Cube { size: f64::NAN }.is_drawable());
        assert!(
            !Shape::Frustum {
                bottom: 0.0,
                top: 0.0,
                height: 1.0
            }
            .is_drawable()
        );
        assert!(
            !Shape::Capsule {
                bottom: 0.5,
                top: 0.5,
                height: -1.0
            }
            .is_drawable()
        );
        assert!(
            Shape::Capsule {
                bottom: 0.5,
                top: 0.5,
                height: 0.0
            }
            .is_drawable()
        );
        assert!(
            Shape::Frustum {
                bottom: 1.0,
                top: 0.0,
                height: 1.0
            }
            .is_drawable()
        );
    }
}
