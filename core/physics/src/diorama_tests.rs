use super::*;
use crate::bodies::default_scene;

const MS: i64 = 1_000_000;

fn scene(n: usize) -> (Screen, Diorama) {
    let screen = Screen::default();
    let params = DioramaParams::default();
    let bodies = default_scene(&screen, -params.depth_m, n);
    let d = Diorama::new(&screen, bodies, params).unwrap();
    (screen, d)
}

/// The largest amount by which any body's part in front of the glass leaves either eye's
/// pyramid, metres (≤ 0: none does).
fn worst_escape_m(d: &Diorama) -> f32 {
    let Some(planes) = d.pyramid_planes() else { return 0.0 };
    d.stepped_poses()
        .iter()
        .zip(d.specs())
        .filter_map(|(pose, spec)| reach_out_of_view_m(&spec.shape, pose, &planes))
        .fold(f32::MIN, f32::max)
}

#[test]
fn bodies_settle_on_the_floor_and_sleep() {
    let (_, mut d) = scene(20);
    let eyes = [Vec3::new(-0.0315, 0.0, 0.3), Vec3::new(0.0315, 0.0, 0.3)];
    d.set_eyes(eyes);
    for k in 0..=240 {
        d.advance_to(k * 10 * MS);
    }
    assert_eq!(d.steps(), 288, "2.4 s at 120 Hz");
    for (pose, spec) in d.stepped_poses().iter().zip(d.specs()) {
        let bottom = pose.translation_m.z - spec.shape.support_m(pose.rotation.inverse() * -Vec3::Z);
        assert!(
            bottom > -0.0305 && bottom < 0.0,
            "{:?} at {:?}",
            spec.kind,
            pose.translation_m
        );
        assert!(pose.translation_m.is_finite());
    }
}

#[test]
fn gravity_towards_the_left_edge_gathers_the_bodies_there() {
    let (screen, mut d) = scene(20);
    d.set_eyes([Vec3::new(-0.0315, 0.0, 0.3), Vec3::new(0.0315, 0.0, 0.3)]);
    // The phone rolled 40° with its left edge down.
    d.set_gravity(crate::apparent_gravity::gravity_device(Quat::from_rotation_y(
        -40f32.to_radians(),
    )));
    for k in 0..=300 {
        d.advance_to(k * 10 * MS);
    }
    let half_w = screen.width_m() / 2.0;
    for (pose, spec) in d.stepped_poses().iter().zip(d.specs()) {
        assert!(
            pose.translation_m.x < -half_w + 3.0 * spec.shape.bounding_radius_m() + 0.025,
            "{:?} stayed at x = {}",
            spec.kind,
            pose.translation_m.x
        );
    }
}

#[test]
fn the_same_inputs_give_bit_identical_poses() {
    let run = || {
        let (_, mut d) = scene(50);
        for k in 0..=400i64 {
            let a = k as f32 * 0.01;
            d.set_gravity(Vec3::new(a.sin() * 6.0, a.cos() * 3.0, -7.0));
            d.set_eyes([Vec3::new(-0.03 + a.sin() * 0.02, 0.0, 0.3), Vec3::new(0.033, 0.0, 0.3)]);
            d.advance_to(k * 16_666_667);
        }
        d.stepped_poses()
            .iter()
            .flat_map(|p| {
                p.translation_m
                    .to_array()
                    .into_iter()
                    .chain(p.rotation.to_array())
                    .map(f32::to_bits)
            })
            .collect::<Vec<u32>>()
    };
    assert_eq!(run(), run());
}

#[test]
fn bodies_thrown_at_the_glass_stay_inside_both_eyes_pyramids() {
    let (_, mut d) = scene(50);
    // Viewer off to the side and near: narrow, slanted pyramids.
    let eyes = [Vec3::new(0.02, -0.04, 0.22), Vec3::new(0.083, -0.04, 0.22)];
    d.set_eyes(eyes);
    // Gravity out of the glass, towards the eyes (the phone face down): everything falls
    // against the pyramids and the lid.
    d.set_gravity(Vec3::new(0.0, 0.0, 9.81));
    let mut worst = f32::MIN;
    for k in 0..=360 {
        d.advance_to(k * 10 * MS);
        worst = worst.max(worst_escape_m(&d));
    }
    assert!(
        worst <= CONTAINMENT_TOLERANCE_M + 1e-6,
        "a body stood {:.2} mm outside an eye's pyramid",
        worst * 1e3
    );
    let lid = 0.5 * 0.22;
    for (pose, spec) in d.stepped_poses().iter().zip(d.specs()) {
        let top = pose.translation_m.z + spec.shape.support_m(pose.rotation.inverse() * Vec3::Z);
        assert!(top < lid + 0.0005, "through the lid: {top}");
        assert!(pose.translation_m.z > 0.0, "everything fell towards the eyes");
    }
}

#[test]
fn a_dragged_body_is_stopped_by_the_wall_and_flicked_on_release() {
    let (screen, mut d) = scene(4);
    d.set_eyes([Vec3::new(-0.0315, 0.0, 0.3), Vec3::new(0.0315, 0.0, 0.3)]);
    for k in 0..=60 {
        d.advance_to(k * 10 * MS);
    }
    let start = d.stepped_poses()[0].translation_m;
    // Dragged far past the right wall: it ends at the wall.
    d.grab(0, start + Vec3::X * 0.2);
    for k in 61..=160 {
        d.advance_to(k * 10 * MS);
    }
    let at = d.stepped_poses()[0].translation_m;
    let r = d.specs()[0].shape.bounding_radius_m();
    assert!(
        (at.x - (screen.width_m() / 2.0 - r)).abs() < 0.002,
        "held against the wall at x = {}",
        at.x
    );
    // Back and released while moving left: it keeps going.
    d.drag_to(at - Vec3::X * 0.05);
    d.advance_to(161 * 10 * MS);
    d.release();
    let before = d.stepped_poses()[0].translation_m.x;
    d.advance_to(163 * 10 * MS);
    assert!(d.stepped_poses()[0].translation_m.x < before - 0.001, "flicked");
    // Picking: the line from a viewer through a body finds it.
    let p = d.stepped_poses()[1].translation_m;
    let eye = Vec3::Z * 0.3;
    assert_eq!(d.pick(eye, p - eye), Some(1));
    assert_eq!(d.pick(eye, Vec3::Z), None);
    d.reset();
    assert_eq!(d.stepped_poses()[0].translation_m, d.specs()[0].start_m);
}

#[test]
fn a_long_pause_is_skipped_and_nonsense_ignored() {
    let (_, mut d) = scene(10);
    d.advance_to(0);
    assert_eq!(d.advance_to(10_000 * MS), 12, "at most the catch-up steps");
    assert_eq!(d.steps(), 1200);
    assert!(d.skipped_steps() > 1000);
    assert_eq!(d.advance_to(5_000 * MS), 0, "time going backwards waits");
    d.set_gravity(Vec3::NAN);
    d.set_eyes([Vec3::NAN, Vec3::Z]);
    d.advance_to(10_100 * MS);
    assert!(
        d.poses()
            .iter()
            .all(|p| p.translation_m.is_finite() && p.rotation.is_finite())
    );
    // Bad settings and bodies are errors, not panics.
    let screen = Screen::default();
    let bad = DioramaParams {
        step_hz: 0,
        ..DioramaParams::default()
    };
    assert!(matches!(
        Diorama::new(&screen, vec![], bad),
        Err(DioramaError::StepRate(0))
    ));
    let mut body = default_scene(&screen, -0.03, 1).remove(0);
    body.shape = BodyShape::Ball { radius_m: f32::NAN };
    assert!(matches!(
        Diorama::new(&screen, vec![body], DioramaParams::default()),
        Err(DioramaError::Body { index: 0, .. })
    ));
}

#[test]
fn a_panic_inside_the_physics_engine_rebuilds_the_world_where_the_bodies_were() {
    let (_, mut d) = scene(20);
    d.set_eyes([Vec3::new(-0.0315, 0.0, 0.3), Vec3::new(0.0315, 0.0, 0.3)]);
    for k in 0..=100 {
        d.advance_to(k * 10 * MS);
    }
    let before = d.stepped_poses().to_vec();
    let steps = d.steps();
    d.fault_next_step = true;
    d.advance_to(101 * 10 * MS);
    assert_eq!(d.faults(), 1);
    assert_eq!(d.steps(), steps + 1, "the clock goes on");
    for (a, b) in before.iter().zip(d.stepped_poses()) {
        assert!(a.translation_m.distance(b.translation_m) < 1e-6, "{a:?} → {b:?}");
    }
    // And the rebuilt world runs on: tilted, the bodies slide, stay finite and in the tray.
    d.set_gravity(crate::apparent_gravity::gravity_device(Quat::from_rotation_y(
        -40f32.to_radians(),
    )));
    for k in 102..=300 {
        d.advance_to(k * 10 * MS);
    }
    assert_eq!(d.faults(), 1);
    let moved = before
        .iter()
        .zip(d.stepped_poses())
        .filter(|(a, b)| a.translation_m.distance(b.translation_m) > 0.005)
        .count();
    assert!(moved > 10, "only {moved} bodies slid after the rebuild");
    assert!(d.stepped_poses().iter().all(|p| p.translation_m.is_finite()));
    assert!(worst_escape_m(&d) <= CONTAINMENT_TOLERANCE_M + 1e-6);
    // The starting poses are the scene's, not the rebuild's.
    d.reset();
    assert_eq!(d.stepped_poses()[0].translation_m, d.specs()[0].start_m);
    let (_, fresh) = scene(20);
    assert_eq!(d.specs(), fresh.specs());
}
