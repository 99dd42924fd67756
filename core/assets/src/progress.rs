//! How far a long load has come, and the request to give it up: shared between the thread that
//! loads and the one that draws the progress bar (or the user's "Cancel").
//!
//! A [`Progress`] is a fraction in [0, 1] that only grows, and a cancel flag. The loader reports at
//! its natural steps (file read, buffers, each image decoded, each mesh built) and checks the flag
//! at the same steps, so a cancelled load ends within one step — one image or one mesh, well under a
//! second for the scans we meet — with [`Cancelled`].
//!
//! **Threading**: lock-free atomics; share it by `Arc`. **Panics**: none.

use std::sync::atomic::{AtomicBool, AtomicU32, Ordering};

/// A load's progress and its cancel flag (see the module docs).
#[derive(Debug, Default)]
pub struct Progress {
    /// The fraction's `f32` bits.
    fraction_bits: AtomicU32,
    cancelled: AtomicBool,
}

/// The load was given up ([`Progress::cancel`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error("cancelled")]
pub struct Cancelled;

impl Progress {
    pub fn new() -> Self {
        Self::default()
    }

    /// How far the load has come, 0 to 1.
    pub fn fraction(&self) -> f32 {
        f32::from_bits(self.fraction_bits.load(Ordering::Relaxed))
    }

    /// Reports `fraction` (clamped to [0, 1]); a smaller value than the last is ignored, so that
    /// steps reported from several threads never make the bar go back.
    pub fn advance_to(&self, fraction: f32) {
        let f = if fraction.is_nan() {
            0.0
        } else {
            fraction.clamp(0.0, 1.0)
        };
        // Non-negative floats order as their bits do.
        self.fraction_bits.fetch_max(f.to_bits(), Ordering::Relaxed);
    }

    /// Asks the load to stop at its next step.
    pub fn cancel(&self) {
        self.cancelled.store(true, Ordering::Relaxed);
    }

    pub fn is_cancelled(&self) -> bool {
        self.cancelled.load(Ordering::Relaxed)
    }

    /// Reports `fraction` and fails if the load was cancelled: what a loader calls at each step.
    pub fn step(&self, fraction: f32) -> Result<(), Cancelled> {
        self.advance_to(fraction);
        if self.is_cancelled() { Err(Cancelled) } else { Ok(()) }
    }
}

/// Maps a step's own progress (0 to 1) onto its share `[from, to]` of the whole load.
#[derive(Clone, Copy, Debug)]
pub struct Span<'a> {
    pub progress: &'a Progress,
    pub from: f32,
    pub to: f32,
}

impl<'a> Span<'a> {
    pub fn new(progress: &'a Progress, from: f32, to: f32) -> Self {
        Self { progress, from, to }
    }

    /// The whole's fraction when `done` of this step (0 to 1) is done.
    pub fn at(&self, done: f32) -> f32 {
        self.from + (self.to - self.from) * done.clamp(0.0, 1.0)
    }

    /// Reports `done` of this step (0 to 1) and fails if the load was cancelled.
    pub fn step(&self, done: f32) -> Result<(), Cancelled> {
        self.progress.step(self.at(done))
    }

    /// Reports `done` of this step without looking at the cancel flag (from a task that cannot
    /// stop half-way).
    pub fn advance(&self, done: f32) {
        self.progress.advance_to(self.at(done));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_fraction_only_grows_and_stays_within_zero_and_one() {
        let p = Progress::new();
        assert_eq!(p.fraction(), 0.0);
        p.advance_to(0.5);
        p.advance_to(0.25);
        assert_eq!(p.fraction(), 0.5);
        p.advance_to(7.0);
        assert_eq!(p.fraction(), 1.0);
        let q = Progress::new();
        q.advance_to(f32::NAN);
        q.advance_to(-3.0);
        assert_eq!(q.fraction(), 0.0);
    }

    #[test]
    fn a_cancelled_load_fails_at_its_next_step() {
        let p = Progress::new();
        assert_eq!(p.step(0.1), Ok(()));
        p.cancel();
        assert_eq!(p.step(0.2), Err(Cancelled));
        assert_eq!(p.fraction(), 0.2);
    }

    #[test]
    fn spans_map_onto_their_share_of_the_whole() {
        let p = Progress::new();
        let s = Span::new(&p, 0.2, 0.6);
        s.step(0.5).unwrap();
        assert!((p.fraction() - 0.4).abs() < 1e-6);
        s.advance(1.0);
        assert!((p.fraction() - 0.6).abs() < 1e-6);
        p.cancel();
        s.advance(0.9);
        assert!((p.fraction() - 0.6).abs() < 1e-6, "never back, cancelled or not");
    }
}
