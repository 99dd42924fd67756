//! The diorama's world: a tray behind the glass, loose bodies, the eyes' pyramids, a fixed time
//! step and interpolated poses.
//!
//! * **The tray**: a floor [`DioramaParams::depth_m`] behind the glass and four walls along the
//!   screen's edges, from the floor to the glass and a little beyond (thick fixed boxes, so that
//!   no body passes through them between two steps); a lid at [`DioramaParams::lid_fraction`] of
//!   the way to the eyes. In front of the glass the eyes' pyramids ([`crate::frustum`]) are the
//!   walls: eight slabs standing on the glass, one per side and eye, reshaped to the current
//!   eyes before every step.
//! * **Time**: the world advances in fixed steps of `1 / step_hz` seconds of the sensor clock
//!   ([`Diorama::advance_to`]), whatever the frame rate; a frame's poses are interpolated
//!   between the last two steps ([`Diorama::poses`]). After a pause (a suspended app, a gap in a
//!   log) at most [`DioramaParams::max_catch_up_steps`] are taken and the rest of the gap is
//!   skipped, so one late frame cannot stall the next ones.
//! * **Determinism**: steps are counted from integer nanoseconds and the engine runs on one
//!   thread, so a given sequence of calls gives bit-identical poses on the same binary.
//! * **The finger**: [`Diorama::grab`] holds a body and [`Diorama::drag_to`] moves it by
//!   setting its velocity towards the finger (a kinematic grab that still collides, so the
//!   walls and the pyramids stop it); [`Diorama::release`] lets it go with that velocity (a
//!   flick).
//!
//! **Threading**: plain data, one thread. **Panics**: none; non-finite inputs are ignored. A
//! panic inside the physics engine (degenerate contact geometry in parry, found by fuzzing) is
//! caught: the world is rebuilt at the last poses ([`Diorama::faults`] counts it).

use glam::{Quat, Vec3};
use phantogram_geometry::screen::Screen;
use rapier3d::prelude::*;

use crate::bodies::{BodyShape, BodySpec};
use crate::convert::{from_rapier, pose, quat_from_rapier, to_rapier};
use crate::frustum::{EyePlane, screen_edges, side_prism, stereo_pyramids};

/// How far a body may reach out of an eye's pyramid before it is moved back (0.2 mm: about three
/// pixels of a 420 dpi screen).
pub const CONTAINMENT_TOLERANCE_M: f32 = 0.0002;

/// How thick the pyramids' side slabs are, and how far they reach past the screen's corners.
const SIDE_THICKNESS_M: f32 = 0.05;
const SIDE_OVERLAP_M: f32 = 0.02;

/// How far a body of `shape` at `pose` reaches out of the planes (an eye's pyramid sides) in
/// front of the glass, metres (≤ 0: inside them all); `None` when it lies wholly behind the
/// glass, where the window may frame it. The whole body is measured, not only its part in
/// front of the glass: a conservative test, the one [`Diorama`]'s containment holds to.
pub fn reach_out_of_view_m(shape: &BodyShape, pose: &BodyPose, planes: &[EyePlane]) -> Option<f32> {
    let to_body = pose.rotation.inverse();
    let front = pose.translation_m.z + shape.support_m(to_body * Vec3::Z);
    if front <= 0.0 {
        return None;
    }
    Some(
        planes
            .iter()
            .map(|p| shape.support_m(to_body * -p.normal) - p.distance_m(pose.translation_m))
            .fold(f32::MIN, f32::max),
    )
}

/// The diorama's settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DioramaParams {
    /// Physics steps per second of sensor time.
    pub step_hz: u32,
    /// The tray's floor, metres behind the glass.
    pub depth_m: f32,
    /// The lid, as a fraction of the eyes' distance in front of the glass.
    pub lid_fraction: f32,
    /// Most steps one [`Diorama::advance_to`] takes; a longer gap is skipped.
    pub max_catch_up_steps: u32,
    /// Fastest a grabbed body follows the finger, m/s.
    pub max_grab_speed_m_s: f32,
}

impl Default for DioramaParams {
    fn default() -> Self {
        Self {
            step_hz: 120,
            depth_m: 0.03,
            lid_fraction: 0.5,
            max_catch_up_steps: 12,
            max_grab_speed_m_s: 1.0,
        }
    }
}

/// Why a diorama could not be made.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum DioramaError {
    #[error("the diorama needs a step rate of 1 to 10000 Hz, got {0}")]
    StepRate(u32),
    #[error("the tray's depth must be a positive number of metres, got {0}")]
    Depth(f32),
    #[error("body {index}: {reason}")]
    Body { index: usize, reason: String },
}

/// A body's pose for drawing.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BodyPose {
    pub translation_m: Vec3,
    pub rotation: Quat,
}

/// The world (see the module docs).
pub struct Diorama {
    world: PhysicsWorld,
    params: DioramaParams,
    screen: Screen,
    specs: Vec<BodySpec>,
    handles: Vec<RigidBodyHandle>,
    /// The colliders of the eight sides of the eyes' pyramids (on one fixed body), and the lid's
    /// kinematic half-space.
    pyramid: [ColliderHandle; 8],
    lid: RigidBodyHandle,
    eyes_m: Option<[Vec3; 2]>,
    /// The eyes the pyramids were last shaped for, and their planes (left eye's four first).
    placed: Option<([Vec3; 2], [EyePlane; 8])>,
    /// The tray's floor and walls as planes, normals inwards.
    tray: [EyePlane; 5],
    gravity: Vec3,
    /// Sensor time of step 0, and the steps taken since.
    t0_ns: Option<i64>,
    steps: u64,
    /// Steps skipped after pauses (they count as taken, without simulating).
    skipped_steps: u64,
    previous: Vec<BodyPose>,
    current: Vec<BodyPose>,
    /// Where the interpolation stands between `previous` and `current`, 0 to 1.
    alpha: f32,
    grab: Option<(usize, Vec3)>,
    /// Steps the physics engine panicked in (see [`Diorama::faults`]).
    faults: u64,
    /// Tests: the next step panics inside the engine, as a degenerate contact once did.
    #[cfg(test)]
    fault_next_step: bool,
}

impl std::fmt::Debug for Diorama {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Diorama")
            .field("bodies", &self.specs.len())
            .field("steps", &self.steps)
            .field("gravity", &self.gravity)
            .finish_non_exhaustive()
    }
}

/// The tray's floor and four walls under `screen` as planes, normals inwards.
fn tray_planes(screen: &Screen, depth_m: f32) -> [EyePlane; 5] {
    let (hw, hh) = (screen.width_m() / 2.0, screen.height_m() / 2.0);
    let (r, u) = (screen.right_device(), screen.up_device());
    let plane = |normal: Vec3, offset_m: f32| EyePlane { normal, offset_m };
    [
        plane(Vec3::Z, -depth_m),
        plane(r, -hw),
        plane(-r, -hw),
        plane(u, -hh),
        plane(-u, -hh),
    ]
}

fn collider_for(shape: &BodyShape) -> Option<ColliderBuilder> {
    let ok = |v: f32| v.is_finite() && v > 0.0;
    Some(match shape {
        BodyShape::Ball { radius_m } if ok(*radius_m) => ColliderBuilder::ball(*radius_m),
        BodyShape::Cuboid { half_extents_m: h } if ok(h.x) && ok(h.y) && ok(h.z) => {
            ColliderBuilder::cuboid(h.x, h.y, h.z)
        }
        // rapier's cylinders stand along y; ours along z. Rounded edges (a third of the
        // thickness): a sharp-edged thin cylinder wedged in the tray's corner was seen to sink
        // millimetres into the wall and the floor.
        BodyShape::Cylinder {
            radius_m,
            half_height_m,
        } if ok(*radius_m) && ok(*half_height_m) => {
            let border = (half_height_m * 0.66).min(*radius_m * 0.5);
            ColliderBuilder::round_cylinder(half_height_m - border, radius_m - border, border)
                .rotation(to_rapier(Vec3::X * std::f32::consts::FRAC_PI_2))
        }
        BodyShape::Convex { points_m } if points_m.iter().all(|p| p.is_finite()) => {
            let points: Vec<_> = points_m.iter().map(|p| to_rapier(*p)).collect();
            ColliderBuilder::convex_hull(&points)?
        }
        _ => return None,
    })
}

impl Diorama {
    /// A tray under `screen` with `bodies` at their starting poses, the eyes not yet known (the
    /// pyramids wait at a default viewer, straight on at 30 cm, until [`Self::set_eyes`]).
    pub fn new(screen: &Screen, bodies: Vec<BodySpec>, params: DioramaParams) -> Result<Self, DioramaError> {
        if !(1..=10_000).contains(&params.step_hz) {
            return Err(DioramaError::StepRate(params.step_hz));
        }
        if !(params.depth_m.is_finite() && params.depth_m > 0.0) {
            return Err(DioramaError::Depth(params.depth_m));
        }
        let mut world = PhysicsWorld::new();
        world.gravity = to_rapier(Vec3::new(0.0, 0.0, -crate::apparent_gravity::G_M_S2));
        world.integration_parameters.dt = 1.0 / params.step_hz as f32;
        // Small bodies in a small box: centimetres are the scale the solver's tolerances see
        // (at the default metre, 5 mm balls were seen to tunnel through a pushed floor).
        world.integration_parameters.length_unit = 0.01;
        world.integration_parameters.num_solver_iterations = 8;
        Self::build_tray(&mut world, screen, params.depth_m);
        let mut handles = Vec::with_capacity(bodies.len());
        for (index, spec) in bodies.iter().enumerate() {
            let bad = |reason: &str| DioramaError::Body {
                index,
                reason: reason.to_owned(),
            };
            let collider = collider_for(&spec.shape).ok_or_else(|| bad("the shape has no volume or is not finite"))?;
            if !(spec.start_m.is_finite() && spec.start_rotation.is_finite()) {
                return Err(bad("the starting pose is not finite"));
            }
            let density = if spec.density_kg_m3.is_finite() && spec.density_kg_m3 > 0.0 {
                spec.density_kg_m3
            } else {
                return Err(bad("the density must be positive"));
            };
            let body = RigidBodyBuilder::dynamic()
                .pose(pose(spec.start_m, spec.start_rotation.normalize()))
                .ccd_enabled(true)
                .linear_damping(0.1)
                .angular_damping(0.2);
            let collider = collider
                .density(density)
                .friction(spec.friction.clamp(0.0, 2.0))
                .restitution(spec.restitution.clamp(0.0, 1.0));
            let (handle, _) = world.insert(body, collider);
            handles.push(handle);
        }
        // The pyramids' sides: reshaped as the eyes move (a tiny placeholder until then).
        let sides_body = world.insert_body(RigidBodyBuilder::fixed());
        let pyramid = std::array::from_fn(|_| {
            let placeholder = ColliderBuilder::ball(1e-4)
                .translation(to_rapier(Vec3::new(0.0, 0.0, 10.0)))
                .friction(0.2);
            world
                .colliders
                .insert_with_parent(placeholder, sides_body, &mut world.bodies)
        });
        // The lid's solid lies above its local xy plane turned over: free side along its +z.
        let lid = world
            .insert(
                RigidBodyBuilder::kinematic_position_based(),
                ColliderBuilder::new(SharedShape::halfspace(to_rapier(Vec3::Z))).friction(0.2),
            )
            .0;
        let mut diorama = Self {
            world,
            params,
            screen: *screen,
            specs: bodies,
            handles,
            pyramid,
            lid,
            eyes_m: None,
            placed: None,
            tray: tray_planes(screen, params.depth_m),
            gravity: Vec3::new(0.0, 0.0, -crate::apparent_gravity::G_M_S2),
            t0_ns: None,
            steps: 0,
            skipped_steps: 0,
            previous: Vec::new(),
            current: Vec::new(),
            alpha: 1.0,
            grab: None,
            faults: 0,
            #[cfg(test)]
            fault_next_step: false,
        };
        let default_eye = Vec3::Z * 0.3;
        diorama.place_planes([default_eye, default_eye], true);
        diorama.current = diorama.read_poses();
        diorama.previous = diorama.current.clone();
        Ok(diorama)
    }

    /// The fixed floor and walls (see the module docs).
    fn build_tray(world: &mut PhysicsWorld, screen: &Screen, depth_m: f32) {
        let (hw, hh) = (screen.width_m() / 2.0, screen.height_m() / 2.0);
        let (right, up) = (screen.right_device(), screen.up_device());
        let rotation = Quat::from_mat3(&glam::Mat3::from_cols(right, up, Vec3::Z));
        let thick = 0.05;
        let tray = world.insert_body(RigidBodyBuilder::fixed());
        let floor = ColliderBuilder::cuboid(hw + thick, hh + thick, thick / 2.0)
            .position(pose(Vec3::new(0.0, 0.0, -depth_m - thick / 2.0), rotation))
            .friction(0.6);
        world.colliders.insert_with_parent(floor, tray, &mut world.bodies);
        // The walls rise from the floor to well in front of the glass (the pyramids and the lid
        // close the box there); in the screen's own axes, then turned with it.
        let wall_top = 0.3;
        let half_z = (wall_top + depth_m) / 2.0;
        let centre_z = (wall_top - depth_m) / 2.0;
        let walls = [
            (
                Vec3::new(hw + thick / 2.0, 0.0, centre_z),
                Vec3::new(thick / 2.0, hh + thick, half_z),
            ),
            (
                Vec3::new(-hw - thick / 2.0, 0.0, centre_z),
                Vec3::new(thick / 2.0, hh + thick, half_z),
            ),
            (
                Vec3::new(0.0, hh + thick / 2.0, centre_z),
                Vec3::new(hw + thick, thick / 2.0, half_z),
            ),
            (
                Vec3::new(0.0, -hh - thick / 2.0, centre_z),
                Vec3::new(hw + thick, thick / 2.0, half_z),
            ),
        ];
        for (centre, half) in walls {
            let collider = ColliderBuilder::cuboid(half.x, half.y, half.z)
                .position(pose(rotation * centre, rotation))
                .friction(0.6);
            world.colliders.insert_with_parent(collider, tray, &mut world.bodies);
        }
    }

    /// Reshapes the pyramids' sides for `eyes_m` and moves the lid (at once when `teleport`,
    /// else as the next step's kinematic target).
    fn place_planes(&mut self, eyes_m: [Vec3; 2], teleport: bool) {
        let Some(planes) = stereo_pyramids(&self.screen, eyes_m) else {
            return; // an eye behind the glass: the pyramids stay where they were
        };
        let edges = screen_edges(&self.screen);
        for (k, (plane, &collider)) in planes.iter().zip(&self.pyramid).enumerate() {
            let (a, b) = edges[k % 4];
            let eye = eyes_m[k / 4];
            let Some(points) = side_prism(plane, a, b, eye, SIDE_THICKNESS_M, SIDE_OVERLAP_M) else {
                continue;
            };
            let points: Vec<_> = points.iter().map(|p| to_rapier(*p)).collect();
            if let (Some(shape), Some(c)) = (
                SharedShape::convex_hull(&points),
                self.world.colliders.get_mut(collider),
            ) {
                c.set_shape(shape);
                c.set_translation_wrt_parent(to_rapier(Vec3::ZERO));
            }
        }
        let lid = self.lid_plane(eyes_m);
        let target = pose(lid.point_m(), Quat::from_rotation_arc(Vec3::Z, lid.normal));
        if let Some(body) = self.world.bodies.get_mut(self.lid) {
            if teleport {
                body.set_position(target, false);
            } else {
                body.set_next_kinematic_position(target);
            }
        }
        self.eyes_m = Some(eyes_m);
        self.placed = Some((eyes_m, planes));
    }

    /// The gravity the bodies feel, device frame (see [`crate::apparent_gravity`]); sleeping
    /// bodies wake when it turns.
    pub fn set_gravity(&mut self, gravity_device: Vec3) {
        if !gravity_device.is_finite() {
            return;
        }
        if gravity_device.distance(self.gravity) > 1e-3 {
            for &h in &self.handles {
                if let Some(b) = self.world.bodies.get_mut(h) {
                    b.wake_up(true);
                }
            }
        }
        self.gravity = gravity_device;
        self.world.gravity = to_rapier(gravity_device);
    }

    /// The viewer's eyes for the next steps (device frame): the pyramids follow them.
    pub fn set_eyes(&mut self, eyes_m: [Vec3; 2]) {
        if eyes_m.iter().all(|e| e.is_finite()) {
            self.eyes_m = Some(eyes_m);
        }
    }

    /// Runs the steps due by sensor time `t_ns` (the first call only starts the clock); returns
    /// how many were simulated.
    pub fn advance_to(&mut self, t_ns: i64) -> u32 {
        let t0 = *self.t0_ns.get_or_insert(t_ns);
        let elapsed_ns = i128::from(t_ns) - i128::from(t0);
        if elapsed_ns < 0 {
            return 0; // time went backwards: wait for it
        }
        let hz = i128::from(self.params.step_hz);
        let due = (elapsed_ns * hz / 1_000_000_000) as u64;
        let mut pending = due.saturating_sub(self.steps);
        if pending > u64::from(self.params.max_catch_up_steps) {
            let skip = pending - u64::from(self.params.max_catch_up_steps);
            self.steps += skip;
            self.skipped_steps += skip;
            pending -= skip;
        }
        for _ in 0..pending {
            self.step();
        }
        // Between the last step and the next.
        let step_ns = 1_000_000_000 / hz;
        let since_last = elapsed_ns - i128::from(self.steps) * 1_000_000_000 / hz;
        self.alpha = (since_last as f32 / step_ns as f32).clamp(0.0, 1.0);
        pending as u32
    }

    fn step(&mut self) {
        if let Some(eyes) = self.eyes_m
            && self.placed.is_none_or(|(placed, _)| placed != eyes)
        {
            self.place_planes(eyes, false);
        }
        if let Some((index, target)) = self.grab
            && let Some(body) = self.handles.get(index).and_then(|&h| self.world.bodies.get_mut(h))
        {
            let to = target - from_rapier(body.translation());
            let v = (to * self.params.step_hz as f32).clamp_length_max(self.params.max_grab_speed_m_s);
            body.set_linvel(to_rapier(v), true);
            // Held, it neither falls nor spins away.
            body.set_angvel(to_rapier(Vec3::ZERO), true);
        }
        // rapier and parry can panic on degenerate contact geometry (parry's EPA indexed out
        // of bounds once, found by fuzzing the C ABI with extreme display and sensor input):
        // the world is then rebuilt from the last poses, at rest, and the frame goes on.
        let stepped = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            #[cfg(test)]
            if std::mem::take(&mut self.fault_next_step) {
                panic!("a fault injected by a test");
            }
            self.world.step();
        }));
        if stepped.is_err() {
            self.steps += 1;
            self.recover();
            return;
        }
        self.enforce_pyramids();
        self.steps += 1;
        let now = self.read_poses();
        self.previous = std::mem::replace(&mut self.current, now);
    }

    /// After a panic inside the physics engine (whose world may be half-stepped): a fresh world
    /// with the bodies where the last whole step left them, at rest, the same clock, gravity,
    /// eyes and starting poses (for [`Self::reset`]).
    fn recover(&mut self) {
        self.faults += 1;
        let here: Vec<BodySpec> = self
            .specs
            .iter()
            .zip(&self.current)
            .map(|(spec, pose)| BodySpec {
                start_m: pose.translation_m,
                start_rotation: pose.rotation,
                ..spec.clone()
            })
            .collect();
        // The specs were accepted once and the poses are finite (non-finite input is ignored
        // before it reaches the world), so this cannot fail; if it did, the old world stays.
        let Ok(mut fresh) = Diorama::new(&self.screen, here, self.params) else {
            return;
        };
        fresh.specs = std::mem::take(&mut self.specs);
        fresh.t0_ns = self.t0_ns;
        fresh.steps = self.steps;
        fresh.skipped_steps = self.skipped_steps;
        fresh.faults = self.faults;
        fresh.set_gravity(self.gravity);
        if let Some(eyes) = self.eyes_m {
            fresh.place_planes(eyes, true);
        }
        *self = fresh;
    }

    /// How many steps the physics engine panicked in, each recovered from by rebuilding the
    /// world at the last poses (0 in normal use; a count for the logs and the tests).
    pub fn faults(&self) -> u64 {
        self.faults
    }

    /// The tray and the pyramids as hard limits: after the solver, a body reaching more than
    /// [`CONTAINMENT_TOLERANCE_M`] through the tray's floor or a wall is moved back in, and one
    /// whose part in front of the glass
    /// reaches more than [`CONTAINMENT_TOLERANCE_M`] out of an eye's pyramid or the lid
    /// (pressed into a corner of three planes, the solver's soft contacts were seen to leave a
    /// die 2–3 mm out of both eyes' pyramids) is moved the shorter way back: onto the pyramids
    /// (the planes taken in turn until none is crossed: projections onto convex sets converge
    /// inside all of them) or just behind the glass, where the window may frame it. Its
    /// velocity out of the planes is removed.
    fn enforce_pyramids(&mut self) {
        let Some((eyes, pyramids)) = self.placed else { return };
        let lid = self.lid_plane(eyes);
        let planes: Vec<EyePlane> = pyramids.into_iter().chain(std::iter::once(lid)).collect();
        let tray = self.tray;
        for (&h, spec) in self.handles.iter().zip(&self.specs) {
            let Some(body) = self.world.bodies.get_mut(h) else {
                continue;
            };
            let to_body = quat_from_rapier(*body.rotation()).inverse();
            let front = |c: Vec3| c.z + spec.shape.support_m(to_body * Vec3::Z);
            let out_of = |c: Vec3, p: &EyePlane| spec.shape.support_m(to_body * -p.normal) - p.distance_m(c);
            // The tray's floor and walls first (at right angles: one pass each), so that no body
            // is left even partly through them (a coin wedged in a corner under a pile was).
            let into_tray = |c: Vec3| {
                tray.iter().fold(c, |c, p| {
                    let out = out_of(c, p);
                    if out > CONTAINMENT_TOLERANCE_M {
                        c + p.normal * out
                    } else {
                        c
                    }
                })
            };
            let original = from_rapier(body.translation());
            let start = into_tray(original);
            let in_view = front(start) <= 0.0 || planes.iter().all(|p| out_of(start, p) <= CONTAINMENT_TOLERANCE_M);
            if in_view {
                if start != original {
                    body.set_translation(to_rapier(start), true);
                    let mut velocity = from_rapier(body.linvel());
                    for p in &tray {
                        let into = velocity.dot(p.normal);
                        if into < 0.0 && out_of(original, p) > CONTAINMENT_TOLERANCE_M {
                            velocity -= p.normal * into;
                        }
                    }
                    body.set_linvel(to_rapier(velocity), true);
                }
                continue;
            }
            let mut inside = start;
            let mut crossed_normals: Vec<Vec3> = Vec::new();
            // In a narrow wedge each turn gains a fixed fraction: enough turns for millimetres.
            for _ in 0..32 {
                let mut crossed = false;
                for p in &planes {
                    let out = out_of(inside, p);
                    if out > CONTAINMENT_TOLERANCE_M {
                        inside += p.normal * out;
                        crossed = true;
                        if !crossed_normals.contains(&p.normal) {
                            crossed_normals.push(p.normal);
                        }
                    }
                }
                if !crossed {
                    break;
                }
            }
            let behind = start - Vec3::Z * front(start);
            // In a sliver of a pyramid (an eye low over the glass) the turns may not get inside
            // at all: then behind the glass it goes.
            let got_inside = planes.iter().all(|p| out_of(inside, p) <= CONTAINMENT_TOLERANCE_M);
            let (mut target, normals) = if !got_inside || start.distance(behind) < start.distance(inside) {
                (behind, vec![-Vec3::Z])
            } else {
                (inside, crossed_normals)
            };
            // Back into the tray if that left it; still out of view then, behind the glass.
            target = into_tray(target);
            if front(target) > 0.0 && planes.iter().any(|p| out_of(target, p) > CONTAINMENT_TOLERANCE_M) {
                target = into_tray(target - Vec3::Z * front(target));
            }
            let mut velocity = from_rapier(body.linvel());
            for n in normals {
                let into = velocity.dot(n);
                if into < 0.0 {
                    velocity -= n * into;
                }
            }
            body.set_translation(to_rapier(target), true);
            body.set_linvel(to_rapier(velocity), true);
        }
    }

    /// The lid over the tray, a fraction of the nearer eye's distance in front of the glass.
    fn lid_plane(&self, eyes_m: [Vec3; 2]) -> EyePlane {
        let lid_z = self.params.lid_fraction.clamp(0.05, 0.95) * eyes_m[0].z.min(eyes_m[1].z);
        EyePlane {
            normal: -Vec3::Z,
            offset_m: -lid_z,
        }
    }

    fn read_poses(&self) -> Vec<BodyPose> {
        self.handles
            .iter()
            .map(|&h| match self.world.bodies.get(h) {
                Some(b) => BodyPose {
                    translation_m: from_rapier(b.translation()),
                    rotation: quat_from_rapier(*b.rotation()),
                },
                None => BodyPose {
                    translation_m: Vec3::ZERO,
                    rotation: Quat::IDENTITY,
                },
            })
            .collect()
    }

    /// The bodies' poses for the frame at the last [`Self::advance_to`], interpolated between
    /// the last two steps. A body whose interpolated pose would reach out of the eyes' view in
    /// front of the glass (by more than [`CONTAINMENT_TOLERANCE_M`]) is drawn at its last
    /// step instead: the step was held inside the pyramids, the blend of two held poses need
    /// not be (the view in front of the glass and the tray behind it together are not convex:
    /// a body moved from under the window's frame onto the pyramids passes outside both).
    pub fn poses(&self) -> Vec<BodyPose> {
        let planes = self.pyramid_planes();
        self.previous
            .iter()
            .zip(&self.current)
            .zip(&self.specs)
            .map(|((a, b), spec)| {
                let blended = BodyPose {
                    translation_m: a.translation_m.lerp(b.translation_m, self.alpha),
                    rotation: a.rotation.slerp(b.rotation, self.alpha),
                };
                let escapes = planes
                    .as_ref()
                    .and_then(|planes| reach_out_of_view_m(&spec.shape, &blended, planes))
                    .is_some_and(|reach| reach > CONTAINMENT_TOLERANCE_M);
                if escapes { *b } else { blended }
            })
            .collect()
    }

    /// The poses after the last step, not interpolated (for checks and determinism).
    pub fn stepped_poses(&self) -> &[BodyPose] {
        &self.current
    }

    pub fn specs(&self) -> &[BodySpec] {
        &self.specs
    }

    /// Steps taken since the first [`Self::advance_to`] (simulated or skipped after a pause).
    pub fn steps(&self) -> u64 {
        self.steps
    }

    /// How many bodies the engine has put to sleep (at rest, not simulated until disturbed).
    pub fn sleeping_bodies(&self) -> usize {
        self.handles
            .iter()
            .filter(|&&h| self.world.bodies.get(h).is_some_and(|b| b.is_sleeping()))
            .count()
    }

    pub fn skipped_steps(&self) -> u64 {
        self.skipped_steps
    }

    /// The eight planes the pyramids stand on now (left eye's four first): those the last
    /// step held the bodies by. `None` before the eyes were first in front of the glass.
    pub fn pyramid_planes(&self) -> Option<[EyePlane; 8]> {
        self.placed.map(|(_, planes)| planes)
    }

    pub fn params(&self) -> &DioramaParams {
        &self.params
    }

    /// Holds body `index` for the finger at `target_m` (device frame).
    pub fn grab(&mut self, index: usize, target_m: Vec3) {
        if index < self.handles.len() && target_m.is_finite() {
            self.grab = Some((index, target_m));
        }
    }

    /// Moves the held body's target.
    pub fn drag_to(&mut self, target_m: Vec3) {
        if let Some((index, _)) = self.grab
            && target_m.is_finite()
        {
            self.grab = Some((index, target_m));
        }
    }

    /// Lets the held body go, with the velocity it had (a flick).
    pub fn release(&mut self) {
        self.grab = None;
    }

    /// The body the line from `origin_m` along `direction` meets first, if any.
    pub fn pick(&self, origin_m: Vec3, direction: Vec3) -> Option<usize> {
        let d = direction.try_normalize()?;
        let mut best: Option<(usize, f32)> = None;
        for (i, (pose, spec)) in self.current.iter().zip(&self.specs).enumerate() {
            // A sphere around each body is near enough for a finger.
            let r = spec.shape.bounding_radius_m();
            let oc = pose.translation_m - origin_m;
            let along = oc.dot(d);
            let miss = (oc - d * along).length();
            if along > 0.0 && miss <= r && best.is_none_or(|(_, t)| along < t) {
                best = Some((i, along));
            }
        }
        best.map(|(i, _)| i)
    }

    /// Back to the starting poses, at rest.
    pub fn reset(&mut self) {
        self.grab = None;
        for (&h, spec) in self.handles.iter().zip(&self.specs) {
            if let Some(b) = self.world.bodies.get_mut(h) {
                b.set_position(pose(spec.start_m, spec.start_rotation.normalize()), true);
                b.set_linvel(to_rapier(Vec3::ZERO), true);
                b.set_angvel(to_rapier(Vec3::ZERO), true);
            }
        }
        self.current = self.read_poses();
        self.previous = self.current.clone();
    }
}

#[cfg(test)]
#[path = "diorama_tests.rs"]
mod tests;
