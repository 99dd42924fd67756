//! The Diorama over recorded and synthetic tilting (issue 19's goals):
//!
//! * sixteen minutes of recorded handling (`imu/phone`, and two BROAD trials that turn the
//!   sensor over and round; needs `PHANTOGRAM_DATA`): no body ever reaches out of either eye's
//!   pyramid in front of the glass — as stepped, and as drawn (interpolated between steps)
//!   against the frame's own eyes — checked every frame from the planes through the eyes and
//!   the screen's edges, not from pixels; none leaves the tray through a wall, the floor or
//!   the lid, no NaN;
//! * the same log gives bit-identical final poses on two runs;
//! * tilt the phone so that a side of it is lower in the room, from any holding pose: the
//!   bodies end up on that side, in the world frame (synthetic orientations, and every steady
//!   stretch of the recordings);
//! * golden frames of the Diorama at rest and mid-slide.

use crate::golden;

use phantogram::FrameView;
use phantogram::diorama::DioramaScene;
use phantogram::glam::{Quat, Vec3};
use phantogram::physics::apparent_gravity::gravity_device;
use phantogram::physics::bodies::default_scene;
use phantogram::physics::diorama::{BodyPose, CONTAINMENT_TOLERANCE_M, Diorama, DioramaParams, reach_out_of_view_m};
use phantogram::physics::frustum::{EyePlane, stereo_pyramids};
use phantogram::screen::Screen;
use phantogram::sensors::{SensorEvent, SensorKind};
use phantogram::{Session, SessionConfig};
use phantogram_integration::data_subdir;
use phantogram_lab::sensorlog::import::import;

/// Frames of the replays: 30 a second of sensor time (the physics steps at 120 Hz regardless).
const FRAME_NS: i64 = 33_333_333;

/// What one replay found.
#[derive(Default)]
struct Findings {
    frames: usize,
    /// The largest reach of a body out of an eye's pyramid in front of the glass, metres, as
    /// stepped and as drawn.
    worst_escape_m: f32,
    /// Bodies found outside the tray (through a wall, the floor or the lid).
    outside_tray: usize,
    non_finite: usize,
    /// Steady stretches where the bodies were on the downhill side / all checked.
    downhill: (usize, usize),
    final_bits: Vec<u32>,
}

/// How far a body reaches out of the pyramids of the eyes it was stepped with (≤ 0: inside).
fn escape_m(world: &Diorama) -> f32 {
    let Some(planes) = world.pyramid_planes() else {
        return 0.0;
    };
    worst_reach_m(world.stepped_poses(), world, &planes)
}

/// How far a body *as drawn* (interpolated between steps) reaches out of the pyramids of the
/// frame's own eyes, the planes through each eye and the screen's edges (≤ 0: inside).
fn drawn_escape_m(world: &Diorama, screen: &Screen, eyes: [Vec3; 2]) -> f32 {
    let Some(planes) = stereo_pyramids(screen, eyes) else {
        return 0.0;
    };
    worst_reach_m(&world.poses(), world, &planes)
}

fn worst_reach_m(poses: &[BodyPose], world: &Diorama, planes: &[EyePlane]) -> f32 {
    poses
        .iter()
        .zip(world.specs())
        .filter_map(|(pose, spec)| reach_out_of_view_m(&spec.shape, pose, planes))
        .fold(0.0, f32::max)
}

/// Bodies reaching through the tray's floor or a wall, or its lid, by more than the
/// containment tolerance (from their shapes, not their centres).
fn outside_tray(world: &Diorama, screen: &Screen, eyes: [Vec3; 2]) -> usize {
    let (hw, hh) = (screen.width_m() / 2.0, screen.height_m() / 2.0);
    let (r, u) = (screen.right_device(), screen.up_device());
    let lid = world.params().lid_fraction * eyes[0].z.min(eyes[1].z);
    // Inward normals and offsets: n · p ≥ offset inside.
    let limits = [
        (Vec3::Z, -world.params().depth_m),
        (-Vec3::Z, -lid),
        (r, -hw),
        (-r, -hw),
        (u, -hh),
        (-u, -hh),
    ];
    world
        .stepped_poses()
        .iter()
        .zip(world.specs())
        .filter(|(p, spec)| {
            limits.iter().any(|(n, offset)| {
                let reach = spec.shape.support_m(p.rotation.inverse() * -*n);
                reach - (n.dot(p.translation_m) - offset) > CONTAINMENT_TOLERANCE_M + 1e-5
            })
        })
        .count()
}

/// The bodies' centre of mass in the device frame.
fn centroid(world: &Diorama) -> Vec3 {
    let poses = world.stepped_poses();
    poses.iter().map(|p| p.translation_m).sum::<Vec3>() / poses.len().max(1) as f32
}

/// Whether the bodies lie on the downhill side of the tray in the room: their centroid's offset
/// from the tray's centre, in the world, along the floor's steepest descent. `None` where the
/// floor is too flat for a body to slide (within 40° of level: friction may hold a die).
fn on_downhill_side(world: &Diorama, device_to_world: Quat) -> Option<bool> {
    let floor_normal = device_to_world * Vec3::Z;
    let down = Vec3::new(0.0, 0.0, -1.0);
    let along_floor = down - floor_normal * down.dot(floor_normal);
    if along_floor.length() < 40f32.to_radians().sin() {
        return None;
    }
    let offset = device_to_world * (centroid(world) - Vec3::new(0.0, 0.0, -world.params().depth_m));
    Some(offset.dot(along_floor.normalize()) > 0.005)
}

/// Replays `events` (at most `max_s` seconds) through a session into the Diorama as the engine
/// does, checking every frame.
fn replay(events: &[SensorEvent], max_s: f64) -> Findings {
    let mut session = Session::new(SessionConfig::default()).unwrap();
    let screen = session.config().screen;
    let mut scene = DioramaScene::new(&screen).unwrap();
    let mut found = Findings::default();
    let Some(t0) = events.first().map(|e| e.t_ns) else {
        return found;
    };
    let end = t0 + (max_s * 1e9) as i64;
    let mut next = 0usize;
    let mut t = t0;
    // Orientation history for the steady stretches: (time, device → world).
    let mut recent: Vec<(i64, Quat)> = Vec::new();
    let inbox = session.inbox();
    while t <= end && next < events.len() {
        while next < events.len() && events[next].t_ns <= t {
            let _ = inbox.push(events[next]);
            next += 1;
        }
        let view: FrameView = session.frame_at(Some(t)).unwrap();
        scene.update(&view, session.newest_specific_force(), t);
        let world = scene.world();
        found.frames += 1;
        found.worst_escape_m =
            found
                .worst_escape_m
                .max(escape_m(world))
                .max(drawn_escape_m(world, &screen, view.stereo_eyes_m()));
        let out = outside_tray(world, &screen, view.stereo_eyes_m());
        found.outside_tray += out;
        found.non_finite += world
            .stepped_poses()
            .iter()
            .filter(|p| !(p.translation_m.is_finite() && p.rotation.is_finite()))
            .count();
        if let Some(q) = view.device_to_world {
            recent.push((t, q));
            recent.retain(|(at, _)| t - at <= 2_000_000_000);
            // Held still for two seconds (within 5°): the bodies have settled where it is low.
            let steady = recent.first().is_some_and(|(at, _)| t - at >= 1_900_000_000)
                && recent.iter().all(|(_, r)| r.angle_between(q) < 5f32.to_radians());
            if steady && let Some(ok) = on_downhill_side(world, q) {
                found.downhill.1 += 1;
                found.downhill.0 += usize::from(ok);
            }
        }
        t += FRAME_NS;
    }
    found.final_bits = scene
        .world()
        .stepped_poses()
        .iter()
        .flat_map(|p| p.translation_m.to_array().into_iter().chain(p.rotation.to_array()))
        .map(f32::to_bits)
        .collect();
    found
}

fn phone_trials() -> Option<Vec<(String, Vec<SensorEvent>)>> {
    let dir = data_subdir("imu/phone")?;
    let mut names: Vec<_> = std::fs::read_dir(&dir).ok()?.flatten().map(|e| e.path()).collect();
    names.sort();
    Some(imported(&names))
}

/// BROAD trials that turn the sensor over and round (face down too), slowly and fast: the
/// bodies fall out of the tray into the front space, where the pyramids must hold them.
fn turning_trials() -> Option<Vec<(String, Vec<SensorEvent>)>> {
    let dir = data_subdir("imu/broad")?;
    let names = [
        "02_undisturbed_slow_rotation_B.csv.gz",
        "07_undisturbed_fast_rotation_B.csv.gz",
    ]
    .map(|n| dir.join(n));
    Some(imported(&names))
}

fn imported(names: &[std::path::PathBuf]) -> Vec<(String, Vec<SensorEvent>)> {
    names
        .iter()
        .map(|p| {
            let events = import(p).unwrap_or_else(|e| panic!("{}: {e}", p.display())).events;
            (p.file_name().unwrap().to_string_lossy().into_owned(), events)
        })
        .collect()
}

#[test]
fn ten_minutes_of_recorded_handling_keep_every_body_in_view_and_in_the_tray() {
    let (Some(mut trials), Some(turning)) = (phone_trials(), turning_trials()) else {
        return;
    };
    trials.extend(turning);
    let mut total_s = 0.0;
    let (mut downhill, mut steady) = (0, 0);
    for (name, events) in &trials {
        let f = replay(events, 1e9);
        let seconds = f.frames as f64 * FRAME_NS as f64 * 1e-9;
        total_s += seconds;
        eprintln!(
            "{name}: {seconds:.0} s, worst reach out of a pyramid {:.3} mm, {} outside the tray, {} non-finite, downhill {}/{}",
            f.worst_escape_m * 1e3,
            f.outside_tray,
            f.non_finite,
            f.downhill.0,
            f.downhill.1
        );
        assert!(
            f.worst_escape_m <= CONTAINMENT_TOLERANCE_M + 1e-6,
            "{name}: a body reached {:.2} mm out of an eye's view",
            f.worst_escape_m * 1e3
        );
        assert_eq!((f.outside_tray, f.non_finite), (0, 0), "{name}");
        downhill += f.downhill.0;
        steady += f.downhill.1;
    }
    assert!(total_s >= 600.0, "only {total_s:.0} s of recordings");
    // Wherever the phone was held still and tilted enough for bodies to slide, they lay on its
    // lower side in the room.
    assert!(steady >= 50, "only {steady} steady, tilted frames");
    assert_eq!(
        downhill,
        steady,
        "bodies on the high side in {} frames",
        steady - downhill
    );
}

#[test]
fn the_same_log_gives_bit_identical_poses() {
    let events = match phone_trials() {
        Some(mut trials) => trials.swap_remove(0).1,
        None => {
            // Without the shared data: the default tilt log of the repository.
            let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/logs/tilt-sweep.pglog");
            import(&path).unwrap().events
        }
    };
    let (a, b) = (replay(&events, 60.0), replay(&events, 60.0));
    assert!(a.frames > 100 && !a.final_bits.is_empty());
    assert!(a.final_bits == b.final_bits, "two runs of one log differ");
}

/// Every holding pose (turned about the vertical, tilted from lying flat through upright to
/// face down), then turned 40° about the world's vertical-plane axis so that one side of the
/// phone goes down in the room: the bodies gather on that side of the phone, and downhill along
/// the tray's floor, in the world.
#[test]
fn tilted_to_one_side_in_the_room_the_bodies_end_up_on_that_side_from_any_pose() {
    let screen = Screen::default();
    let params = DioramaParams::default();
    let eyes = [Vec3::new(-0.0315, 0.0, 0.3), Vec3::new(0.0315, 0.0, 0.3)];
    let mut checked = 0;
    for yaw_deg in [0.0f32, 90.0, 200.0, 300.0] {
        for pitch_deg in [0.0f32, 35.0, 70.0, 110.0, 160.0] {
            for roll_deg in [-40.0f32, 40.0] {
                let pose = Quat::from_rotation_z(yaw_deg.to_radians()) * Quat::from_rotation_x(pitch_deg.to_radians());
                // Turned about the phone's own long axis as it lies in the room: its left or
                // right edge goes down.
                let q = pose * Quat::from_rotation_y(roll_deg.to_radians());
                // Which edge is lower in the room, and by how much its side slopes.
                let x_down = (q * Vec3::X).z;
                if x_down.abs() < 20f32.to_radians().sin() {
                    continue; // the edges level: no side to gather on
                }
                let lower_side = -x_down.signum();
                let mut world = Diorama::new(&screen, default_scene(&screen, -params.depth_m, 30), params).unwrap();
                world.set_eyes(eyes);
                world.set_gravity(gravity_device(q));
                for k in 0..=480 {
                    world.advance_to(k * 8_333_334);
                }
                let c = centroid(&world);
                let label = format!("yaw {yaw_deg}°, pitch {pitch_deg}°, roll {roll_deg}°");
                // Face down they fall out of the tray into the eyes' narrowing pyramids, which
                // leave them less room to the side than the tray's floor does.
                let facing_up = (q * Vec3::Z).z > 0.0;
                let least_m = if facing_up { 0.008 } else { 0.002 };
                assert!(
                    c.x * lower_side > least_m,
                    "{label}: centroid {c} (device), lower edge {lower_side}"
                );
                if let Some(downhill) = on_downhill_side(&world, q) {
                    assert!(downhill, "{label}: not downhill along the floor");
                }
                checked += 1;
            }
        }
    }
    assert!(checked >= 20, "{checked}");
}

/// A replayed sensor history for the golden frames: held still at `tilt_deg` from flat about
/// the screen's x axis (the viewer's pose), then rolled by `roll_deg` at 1 s.
fn tilt_events(tilt_deg: f32, roll_deg: f32, until_s: f32) -> Vec<SensorEvent> {
    let mut events = Vec::new();
    let mut k = 0i64;
    while (k as f32) * 0.005 <= until_s {
        let t = k * 5_000_000;
        let roll = if t >= 1_000_000_000 { roll_deg } else { 0.0 };
        let q = Quat::from_rotation_y(roll.to_radians()) * Quat::from_rotation_x(tilt_deg.to_radians());
        let up = q.inverse() * Vec3::Z * 9.81;
        events.push(SensorEvent::accelerometer(t, up));
        events.push(SensorEvent::gyroscope(t, Vec3::ZERO));
        k += 1;
    }
    let _ = SensorKind::Accelerometer;
    events
}

#[test]
fn the_diorama_at_rest_and_mid_slide_matches_its_golden_frames() {
    use phantogram::engine::Engine;
    let Some(mut engine) = diorama_engine() else {
        return;
    };
    assert!(engine.diorama().is_some(), "the Diorama is on screen");
    let (w, h) = OFFSCREEN_PX;
    let events = tilt_events(35.0, -30.0, 3.0);
    let inbox = engine.inbox();
    let mut next = 0;
    let mut frame_at = |engine: &mut Engine, t: i64| {
        while next < events.len() && events[next].t_ns <= t {
            inbox.push(events[next]).unwrap();
            next += 1;
        }
        engine.draw(Some(t)).unwrap();
    };
    // At rest on the tilted floor, then 0.3 s into the roll, then settled again.
    let mut t = 0;
    while t <= 950_000_000 {
        frame_at(&mut engine, t);
        t += 50_000_000;
    }
    let rest = engine.last_frame().unwrap().2.to_vec();
    while t <= 1_300_000_000 {
        frame_at(&mut engine, t);
        t += 50_000_000;
    }
    let sliding = engine.last_frame().unwrap().2.to_vec();
    let differing = phantogram_integration::differing_pixels(&rest, &sliding);
    assert!(differing > 2000, "the roll moved the bodies ({differing} pixels)");
    golden::check("diorama-rest", w, h, &rest, 3, 0.003);
    golden::check("diorama-sliding", w, h, &sliding, 3, 0.003);
}

/// The offscreen target [`diorama_engine`] draws into, pixels.
const OFFSCREEN_PX: (u32, u32) = (180, 400);

/// An engine showing the Diorama offscreen ([`OFFSCREEN_PX`]); `None` (skipped) without a GPU
/// adapter.
fn diorama_engine() -> Option<phantogram::engine::Engine> {
    let mut engine = phantogram_integration::engine_or_skip(phantogram::engine::EngineConfig {
        artifact: Some("builtin:diorama".parse().unwrap()),
        ..phantogram::engine::EngineConfig::default()
    })?;
    engine.resume_offscreen(OFFSCREEN_PX.0, OFFSCREEN_PX.1).unwrap();
    Some(engine)
}

/// One second lying flat, a frame every 50 ms: the bodies settle where they start.
fn lie_flat(engine: &mut phantogram::engine::Engine) {
    let ms = 1_000_000;
    for k in 0..20 {
        engine
            .inbox()
            .push(SensorEvent::accelerometer(k * 50 * ms, Vec3::Z * 9.81))
            .unwrap();
        engine.draw(Some(k * 50 * ms)).unwrap();
    }
}

/// The finger in the Diorama through the engine, as a shell sends touches: a drag on a body
/// carries it across the tray; a double tap puts everything back.
#[test]
fn a_finger_drags_a_body_and_a_double_tap_resets_the_diorama() {
    use phantogram::gesture::TouchPhase;
    let Some(mut engine) = diorama_engine() else {
        return;
    };
    let w = OFFSCREEN_PX.0;
    let ms = 1_000_000;
    lie_flat(&mut engine);
    let world = engine.diorama().unwrap().world();
    let before = world.stepped_poses().to_vec();
    // The body nearest the screen's centre, and where it is drawn.
    let screen = Screen::default();
    let (i, at) = before
        .iter()
        .enumerate()
        .min_by(|a, b| {
            a.1.translation_m
                .truncate()
                .length()
                .total_cmp(&b.1.translation_m.truncate().length())
        })
        .map(|(i, p)| (i, p.translation_m))
        .unwrap();
    let eye = Vec3::Z * 0.3;
    let on_glass = |p: Vec3| eye + (p - eye) * (eye.z / (eye.z - p.z));
    let px = screen.pixel_of_glass_point(on_glass(at)) * (w as f32 / screen.width_px() as f32);
    let mut t = 1000;
    engine.touch(TouchPhase::Down, 0, px.x, px.y, t * ms);
    // 15 mm to the right on the glass, over half a second, drawing meanwhile.
    let right_px = 15.0 / 25.4 * screen.panel().xdpi * (w as f32 / screen.width_px() as f32);
    for k in 1..=30 {
        t += 16;
        engine.touch(TouchPhase::Move, 0, px.x + right_px * k as f32 / 30.0, px.y, t * ms);
        engine.draw(Some(t * ms)).unwrap();
    }
    engine.touch(TouchPhase::Up, 0, px.x + right_px, px.y, (t + 16) * ms);
    for _ in 0..10 {
        t += 50;
        engine.draw(Some(t * ms)).unwrap();
    }
    let moved = engine.diorama().unwrap().world().stepped_poses()[i].translation_m;
    assert!(
        moved.x - at.x > 0.008,
        "dragged {:.1} mm to the right",
        (moved.x - at.x) * 1e3
    );
    // A double tap away from the bodies: back to the start.
    let corner = (5.0, 5.0);
    for k in 0..2 {
        let t0 = t + 100 + k * 150;
        engine.touch(TouchPhase::Down, 0, corner.0, corner.1, t0 * ms);
        engine.touch(TouchPhase::Up, 0, corner.0, corner.1, (t0 + 60) * ms);
    }
    let reset = engine.diorama().unwrap().world();
    assert_eq!(
        reset.stepped_poses()[i].translation_m,
        reset.specs()[i].start_m,
        "the double tap put it back"
    );
}

/// A display density no screen has is refused through the engine, and the Diorama keeps the
/// screen it had. Found by fuzzing the C ABI: after random display calls the tray was 10⁻²⁷ m wide
/// and 10¹⁷ m tall, and one physics step (rapier's continuous collision detection on bodies at
/// 10¹⁷ m, where a float's step is kilometres) ran for over 45 s.
#[test]
fn a_display_no_screen_has_is_refused_and_the_diorama_goes_on() {
    use phantogram::engine::ErrorKind;
    use phantogram::screen::{DisplayRotation, PanelSpec};
    let Some(mut engine) = diorama_engine() else {
        return;
    };
    let screen = engine.session().config().screen;
    for (width_px, height_px, xdpi, ydpi) in [(1, 1000, 1.4e25f32, 400.0f32), (1080, 1000, 400.0, 9.4e-20)] {
        let panel = PanelSpec {
            width_px,
            height_px,
            xdpi,
            ydpi,
        };
        let refused = engine.set_display(panel, DisplayRotation::Deg0);
        assert_eq!(
            refused.map_err(|e| e.kind()),
            Err(ErrorKind::InvalidArgument),
            "{panel:?}"
        );
        assert_eq!(engine.session().config().screen, screen, "the screen is kept");
    }
    lie_flat(&mut engine);
    let half = screen.half_extent_device_m();
    for pose in engine.diorama().unwrap().world().stepped_poses() {
        let p = pose.translation_m;
        assert!(p.x.abs() <= half.x && p.y.abs() <= half.y, "a body left the tray: {p}");
    }
}
