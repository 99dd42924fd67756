//! The Diorama as the engine shows it: [`crate::physics`]'s world, fed each frame from the
//! session (the fused orientation's gravity, the accelerometer's hand acceleration, the eyes),
//! and drawn as one model — the bodies merged into one vertex-painted primitive that is
//! rewritten in place each frame ([`crate::render::Renderer::update_vertices`]), the tray's
//! walls and its floor, on which the bodies' shadows fall.
//!
//! It is the artifact library's `builtin:diorama` entry (see [`crate::engine`]); the desktop
//! replays a log into it with `phantogram render --artifact diorama`.
//!
//! **Two ways of keeping things inside the eyes' view, one for each case.** A single artifact
//! is pushed back along −z as a whole ([`crate::containment`]'s smoothed push-back): it is the
//! thing looked at, rigid and placed by its curator, so it keeps its shape, its footprint on the
//! floor and its place on the screen, and only its depth changes as the eyes move. The
//! Diorama's loose bodies are held per body by the physics (the pyramids as walls, the paper's
//! way): pushing the whole scene back would lift the tray off the glass and push every body for
//! the one that strays, while per body only the stray one is stopped, and as a body would be
//! in a real box. So the engine uses the push-back for artifacts and the pyramids for the
//! Diorama, never both (the Diorama's push is 0).
//!
//! **Threading**: plain data owned by the render thread. **Panics**: none.

use glam::{Mat4, Quat, Vec3};

use crate::model::{Material, Mesh, Model, Primitive, Vertex};
use crate::physics::apparent_gravity::{ApparentGravity, ShakeParams};
use crate::physics::bodies::{BodyKind, BodyShape, BodySpec, default_scene, vessel_points};
use crate::physics::diorama::{Diorama, DioramaError, DioramaParams};
use crate::screen::Screen;

/// The library id of the Diorama.
pub const DIORAMA_ID: &str = "builtin:diorama";

/// How many bodies the default Diorama holds.
pub const DEFAULT_BODIES: usize = 40;

/// The Diorama's world and its drawing.
pub struct DioramaScene {
    world: Diorama,
    gravity: ApparentGravity,
    /// Each body's mesh in its own frame.
    body_meshes: Vec<Mesh>,
    model: Model,
}

impl std::fmt::Debug for DioramaScene {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("DioramaScene")
            .field("world", &self.world)
            .finish_non_exhaustive()
    }
}

impl DioramaScene {
    /// The default scene under `screen`: [`DEFAULT_BODIES`] bodies in the tray, at rest.
    pub fn new(screen: &Screen) -> Result<Self, DioramaError> {
        let params = DioramaParams::default();
        Self::with_bodies(screen, default_scene(screen, -params.depth_m, DEFAULT_BODIES), params)
    }

    pub fn with_bodies(screen: &Screen, bodies: Vec<BodySpec>, params: DioramaParams) -> Result<Self, DioramaError> {
        let body_meshes = bodies.iter().map(body_mesh).collect();
        let world = Diorama::new(screen, bodies, params)?;
        let mut scene = Self {
            world,
            gravity: ApparentGravity::new(ShakeParams::default()),
            body_meshes,
            model: tray_model(screen, params.depth_m),
        };
        scene.pose_bodies();
        Ok(scene)
    }

    /// One frame: the session's view (eyes, orientation), the newest accelerometer reading,
    /// and the frame's sensor time; runs the physics steps due and poses the model.
    pub fn update(&mut self, view: &crate::FrameView, specific_force: Option<(i64, Vec3)>, t_ns: i64) {
        // Before an orientation is known, lying flat.
        let q = view.device_to_world.unwrap_or(Quat::IDENTITY);
        if let Some((t, s)) = specific_force {
            self.gravity.observe(t, s, q);
        }
        self.world.set_gravity(self.gravity.device(q));
        self.world.set_eyes(view.stereo_eyes_m());
        self.world.advance_to(t_ns);
        self.pose_bodies();
    }

    /// Rewrites the bodies' primitive (the model's first) from the interpolated poses.
    fn pose_bodies(&mut self) {
        let poses = self.world.poses();
        let merged = &mut self.model.primitives[0].mesh;
        // The same bodies in the same order every frame: the indices are made once, the
        // vertices rewritten in their buffer.
        if merged.indices.is_empty() {
            let mut base = 0u32;
            for mesh in &self.body_meshes {
                merged.indices.extend(mesh.indices.iter().map(|i| i + base));
                base += mesh.vertices.len() as u32;
            }
        }
        merged.vertices.clear();
        for (mesh, pose) in self.body_meshes.iter().zip(&poses) {
            let m = Mat4::from_rotation_translation(pose.rotation, pose.translation_m);
            let normal_m = glam::Mat3::from_quat(pose.rotation);
            merged.vertices.extend(mesh.vertices.iter().map(|v| {
                Vertex {
                    position: m.transform_point3(Vec3::from(v.position)).to_array(),
                    normal: (normal_m * Vec3::from(v.normal)).to_array(),
                    tangent: (normal_m * Vec3::new(v.tangent[0], v.tangent[1], v.tangent[2]))
                        .extend(v.tangent[3])
                        .to_array(),
                    ..*v
                }
            }));
        }
    }

    /// The model to draw now.
    pub fn model(&self) -> &Model {
        &self.model
    }

    pub fn world(&self) -> &Diorama {
        &self.world
    }

    pub fn world_mut(&mut self) -> &mut Diorama {
        &mut self.world
    }

    /// Back to the start, bodies at rest.
    pub fn reset(&mut self) {
        self.world.reset();
        self.pose_bodies();
    }
}

/// The tray as drawn: primitive 0 the bodies (filled by [`DioramaScene::pose_bodies`]), 1 the
/// walls, 2 the floor (where the shadows fall).
fn tray_model(screen: &Screen, depth_m: f32) -> Model {
    let (hw, hh) = (screen.width_m() / 2.0, screen.height_m() / 2.0);
    let (r, u) = (screen.right_device(), screen.up_device());
    let at = |x: f32, y: f32, z: f32| r * x + u * y + Vec3::Z * z;
    let mut walls = Mesh::default();
    // Each wall from the floor to the glass, facing into the tray.
    let sides = [
        (at(-hw, -hh, 0.0), at(hw, -hh, 0.0), u),
        (at(hw, -hh, 0.0), at(hw, hh, 0.0), -r),
        (at(hw, hh, 0.0), at(-hw, hh, 0.0), -u),
        (at(-hw, hh, 0.0), at(-hw, -hh, 0.0), r),
    ];
    for (a, b, inward) in sides {
        let down = Vec3::Z * -depth_m;
        quad(
            &mut walls,
            [a + down, b + down, b, a],
            inward,
            [0.32, 0.26, 0.2, 1.0],
            [0.0, 0.8],
        );
    }
    let mut floor = Mesh::default();
    quad(
        &mut floor,
        [
            at(-hw, -hh, -depth_m),
            at(hw, -hh, -depth_m),
            at(hw, hh, -depth_m),
            at(-hw, hh, -depth_m),
        ],
        Vec3::Z,
        [0.42, 0.36, 0.28, 1.0],
        [0.0, 0.9],
    );
    let primitive = |mesh: Mesh, is_floor: bool| Primitive {
        mesh,
        material: 0,
        is_floor,
        lods: Vec::new(),
    };
    Model {
        name: "diorama".into(),
        primitives: vec![
            primitive(Mesh::default(), false),
            primitive(walls, false),
            primitive(floor, true),
        ],
        materials: vec![Material::vertex_painted()],
        images: Vec::new(),
        warnings: Vec::new(),
        annotations: Vec::new(),
    }
}

/// Appends a quad (corners counter-clockwise seen from `normal`).
fn quad(mesh: &mut Mesh, corners: [Vec3; 4], normal: Vec3, color: [f32; 4], material: [f32; 2]) {
    let base = mesh.vertices.len() as u32;
    let tangent = (corners[1] - corners[0]).normalize_or_zero();
    for (c, uv) in corners.iter().zip([[0.0, 1.0], [1.0, 1.0], [1.0, 0.0], [0.0, 0.0]]) {
        mesh.vertices.push(Vertex {
            position: c.to_array(),
            normal: normal.to_array(),
            tangent: tangent.extend(1.0).to_array(),
            uv: [uv[0], uv[1], 0.0, 0.0],
            color,
            material,
        });
    }
    // Wound so that the face is seen from `normal`'s side.
    let n = (corners[1] - corners[0]).cross(corners[2] - corners[0]);
    if n.dot(normal) >= 0.0 {
        mesh.indices
            .extend_from_slice(&[base, base + 1, base + 2, base, base + 2, base + 3]);
    } else {
        mesh.indices
            .extend_from_slice(&[base, base + 2, base + 1, base, base + 3, base + 2]);
    }
}

/// A body's mesh in its own frame: a lathe around `z` for round things, a box for dice.
fn body_mesh(spec: &BodySpec) -> Mesh {
    // Linear colour, then [metallic, roughness]: glass marbles are smooth, bone dice matte,
    // bronze coins metal, terracotta vessels rough.
    let material = match spec.kind {
        BodyKind::Marble => [0.0, 0.08],
        BodyKind::Die => [0.0, 0.55],
        BodyKind::Coin => [1.0, 0.35],
        BodyKind::Vessel | BodyKind::Artifact => [0.0, 0.75],
    };
    let mut mesh = Mesh::default();
    match &spec.shape {
        BodyShape::Ball { radius_m } => {
            let profile: Vec<(f32, f32)> = (0..=8)
                .map(|k| {
                    let a = std::f32::consts::PI * (k as f32 / 8.0 - 0.5);
                    (radius_m * a.cos(), radius_m * a.sin())
                })
                .collect();
            lathe(&mut mesh, &profile, 16, spec.colour, material);
        }
        BodyShape::Cuboid { half_extents_m: h } => {
            mesh.push_cube(Vec3::ZERO, 1.0, spec.colour);
            mesh.transform(Mat4::from_scale(*h));
            for v in &mut mesh.vertices {
                v.material = material;
            }
        }
        BodyShape::Cylinder {
            radius_m,
            half_height_m,
        } => {
            let profile = [
                (0.0, -half_height_m),
                (*radius_m, -half_height_m),
                (*radius_m, *half_height_m),
                (0.0, *half_height_m),
            ];
            lathe(&mut mesh, &profile, 20, spec.colour, material);
        }
        BodyShape::Convex { points_m } => {
            if spec.kind == BodyKind::Vessel && *points_m == vessel_points() {
                // The vessel's own profile (its neck is narrower than the hull the physics uses).
                let profile: Vec<(f32, f32)> = [
                    (0.0, 0.0),
                    (2.5, 0.0),
                    (4.5, 3.0),
                    (5.0, 6.0),
                    (3.0, 10.0),
                    (2.8, 12.0),
                    (0.0, 12.0),
                ]
                .iter()
                .map(|(r, z)| (r * 1e-3, (z - 6.0) * 1e-3))
                .collect();
                lathe(&mut mesh, &profile, 12, spec.colour, material);
            } else {
                // Any other hull: its points' bounding box, as a stand-in.
                let (lo, hi) = points_m
                    .iter()
                    .fold((Vec3::MAX, Vec3::MIN), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
                mesh.push_cube(Vec3::ZERO, 1.0, spec.colour);
                mesh.transform(Mat4::from_translation((lo + hi) * 0.5) * Mat4::from_scale((hi - lo) * 0.5));
            }
        }
    }
    mesh
}

/// A surface of revolution about `z` from a (radius, z) profile, bottom to top.
fn lathe(mesh: &mut Mesh, profile: &[(f32, f32)], segments: usize, color: [f32; 4], material: [f32; 2]) {
    for w in profile.windows(2) {
        let ((r0, z0), (r1, z1)) = (w[0], w[1]);
        // The side's outward normal in the profile plane: perpendicular to the segment.
        let (dr, dz) = (r1 - r0, z1 - z0);
        let len = (dr * dr + dz * dz).sqrt().max(1e-9);
        let (nr, nz) = (dz / len, -dr / len);
        for k in 0..segments {
            let a0 = k as f32 / segments as f32 * std::f32::consts::TAU;
            let a1 = (k + 1) as f32 / segments as f32 * std::f32::consts::TAU;
            let ring = |r: f32, z: f32, a: f32| Vec3::new(r * a.cos(), r * a.sin(), z);
            let normal_at = |a: f32| Vec3::new(nr * a.cos(), nr * a.sin(), nz).normalize_or_zero();
            let base = mesh.vertices.len() as u32;
            for (p, a) in [
                (ring(r0, z0, a0), a0),
                (ring(r0, z0, a1), a1),
                (ring(r1, z1, a1), a1),
                (ring(r1, z1, a0), a0),
            ] {
                mesh.vertices.push(Vertex {
                    position: p.to_array(),
                    normal: normal_at(a).to_array(),
                    tangent: [-a.sin(), a.cos(), 0.0, 1.0],
                    uv: [0.0; 4],
                    color,
                    material,
                });
            }
            mesh.indices
                .extend_from_slice(&[base, base + 1, base + 2, base, base + 2, base + 3]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_scene_draws_every_body_in_the_tray() {
        let screen = Screen::default();
        let scene = DioramaScene::new(&screen).unwrap();
        let model = scene.model();
        assert_eq!(model.primitives.len(), 3);
        assert!(model.primitives[2].is_floor);
        let bodies = model.primitives[0].mesh.bounds().unwrap();
        assert!(bodies.min.z >= -0.0301, "above the floor: {:?}", bodies.min);
        assert!(bodies.min.x > -screen.width_m() / 2.0 && bodies.max.x < screen.width_m() / 2.0);
        assert!(model.triangle_count() > DEFAULT_BODIES * 20);
        // Every body mesh's vertices face outwards from its centre (a lathe's winding).
        for spec in scene.world().specs().iter().take(4) {
            let mesh = body_mesh(spec);
            let outward = mesh
                .vertices
                .iter()
                .filter(|v| Vec3::from(v.position).dot(Vec3::from(v.normal)) >= -1e-6)
                .count();
            assert!(outward * 10 >= mesh.vertices.len() * 9, "{:?}", spec.kind);
        }
    }
}
