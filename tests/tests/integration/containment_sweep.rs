//! Front-space containment over a replayed tilt sweep: in no frame may geometry in front of the
//! glass fall outside either eye's frustum, and the push-back never jumps by more than its
//! per-frame limit. The check projects sample points of the pushed-back object with each eye's
//! projection matrix — independent of the containment geometry it checks.

use phantogram::containment::{Aabb, ContainmentSmoother, required_push_back_m};
use phantogram::glam::Vec3;
use phantogram::synthetic::{ImuSpec, tilt_sweep};
use phantogram::{FrameView, Session, SessionConfig};
use phantogram_lab::replay::{Pace, replay};

const FRAME_NS: i64 = 16_666_667; // 60 Hz

/// An artifact 4 × 6 cm across, 9 cm tall, standing 4 cm out of the glass.
fn artifact() -> Aabb {
    Aabb::new(Vec3::new(-0.02, -0.03, -0.05), Vec3::new(0.02, 0.03, 0.04))
}

/// Sample points of the box's part in front of the glass that fall outside a frustum, as
/// (eye index, point, ndc).
fn escapes(view: &FrameView, bounds: &Aabb) -> Vec<(usize, Vec3, [f32; 2])> {
    let mut out = Vec::new();
    for p in bounds.lattice(8).filter(|p| p.z > 0.0) {
        for (e, proj) in [view.left, view.right].iter().enumerate() {
            let q = proj.project(p).expect("in front of the eye");
            let inside = q.ndc.abs().max_element() <= 1.0 + 1e-4 && (0.0..=1.0).contains(&q.depth);
            if !inside {
                out.push((e, p, q.ndc.to_array()));
            }
        }
    }
    out
}

struct SweepResult {
    frames: usize,
    frames_needing_push: usize,
    violations: usize,
    max_step_m: f32,
    max_push_m: f32,
}

fn sweep(smoother: ContainmentSmoother) -> SweepResult {
    let mut session = Session::new(SessionConfig::default()).unwrap();
    let events = tilt_sweep(&ImuSpec::default());
    let bounds = artifact();
    let mut smoother = smoother;
    let mut last = 0.0f32;
    let mut r = SweepResult {
        frames: 0,
        frames_needing_push: 0,
        violations: 0,
        max_step_m: 0.0,
        max_push_m: 0.0,
    };
    let mut calibrated = false;
    replay(
        events.into_iter().map(Ok),
        &mut session,
        FRAME_NS,
        Pace::AsFastAsPossible,
        |session, t_ns, view| {
            // The viewer holds the phone at its resting 35° and calls that straight on.
            if !calibrated && t_ns >= 500_000_000 {
                session.calibrate_flat_angle().unwrap();
                calibrated = true;
            }
            let screen = &session.config().screen;
            let required = required_push_back_m(&bounds, &view.stereo_eyes_m(), screen);
            let push = smoother.update(required, FRAME_NS as f32 * 1e-9);
            r.frames += 1;
            r.frames_needing_push += usize::from(required > 0.0);
            r.max_step_m = r.max_step_m.max((push - last).abs());
            r.max_push_m = r.max_push_m.max(push);
            last = push;
            r.violations += usize::from(!escapes(view, &bounds.translated(Vec3::Z * -push)).is_empty());
        },
    )
    .unwrap();
    r
}

#[test]
fn nothing_protrudes_and_the_push_back_never_pops() {
    let smoother = ContainmentSmoother::default();
    let r = sweep(smoother);
    println!(
        "containment sweep: {} frames, {} needing push-back, max push-back {:.1} mm, max step {:.2} mm/frame (limit {:.1})",
        r.frames,
        r.frames_needing_push,
        r.max_push_m * 1000.0,
        r.max_step_m * 1000.0,
        smoother.max_step_m * 1000.0
    );
    assert!(r.frames > 600, "the sweep lasts 12 s at 60 Hz");
    assert!(
        r.frames_needing_push > 100,
        "the sweep must actually exercise containment"
    );
    assert_eq!(r.violations, 0, "frames with geometry outside a frustum");
    assert!(r.max_step_m <= smoother.max_step_m + 1e-6);
}

#[test]
fn the_check_catches_a_push_back_that_lags() {
    // A smoother 30× slower than the default cannot follow the sweep: the frustum check must see it.
    let r = sweep(ContainmentSmoother::new(0.0001, 0.0, 0.5));
    assert!(r.violations > 0);
}

#[test]
fn unpushed_artifact_would_protrude() {
    // Without containment the same artifact breaks the frame edge from a grazing view.
    let mut session = Session::new(SessionConfig::default()).unwrap();
    let tilt = 50f32.to_radians();
    session
        .push(phantogram::sensors::SensorEvent::accelerometer(
            0,
            Vec3::new(tilt.sin(), 0.0, tilt.cos()) * 9.81,
        ))
        .unwrap();
    let view = session.frame().unwrap();
    assert!(!escapes(&view, &artifact()).is_empty());
    let d = required_push_back_m(&artifact(), &view.stereo_eyes_m(), &session.config().screen);
    assert!(escapes(&view, &artifact().translated(Vec3::Z * -d)).is_empty());
}
