//! `cargo bench -p phantogram-physics --bench step` (or `cargo xtask bench diorama`): time per
//! physics step of the diorama with 50 bodies, release build, on this machine: while the bodies
//! move (gravity turning as a tilted phone's does, the eyes moving), and once they sleep. Each
//! figure is the median over several blocks of steps; the machine is shared and noisy, so
//! compare figures of one run only.

use std::time::Instant;

use glam::{Quat, Vec3};
use phantogram_geometry::screen::Screen;
use phantogram_physics::apparent_gravity::gravity_device;
use phantogram_physics::bodies::default_scene;
use phantogram_physics::diorama::{Diorama, DioramaParams};

const BODIES: usize = 50;
/// Sensor time of step `k` at 120 Hz (rounded up, so that each is due at its time).
fn step_t_ns(k: i64) -> i64 {
    (k * 1_000_000_000 + 119) / 120
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let screen = Screen::default();
    let params = DioramaParams::default();
    let mut d = Diorama::new(&screen, default_scene(&screen, -params.depth_m, BODIES), params).expect("diorama");
    let mut k = 0i64;
    d.advance_to(step_t_ns(k));
    // Moving: the phone rocks ±35° about both axes at 0.5 Hz, the head sways.
    let mut moving = Vec::new();
    for block in 0..40 {
        let start = Instant::now();
        let mut steps = 0;
        for _ in 0..30 {
            let s = step_t_ns(k) as f32 * 1e-9;
            let q = Quat::from_rotation_y(0.6 * (s * std::f32::consts::PI).sin())
                * Quat::from_rotation_x(0.6 * (s * 1.3).cos());
            d.set_gravity(gravity_device(q));
            let sway = Vec3::new(0.02 * (s * 2.0).sin(), 0.0, 0.0);
            d.set_eyes([
                Vec3::new(-0.0315, -0.05, 0.3) + sway,
                Vec3::new(0.0315, -0.05, 0.3) + sway,
            ]);
            k += 1;
            steps += d.advance_to(step_t_ns(k));
        }
        assert_eq!(steps, 30, "one step per call");
        if block >= 5 {
            moving.push(start.elapsed().as_secs_f64() * 1e3 / 30.0);
        }
    }
    // At rest: lying flat, still eyes, until the bodies sleep.
    d.set_gravity(gravity_device(Quat::IDENTITY));
    d.set_eyes([Vec3::new(-0.0315, 0.0, 0.3), Vec3::new(0.0315, 0.0, 0.3)]);
    for _ in 0..1200 {
        k += 1;
        d.advance_to(step_t_ns(k));
    }
    let mut resting = Vec::new();
    for _ in 0..20 {
        let start = Instant::now();
        for _ in 0..30 {
            k += 1;
            d.advance_to(step_t_ns(k));
        }
        resting.push(start.elapsed().as_secs_f64() * 1e3 / 30.0);
    }
    println!(
        "diorama, {BODIES} bodies, 120 Hz: {:.3} ms per step while they move (gravity turning, eyes moving), {:.4} ms at rest ({} of {BODIES} asleep)",
        median(moving),
        median(resting),
        d.sleeping_bodies()
    );
}
