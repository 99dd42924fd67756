//! `cargo bench -p phantogram --bench core` (or `cargo xtask bench core`): nanoseconds per sensor
//! update and per frame (viewpoint + left, right and mono projections + world light).
//!
//! A plain timing harness rather than criterion: two figures, printed as the median of several
//! rounds, are all this needs. Compare figures from one run; the machine is shared and noisy.

use std::hint::black_box;
use std::time::Instant;

use phantogram::session::EstimatorChoice;
use phantogram::synthetic::{ImuSpec, tilt_sweep};
use phantogram::{Session, SessionConfig};

fn median(mut xs: Vec<f64>) -> f64 {
    xs.sort_by(f64::total_cmp);
    xs[xs.len() / 2]
}

fn main() {
    // `cargo test --benches` runs bench targets with `--bench`-less args; keep that quick.
    let quick = std::env::args().any(|a| a == "--test" || a == "--list");
    let rounds = if quick { 1 } else { 7 };
    let events = tilt_sweep(&ImuSpec::default());
    let inertial: Vec<_> = events.iter().copied().filter(|e| !e.kind.is_orientation()).collect();

    let per_event = |config: SessionConfig| {
        let mut samples = Vec::new();
        for _ in 0..rounds {
            let mut session = Session::new(config).expect("valid config");
            let start = Instant::now();
            // Push and consume in batches of 4, as a 100 Hz sensor stream drains into 60 Hz frames.
            for chunk in inertial.chunks(4) {
                for e in chunk {
                    let _ = session.push(*e);
                }
                black_box(session.update());
            }
            samples.push(start.elapsed().as_nanos() as f64 / inertial.len() as f64);
        }
        median(samples)
    };
    let fused = per_event(SessionConfig::default());
    let low_pass = per_event(SessionConfig {
        estimator: EstimatorChoice::LowPass {
            tau_s: phantogram::attitude::LowPassAttitude::DEFAULT_TAU_S,
        },
        ..SessionConfig::default()
    });

    let frames = if quick { 1_000 } else { 100_000 };
    let mut per_frame = Vec::new();
    let mut session = Session::new(SessionConfig::default()).expect("default config");
    for e in &inertial[..inertial.len() / 2] {
        let _ = session.push(*e);
    }
    session.update();
    for _ in 0..rounds {
        let start = Instant::now();
        for _ in 0..frames {
            black_box(session.frame().expect("frame"));
        }
        per_frame.push(start.elapsed().as_nanos() as f64 / frames as f64);
    }

    println!("sensor update, fused estimator (push + drain + estimate):  {fused:8.1} ns/event");
    println!("sensor update, paper's low-pass (push + drain + estimate): {low_pass:8.1} ns/event");
    println!(
        "frame (viewpoint + 3 projections + light), fused:          {:8.1} ns/frame",
        median(per_frame)
    );
}
